// SPDX-License-Identifier: MIT
// Classic fixed-step fourth-order Runge-Kutta integrator with Hermite-interpolated sampling.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

namespace detail {

/// Cubic Hermite interpolant on [t, t + h] at fraction theta, written as a
/// correction to linear interpolation (Hairer's form) so that it loses no
/// digits when x0 and x1 are close.
template <class Real>
void hermite_interpolate(const Real* x0, const Real* f0, const Real* x1, const Real* f1, same_t<Real> h,
                         same_t<Real> theta, Real* out, std::size_t n) {
  const Real theta1 = theta - Real(1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Real dx = x1[i] - x0[i];
    out[i] = x0[i] + theta * dx +
             theta * theta1 * ((Real(1.0) - Real(2.0) * theta) * dx + theta1 * h * f0[i] + theta * h * f1[i]);
  }
}

}  // namespace detail

/// Caller-provided work space of the heap-free integrate_rk4: a non-owning view of reals(n) reals of type Real (the
/// run's scalar type); Rk4Workspace for double.
template <class Real>
struct BasicRk4Workspace {
  /// Reals needed for n states: the four stages, a stage argument, the new state and a sample.
  static constexpr std::size_t reals(std::size_t n) { return 7 * n; }
  static constexpr std::size_t doubles(std::size_t n) { return reals(n); }

  Real* data = nullptr;
  std::size_t size = 0;  // reals at data
};
using Rk4Workspace = BasicRk4Workspace<double>;

/// Integrates x' = rhs(t, x) from t0 to t_end with the classic RK4 method.
///
/// The interval is split into count = ceil(|t_end - t0| / h - 1e-9) equal steps,
/// so a step h that divides the interval is used exactly (the 1e-9 absorbs the
/// rounding of the quotient) and otherwise the steps shrink slightly to land on
/// t_end exactly; t_end may lie before t0. observe(t, x) is called at t0, at
/// every t0 + k*sample_dt strictly inside the interval, and at t_end, once each
/// and in order; the samples come from the cubic Hermite interpolant of the
/// step, whose O(h^4) error matches the method. sample_dt <= 0 observes every
/// step instead. The cost is 4 rhs evaluations per step, plus one when a sample
/// falls inside the last step.
///
/// Failures: a non-finite t0, t_end, initial state or state derivative, or a
/// non-finite state after a step, gives non_finite_state with the last finite
/// state and its time; h <= 0 (or NaN), or a sample_dt below the resolution of t
/// or asking for more than 1e15 samples (detail::sampling_valid), gives invalid_argument; a step below
/// 1e-14 * max(1, |t|) gives step_size_underflow; more than 1e15 steps gives
/// too_many_steps.
///
/// Heap-free form: x holds the n initial values on entry and the state at the returned t on return; work
/// is Rk4Workspace::doubles(n) doubles of the caller's (a smaller or null work space gives
/// invalid_argument before any work). Nothing in the run allocates; the observer sees pointers into x and
/// work.
///
/// With a projector (projection.hpp; the last argument, optional): every new state is projected before the
/// derivative at it is taken (which is the next step's first stage and the samples' end slope: no extra rhs
/// evaluation), and every sample before it is observed; a projector status other than ok ends the run with it and
/// the state at the start of the step.
template <class Rhs, class Real, class Observer, class Projector>
BasicIntegrationOutcome<Real> integrate_rk4(Rhs&& rhs, detail::same_t<Real>* x_io, std::size_t n,
                                            detail::same_t<Real> t0, detail::same_t<Real> t_end, detail::same_t<Real> h,
                                            detail::same_t<Real> sample_dt, Observer&& observe,
                                            BasicRk4Workspace<Real> work, Projector&& project) {
  BasicIntegrationOutcome<Real> result;
  result.t = t0;
  if (!detail::buffers_fit(x_io, n, work.data, work.size, BasicRk4Workspace<Real>::reals(n)) ||
      !detail::sampling_valid(t0, t_end, sample_dt)) {
    result.status = Status::invalid_argument;
    return result;
  }
  // The current and the new state swap roles every step (pointers, not data); the final state is
  // copied back into the caller's x_io if it ends up in the work space.
  Real* x = x_io;
  Real* x_new = work.data + 6 * n;
  auto finish = [&](Status status) {
    result.status = status;
    if (x != x_io) std::copy(x, x + n, x_io);
    return result;
  };

  if (!std::isfinite(t0) || !std::isfinite(t_end) || !all_finite(x, n)) {
    return finish(Status::non_finite_state);
  }
  const Real span = t_end - t0;
  long count = 0;
  if (const Status grid = detail::fixed_step_count(t0, t_end, h, count); grid != Status::ok) {
    return finish(grid);
  }

  observe(t0, x);
  if (count == 0) {
    return finish(Status::ok);
  }
  const Real h_eff = span / static_cast<Real>(count);

  Real* k1 = work.data;  // derivative at the step start
  Real* k2 = k1 + n;     // also receives the derivative at the step end
  Real* k3 = k2 + n;
  Real* k4 = k3 + n;
  Real* stage = k4 + n;
  Real* sample = stage + n;

  detail::SampleClock<Real> clock(t0, t_end, sample_dt);
  Real t = t0;
  rhs(t, x, k1);
  ++result.stats.rhs_evals;
  if (!all_finite(k1, n)) {
    return finish(Status::non_finite_state);
  }

  for (long i = 1; i <= count; ++i) {
    // Step ends come from t0 + i*h_eff, not from accumulation, so the grid does
    // not drift; the actual step is whatever separates consecutive grid points.
    const Real t_next = (i == count) ? t_end : t0 + static_cast<Real>(i) * h_eff;
    const Real hs = t_next - t;
    const Real half = Real(0.5) * hs;

    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + half * k1[j];
    rhs(t + half, stage, k2);
    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + half * k2[j];
    rhs(t + half, stage, k3);
    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + hs * k3[j];
    rhs(t_next, stage, k4);
    result.stats.rhs_evals += 3;
    const Real sixth = hs / Real(6.0);
    for (std::size_t j = 0; j < n; ++j) {
      x_new[j] = x[j] + sixth * (k1[j] + Real(2.0) * (k2[j] + k3[j]) + k4[j]);
    }
    if (!all_finite(x_new, n)) {
      return finish(Status::non_finite_state);
    }
    if constexpr (detail::projects<Projector>) {
      const Status projected = project(t_next, x_new);
      if (projected != Status::ok) {
        return finish(projected);
      }
    }
    ++result.stats.steps;

    // The end derivative doubles as the next step's first stage; after the last
    // step it is needed only to interpolate samples.
    const bool sample_due = clock.due(t_next);
    if (i < count || sample_due) {
      rhs(t_next, x_new, k2);
      ++result.stats.rhs_evals;
      if (!all_finite(k2, n)) {
        // The state is fine but cannot be advanced (or interpolated) further.
        result.t = t_next;
        std::swap(x, x_new);
        return finish(Status::non_finite_state);
      }
    }
    while (clock.due(t_next)) {
      const Real s = clock.next();
      detail::hermite_interpolate(x, k1, x_new, k2, hs, (s - t) / hs, sample, n);
      if constexpr (detail::projects<Projector>) {
        const Status projected = project(s, sample);
        if (projected != Status::ok) {
          return finish(projected);
        }
      }
      observe(s, sample);
      clock.advance();
    }

    t = t_next;
    std::swap(x, x_new);
    std::swap(k1, k2);
    result.t = t;
    if (!clock.enabled() || i == count) {
      observe(t, x);
    }
  }
  return finish(Status::ok);
}

