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
// Every integrator of rk4.hpp, dopri5.hpp, dop853.hpp and radau5.hpp also takes, as an optional last argument, a
// projector: any callable Status(double t, double* x) that moves an accepted state (and every observed sample) onto
// position constraints g(q) = 0 in place (projection.hpp: ConstraintProjector, fed by hamel's constraint_position
// kernels). It is called before the state is observed or stepped from; methods that reuse f(t, x_new) evaluate it
// again at the projected state; a status other than ok ends the run with it (and the last accepted state). Without
// one (NoProjector, the default) results are bit-identical to the integrators without projectors.
// The heap-free forms are templates in the scalar type Real, deduced from the work space (Rk4Workspace is
// BasicRk4Workspace<double>; a float package passes BasicRk4Workspace<float>, BasicDopri5Options<float> and so on):
// its state, times, tolerances and arithmetic are all Real, so a float package integrates in float, with no double
// operation (on a single-precision FPU such as a Cortex-M4F's double is emulated in software). Double runs are
// bit-identical to the double-only runtime they replace. The vector forms stay double.
// The Lie-group integrators follow the same pattern: lie/rkmk_coupled.hpp's integrate_rkmk4_coupled has a
// vector form and a heap-free form with RkmkCoupledWorkspace (for the vector part; the group part is
// fixed-size), and lie/rkmk.hpp's integrate_rkmk4, whose state is fixed-size, allocates nothing at all.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
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
/// state at t is in the caller's buffer x rather than in a vector. Real: the run's scalar type.
template <class Real>
struct BasicIntegrationOutcome {
  Status status = Status::ok;
  Real t = 0;  // t_end on success, else the time of the last finite accepted state
  IntegrationStats stats;
};
using IntegrationOutcome = BasicIntegrationOutcome<double>;

/// Observer that ignores everything, for callers that only want the final state.
struct NoObserver {
  template <class Real>
  void operator()(Real /*t*/, const Real* /*x*/) const noexcept {}
};

/// The projector of a run without position constraints, every integrator's default: leaves every state as it is, and
/// the integrators skip everything a projector needs (bit-identical results, no extra evaluations).
struct NoProjector {
  template <class Real>
  Status operator()(Real /*t*/, Real* /*x*/) const noexcept {
    return Status::ok;
  }
};

/// True when none of the n values is NaN or infinite.
template <class Real>
bool all_finite(const Real* x, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      return false;
    }
  }
  return true;
}

