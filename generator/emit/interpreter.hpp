// The interpreter of the IR (emit/expression_graph.hpp), in any number type: the one loop behind hamel's numeric
// evaluations of a graph.
//   - double (DoubleArithmetic below): numeric/graph_evaluator's GraphEvaluator, what `hamel simulate`, the
//     work-precision study, the phase integrals and the tests run, the same program `emit` prints;
//   - 50-digit floats (algebra/high_precision.hpp): HighPrecisionGraphEvaluator, the evaluation-only reference of
//     `hamel accuracy`;
//   - residues modulo 2^61 − 1 (algebra/modular_arithmetic.hpp): emit/zero_test's ZeroTest, which finds values that
//     vanish identically.
// An Arithmetic gives the number type (Value), the value of a constant node, `constant(graph, node)`, and of an
// operation node from its operands' values, `operation(graph, node, op, a, b)` (b is a's value for a function of
// one argument); arguments are loaded per run. The interpreter compiles a schedule into a dense program, one slot
// per scheduled node, constants filled once, then one instruction per operation on slots in schedule order
// (operands before users): the operations and their order are the graph's, without reading the graph's nodes,
// scattered over all kernels, on every run.
#pragma once

#include "algebra/operations.hpp"
#include "emit/expression_graph.hpp"

#include <utility>
#include <vector>

namespace hamel {

/// The IR in double: constants as the graph holds them, operations as the emitted C++ computes them.
struct DoubleArithmetic {
  using Value = double;
  double constant(const ExpressionGraph& g, int node) const { return g.node(node).value; }
  double operation(const ExpressionGraph&, int, Op op, double a, double b) const {
    // The arithmetic inline (evaluate_in's switch); pow and the elementary functions through the operation table.
    return evaluate_in<double>(
        op, a, b, [](double x, double y) { return x / y; }, [](double x, double y) { return evaluate(Op::pow, x, y); },
        [](Op f, double x) { return evaluate(f, x, x); });
  }
};

template <class Arithmetic>
class Interpreter {
 public:
  using Value = typename Arithmetic::Value;
  struct Load {
    int slot;
    Argument argument;
    int index;
  };
  struct Instruction {
    Op op;
    int slot, a, b;  ///< result and operands (b = a for a function of one argument)
  };
  /// Where the program stood: what compile() adds after it, run(from) runs.
  struct Mark {
    std::size_t loads = 0, instructions = 0;
  };

  explicit Interpreter(const ExpressionGraph& graph, Arithmetic arithmetic = {})
      : graph_(graph), arithmetic_(std::move(arithmetic)) {}

  /// Compiles the nodes `outputs` need that are not compiled yet, in the graph's schedule order (depth first from
  /// the outputs, first operand first: ExpressionGraph::schedule); constants get their values now. The graph may
  /// have grown since the last call. Returns the outputs' slots.
  std::vector<int> compile(const std::vector<int>& outputs) {
    if (slot_of_.size() < static_cast<std::size_t>(graph_.size()))
      slot_of_.resize(static_cast<std::size_t>(graph_.size()), -1);
    std::vector<std::pair<int, int>> stack;  // node, operands pushed so far
    for (int o : outputs) {
      if (compiled(o) || pending(o)) continue;
      mark_pending(o);
      stack.emplace_back(o, 0);
      while (!stack.empty()) {
        const int i = stack.back().first;
        const int k = stack.back().second++;
        const Node& n = graph_.node(i);
        const int operand = k == 0 ? n.a : k == 1 ? n.b : -1;
        if (k < 2) {
          if (operand >= 0 && !compiled(operand) && !pending(operand)) {
            mark_pending(operand);
            stack.emplace_back(operand, 0);
          }
          continue;
        }
        emit(i);
        stack.pop_back();
      }
    }
    std::vector<int> slots;
    slots.reserve(outputs.size());
    for (int o : outputs) slots.push_back(slot(o));
    return slots;
  }

  Mark mark() const { return {loads_.size(), instructions_.size()}; }

  /// Loads the arguments (`argument(Argument, index)` gives each value) and runs the instructions, all of them or
  /// those compiled after `from`.
  template <class Arguments>
  void run(Arguments&& argument, Mark from = {}) {
    Value* v = values_.data();
    for (const Load *l = loads_.data() + from.loads, *end = loads_.data() + loads_.size(); l != end; ++l)
      v[l->slot] = argument(l->argument, l->index);
    const int* node = node_of_.data();
    for (const Instruction *i = instructions_.data() + from.instructions,
                           *end = instructions_.data() + instructions_.size();
         i != end; ++i)
      v[i->slot] = arithmetic_.operation(graph_, node[i->slot], i->op, v[i->a], v[i->b]);
  }

  /// Runs the listed instructions (positions in instructions()) again, in the order given.
  void rerun(const std::vector<std::size_t>& which) {
    Value* v = values_.data();
    for (std::size_t k : which) {
      const Instruction& i = instructions_[k];
      v[i.slot] = arithmetic_.operation(graph_, node_of_[static_cast<std::size_t>(i.slot)], i.op, v[i.a], v[i.b]);
    }
  }

  int slot(int node) const { return slot_of_[static_cast<std::size_t>(node)]; }
  const Value& value(int slot) const { return values_[static_cast<std::size_t>(slot)]; }
  Value& value(int slot) { return values_[static_cast<std::size_t>(slot)]; }
  const std::vector<Load>& loads() const { return loads_; }
  const std::vector<Instruction>& instructions() const { return instructions_; }
  const ExpressionGraph& graph() const { return graph_; }
  Arithmetic& arithmetic() { return arithmetic_; }

 private:
  static constexpr int kPending = -2;
  bool compiled(int node) const { return slot_of_[static_cast<std::size_t>(node)] >= 0; }
  bool pending(int node) const { return slot_of_[static_cast<std::size_t>(node)] == kPending; }
  void mark_pending(int node) { slot_of_[static_cast<std::size_t>(node)] = kPending; }

  void emit(int i) {
    const Node& n = graph_.node(i);
    const int s = static_cast<int>(values_.size());
    slot_of_[static_cast<std::size_t>(i)] = s;
    node_of_.push_back(i);
    if (n.op == Op::constant) {
      values_.push_back(arithmetic_.constant(graph_, i));
      return;
    }
    values_.emplace_back();
    if (n.op == Op::input) {
      loads_.push_back({s, n.argument, n.index});
    } else {
      const int a = slot(n.a);
      instructions_.push_back({n.op, s, a, n.b >= 0 ? slot(n.b) : a});
    }
  }

  const ExpressionGraph& graph_;
  Arithmetic arithmetic_;
  std::vector<int> slot_of_;  ///< by graph node: its slot, −1 not compiled (kPending while compiling)
  std::vector<int> node_of_;  ///< by slot: its graph node
  std::vector<Value> values_;
  std::vector<Load> loads_;
  std::vector<Instruction> instructions_;
};

}  // namespace hamel
