// The double interpreter of the expression graph: what `hamel simulate`, the work-precision study, the phase
// integrals and the tests run, the same program `emit` prints.
#pragma once

#include "emit/expression_graph.hpp"

#include <vector>

namespace hamel {

/// Evaluates `outputs` numerically in double (the interpreter behind `hamel simulate`).
class GraphEvaluator {
 public:
  GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs);
  void evaluate(double t, const double* x, const double* p, const double* in, double* out);

 private:
  const ExpressionGraph& graph_;
  std::vector<int> outputs_;
  std::vector<int> schedule_;
  std::vector<double> values_;
};

}  // namespace hamel
