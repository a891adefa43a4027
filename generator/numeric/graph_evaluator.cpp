#include "numeric/graph_evaluator.hpp"

#include "algebra/operations.hpp"

#include <unordered_map>

namespace hamel {

GraphEvaluator::GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs) {
  std::unordered_map<int, int> slot_of;  // node -> slot
  for (int i : graph.schedule(outputs)) {
    const Node& n = graph.node(i);
    const int slot = static_cast<int>(slots_.size());
    slot_of.emplace(i, slot);
    slots_.push_back(n.op == Op::constant ? n.value : 0.0);
    if (n.op == Op::input) {
      loads_.push_back({slot, n.argument, n.index});
    } else if (n.op != Op::constant) {
      const int a = slot_of.at(n.a);
      program_.push_back({n.op, slot, a, n.b >= 0 ? slot_of.at(n.b) : a});
    }
  }
  for (int o : outputs) output_slots_.push_back(slot_of.at(o));
}

void GraphEvaluator::evaluate(double t, const double* x, const double* p, const double* in, double* out) {
  double* v = slots_.data();
  for (const Load& l : loads_) {
    switch (l.argument) {
      case Argument::time:
        v[l.slot] = t;
        break;
      case Argument::state:
        v[l.slot] = x[l.index];
        break;
      case Argument::parameter:
        v[l.slot] = p[l.index];
        break;
      case Argument::input:
        v[l.slot] = in[l.index];
        break;
    }
  }
  for (const Instruction& i : program_) {
    const double a = v[i.a], b = v[i.b];
    switch (i.op) {
      case Op::add:
        v[i.slot] = a + b;
        break;
      case Op::sub:
        v[i.slot] = a - b;
        break;
      case Op::mul:
        v[i.slot] = a * b;
        break;
      case Op::div:
        v[i.slot] = a / b;
        break;
      case Op::neg:
        v[i.slot] = -a;
        break;
      default:
        v[i.slot] = hamel::evaluate(i.op, a, b);  // pow and the elementary functions
    }
  }
  for (std::size_t k = 0; k < output_slots_.size(); ++k) out[k] = v[output_slots_[k]];
}

}  // namespace hamel