namespace detail {

/// T itself, in a context that does not take part in template argument deduction: the scalar type of a run is
/// deduced from its work space alone, and times and steps given as double literals convert to it.
template <class T>
struct identity {
  using type = T;
};
template <class T>
using same_t = typename identity<T>::type;

/// Whether `Projector` projects (anything but NoProjector): the integrators compile its calls, and the extra
/// evaluation of f at a projected state, only then.
template <class Projector>
constexpr bool projects = !std::is_same_v<std::decay_t<Projector>, NoProjector>;

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
template <class Real>
bool buffers_fit(const Real* x, std::size_t n, const Real* work, std::size_t size, std::size_t needed) {
  return (x != nullptr || n == 0) && (work != nullptr || needed == 0) && size >= needed;
}

/// Settings shared by the adaptive integrators that make no sense: a tolerance that is negative or not
/// finite, an initial step h0 that is not finite (its sign is ignored, 0 asks for the automatic choice),
/// or a step limit h_max that is negative or NaN (0 and +infinity mean no limit).
template <class Real>
bool adaptive_settings_valid(Real rtol, Real atol, Real h0, Real h_max) {
  return rtol >= 0 && std::isfinite(rtol) && atol >= 0 && std::isfinite(atol) && std::isfinite(h0) && h_max >= 0;
}

/// Whether sampling every dt on [t0, t_end] can be done: true when sampling is off (dt <= 0 or NaN), the interval is
/// empty or t0, t_end are not finite (reported otherwise); false, for invalid_argument before any work, when dt is
/// below the resolution of t on the interval (t + dt == t for some t in it: consecutive samples would be the same
/// time) or asks for more than 1e15 samples (the limit on fixed steps): either never finishes.
template <class Real>
bool sampling_valid(Real t0, same_t<Real> t_end, same_t<Real> dt) {
  if (!(dt > 0) || t0 == t_end || !std::isfinite(t0) || !std::isfinite(t_end)) {
    return true;
  }
  const Real t_max = std::max(std::fabs(t0), std::fabs(t_end));
  const Real resolution = 2 * std::numeric_limits<Real>::epsilon() * t_max;
  return dt > resolution && std::fabs(t_end - t0) / dt <= Real(1e15);
}

/// Smallest step the integrators accept at time t. Below it t + h is no longer
/// meaningfully different from t, so continuing would only burn time: 1e-14 * max(1, |t|) in double (45 ulps),
/// 45 ulps (5.4e-6 * max(1, |t|)) in float.
template <class Real>
Real min_step(Real t) {
  const Real relative = std::max(Real(1e-14), 45 * std::numeric_limits<Real>::epsilon());
  return relative * std::max(Real(1.0), std::fabs(t));
}

/// The first step when nothing better is known: 1e-6 (as in dopri5.f's hinit and radau5.f), in float at least
/// 10 min_step(t), which 1e-6 is not beyond |t| = 0.02 (float gets its own floor, double runs stay as they were).
template <class Real>
Real default_first_step(Real t) {
  if constexpr (std::numeric_limits<Real>::digits >= std::numeric_limits<double>::digits) {
    return Real(1e-6);
  } else {
    return std::max(Real(1e-6), 10 * min_step(t));
  }
}

/// The grid of a fixed-step method: `count` steps of equal size that cover [t0, t_end] with steps no
/// longer than h. Status::ok with count 0 when t_end == t0; invalid_argument for h <= 0 (or NaN);
/// step_size_underflow for steps below min_step; too_many_steps beyond 1e15 steps.
template <class Real>
Status fixed_step_count(Real t0, same_t<Real> t_end, same_t<Real> h, long& count) {
  count = 0;
  const Real span = t_end - t0;
  if (span == Real(0.0)) {
    return Status::ok;
  }
  if (!(h > 0)) {
    return Status::invalid_argument;
  }
  const Real ratio = std::fabs(span) / h;
  if (!(ratio <= Real(1e15))) {
    return Status::too_many_steps;
  }
  count = std::max(1L, static_cast<long>(std::ceil(ratio - Real(1e-9))));
  if (std::fabs(span) / static_cast<Real>(count) < min_step(std::max(std::fabs(t0), std::fabs(t_end)))) {
    return Status::step_size_underflow;
  }
  return Status::ok;
}

/// Hairer's starting-step heuristic (hinit in dopri5.f and dop853.f) for an explicit method of order
/// `order`: an explicit Euler probe of a size where the first derivative looks resolved estimates the
/// second derivative, then h is chosen so that h^order * max(|x'|, |x''|) is about 0.01 in the norm
/// scaled by atol + rtol |x|. Costs one rhs evaluation (counted in rhs_evals); x1 and f1 are work space.
template <class Rhs, class Real>
Real hairer_initial_step(Rhs& rhs, Real t, const Real* x, const Real* f0, Real dir, Real h_limit, Real atol, Real rtol,
                         int order, Real* x1, Real* f1, std::size_t n, long& rhs_evals) {
  Real dnf = Real(0.0);
  Real dny = Real(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Real sk = atol + rtol * std::fabs(x[i]);
    dnf += (f0[i] / sk) * (f0[i] / sk);
    dny += (x[i] / sk) * (x[i] / sk);
  }
  Real h = (dnf <= Real(1e-10) || dny <= Real(1e-10)) ? default_first_step(t) : Real(0.01) * std::sqrt(dny / dnf);
  h = std::min(h, h_limit);

  for (std::size_t i = 0; i < n; ++i) x1[i] = x[i] + dir * h * f0[i];
  rhs(t + dir * h, x1, f1);
  ++rhs_evals;
  Real der2 = Real(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Real sk = atol + rtol * std::fabs(x[i]);
    der2 += ((f1[i] - f0[i]) / sk) * ((f1[i] - f0[i]) / sk);
  }
  der2 = std::sqrt(der2) / h;
  if (!std::isfinite(der2) || !std::isfinite(dnf)) {
    return h;  // The guess is unusable; let step rejection shrink h instead.
  }
  const Real der12 = std::max(der2, std::sqrt(dnf));
  const Real h1 = der12 <= Real(1e-15) ? std::max(default_first_step(t), h * Real(1e-3))
                                       : std::pow(Real(0.01) / der12, Real(1.0) / static_cast<Real>(order));
  return std::min({Real(100.0) * h, h1, h_limit});
}

/// Sample times t0 + k*dt (k = 1, 2, ...) strictly inside (t0, t_end), in
/// either direction of time.
///
/// Times are formed by multiplication rather than by summing dt, so sample k
/// carries a single rounding error however long the run. A sample within
/// rounding distance of t_end is dropped because the integrators observe t_end
/// itself; without this, 0.1-spaced samples on [0, 0.3] would observe
/// 0.30000000000000004 next to 0.3.
template <class Real = double>
class SampleClock {
 public:
  /// dt <= 0 (or NaN) disables sampling.
  SampleClock(Real t0, same_t<Real> t_end, same_t<Real> dt)
      : t0_(t0),
        t_end_(t_end),
        dir_(t_end >= t0 ? Real(1.0) : Real(-1.0)),
        dt_(dt > 0 ? dt : Real(0.0)),
        guard_(std::max(Real(1e-9) * dt_,
                        8 * std::numeric_limits<Real>::epsilon() * std::max(std::fabs(t0), std::fabs(t_end)))) {}

