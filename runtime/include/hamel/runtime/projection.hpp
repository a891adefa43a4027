// SPDX-License-Identifier: MIT
// Projection of a state onto position constraints g(q) = 0: holonomic constraints, closed kinematic loops.
//
// A model whose equations hold a position constraint only in its velocity form ġ = G(q) q̇ = 0 (G = ∂g/∂q; hamel's
// holonomic constraints, whose velocity form is exact by construction) keeps g(q) = 0 only up to the integration
// error, which accumulates: a four-bar closes to 2.5e-8 after 10 s of dopri5 at its default tolerance. The projector
// moves the coordinates back after every accepted step by Gauss-Newton with the minimum-norm correction
//
//   q <- q - G^T (G G^T)^-1 g(q),
//
// repeated until the correction is at rounding level (|dq|_inf <= 16 eps max(1, |q|_inf), or a tolerance of the
// caller's), so that g(q) is at rounding level too. Only the first n_q entries of the state (the coordinates) move;
// the rest (hamel's independent quasi-velocities u_I, from which q_dot = B_I(q) u_I keeps G q_dot = 0 exactly)
// stays. It needs nothing but two callables over the whole state x, as hamel's emitted kernels provide them:
//   g(t, x, out):  out[k] = g(q), the kernel constraint_position;
//   G(t, x, out):  out[k * n_q] = dg/dq row-major, the kernel constraint_position_jacobian;
// (bind p and in of the kernel ABI in a lambda), and a work space of the caller's, ProjectionWorkspace::doubles(n_q,
// k) doubles: nothing allocates. G G^T is solved by ldlt_solve (ldlt.hpp). Like the integrators, it is a template in
// the scalar type: a float package projects in float with BasicProjectionWorkspace<float> (and
// BasicProjectionOptions<float>), with no double operation.
//
// Every integrator (rk4.hpp, dopri5.hpp, dop853.hpp, radau5.hpp) takes an optional projector, any callable
// Status(double t, double* x) such as ConstraintProjector below, as its last argument and calls it on every accepted
// state before it is observed or stepped from, and on every sample it observes (samples are interpolated between
// the accepted states, so they drift too); the methods that reuse f(x_new) as the next first stage (dopri5, dop853:
// FSAL; radau5: f at the step start) evaluate it again at the projected state. A status other than ok ends the run
// with that status and the last accepted state. Without a projector (or with NoProjector) every integrator runs the
// code it ran before projectors existed: results are bit-identical. The initial state is not projected: project it
// first (project_positions), as `hamel simulate` does.
//
//   using namespace hamel::runtime;
//   constexpr std::size_t n = four_bar::n_state, nq = four_bar::n_coordinates, k = four_bar::n_out_constraint_position;
//   const double* p = four_bar::default_parameters;
//   auto g = [&](double t, const double* x, double* out) { four_bar::constraint_position(t, x, p, nullptr, out); };
//   auto G = [&](double t, const double* x, double* out) {
//     four_bar::constraint_position_jacobian(t, x, p, nullptr, out);
//   };
//   static double pwork[ProjectionWorkspace::doubles(nq, k)];
//   const ProjectionWorkspace pw{pwork, std::size(pwork)};
//   project_positions(g, G, 0.0, x, nq, k, pw);  // the initial state, once
//   ConstraintProjector project(g, G, nq, k, pw);
//   integrate_dopri5(rhs, x, n, 0.0, 10.0, Dopri5Options{}, 0.0, NoObserver{}, Dopri5Workspace{work, size}, project);
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/ldlt.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Settings of project_positions. Real: the scalar type of the state (float for a float package).
template <class Real>
struct BasicProjectionOptions {
  int max_iterations = 10;  // corrections at most; not converged after them: projection_failure
  Real tolerance = 0;       // converged once a correction has |dq|_inf <= tolerance; 0: 16 eps max(1, |q|_inf)
  /// For ldlt_solve of G G^T: smaller pivots are singular_constraint_jacobian. 1e-13 in double; in float 64 eps
  /// (7.6e-6), since float's rounding leaves a singular G G^T pivots of about eps, far above 1e-13.
  Real relative_pivot_tolerance =
      sizeof(Real) >= sizeof(double) ? Real(1e-13) : Real(64) * std::numeric_limits<Real>::epsilon();
};
using ProjectionOptions = BasicProjectionOptions<double>;

/// Caller-provided work space of project_positions: a non-owning view of reals(n_q, k) reals of type Real.
template <class Real>
struct BasicProjectionWorkspace {
  /// Reals needed for n_q coordinates and k constraints: g (then the multipliers), G and G G^T.
  static constexpr std::size_t reals(std::size_t n_q, std::size_t k) { return k * (n_q + k + 1); }
  static constexpr std::size_t doubles(std::size_t n_q, std::size_t k) { return reals(n_q, k); }

  Real* data = nullptr;
  std::size_t size = 0;  // reals at data
};
using ProjectionWorkspace = BasicProjectionWorkspace<double>;

/// Outcome of project_positions.
template <class Real>
struct BasicProjectionOutcome {
  Status status = Status::ok;
  int iterations = 0;   // corrections applied
  Real residual = 0;    // max_i |g_i(q)| at entry
  Real correction = 0;  // |dq|_inf of the last correction
};
using ProjectionOutcome = BasicProjectionOutcome<double>;