/// Heap-free form without a projector.
template <class Rhs, class Real, class Observer>
BasicIntegrationOutcome<Real> integrate_rk4(Rhs&& rhs, detail::same_t<Real>* x_io, std::size_t n,
                                            detail::same_t<Real> t0, detail::same_t<Real> t_end, detail::same_t<Real> h,
                                            detail::same_t<Real> sample_dt, Observer&& observe,
                                            BasicRk4Workspace<Real> work) {
  return integrate_rk4(rhs, x_io, n, t0, t_end, h, sample_dt, observe, work, NoProjector{});
}

/// Convenience form: the work space is allocated once, before the first step, and the final state is
/// returned in the result's vector. Results are bit-identical to the heap-free form.
template <class Rhs, class Observer, class Projector>
IntegrationResult integrate_rk4(Rhs&& rhs, std::vector<double> x, double t0, double t_end, double h, double sample_dt,
                                Observer&& observe, Projector&& project) {
  std::vector<double> work(Rk4Workspace::doubles(x.size()));
  const IntegrationOutcome outcome = integrate_rk4(rhs, x.data(), x.size(), t0, t_end, h, sample_dt, observe,
                                                   Rk4Workspace{work.data(), work.size()}, project);
  return detail::to_result(outcome, std::move(x));
}

/// Convenience form without a projector.
template <class Rhs, class Observer>
IntegrationResult integrate_rk4(Rhs&& rhs, std::vector<double> x, double t0, double t_end, double h, double sample_dt,
                                Observer&& observe) {
  return integrate_rk4(rhs, std::move(x), t0, t_end, h, sample_dt, observe, NoProjector{});
}

/// One classical fourth-order Runge-Kutta step of size h of an emitted package's rhs kernel, x in place, with
/// three stack arrays of n_state reals (no allocation); the inputs `in` are held over the step. hamel emit prints the
/// lines between the markers below into every package that has rhs, as the package's own rk4_step (the generator's
/// build reads them into its emit/rk4_step.inc), so that a package needs nothing of the runtime; here the same code
/// is a template over the package's scalar type, state size and rhs:
/// hamel::runtime::rk4_step<pkg::real, pkg::n_state, pkg::rhs>(t, h, x, p, in). The text between the markers is
/// printed as it stands, so it may use only what an emitted package defines (real, n_state, rhs) and <cmath>.
template <class real, int n_state, void (*rhs)(real, const real*, const real*, const real*, real*)>
// clang-format off
// hamel emit: rk4_step begin
/* rk4_step: classical Runge-Kutta step of size h on x' = rhs(t, x), in place; 4 rhs calls, rk4_stack_reals reals of stack */
void rk4_step(real t, real h, real* x, const real* p, const real* in) {
  real k[n_state];
  real xs[n_state];
  real sum[n_state];
  const real half = h * real(0.5);
  rhs(t, x, p, in, k);
  for (int i = 0; i < n_state; ++i) {
    sum[i] = k[i];
    xs[i] = x[i] + half * k[i];
  }
  rhs(t + half, xs, p, in, k);
  for (int i = 0; i < n_state; ++i) {
    sum[i] += real(2.0) * k[i];
    xs[i] = x[i] + half * k[i];
  }
  rhs(t + half, xs, p, in, k);
  for (int i = 0; i < n_state; ++i) {
    sum[i] += real(2.0) * k[i];
    xs[i] = x[i] + h * k[i];
  }
  rhs(t + h, xs, p, in, k);
  const real sixth = h / real(6.0);
  for (int i = 0; i < n_state; ++i) x[i] += sixth * (sum[i] + k[i]);
}
// hamel emit: rk4_step end
// clang-format on

}  // namespace hamel::runtime
