#include "algebra/high_precision.hpp"

#include "algebra/digits_guard.hpp"
#include "algebra/expression_text.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;
using GiNaC::numeric;

GiNaC::numeric exact_rational(double v) {
  if (!std::isfinite(v)) throw std::domain_error("exact_rational: not a finite number");
  if (v == 0) return 0;
  int e = 0;
  const double m = std::frexp(v, &e);  // v = m 2^e, 0.5 ≤ |m| < 1
  const auto mantissa = static_cast<long>(std::ldexp(m, 53));
  return numeric(mantissa) * GiNaC::pow(numeric(2), numeric(e - 53));
}

namespace {

numeric to_float(const numeric& v) {
  if (!v.is_rational()) return v;
  return ex_to<numeric>(v.evalf());
}

numeric integer_power(const numeric& base, const numeric& exponent) {
  // CLN's expt with an integer exponent is exact repeated squaring; a negative one divides.
  if (exponent.is_negative() && base.is_zero()) throw std::domain_error("high precision: 0 to a negative power");
  return GiNaC::pow(base, exponent);
}

numeric numeric_power(const numeric& base, const numeric& exponent) {
  if (exponent.is_integer()) return integer_power(base, exponent);
  if (base.is_negative()) throw std::domain_error("high precision: negative base of a fractional power");
  if (base.is_zero()) {
    if (exponent.is_negative()) throw std::domain_error("high precision: 0 to a negative power");
    return 0;
  }
  if ((2 * exponent).is_integer()) return integer_power(GiNaC::sqrt(to_float(base)), 2 * exponent);
  return GiNaC::exp(to_float(exponent) * GiNaC::log(to_float(base)));
}

}  // namespace

GiNaC::numeric high_precision(double v) { return to_float(exact_rational(v)); }

HighPrecision::Value HighPrecision::of(const numeric& v) {
  if (!v.is_real()) throw std::logic_error("high precision: complex number in an expression");
  return cln::the<cln::cl_R>(v.to_cl_N());
}

numeric HighPrecision::numeric_of(const Value& v) { return numeric(cln::cl_N(v)); }

HighPrecision::Value HighPrecision::constant(double v) { return of(high_precision(v)); }

HighPrecision::Value HighPrecision::divide(const Value& a, const Value& b) {
  if (cln::zerop(b)) throw std::domain_error("high precision: division by zero");
  return a / b;
}

HighPrecision::Value HighPrecision::power(const Value& base, const numeric& exponent) {
  if (!exponent.is_integer()) return of(numeric_power(numeric_of(base), exponent));
  if (exponent.is_equal(1)) return base;
  if (cln::zerop(base)) {
    if (exponent.is_negative()) throw std::domain_error("high precision: 0 to a negative power");
    if (exponent.is_zero()) return of(integer_power(numeric_of(base), exponent));  // GiNaC's own error
    return 0;
  }
  return cln::expt(base, cln::the<cln::cl_I>(exponent.to_cl_N()));
}

HighPrecision::Value HighPrecision::power(const Value& base, const Value& exponent) {
  return of(numeric_power(numeric_of(base), numeric_of(exponent)));
}

HighPrecision::Value HighPrecision::function(Op f, const Value& x) {
  const Function* fn = function_of(f);
  if (!fn) throw std::logic_error("high precision: not an elementary function");
  return of(fn->evaluate_exactly(to_float(numeric_of(x))));
}

// ---------------------------------------------------------------------------------------------------------

HighPrecisionExpressionEvaluator::HighPrecisionExpressionEvaluator(int digits)
    : digits_(digits), order_(std::make_unique<StructuralOrder>()) {}

HighPrecisionExpressionEvaluator::~HighPrecisionExpressionEvaluator() = default;

void HighPrecisionExpressionEvaluator::assign(const std::map<ex, numeric, GiNaC::ex_is_less>& values) {
  const DigitsGuard digits(digits_);
  values_.clear();
  for (const auto& [symbol, v] : values) values_[symbol] = HighPrecision::of(to_float(v));
  ++generation_;
}

void HighPrecisionExpressionEvaluator::define(const Intermediates& intermediates) {
  for (const Intermediates::Definition& d : intermediates.definitions()) definitions_[d.symbol] = d.value;
  number_.clear();  // compiled symbols may now be intermediates
  nodes_.clear();
  ++generation_;
}

GiNaC::numeric HighPrecisionExpressionEvaluator::value(const ex& e) {
  const int node = compile(e);
  const DigitsGuard digits(digits_);
  return HighPrecision::numeric_of(eval(node, false));
}

