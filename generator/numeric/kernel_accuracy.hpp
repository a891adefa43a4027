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
//
// The study is this file; the evaluators it runs are the IR's interpreter in double and in 50 digits
// (numeric/graph_evaluator.hpp) and the 50-digit evaluator of GiNaC expressions (algebra/high_precision.hpp); the
// references are numeric/kernel_references.hpp's.
#pragma once

#include "algebra/digits_guard.hpp"
#include "algebra/high_precision.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <ginac/ginac.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hamel {

/// The spacing of doubles at magnitude y ≥ 0: 2^(⌊log2 y⌋ − 52), at least the smallest subnormal.
double ulp_of(double y);

/// |computed − reference| / ulp_of(max(|reference|, floor)); infinite when `computed` is not finite.
double ulp_error(double computed, const GiNaC::numeric& reference, double floor);

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