  /// Whether the sampling can be done (sampling_valid).
  bool valid() const { return sampling_valid(t0_, t_end_, dt_); }

  /// Whether sampling was requested at all.
  bool enabled() const { return dt_ > 0; }

  /// Whether the next sample is at or before t (in the direction of integration).
  bool due(Real t) const {
    if (!enabled()) {
      return false;
    }
    const Real s = next();
    return (t - s) * dir_ >= 0 && (t_end_ - s) * dir_ > guard_;
  }

  /// Time of the next sample.
  Real next() const { return t0_ + dir_ * k_ * dt_; }

  /// Moves on to the following sample.
  void advance() { k_ += Real(1.0); }

 private:
  Real t0_;
  Real t_end_;
  Real dir_;
  Real dt_;
  Real guard_;
  Real k_ = Real(1.0);  // a real so that absurdly many samples cannot overflow an integer
};

/// Times an adaptive run's steps end on exactly (Options::stops, ascending): the knots of a piecewise input (a table
/// interpolated linearly), where the right-hand side has a kink that a step straddling it would resolve only by
/// rejections and with a larger error. `clamp` shortens a step from t that would pass the next stop strictly between
/// t and t_end so that it ends there. The run's time only advances, so a cursor passes each stop once: a step costs
/// O(1) whatever the table's length.
template <class Real>
class Stops {
 public:
  Stops(const Real* stops, std::size_t count, Real dir) : stops_(stops), count_(stops ? count : 0), dir_(dir) {}
  /// The step h (unsigned) from t, shortened to end on the next stop ahead when it would pass it (or stop within 1 %
  /// of it); `at` is then that stop.
  bool clamp(Real t, Real t_end, Real& h, Real& at) {
    while (passed_ < count_ && (ahead(passed_) - t) * dir_ <= 0) ++passed_;  // behind or at t
    if (passed_ == count_) return false;
    const Real s = ahead(passed_);
    if ((s - t_end) * dir_ >= 0) return false;  // at or beyond the end: t_end is where the run stops anyway
    if ((t + Real(1.01) * dir_ * h - s) * dir_ <= 0) return false;
    h = std::fabs(s - t);
    at = s;
    return true;
  }

