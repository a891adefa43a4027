// SPDX-License-Identifier: MIT
// Types and helpers shared by the ODE integrators (rk4.hpp, dopri5.hpp, dop853.hpp, radau5.hpp).
//
// A right-hand side is any callable void(double t, const double* x, double* xdot);
// an observer is any callable void(double t, const double* x); a Jacobian (for
// the implicit methods) is any callable void(double t, const double* x,
// double* J) writing df/dx row-major. All see raw pointers so that generated
// code can pass its own fixed-size storage.
//
// Every integrator has two forms:
// - integrate_X(rhs, std::vector<double> x, ...) -> IntegrationResult: convenient; it allocates its work
//   space once, before the first step, and returns the final state in a vector;
// - integrate_X(rhs, double* x, std::size_t n, ..., XWorkspace work) -> IntegrationOutcome: heap-free. The
//   caller provides the work space (XWorkspace::doubles(n) doubles, sizes constexpr, so a package can use
//   static arrays sized from its n_state), x holds the initial state on entry and the final state (the last
//   finite accepted state on failure) on return, and nothing in the run allocates: not the steps, not the
//   observer calls (which see pointers into x or the work space), not the result. Both forms run the same
//   code and give bit-identical results (tests/runtime/integrators_do_not_allocate_test.cpp).
// The Lie-group integrators follow the same pattern: lie/rkmk_coupled.hpp's integrate_rkmk4_coupled has a
// vector form and a heap-free form with RkmkCoupledWorkspace (for the vector part; the group part is
// fixed-size), and lie/rkmk.hpp's integrate_rkmk4, whose state is fixed-size, allocates nothing at all.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Work counters of one integration run.
struct IntegrationStats {
  long steps = 0;              // accepted steps
  long rejected = 0;           // rejected step attempts (always 0 for fixed-step methods)
  long rhs_evals = 0;          // calls of the right-hand side
  long jac_evals = 0;          // calls of the Jacobian (implicit methods only)
  long lu_decompositions = 0;  // factorisations of the Newton iteration matrix (implicit methods only)
};

/// Outcome of an integration run.
struct IntegrationResult {
  Status status = Status::ok;
  double t = 0;  // t_end on success, else the time of the last finite accepted state
  IntegrationStats stats;
  std::vector<double> x;  // state at t (the failure point on failure)
};

/// Outcome of a heap-free integration run (the workspace overloads): as IntegrationResult, but the
/// state at t is in the caller's buffer x rather than in a vector.
struct IntegrationOutcome {
  Status status = Status::ok;
  double t = 0;  // t_end on success, else the time of the last finite accepted state
  IntegrationStats stats;
};

/// Observer that ignores everything, for callers that only want the final state.
struct NoObserver {
  void operator()(double /*t*/, const double* /*x*/) const noexcept {}
};

/// True when none of the n values is NaN or infinite.
inline bool all_finite(const double* x, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      return false;
    }
  }
  return true;
}

