// Forward error of the emitted kernels in units in the last place.
//
// For every kernel of a model, the double evaluation of its expression graph (GraphEvaluator, the interpreter
// that evaluates exactly the graph the C++ emitter prints) is compared with a 50-digit evaluation of the
// derivation's symbolic expressions the kernel outputs come from, at the same double inputs (converted
// exactly). The rhs and jacobian kernels end in an LDLᵀ solve built in the graph: their reference is
// M u̇ = f (and M ∂u̇/∂x_k = ∂f/∂x_k − ∂M/∂x_k u̇) solved in 50 digits from the symbolic M, f and their
// symbolic derivatives. So the error includes everything double arithmetic does: the rounding of constants
// folded into the graph, of every operation, and the cancellation the generator's choice of form causes.
//
// Error of one output value (documented in docs/accuracy.md):
//
//   ulps = |double − ref| / ulp(max(|ref|, φ·S)),   ulp(y) = 2^(⌊log2 y⌋ − 52) (the spacing of doubles at y),
//
// where S is the kernel's output magnitude at that point, the largest |ref| over its outputs, and φ is the
// floor fraction (default 1e-3). A kernel whose outputs are all exactly zero (the constraint residual) has
// no relative accuracy: its errors are counted in ulps of the largest magnitude of the terms its outputs sum
// (HighPrecisionExpressionEvaluator::magnitude), without φ. Without the floor, an output that is tiny next to its
// siblings (a velocity component crossing zero) would count its unavoidable absolute error of about eps·S as huge
// relative error; with it, such noise costs at most 1/φ ulps, while a form that loses digits through cancellation of
// terms larger than S still shows as more.
#pragma once

#include "algebra/digits_guard.hpp"
#include "algebra/intermediates.hpp"
#include "algebra/operations.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <cln/real.h>
#include <ginac/ginac.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

namespace hamel {

/// The value of a finite double as an exact GiNaC rational.
GiNaC::numeric exact_rational(double v);

/// A finite double as a CLN float with the current GiNaC::Digits (exact: doubles have 53 bits).
GiNaC::numeric high_precision(double v);

/// The spacing of doubles at magnitude y ≥ 0: 2^(⌊log2 y⌋ − 52), at least the smallest subnormal.
double ulp_of(double y);

/// |computed − reference| / ulp_of(max(|reference|, floor)); infinite when `computed` is not finite.
double ulp_error(double computed, const GiNaC::numeric& reference, double floor);

/// Evaluates nodes of an ExpressionGraph in CLN floating point with `digits` decimal digits: the same operations as
/// GraphEvaluator, constants and inputs converted exactly from their doubles. It computes on CLN's reals
/// (cln::cl_R) directly, with the operations GiNaC::numeric would call, so the results are those of GiNaC::numeric
/// without its wrapping of every intermediate value.
class HighPrecisionGraphEvaluator {
 public:
  HighPrecisionGraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs, int digits = 50);
  std::vector<GiNaC::numeric> evaluate(double t, const double* x, const double* p, const double* in);
  /// The same at arbitrary (high-precision) arguments: x, p and in must have the kernel ABI's lengths.
  std::vector<GiNaC::numeric> evaluate(const GiNaC::numeric& t, const std::vector<GiNaC::numeric>& x,
                                       const std::vector<GiNaC::numeric>& p, const std::vector<GiNaC::numeric>& in);
  /// After an evaluate() that returned: the outputs with one argument element changed to `value`, the others as
  /// that call had them. Only the nodes that depend on the element are evaluated again (the same operations on
  /// the same operands as a whole evaluation, so the same results); the evaluator then holds the last
  /// evaluate()'s values again, also when this throws.
  std::vector<GiNaC::numeric> evaluate_moved(Argument argument, int index, const GiNaC::numeric& value);

 private:
  struct Moved {
    Argument argument;
    int index;
    const cln::cl_R* value;
  };
  void run(const std::vector<int>& schedule, const Moved* moved);
  std::vector<GiNaC::numeric> outputs() const;
  const ExpressionGraph& graph_;
  std::vector<int> outputs_;
  std::vector<int> schedule_;
  int digits_;
  std::vector<cln::cl_R> values_;
  std::unordered_map<double, cln::cl_R> constants_;  ///< a graph constant's value at digits_, converted once
  std::array<std::vector<cln::cl_R>, 4> arguments_;  ///< of the last evaluate(), by Argument
  std::map<std::pair<Argument, int>, std::vector<int>> dependents_;
};

