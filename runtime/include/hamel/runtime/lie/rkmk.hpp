// SPDX-License-Identifier: MIT
// Munthe-Kaas Runge-Kutta (RKMK4) reconstruction on a Lie group:
// g' = g hat(xi(t, g)) or g' = hat(xi(t, g)) g.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime::lie {

/// Which reconstruction equation is solved (the paper's (KinRec)):
/// left: g' = g hat(xi), xi = vee(g^-1 g') are body velocities;
/// right: g' = hat(xi) g, xi = vee(g' g^-1) are spatial velocities.
enum class Trivialization { left, right };

/// Outcome of a group integration run; see IntegrationResult.
template <class Group>
struct GroupIntegrationResult {
  Status status = Status::ok;
  double t = 0;  // t_end on success, else the time of the last finite state
  IntegrationStats stats;
  typename Group::Element g;  // state at t (the last finite state on failure)
};

/// Observer that ignores everything.
struct NoGroupObserver {
  template <class Element>
  void operator()(double /*t*/, const Element& /*g*/) const noexcept {}
};

namespace detail {

/// a x for an algebra coordinate vector x.
template <std::size_t N>
std::array<double, N> scaled(double a, const std::array<double, N>& x) {
  std::array<double, N> r;
  for (std::size_t i = 0; i < N; ++i) r[i] = a * x[i];
  return r;
}

}  // namespace detail

