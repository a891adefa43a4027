#include "numeric/graph_evaluator.hpp"

#include <utility>

namespace hamel {

GraphEvaluator::GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs)
    : graph_(graph),
      outputs_(std::move(outputs)),
      schedule_(graph.schedule(outputs_)),
      values_(static_cast<std::size_t>(graph.size()), 0.0) {}

void GraphEvaluator::evaluate(double t, const double* x, const double* p, const double* in, double* out) {
  interpret(
      graph_, schedule_, values_, [](const Node& n) { return n.value; },
      [&](Argument argument, int index) {
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
      },
      [](const Node& n, double a, double b) { return hamel::evaluate(n.op, a, b); });
  for (std::size_t k = 0; k < outputs_.size(); ++k) out[k] = values_[static_cast<std::size_t>(outputs_[k])];
}

}  // namespace hamel
