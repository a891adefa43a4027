// The IR's interpreter (emit/interpreter.hpp) in double and in high precision: what `hamel simulate`, the
// work-precision study, the phase integrals and the tests run, the same program `emit` prints, and its 50-digit
// evaluation for `hamel accuracy`.
#pragma once

#include "algebra/high_precision.hpp"
#include "emit/interpreter.hpp"

#include <ginac/ginac.h>

#include <map>
#include <utility>
#include <vector>

namespace hamel {

/// Evaluates `outputs` numerically in double (the interpreter behind `hamel simulate`): the graph's operations in
/// its order, so the results are those of evaluating node by node.
class GraphEvaluator {
 public:
  GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs);
  void evaluate(double t, const double* x, const double* p, const double* in, double* out);

 private:
  Interpreter<DoubleArithmetic> program_;
  std::vector<int> output_slots_;
};

/// The IR in high precision (algebra/high_precision.hpp's HighPrecision) at `digits` digits: constants and inputs
/// converted exactly from their doubles, a power to a constant exponent taken with the exponent's exact value (the
/// double the emitter prints: 1.5 is a square root cubed).
class HighPrecisionGraphArithmetic {
 public:
  using Value = cln::cl_R;
  explicit HighPrecisionGraphArithmetic(int digits = 50) : digits_(digits) {}
  Value constant(const ExpressionGraph& g, int node) const;
  Value operation(const ExpressionGraph& g, int node, Op op, const Value& a, const Value& b) const;
  int digits() const { return digits_; }

 private:
  int digits_;
};

/// Evaluates nodes of an ExpressionGraph in CLN floating point with `digits` decimal digits: the same operations as
/// GraphEvaluator, in HighPrecisionGraphArithmetic.
class HighPrecisionGraphEvaluator {
 public:
  HighPrecisionGraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs, int digits = 50);
  std::vector<GiNaC::numeric> evaluate(double t, const double* x, const double* p, const double* in);
  /// The same at arbitrary (high-precision) arguments: x, p and in must have the kernel ABI's lengths.
  std::vector<GiNaC::numeric> evaluate(const GiNaC::numeric& t, const std::vector<GiNaC::numeric>& x,
                                       const std::vector<GiNaC::numeric>& p, const std::vector<GiNaC::numeric>& in);
  /// After an evaluate() that returned: the outputs with one argument element changed to `value`, the others as
  /// that call had them. Only the instructions that depend on the element run again (the same operations on the
  /// same operands as a whole evaluation, so the same results); the evaluator then holds the last evaluate()'s
  /// values again, also when this throws.
  std::vector<GiNaC::numeric> evaluate_moved(Argument argument, int index, const GiNaC::numeric& value);

 private:
  std::vector<GiNaC::numeric> outputs() const;
  int digits_;
  Interpreter<HighPrecisionGraphArithmetic> program_;
  std::vector<int> output_slots_;
  int nx_ = 0, np_ = 0, nin_ = 0;  ///< argument lengths the program reads
  struct Dependents {
    std::vector<int> loads;                 ///< slots loaded from the argument
    std::vector<std::size_t> instructions;  ///< instructions that depend on it, in program order
  };
  std::map<std::pair<Argument, int>, Dependents> dependents_;
};

}  // namespace hamel