/// Integrates g' = g hat(xi(t, g)) (left) or g' = hat(xi(t, g)) g (right) from
/// g(t0) = g0 to t_end with the fourth-order Runge-Kutta-Munthe-Kaas method.
///
/// Group is a policy such as SO3, SE3, SO3xR3, SE2 or Rn<k>: it provides dim,
/// Vector, Element, exp, dexpinv and compose (see so3.hpp). xi(t, g, out) writes
/// the dim components of the velocity to the double* out.
///
/// Each step writes the solution near g_n as g_n exp(eta) (left) or
/// exp(eta) g_n (right) and applies the classic RK4 tableau to the equation of
/// the chart coordinate eta (the paper's (KinRec2)):
///     eta' = dexp(-eta)^-1 xi   (left),   eta' = dexp(eta)^-1 xi   (right),
/// with eta(t_n) = 0. The chart is re-centred at g_n every step, so eta stays of
/// size h |xi| and never approaches the singularity of dexp^-1 (at |w| = 2 pi
/// for rotations); motions of any number of turns are integrated at the same
/// accuracy. The iterates stay on the group up to rounding, since they are
/// products of exponentials. The method has order 4 (Munthe-Kaas 1998); the
/// exact dexp^-1 is used rather than a truncated commutator series.
///
/// Steps, sampling and failures follow integrate_rk4 (rk4.hpp): count =
/// ceil(|t_end - t0| / h - 1e-9) equal steps; observe(t, g) at t0, at every
/// t0 + k sample_dt strictly inside, and at t_end (every step if
/// sample_dt <= 0). Samples between steps are g_n exp(eta(s)) (or
/// exp(eta(s)) g_n) with eta(s) the cubic Hermite interpolant of the chart
/// coordinate, whose error O(h^4) matches the method. The cost is 4 xi
/// evaluations per step (the one at the end of a step is the next step's
/// first) plus one when a sample falls inside the last step.
///
/// Failures: a non-finite t0, t_end or g0, or a non-finite velocity or state,
/// gives non_finite_state with the last finite state and its time; h <= 0, or a sample_dt that
/// detail::sampling_valid refuses, gives invalid_argument, a
/// step below 1e-14 * max(1, |t|) gives step_size_underflow; more than 1e15
/// steps gives too_many_steps.
///
/// Memory: none is allocated. The state, the stages and the chart coordinates are fixed-size values
/// (Group::Element and std::array of Group::dim doubles), so there is no work space to provide and no
/// separate heap-free form; the observer sees a group element on the stack
/// (tests/runtime/integrators_do_not_allocate_test.cpp).
template <class Group, class Xi, class Observer>
GroupIntegrationResult<Group> integrate_rkmk4(Trivialization side, Xi&& xi, const typename Group::Element& g0,
                                              double t0, double t_end, double h, double sample_dt, Observer&& observe) {
  using Vector = typename Group::Vector;
  using Element = typename Group::Element;
  constexpr std::size_t n = Group::dim;

  GroupIntegrationResult<Group> result;
  result.t = t0;
  result.g = g0;
  auto finish = [&](Status status) {
    result.status = status;
    return result;
  };
  if (!hamel::runtime::detail::sampling_valid(t0, t_end, sample_dt)) {
    return finish(Status::invalid_argument);
  }
  if (!std::isfinite(t0) || !std::isfinite(t_end) || !Group::is_finite(g0)) {
    return finish(Status::non_finite_state);
  }
  const double span = t_end - t0;
  long count = 0;
  if (const Status grid = hamel::runtime::detail::fixed_step_count(t0, t_end, h, count); grid != Status::ok) {
    return finish(grid);
  }

  observe(t0, result.g);
  if (count == 0) {
    return finish(Status::ok);
  }
  const double h_eff = span / static_cast<double>(count);
  const bool left = side == Trivialization::left;

  // The point of the chart centred at g with coordinate eta.
  auto chart = [&](const Element& g, const Vector& eta) {
    return left ? Group::compose(g, Group::exp(eta)) : Group::compose(Group::exp(eta), g);
  };
  // Velocity at (t, g) without chart correction; false if not finite.
  auto velocity = [&](double t, const Element& g, Vector& out) {
    xi(t, g, out.data());
    ++result.stats.rhs_evals;
    return all_finite(out);
  };
  // eta' for the chart coordinate eta, given the velocity v at chart(g, eta).
  auto chart_rate = [&](const Vector& eta, const Vector& v) {
    Vector e = eta;
    if (left) {
      for (double& c : e) c = -c;
    }
    return mat_vec<n>(Group::dexpinv(e), v);
  };

  hamel::runtime::detail::SampleClock clock(t0, t_end, sample_dt);
  double t = t0;
  Element g = g0;
  Vector k1, k2, k3, k4, v, end_rate;
  if (!velocity(t, g, k1)) {
    return finish(Status::non_finite_state);
  }

  for (long i = 1; i <= count; ++i) {
    const double t_next = (i == count) ? t_end : t0 + static_cast<double>(i) * h_eff;
    const double hs = t_next - t;
    const double half = 0.5 * hs;

    // k1 needs no correction: dexp(0)^-1 = I.
    Vector eta = detail::scaled(half, k1);
    velocity(t + half, chart(g, eta), v);
    k2 = chart_rate(eta, v);
    eta = detail::scaled(half, k2);
    velocity(t + half, chart(g, eta), v);
    k3 = chart_rate(eta, v);
    eta = detail::scaled(hs, k3);
    velocity(t_next, chart(g, eta), v);
    k4 = chart_rate(eta, v);
    Vector step;
    for (std::size_t j = 0; j < n; ++j) step[j] = hs / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
    // A non-finite stage velocity propagates into step; it is caught here
    // before exp sees it.
    if (!all_finite(step)) {
      return finish(Status::non_finite_state);
    }
    const Element g_next = chart(g, step);
    if (!Group::is_finite(g_next)) {
      return finish(Status::non_finite_state);
    }
    ++result.stats.steps;

    // The velocity at the step end is the next step's k1; after the last step
    // it is needed only to interpolate samples.
    const bool sample_due = clock.due(t_next);
    if (i < count || sample_due) {
      if (!velocity(t_next, g_next, v)) {
        // The state is fine but cannot be advanced (or interpolated) further.
        result.t = t_next;
        result.g = g_next;
        return finish(Status::non_finite_state);
      }
    }
    if (sample_due) {
      // Hermite data of eta on [t, t_next]: eta(t) = 0, eta'(t) = k1,
      // eta(t_next) = step, eta'(t_next) = chart rate of the end velocity.
      end_rate = chart_rate(step, v);
      const Vector zero{};
      while (clock.due(t_next)) {
        const double s = clock.next();
        Vector eta_s;
        hamel::runtime::detail::hermite_interpolate(zero.data(), k1.data(), step.data(), end_rate.data(), hs,
                                                    (s - t) / hs, eta_s.data(), n);
        observe(s, chart(g, eta_s));
        clock.advance();
      }
    }

    t = t_next;
    g = g_next;
    k1 = v;
    result.t = t;
    result.g = g;
    if (!clock.enabled() || i == count) {
      observe(t, result.g);
    }
  }
  return finish(Status::ok);
}

}  // namespace hamel::runtime::lie