/// Moves the coordinates x[0..n_q) onto g(q) = 0 in place by Gauss-Newton with the minimum-norm correction
/// dq = G^T (G G^T)^-1 g(q), until a correction has |dq|_inf <= opt.tolerance (default: rounding level, 16 eps
/// max(1, |q|_inf)). Every iteration evaluates g and G once. k == 0: nothing to do (ok).
///
/// Failures, with x at the last iterate: singular_constraint_jacobian when G G^T is not positive definite to
/// opt.relative_pivot_tolerance (the constraints are dependent at q: a redundant constraint, a dead point of a
/// linkage, or a q where they cannot be met, at which Gauss-Newton ends on a least-squares point with G rank
/// deficient); projection_failure after opt.max_iterations corrections without convergence; non_finite_state when
/// g, G or q is not finite; invalid_argument, before any work, for a work space smaller than
/// BasicProjectionWorkspace<Real>::reals(n_q, k) (or null), max_iterations < 1 or a negative or NaN tolerance. Nothing
/// allocates.
/// Real is deduced from x: a float state projects in float, with no double operation.
template <class Position, class Jacobian, class Real>
BasicProjectionOutcome<Real> project_positions(Position&& g, Jacobian&& G, detail::same_t<Real> t, Real* x,
                                               std::size_t n_q, std::size_t k,
                                               BasicProjectionWorkspace<detail::same_t<Real>> work,
                                               const BasicProjectionOptions<detail::same_t<Real>>& opt = {}) {
  BasicProjectionOutcome<Real> out;
  if (k == 0) {
    return out;
  }
  if (!detail::buffers_fit(x, n_q, work.data, work.size, BasicProjectionWorkspace<Real>::reals(n_q, k)) ||
      opt.max_iterations < 1 || !(opt.tolerance >= 0)) {
    out.status = Status::invalid_argument;
    return out;
  }
  Real* r = work.data;  // g(q), then the multipliers (G G^T)^-1 g
  Real* J = r + k;      // G, k x n_q row-major
  Real* S = J + k * n_q;
  constexpr Real eps = std::numeric_limits<Real>::epsilon();
  for (int it = 1; it <= opt.max_iterations; ++it) {
    g(t, static_cast<const Real*>(x), r);
    if (!all_finite(r, k)) {
      out.status = Status::non_finite_state;
      return out;
    }
    if (it == 1) {
      for (std::size_t i = 0; i < k; ++i) out.residual = std::max(out.residual, std::fabs(r[i]));
    }
    G(t, static_cast<const Real*>(x), J);
    if (!all_finite(J, k * n_q)) {
      out.status = Status::non_finite_state;
      return out;
    }
    for (std::size_t i = 0; i < k; ++i) {
      for (std::size_t j = 0; j <= i; ++j) {
        Real s = 0;
        for (std::size_t a = 0; a < n_q; ++a) s += J[i * n_q + a] * J[j * n_q + a];
        S[i * k + j] = S[j * k + i] = s;
      }
    }
    if (ldlt_solve(S, r, static_cast<int>(k), opt.relative_pivot_tolerance) != Status::ok) {
      out.status = Status::singular_constraint_jacobian;
      return out;
    }
    Real step = 0;
    Real scale = 1;
    for (std::size_t a = 0; a < n_q; ++a) {
      Real d = 0;
      for (std::size_t i = 0; i < k; ++i) d += J[i * n_q + a] * r[i];
      x[a] -= d;
      step = std::max(step, std::fabs(d));
      scale = std::max(scale, std::fabs(x[a]));
    }
    out.iterations = it;
    out.correction = step;
    if (!all_finite(x, n_q)) {
      out.status = Status::non_finite_state;
      return out;
    }
    if (step <= (opt.tolerance > 0 ? opt.tolerance : Real(16) * eps * scale)) {
      return out;
    }
  }
  out.status = Status::projection_failure;
  return out;
}

/// Work counters of a ConstraintProjector.
template <class Real>
struct BasicProjectionStats {
  long projections = 0;       // calls
  long iterations = 0;        // Gauss-Newton corrections, over all calls (each evaluates g and G once)
  Real largest_residual = 0;  // the largest max_i |g_i(q)| a call met: how far a step (or sample) drifted
};
using ProjectionStats = BasicProjectionStats<double>;

/// The projector the integrators take: project_positions with its callables, sizes, work space and settings bound,
/// as a callable Status(Real t, Real* x), counting its work. Copies share nothing but the work space. Real: double
/// unless the work space is a BasicProjectionWorkspace<float> (then a float state is projected in float).
template <class Position, class Jacobian, class Real = double>
class ConstraintProjector {
 public:
  ConstraintProjector(Position g, Jacobian G, std::size_t n_q, std::size_t k, BasicProjectionWorkspace<Real> work,
                      const BasicProjectionOptions<Real>& opt = {})
      : g_(g), G_(G), n_q_(n_q), k_(k), work_(work), opt_(opt) {}

  Status operator()(Real t, Real* x) {
    const BasicProjectionOutcome<Real> o = project_positions(g_, G_, t, x, n_q_, k_, work_, opt_);
    ++stats_.projections;
    stats_.iterations += o.iterations;
    stats_.largest_residual = std::max(stats_.largest_residual, o.residual);
    return o.status;
  }

  const BasicProjectionStats<Real>& stats() const { return stats_; }

 private:
  Position g_;
  Jacobian G_;
  std::size_t n_q_, k_;
  BasicProjectionWorkspace<Real> work_;
  BasicProjectionOptions<Real> opt_;
  BasicProjectionStats<Real> stats_;
};

}  // namespace hamel::runtime
