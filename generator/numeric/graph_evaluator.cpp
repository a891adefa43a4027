#include "numeric/graph_evaluator.hpp"

#include "algebra/digits_guard.hpp"

#include <algorithm>

namespace hamel {

GraphEvaluator::GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs) : program_(graph) {
  program_.compile(graph.schedule(outputs));
  for (int o : outputs) output_slots_.push_back(program_.slot(o));
}

void GraphEvaluator::evaluate(double t, const double* x, const double* p, const double* in, double* out) {
  program_.run([&](Argument argument, int index) {
    switch (argument) {
      case Argument::time:
        return t;
      case Argument::state:
        return x[index];
      case Argument::parameter:
        return p[index];
      case Argument::input:
        break;
    }
    return in[index];
  });
  for (std::size_t k = 0; k < output_slots_.size(); ++k) out[k] = program_.value(output_slots_[k]);
}

// ---------------------------------------------------------------------------------------------------------

HighPrecisionGraphArithmetic::Value HighPrecisionGraphArithmetic::constant(const ExpressionGraph& g, int node) const {
  return HighPrecision::constant(g.node(node).value);
}

HighPrecisionGraphArithmetic::Value HighPrecisionGraphArithmetic::operation(const ExpressionGraph& g, int node, Op op,
                                                                            const Value& a, const Value& b) const {
  if (op == Op::pow) {
    const Node& exponent = g.node(g.node(node).b);
    if (exponent.op == Op::constant) return HighPrecision::power(a, exact_rational(exponent.value));
  }
  return HighPrecision::operation(op, a, b);
}

HighPrecisionGraphEvaluator::HighPrecisionGraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs,
                                                         int digits)
    : digits_(digits), program_(graph, HighPrecisionGraphArithmetic(digits)) {
  const DigitsGuard guard(digits_);  // constants are converted while compiling
  program_.compile(graph.schedule(outputs));
  for (int o : outputs) output_slots_.push_back(program_.slot(o));
  for (const auto& l : program_.loads()) {
    if (l.argument == Argument::state) nx_ = std::max(nx_, l.index + 1);
    if (l.argument == Argument::parameter) np_ = std::max(np_, l.index + 1);
    if (l.argument == Argument::input) nin_ = std::max(nin_, l.index + 1);
  }
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate(double t, const double* x, const double* p,
                                                                  const double* in) {
  const DigitsGuard digits(digits_);
  const auto convert = [](const double* v, int count) {
    std::vector<GiNaC::numeric> out;
    for (int k = 0; k < count; ++k) out.push_back(high_precision(v[k]));
    return out;
  };
  return evaluate(high_precision(t), convert(x, nx_), convert(p, np_), convert(in, nin_));
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate(const GiNaC::numeric& t,
                                                                  const std::vector<GiNaC::numeric>& x,
                                                                  const std::vector<GiNaC::numeric>& p,
                                                                  const std::vector<GiNaC::numeric>& in) {
  const DigitsGuard digits(digits_);
  program_.run([&](Argument argument, int index) {
    const std::size_t k = static_cast<std::size_t>(index);
    switch (argument) {
      case Argument::time:
        return HighPrecision::of(t);
      case Argument::state:
        return HighPrecision::of(x.at(k));
      case Argument::parameter:
        return HighPrecision::of(p.at(k));
      case Argument::input:
        break;
    }
    return HighPrecision::of(in.at(k));
  });
  return outputs();
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate_moved(Argument argument, int index,
                                                                        const GiNaC::numeric& value) {
  const auto key = std::make_pair(argument, index);
  auto it = dependents_.find(key);
  if (it == dependents_.end()) {
    // The slots loaded from this argument, and the instructions that depend on them, in program order.
    Dependents d;
    std::vector<char> slot_depends;
    for (const auto& l : program_.loads())
      if (l.argument == argument && l.index == index) d.loads.push_back(l.slot);
    int slots = 0;
    for (const auto& l : program_.loads()) slots = std::max(slots, l.slot + 1);
    for (const auto& i : program_.instructions()) slots = std::max(slots, i.slot + 1);
    slot_depends.assign(static_cast<std::size_t>(slots), 0);
    for (int s : d.loads) slot_depends[static_cast<std::size_t>(s)] = 1;
    const auto& instructions = program_.instructions();
    for (std::size_t k = 0; k < instructions.size(); ++k) {
      const auto& i = instructions[k];
      if (slot_depends[static_cast<std::size_t>(i.a)] || slot_depends[static_cast<std::size_t>(i.b)]) {
        slot_depends[static_cast<std::size_t>(i.slot)] = 1;
        d.instructions.push_back(k);
      }
    }
    it = dependents_.emplace(key, std::move(d)).first;
  }
  const Dependents& moved = it->second;
  const DigitsGuard digits(digits_);
  std::vector<cln::cl_R> saved;
  saved.reserve(moved.loads.size() + moved.instructions.size());
  for (int s : moved.loads) saved.push_back(program_.value(s));
  for (std::size_t k : moved.instructions) saved.push_back(program_.value(program_.instructions()[k].slot));
  const auto restore = [&] {
    std::size_t n = 0;
    for (int s : moved.loads) program_.value(s) = saved[n++];
    for (std::size_t k : moved.instructions) program_.value(program_.instructions()[k].slot) = saved[n++];
  };
  const cln::cl_R moved_value = HighPrecision::of(value);
  for (int s : moved.loads) program_.value(s) = moved_value;
  try {
    program_.rerun(moved.instructions);
  } catch (...) {
    restore();
    throw;
  }
  std::vector<GiNaC::numeric> out = outputs();
  restore();
  return out;
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::outputs() const {
  std::vector<GiNaC::numeric> out;
  out.reserve(output_slots_.size());
  for (int s : output_slots_) out.push_back(HighPrecision::numeric_of(program_.value(s)));
  return out;
}

}  // namespace hamel