/// Evaluates GiNaC expressions numerically with `digits` decimal digits at given symbol values. Understands
/// numbers, symbols, constants (Pi), sums, products, powers and the functions the emitter knows (sin … tanh,
/// abs, sqrt); throws std::domain_error at a pole and std::logic_error for anything else.
/// An expression is compiled once, when first asked for, into numbered nodes (one per distinct
/// subexpression, intermediates through their definitions); each set of values then evaluates every node it
/// needs once, by number, so repeated points cost arithmetic only, not hashing and comparing expressions.
/// Like HighPrecisionGraphEvaluator it computes on cln::cl_R with GiNaC::numeric's operations.
class HighPrecisionExpressionEvaluator {
 public:
  explicit HighPrecisionExpressionEvaluator(int digits = 50) : digits_(digits) {}
  /// Sets symbol values (numbers converted to floats at the evaluator's precision); forgets computed values.
  void assign(const std::map<GiNaC::ex, GiNaC::numeric, GiNaC::ex_is_less>& values);
  /// Intermediate symbols (algebra/intermediates.hpp) are evaluated through their definitions.
  void define(const Intermediates& intermediates);
  GiNaC::numeric value(const GiNaC::ex& e);
  /// The expression evaluated with every sum taken over the absolute values of its terms (and products,
  /// positive powers and arguments of functions likewise; divisors and function values at their true
  /// values): the size of what is added, the scale below which a result is cancellation noise.
  GiNaC::numeric magnitude(const GiNaC::ex& e);

 private:
  enum class Kind { number, symbol, constant, add, mul, power, function };
  struct Node {
    Kind kind;
    std::vector<int> operands;  ///< node numbers (power: base, exponent)
    GiNaC::ex expression;       ///< number, symbol, constant, or the function (for its name)
    const Function* function = nullptr;
    cln::cl_R number;  ///< a number's exact value
  };
  int compile(const GiNaC::ex& e);
  const cln::cl_R& eval(int node, bool absolute);
  struct Hash {
    std::size_t operator()(const GiNaC::ex& e) const { return e.gethash(); }
  };
  int digits_;
  std::map<GiNaC::ex, cln::cl_R, GiNaC::ex_is_less> values_;
  std::map<GiNaC::ex, GiNaC::ex, GiNaC::ex_is_less> definitions_;
  std::unordered_map<GiNaC::ex, int, Hash, GiNaC::ex_is_equal> number_;  ///< compiled expressions
  std::vector<Node> nodes_;
  std::vector<cln::cl_R> computed_[2];  ///< per node: true value, magnitude
  std::vector<unsigned> stamp_[2];      ///< computed_ holds this set of values' result when == generation_
  unsigned generation_ = 1;
};

struct AccuracySettings {
  int points = 200;               ///< random points per parameter setting
  std::uint64_t seed = 1;         ///< of the random points
  double coordinate_range = 1.0;  ///< coordinates uniform in [−r, r]
  double velocity_range = 1.0;    ///< independent velocities and inputs uniform in [−v, v]
  double floor_fraction = 1e-3;   ///< φ in the definition above
  int digits = 50;                ///< of the reference
  bool condition = true;          ///< also compute κ (one more 50-digit graph evaluation per argument)
  /// κ in full at every point, as each point is measured; by default κ is formed after all points and only where it
  /// can change what is reported (in full at each kernel's worst error; for eval/cond at the points whose eval-only
  /// errors could beat the largest, largest first, each only until a partial κ shows it cannot), with the same
  /// results: for tests of that claim.
  bool condition_at_every_point = false;
  /// Pinned values of state variables (coordinate or independent velocity names), inputs or "t".
  std::map<std::string, double> fixed;
};

/// The forward error of one kernel over the points of one or more parameter settings.
struct KernelAccuracy {
  std::string kernel;
  std::size_t outputs = 0;
  bool has_reference = true;         ///< false: a kernel this module has no symbolic reference for (not measured)
  long points = 0;                   ///< points evaluated
  long skipped = 0;                  ///< points where the reference has a pole
  long values = 0;                   ///< output values compared
  double worst_ulps = 0;             ///< against the symbolic expressions in 50 digits
  double sum_ulps = 0;               ///< over all values (mean_ulps = sum_ulps / values)
  double worst_evaluation_ulps = 0;  ///< against the same graph in 50 digits: rounding of the operations only
  /// max over values of (evaluation ulps) / max(1, κ), κ the relative condition number of the output with
  /// respect to the state, inputs and t (with the same floor): what the form adds beyond the error any
  /// evaluation from rounded arguments has. Large values point at a badly conditioned form.
  double worst_excess = 0;
  std::string worst_excess_output;
  double condition_at_worst = 0;  ///< κ of the output where worst_ulps occurred
  std::string worst_output;       ///< output name where worst_ulps occurred
  std::string worst_setting;      ///< label of the parameter setting
  double worst_time = 0;
  std::vector<double> worst_state;
  double worst_double = 0, worst_reference = 0;
  double mean_ulps() const { return values ? sum_ulps / static_cast<double>(values) : 0.0; }
};

/// Measures every kernel of `kernels` (built by build_kernels(model, derivation)) at `settings.points`
/// random points with parameter values `p` (the kernel ABI's p array; folded parameters are constants in
/// the graph and in the derivation alike). `label` names the setting in the result.
std::vector<KernelAccuracy> measure_kernel_accuracy(const Model& model, const Derivation& derivation,
                                                    const KernelSet& kernels, const std::vector<double>& p,
                                                    const AccuracySettings& settings, const std::string& label = "");

/// Combines the results of another setting into `into` (same kernels, matched by name).
void merge_accuracy(std::vector<KernelAccuracy>& into, const std::vector<KernelAccuracy>& more);

}  // namespace hamel
