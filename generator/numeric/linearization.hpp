// Linearization of the reduced state equations x' = F(t, x, p, in), x = (q, u_I), about a point:
// x' ≈ A (x − x₀) + B (in − in₀) + c, with A and B evaluated from the `linearization` kernel (forward mode
// through the rhs program, emit/kernels.cpp) — the same nodes the emitted kernel prints. On top of it:
// eigenvalues, the zero eigenvalues of coordinates nothing depends on (cyclic: symmetry), relative
// equilibria (steady motions) by Newton's method, and parameter sweeps with the points where an
// eigenvalue crosses the imaginary axis.
#pragma once

#include "emit/kernels.hpp"
#include "numeric/graph_evaluator.hpp"

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamel {

/// A and B row-major, residual = x' at the point.
struct LinearSystem {
  int nx = 0, ni = 0;
  std::vector<double> A, B, residual;
  double a(int i, int j) const { return A[static_cast<std::size_t>(i * nx + j)]; }
};

struct Eigenvalue {
  double re = 0, im = 0;
};

struct Spectrum {
  std::vector<Eigenvalue> values;  ///< all nx, sorted by real part, then imaginary part
  /// State components whose column of A is zero once the rows of the earlier ones are dropped (nothing else
  /// depends on them at this point: cyclic coordinates of a symmetry); each contributes one exact zero
  /// eigenvalue, and the others are the eigenvalues of A without their rows and columns.
  std::vector<int> decoupled;
};

/// The eigenvalues of A could not be computed (a non-finite entry, or the iteration did not converge): what() says
/// which; the CLI reports it without the "internal error" label.
class EigenvalueFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Eigenvalues of A (Eigen's real Schur form) after deflating the decoupled components.
Spectrum spectrum(const LinearSystem& s);

/// Evaluates the linearization of one model (kernels `rhs` and `linearization` of `kernels`).
class Linearizer {
 public:
  Linearizer(const KernelSet& kernels, int nx, int ni);
  LinearSystem at(double t, const std::vector<double>& x, const std::vector<double>& p,
                  const std::vector<double>& in) const;

 private:
  int nx_, ni_;
  // Scheduled once: a sweep evaluates them at every point. Their value buffers change on evaluation.
  mutable GraphEvaluator rhs_, linearization_;
};

/// A relative equilibrium near x: the components `free` are solved for (minimum-norm Newton steps, so they
/// move as little as possible), the others keep their values; the equations are x'_k = 0 for every k not in
/// `moving` (the cyclic coordinates that advance at a constant rate). Returns the number of Newton steps;
/// throws RunFailed-style std::runtime_error when it does not converge. Converged means max |x'_k| over the equations
/// ≤ 1e-9 · max(1, max |x'_m| over the moving coordinates): absolute on x', relative only to the motion's own rates,
/// never to |x|. With no free component it only checks that x is steady.
struct SteadyResult {
  std::vector<double> x;
  int iterations = 0;
  double residual = 0;  ///< max |x'_k| over the equations at the solution
};
SteadyResult find_steady_motion(const std::function<LinearSystem(const std::vector<double>&)>& linearize,
                                std::vector<double> x, const std::vector<int>& free, const std::vector<int>& moving);

/// A point of a sweep where an eigenvalue's real part changes sign, located by bisection to the last digits.
struct Crossing {
  double value = 0;      ///< of the swept quantity
  bool complex = false;  ///< a complex pair (Hopf) or a real eigenvalue
  bool to_unstable = false;
  double frequency = 0;  ///< |Im λ| at the crossing (complex pairs)
};

/// Eigenvalues along a sweep of one quantity; `spectrum_at(v)` linearizes at value v.
struct Sweep {
  std::vector<double> values;
  std::vector<Spectrum> spectra;
  std::vector<Crossing> crossings;
};
Sweep sweep(const std::function<Spectrum(double)>& spectrum_at, double from, double to, double step);

}  // namespace hamel