GiNaC::numeric HighPrecisionExpressionEvaluator::magnitude(const ex& e) {
  const int node = compile(e);
  const DigitsGuard digits(digits_);
  return HighPrecision::numeric_of(eval(node, true));
}

int HighPrecisionExpressionEvaluator::compile(const ex& e) {
  if (auto it = number_.find(e); it != number_.end()) return it->second;
  Node node{Kind::number, {}, e, nullptr, 0};
  if (is_a<numeric>(e)) {
    node.number = HighPrecision::of(ex_to<numeric>(e));
  } else if (is_a<GiNaC::symbol>(e)) {
    // An intermediate is its definition's node: the size of its definition, like the graph's node.
    if (auto def = definitions_.find(e); def != definitions_.end()) {
      const int n = compile(def->second);
      number_.emplace(e, n);
      return n;
    }
    node.kind = Kind::symbol;
  } else if (is_a<GiNaC::constant>(e)) {
    node.kind = Kind::constant;
  } else if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e)) {
    node.kind = is_a<GiNaC::add>(e) ? Kind::add : Kind::mul;
    // Terms and factors in structural order: the rounding of the sum or product does not follow GiNaC's order.
    std::vector<ex> operands;
    for (std::size_t i = 0; i < e.nops(); ++i) operands.push_back(e.op(i));
    std::stable_sort(operands.begin(), operands.end(), std::ref(*order_));
    for (const ex& o : operands) node.operands.push_back(compile(o));
  } else if (is_a<GiNaC::power>(e)) {
    node.kind = Kind::power;
    for (std::size_t i = 0; i < e.nops(); ++i) node.operands.push_back(compile(e.op(i)));
  } else if (is_a<GiNaC::function>(e)) {
    const std::string name = ex_to<GiNaC::function>(e).get_name();
    const Function* f = function_named(name);
    if (e.nops() != 1 || !f) throw std::logic_error("high precision: function '" + name + "' is not supported");
    node.kind = Kind::function;
    node.function = f;
    node.operands.push_back(compile(e.op(0)));
  } else {
    throw std::logic_error("high precision: unsupported expression type");
  }
  nodes_.push_back(std::move(node));
  const int n = static_cast<int>(nodes_.size()) - 1;
  number_.emplace(e, n);
  return n;
}

const cln::cl_R& HighPrecisionExpressionEvaluator::eval(int index, bool absolute) {
  const std::size_t k = static_cast<std::size_t>(index);
  std::vector<cln::cl_R>& computed = computed_[absolute ? 1 : 0];
  std::vector<unsigned>& stamp = stamp_[absolute ? 1 : 0];
  if (stamp.size() < nodes_.size()) stamp.resize(nodes_.size(), 0), computed.resize(nodes_.size());
  if (stamp[k] == generation_) return computed[k];
  const Node& node = nodes_[k];
  cln::cl_R v;
  switch (node.kind) {
    case Kind::number:
      v = node.number;
      break;
    case Kind::symbol: {
      const auto it = values_.find(node.expression);
      if (it == values_.end())
        throw std::logic_error("high precision: no value for symbol '" +
                               ex_to<GiNaC::symbol>(node.expression).get_name() + "'");
      v = it->second;
      break;
    }
    case Kind::constant:
      v = HighPrecision::of(ex_to<numeric>(node.expression.evalf()));
      break;
    case Kind::add:
      v = 0;
      for (int o : node.operands) v = v + eval(o, absolute);
      break;
    case Kind::mul:
      v = 1;
      for (int o : node.operands) v = v * eval(o, absolute);
      break;
    case Kind::power: {
      const Node& exponent = nodes_[static_cast<std::size_t>(node.operands[1])];
      if (exponent.kind != Kind::number) {
        v = HighPrecision::power(eval(node.operands[0], false), eval(node.operands[1], false));
      } else {
        const numeric& y = ex_to<numeric>(exponent.expression);
        // A divisor enters at its true value: |1/x| is not bounded by 1/magnitude(x).
        v = HighPrecision::power(eval(node.operands[0], absolute && y.is_positive()), y);
      }
      break;
    }
    case Kind::function:
      v = HighPrecision::function(node.function->op, eval(node.operands[0], false));
      break;
  }
  if (absolute) v = cln::abs(v);
  computed[k] = v;
  stamp[k] = generation_;
  return computed[k];
}

}  // namespace hamel