namespace detail {

/// The IntegrationResult of the vector overloads from a heap-free run's outcome and final state.
inline IntegrationResult to_result(const IntegrationOutcome& outcome, std::vector<double>&& x) {
  IntegrationResult result;
  result.status = outcome.status;
  result.t = outcome.t;
  result.stats = outcome.stats;
  result.x = std::move(x);
  return result;
}

/// Whether the caller's buffers can hold a run: x (n values) and a work space of `size` doubles where
/// `needed` are required. A null pointer is fine only where nothing is needed.
inline bool buffers_fit(const double* x, std::size_t n, const double* work, std::size_t size, std::size_t needed) {
  return (x != nullptr || n == 0) && (work != nullptr || needed == 0) && size >= needed;
}

/// Settings shared by the adaptive integrators that make no sense: a tolerance that is negative or not
/// finite, an initial step h0 that is not finite (its sign is ignored, 0 asks for the automatic choice),
/// or a step limit h_max that is negative or NaN (0 and +infinity mean no limit).
inline bool adaptive_settings_valid(double rtol, double atol, double h0, double h_max) {
  return rtol >= 0 && std::isfinite(rtol) && atol >= 0 && std::isfinite(atol) && std::isfinite(h0) && h_max >= 0;
}

/// Smallest step the integrators accept at time t. Below it t + h is no longer
/// meaningfully different from t, so continuing would only burn time.
inline double min_step(double t) { return 1e-14 * std::max(1.0, std::fabs(t)); }

/// The grid of a fixed-step method: `count` steps of equal size that cover [t0, t_end] with steps no
/// longer than h. Status::ok with count 0 when t_end == t0; invalid_argument for h <= 0 (or NaN);
/// step_size_underflow for steps below min_step; too_many_steps beyond 1e15 steps.
inline Status fixed_step_count(double t0, double t_end, double h, long& count) {
  count = 0;
  const double span = t_end - t0;
  if (span == 0.0) {
    return Status::ok;
  }
  if (!(h > 0)) {
    return Status::invalid_argument;
  }
  const double ratio = std::fabs(span) / h;
  if (!(ratio <= 1e15)) {
    return Status::too_many_steps;
  }
  count = std::max(1L, static_cast<long>(std::ceil(ratio - 1e-9)));
  if (std::fabs(span) / static_cast<double>(count) < min_step(std::max(std::fabs(t0), std::fabs(t_end)))) {
    return Status::step_size_underflow;
  }
  return Status::ok;
}

/// Hairer's starting-step heuristic (hinit in dopri5.f and dop853.f) for an explicit method of order
/// `order`: an explicit Euler probe of a size where the first derivative looks resolved estimates the
/// second derivative, then h is chosen so that h^order * max(|x'|, |x''|) is about 0.01 in the norm
/// scaled by atol + rtol |x|. Costs one rhs evaluation (counted in rhs_evals); x1 and f1 are work space.
template <class Rhs>
double hairer_initial_step(Rhs& rhs, double t, const double* x, const double* f0, double dir, double h_limit,
                           double atol, double rtol, int order, double* x1, double* f1, std::size_t n,
                           long& rhs_evals) {
  double dnf = 0.0;
  double dny = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double sk = atol + rtol * std::fabs(x[i]);
    dnf += (f0[i] / sk) * (f0[i] / sk);
    dny += (x[i] / sk) * (x[i] / sk);
  }
  double h = (dnf <= 1e-10 || dny <= 1e-10) ? 1e-6 : 0.01 * std::sqrt(dny / dnf);
  h = std::min(h, h_limit);

  for (std::size_t i = 0; i < n; ++i) x1[i] = x[i] + dir * h * f0[i];
  rhs(t + dir * h, x1, f1);
  ++rhs_evals;
  double der2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double sk = atol + rtol * std::fabs(x[i]);
    der2 += ((f1[i] - f0[i]) / sk) * ((f1[i] - f0[i]) / sk);
  }
  der2 = std::sqrt(der2) / h;
  if (!std::isfinite(der2) || !std::isfinite(dnf)) {
    return h;  // The guess is unusable; let step rejection shrink h instead.
  }
  const double der12 = std::max(der2, std::sqrt(dnf));
  const double h1 = der12 <= 1e-15 ? std::max(1e-6, h * 1e-3) : std::pow(0.01 / der12, 1.0 / order);
  return std::min({100.0 * h, h1, h_limit});
}

/// Sample times t0 + k*dt (k = 1, 2, ...) strictly inside (t0, t_end), in
/// either direction of time.
///
/// Times are formed by multiplication rather than by summing dt, so sample k
/// carries a single rounding error however long the run. A sample within
/// rounding distance of t_end is dropped because the integrators observe t_end
/// itself; without this, 0.1-spaced samples on [0, 0.3] would observe
/// 0.30000000000000004 next to 0.3.
class SampleClock {
 public:
  /// dt <= 0 (or NaN) disables sampling.
  SampleClock(double t0, double t_end, double dt)
      : t0_(t0),
        t_end_(t_end),
        dir_(t_end >= t0 ? 1.0 : -1.0),
        dt_(dt > 0 ? dt : 0.0),
        guard_(std::max(1e-9 * dt_,
                        8 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(t0), std::fabs(t_end)))) {}

  /// Whether sampling was requested at all.
  bool enabled() const { return dt_ > 0; }

  /// Whether the next sample is at or before t (in the direction of integration).
  bool due(double t) const {
    if (!enabled()) {
      return false;
    }
    const double s = next();
    return (t - s) * dir_ >= 0 && (t_end_ - s) * dir_ > guard_;
  }

  /// Time of the next sample.
  double next() const { return t0_ + dir_ * k_ * dt_; }

  /// Moves on to the following sample.
  void advance() { k_ += 1.0; }

 private:
  double t0_;
  double t_end_;
  double dir_;
  double dt_;
  double guard_;
  double k_ = 1.0;  // a double so that absurdly many samples cannot overflow an integer
};

}  // namespace detail
}  // namespace hamel::runtime
