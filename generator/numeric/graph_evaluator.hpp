// The double interpreter of the expression graph: what `hamel simulate`, the work-precision study, the phase
// integrals and the tests run, the same program `emit` prints.
#pragma once

#include "emit/expression_graph.hpp"

#include <vector>

namespace hamel {

/// Evaluates `outputs` numerically in double (the interpreter behind `hamel simulate`). The constructor compiles
/// the outputs' schedule into a dense program: one slot per scheduled node, the constants' slots filled once, the
/// arguments' slots loaded per call, then one instruction per operation on slots, in the schedule's order. The
/// operations and their order are the graph's (the results are those of evaluating node by node); what goes is
/// the per-node work of reading the graph's nodes and values scattered over all kernels of the graph.
class GraphEvaluator {
 public:
  GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs);
  void evaluate(double t, const double* x, const double* p, const double* in, double* out);

 private:
  struct Load {
    int slot;
    Argument argument;
    int index;
  };
  struct Instruction {
    Op op;
    int slot, a, b;  ///< result and operands (b = a for a function of one argument)
  };
  std::vector<Load> loads_;
  std::vector<Instruction> program_;
  std::vector<int> output_slots_;
  std::vector<double> slots_;
};

}  // namespace hamel