 private:
  // The k-th stop in the direction of integration.
  Real ahead(std::size_t k) const { return dir_ > 0 ? stops_[k] : stops_[count_ - 1 - k]; }

  const Real* stops_;
  std::size_t count_;
  Real dir_;
  std::size_t passed_ = 0;  ///< stops behind the run's time
};

/// The step bookkeeping the explicit adaptive integrators share (integrate_dopri5, integrate_dop853): the checks
/// before any work, the first derivative and step, where every attempt ends (t_end exactly, never a sliver short of
/// it), rejections, the step after an accepted one and the end of an accepted step. A method adds its stages, its
/// error estimate, its controller and its dense output. `Options` has rtol, atol, h0, h_max and max_steps.
template <class Options>
struct AdaptiveSteps {
  using Real = decltype(Options::rtol);
  AdaptiveSteps(Real t0_, Real t_end_, const Options& opt_)
      : opt(opt_),
        t0(t0_),
        t_end(t_end_),
        dir(t_end_ > t0_ ? Real(1.0) : Real(-1.0)),
        h_limit(opt_.h_max > 0 ? opt_.h_max : std::numeric_limits<Real>::infinity()),
        t(t0_) {
    result.t = t0_;
  }

  /// The run ends with `status` (result.t: the last accepted time); false, for `return` at once.
  bool end(Status status) {
    result.status = status;
    return false;
  }

  /// The checks before any work, then the observation of t0: false when the run ends there, invalid_argument for
  /// settings that make no sense (sampling_valid too) or buffers (x, and `size` doubles of work where `needed` are
  /// required) that do not fit, non_finite_state for a non-finite t0, t_end or state, ok when t_end == t0.
  template <class Observer>
  bool start(const Real* x, std::size_t n, const Real* work, std::size_t size, std::size_t needed, Real sample_dt,
             Observer& observe) {
    if (!buffers_fit(x, n, work, size, needed) || !adaptive_settings_valid(opt.rtol, opt.atol, opt.h0, opt.h_max) ||
        !sampling_valid(t0, t_end, sample_dt)) {
      return end(Status::invalid_argument);
    }
    if (!std::isfinite(t0) || !std::isfinite(t_end) || !all_finite(x, n)) {
      return end(Status::non_finite_state);
    }
    observe(t0, x);
    return t_end == t0 ? end(Status::ok) : true;
  }

  /// f0 = rhs(t0, x), counted; false (non_finite_state) when it is not finite.
  template <class Rhs>
  bool first_derivative(Rhs& rhs, const Real* x, Real* f0, std::size_t n) {
    rhs(t, x, f0);
    ++result.stats.rhs_evals;
    return all_finite(f0, n) ? true : end(Status::non_finite_state);
  }

  /// The first step: |opt.h0|, or when that is 0 Hairer's choice for a method of order `order` (x1 and f1 are work
  /// space), at most h_limit.
  template <class Rhs>
  void first_step(Rhs& rhs, const Real* x, const Real* f0, int order, Real* x1, Real* f1, std::size_t n) {
    h = std::fabs(opt.h0);
    if (h == Real(0.0) || !std::isfinite(h)) {
      h = hairer_initial_step(rhs, t, x, f0, dir, std::min(h_limit, std::fabs(t_end - t0)), opt.atol, opt.rtol, order,
                              x1, f1, n, result.stats.rhs_evals);
    }
    h = std::min(h, h_limit);
  }

