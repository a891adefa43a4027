#include "algebra/operations.hpp"

#include <cmath>
#include <stdexcept>

namespace hamel {

namespace {

using GiNaC::numeric;

numeric exact_log(const numeric& x) {
  if (!x.is_positive()) throw std::domain_error("high precision: log of a non-positive number");
  return GiNaC::log(x);
}
numeric exact_asin(const numeric& x) {
  if (GiNaC::abs(x) > 1) throw std::domain_error("high precision: asin outside [-1, 1]");
  return GiNaC::asin(x);
}
numeric exact_sqrt(const numeric& x) {
  if (x.is_negative()) throw std::domain_error("high precision: sqrt of a negative number");
  return GiNaC::sqrt(x);
}
numeric exact_acos(const numeric& x) {
  if (GiNaC::abs(x) > 1) throw std::domain_error("high precision: acos outside [-1, 1]");
  return GiNaC::acos(x);
}

// The derivative rules: the tangent of y = op(a, b), with t the graph's constructors and x the operation's terms.
using T = TermBuilder;
using X = TangentOf;

int d_add(T& t, const X& x) { return t.add(x.da, x.db); }
int d_sub(T& t, const X& x) { return t.sub(x.da, x.db); }
int d_mul(T& t, const X& x) { return t.add(t.mul(x.da, x.b), t.mul(x.a, x.db)); }
int d_div(T& t, const X& x) { return t.div(t.sub(x.da, t.mul(x.y, x.db)), x.b); }  // (a' − (a/b) b') / b
int d_neg(T& t, const X& x) { return t.neg(x.da); }
int d_sqrt(T& t, const X& x) { return t.div(x.da, t.mul(t.constant(2), x.y)); }
int d_sin(T& t, const X& x) { return t.mul(t.unary(Op::cos, x.a), x.da); }
int d_cos(T& t, const X& x) { return t.neg(t.mul(t.unary(Op::sin, x.a), x.da)); }
int d_tan(T& t, const X& x) { return t.mul(t.add(t.constant(1), t.mul(x.y, x.y)), x.da); }
int d_exp(T& t, const X& x) { return t.mul(x.y, x.da); }
int d_log(T& t, const X& x) { return t.div(x.da, x.a); }
int d_asin(T& t, const X& x) { return t.div(x.da, t.unary(Op::sqrt, t.sub(t.constant(1), t.mul(x.a, x.a)))); }
int d_acos(T& t, const X& x) { return t.neg(d_asin(t, x)); }
int d_atan(T& t, const X& x) { return t.div(x.da, t.add(t.constant(1), t.mul(x.a, x.a))); }
int d_sinh(T& t, const X& x) { return t.mul(t.unary(Op::cosh, x.a), x.da); }
int d_cosh(T& t, const X& x) { return t.mul(t.unary(Op::sinh, x.a), x.da); }
int d_tanh(T& t, const X& x) { return t.mul(t.sub(t.constant(1), t.mul(x.y, x.y)), x.da); }
// sign(a) a' as a / |a|: branch-free, undefined at a = 0 like the derivative.
int d_abs(T& t, const X& x) { return t.mul(t.div(x.a, x.y), x.da); }
// (a^k)' = k a^(k−1) a' for a constant exponent k, else (a^b)' = a^b (b' log a + b a' / a).
int d_pow(T& t, const X& x) {
  double k = 0;
  if (t.is_constant(x.b, k)) return t.mul(t.mul(t.constant(k), t.binary(Op::pow, x.a, t.constant(k - 1))), x.da);
  return t.mul(x.y, t.add(t.mul(x.db, t.unary(Op::log, x.a)), t.div(t.mul(x.b, x.da), x.a)));
}

using D = double (*)(double);

std::vector<Operation> checked(std::vector<Operation> entries) {
  for (std::size_t i = 0; i < entries.size(); ++i)
    if (static_cast<std::size_t>(entries[i].op) != i) throw std::logic_error("operation table: not in the order of Op");
  return entries;
}
constexpr Notation none = Notation::none, infix = Notation::infix, prefix = Notation::prefix, call = Notation::call;

// Every operation, at its position in Op.
const std::vector<Operation>& table() {
  static const std::vector<Operation> entries = checked({
      {Op::constant, 0, none, nullptr, 4, Cost::none, nullptr, nullptr, nullptr, nullptr},
      {Op::input, 0, none, nullptr, 4, Cost::none, nullptr, nullptr, nullptr, nullptr},
      {Op::add, 2, infix, " + ", 1, Cost::add, d_add, nullptr, nullptr, nullptr},
      {Op::sub, 2, infix, " - ", 1, Cost::add, d_sub, nullptr, nullptr, nullptr},
      {Op::mul, 2, infix, " * ", 2, Cost::mul, d_mul, nullptr, nullptr, nullptr},
      {Op::div, 2, infix, " / ", 2, Cost::div, d_div, nullptr, nullptr, nullptr},
      {Op::neg, 1, prefix, "-", 3, Cost::add, d_neg, nullptr, nullptr, nullptr},
      {Op::sqrt, 1, call, "std::sqrt", 4, Cost::call, d_sqrt, "sqrt", static_cast<D>(std::sqrt), exact_sqrt},
      {Op::sin, 1, call, "std::sin", 4, Cost::call, d_sin, "sin", static_cast<D>(std::sin),
       [](const numeric& x) { return GiNaC::sin(x); }},
      {Op::cos, 1, call, "std::cos", 4, Cost::call, d_cos, "cos", static_cast<D>(std::cos),
       [](const numeric& x) { return GiNaC::cos(x); }},
      {Op::tan, 1, call, "std::tan", 4, Cost::call, d_tan, "tan", static_cast<D>(std::tan),
       [](const numeric& x) { return GiNaC::tan(x); }},
      {Op::exp, 1, call, "std::exp", 4, Cost::call, d_exp, "exp", static_cast<D>(std::exp),
       [](const numeric& x) { return GiNaC::exp(x); }},
      {Op::log, 1, call, "std::log", 4, Cost::call, d_log, "log", static_cast<D>(std::log), exact_log},
      {Op::asin, 1, call, "std::asin", 4, Cost::call, d_asin, "asin", static_cast<D>(std::asin), exact_asin},
      {Op::acos, 1, call, "std::acos", 4, Cost::call, d_acos, "acos", static_cast<D>(std::acos), exact_acos},
      {Op::atan, 1, call, "std::atan", 4, Cost::call, d_atan, "atan", static_cast<D>(std::atan),
       [](const numeric& x) { return GiNaC::atan(x); }},
      {Op::sinh, 1, call, "std::sinh", 4, Cost::call, d_sinh, "sinh", static_cast<D>(std::sinh),
       [](const numeric& x) { return GiNaC::sinh(x); }},
      {Op::cosh, 1, call, "std::cosh", 4, Cost::call, d_cosh, "cosh", static_cast<D>(std::cosh),
       [](const numeric& x) { return GiNaC::cosh(x); }},
      {Op::tanh, 1, call, "std::tanh", 4, Cost::call, d_tanh, "tanh", static_cast<D>(std::tanh),
       [](const numeric& x) { return GiNaC::tanh(x); }},
      {Op::abs, 1, call, "std::fabs", 4, Cost::call, d_abs, "abs", static_cast<D>(std::fabs),
       [](const numeric& x) { return GiNaC::abs(x); }},
      {Op::pow, 2, call, "std::pow", 4, Cost::call, d_pow, nullptr, nullptr, nullptr},
  });
  return entries;
}

}  // namespace

const Operation& operation(Op op) { return table().at(static_cast<std::size_t>(op)); }

const std::vector<Function>& functions() {
  static const std::vector<Function> named = [] {
    std::vector<Function> out;
    for (const Operation& entry : table())
      if (entry.name) out.push_back(entry);
    return out;
  }();
  return named;
}

const Function* function_named(const std::string& name) {
  for (const Operation& entry : table())
    if (entry.name && name == entry.name) return &entry;
  return nullptr;
}

const Function* function_of(Op op) {
  const Operation& entry = operation(op);
  return entry.name ? &entry : nullptr;
}

double evaluate(Op op, double a, double b) {
  return evaluate_in<double>(
      op, a, b, [](double x, double y) { return x / y; }, [](double x, double y) { return std::pow(x, y); },
      [](Op f, double x) {
        if (const Function* function = function_of(f)) return function->evaluate(x);
        throw std::logic_error("evaluate: not an operation");
      });
}

}  // namespace hamel