  /// Before an attempt: false when the run ends, too_many_steps after opt.max_steps attempts, step_size_underflow
  /// once h is below min_step (non_finite_state when non-finite values caused the last rejection). Otherwise the
  /// attempt's signed step hs, its end t_next and whether it is the last: a step that would end short of t_end by
  /// less than 1 % of itself, or beyond t_end, is stretched or shrunk to end there exactly.
  bool begin_attempt() {
    if (result.stats.steps + result.stats.rejected >= opt.max_steps) {
      return end(Status::too_many_steps);
    }
    if (!(h >= min_step(t))) {
      return end(non_finite_last ? Status::non_finite_state : Status::step_size_underflow);
    }
    last = false;
    Real stop = t_end;
    bool at_stop = false;
    if ((t + Real(1.01) * dir * h - t_end) * dir > 0) {
      h = std::fabs(t_end - t);
      last = true;
    } else {
      at_stop = stops.clamp(t, t_end, h, stop);
    }
    hs = dir * h;
    t_next = last ? t_end : at_stop ? stop : t + hs;
    return true;
  }

  /// An attempt that met NaN or Inf (most likely the step left the region where the model is defined, or
  /// overflowed; a shorter one may stay inside it): rejected, the next attempt `shrink` times as long.
  void reject_non_finite(Real shrink) {
    ++result.stats.rejected;
    rejected_last = true;
    non_finite_last = true;
    h *= shrink;
  }

  /// An attempt whose error is too large: rejected, the next attempt's step h / divisor.
  void reject(Real divisor) {
    ++result.stats.rejected;
    rejected_last = true;
    non_finite_last = false;
    h /= divisor;
  }

  /// The step after this accepted one: h / fac, at most h_limit, and right after a rejection no longer than h.
  Real next_step(Real fac) const {
    const Real h_new = std::min(h / fac, h_limit);
    return rejected_last ? std::min(h_new, h) : h_new;
  }

  /// Ends an accepted attempt: x = x_new at t_next, observed there unless samples are observed instead
  /// (`sampling`) and it is not t_end; the next attempt has step h_new. False when that was the last (status ok).
  template <class Observer>
  bool accept(Real* x, const Real* x_new, std::size_t n, Real h_new, bool sampling, Observer& observe) {
    ++result.stats.steps;
    std::copy(x_new, x_new + n, x);
    t = t_next;
    result.t = t;
    if (!sampling || last) {
      observe(t, x);
    }
    if (last) {
      return end(Status::ok);
    }
    h = h_new;
    rejected_last = false;
    non_finite_last = false;
    return true;
  }

  const Options& opt;
  const Real t0, t_end;
  const Real dir;      ///< +1 forward in time, -1 backward
  const Real h_limit;  ///< the largest step
  Stops<Real> stops{opt.stops, opt.n_stops, dir};
  BasicIntegrationOutcome<Real> result;
  Real t;                        ///< the last accepted time
  Real h = Real(0.0);            ///< the next attempt's step (unsigned)
  Real hs = Real(0.0);           ///< this attempt's signed step
  Real t_next = Real(0.0);       ///< where it ends
  bool last = false;             ///< it ends at t_end
  bool rejected_last = false;    ///< no growth right after a rejection
  bool non_finite_last = false;  ///< the last rejection came from NaN/Inf, not from the error
};

/// A vector overload's run: the work space of `Workspace` allocated once, before the first step, then the heap-free
/// form `run(x, n, work)`; the final state is returned in the result's vector, bit-identical to the heap-free form.
template <class Workspace, class Run>
IntegrationResult run_with_allocated_work(std::vector<double> x, Run&& run) {
  std::vector<double> work(Workspace::doubles(x.size()));
  const IntegrationOutcome outcome = run(x.data(), x.size(), Workspace{work.data(), work.size()});
  return to_result(outcome, std::move(x));
}

}  // namespace detail
}  // namespace hamel::runtime
