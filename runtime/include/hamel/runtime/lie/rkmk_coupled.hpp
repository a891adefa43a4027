// SPDX-License-Identifier: MIT
// Munthe-Kaas RK4 on G x R^n: reduced dynamics x' = f(t, x) together with the
// reconstruction g' = g hat(xi(t, x)) or g' = hat(xi(t, x)) g.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rkmk.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime::lie {

/// Outcome of a coupled run: the group part as in GroupIntegrationResult, the
/// vector part as in IntegrationResult.
template <class Group>
struct CoupledIntegrationResult {
  Status status = Status::ok;
  double t = 0;  // t_end on success, else the time of the last finite state
  IntegrationStats stats;
  typename Group::Element g;  // group state at t
  std::vector<double> x;      // vector state at t
};

/// Observer of a coupled run that ignores everything.
struct NoCoupledObserver {
  template <class Element>
  void operator()(double /*t*/, const double* /*x*/, const Element& /*g*/) const noexcept {}
};

namespace detail {

/// Calls fn(t, x, g, out) when it takes the group element, else fn(t, x, out).
template <class Element, class Fn>
void call_with_optional_group(Fn& fn, double t, const double* x, const Element& g, double* out) {
  if constexpr (std::is_invocable_v<Fn&, double, const double*, const Element&, double*>) {
    fn(t, x, g, out);
  } else {
    static_assert(std::is_invocable_v<Fn&, double, const double*, double*>,
                  "expected a callable (t, x, out) or (t, x, g, out)");
    fn(t, x, out);
  }
}

template <class Element, class Fn>
constexpr bool takes_group() {
  return std::is_invocable_v<Fn&, double, const double*, const Element&, double*>;
}

}  // namespace detail

/// Outcome of a heap-free coupled run (the workspace overload): as CoupledIntegrationResult, but the
/// vector state at t is in the caller's buffer x rather than in a vector.
template <class Group>
struct CoupledIntegrationOutcome {
  Status status = Status::ok;
  double t = 0;  // t_end on success, else the time of the last finite state
  IntegrationStats stats;
  typename Group::Element g;  // group state at t
};

/// Caller-provided work space of the heap-free integrate_rkmk4_coupled: a non-owning view of
/// doubles(n) doubles, n the dimension of the vector part. The group part needs none: its stages,
/// chart coordinates and elements are fixed-size values (std::array) sized by Group::dim.
struct RkmkCoupledWorkspace {
  /// Doubles needed for n vector states: the four stage derivatives, a stage argument, a sample and
  /// the new state.
  static constexpr std::size_t doubles(std::size_t n) { return 7 * n; }

  double* data = nullptr;
  std::size_t size = 0;  // doubles at data
};

/// Integrates the coupled system
///     x' = f(t, x),   g' = g hat(xi(t, x))  (left)  or  g' = hat(xi(t, x)) g  (right)
/// from (g0, x0) at t0 to t_end: the reduced (Lagrange-Poincare, Hamel)
/// dynamics of a symmetric system in any dimension n together with
/// the reconstruction of its motion on the symmetry group, the paper's (KinRec)
/// with a velocity that is part of the solution.
///
/// The method is RKMK4 on the product group G x R^n: the classic RK4 tableau is
/// applied to x and to the chart coordinate eta of g (g = g_n exp(eta) or
/// exp(eta) g_n, eta' = dexp(-eta)^-1 xi or dexp(eta)^-1 xi as in
/// integrate_rkmk4) with the SAME stages: stage s evaluates f and xi at
/// x_n + c_s h k^x_{s-1} (and g_n exp(c_s h k^eta_{s-1})). The chart is
/// re-centred every step. Order 4. With f = 0 it reproduces integrate_rkmk4
/// for the velocity xi(t, x0); with a trivial group it is integrate_rk4.
///
/// f(t, x, xdot) writes n doubles; xi(t, x, out) writes Group::dim doubles. For
/// systems whose reduced dynamics or velocity depend on the group element as
/// well (broken symmetry), either callable may instead take (t, x, g, out);
/// the stage group elements are then formed (one exp and one product per
/// stage), otherwise they are not.
///
/// Steps, sampling and failures follow integrate_rkmk4: count = ceil(|t_end -
/// t0| / h - 1e-9) equal steps; observe(t, x_ptr, g) at t0, at every t0 + k
/// sample_dt strictly inside (x and eta from their cubic Hermite interpolants)
/// and at t_end (every step if sample_dt <= 0). stats.rhs_evals counts
/// evaluations of the pair (f, xi): 4 per step, plus one when a sample falls
/// inside the last step. A non-finite t0, t_end, g0 or x0, or a non-finite f,
/// xi or state, gives non_finite_state with the last finite state and its time;
/// h <= 0, or a sample_dt that detail::sampling_valid refuses, gives invalid_argument, a step below 1e-14 * max(1, |t|)
/// gives step_size_underflow; more than 1e15 steps gives too_many_steps.
///
/// Heap-free form: x holds the n initial values on entry and the vector state at the returned t on
/// return, the outcome the group state at t; work is RkmkCoupledWorkspace::doubles(n) doubles of the
/// caller's (a smaller or null work space, or a null x with n > 0, gives invalid_argument before any
/// work). Nothing in the run allocates; the observer sees pointers into x and work.
template <class Group, class F, class Xi, class Observer>
CoupledIntegrationOutcome<Group> integrate_rkmk4_coupled(Trivialization side, F&& f, Xi&& xi,
                                                         const typename Group::Element& g0, double* x_io, std::size_t n,
                                                         double t0, double t_end, double h, double sample_dt,
                                                         Observer&& observe, RkmkCoupledWorkspace work) {
  using Vector = typename Group::Vector;
  using Element = typename Group::Element;
  constexpr std::size_t m = Group::dim;
  constexpr bool group_dependent = detail::takes_group<Element, std::remove_reference_t<F>>() ||
                                   detail::takes_group<Element, std::remove_reference_t<Xi>>();

  CoupledIntegrationOutcome<Group> result;
  result.t = t0;
  result.g = g0;
  if (!hamel::runtime::detail::buffers_fit(x_io, n, work.data, work.size, RkmkCoupledWorkspace::doubles(n)) ||
      !hamel::runtime::detail::sampling_valid(t0, t_end, sample_dt)) {
    result.status = Status::invalid_argument;
    return result;
  }
  // The current and the new vector state swap roles every step (pointers, not data); the final state
  // is copied back into the caller's x_io if it ends up in the work space.
  double* x = x_io;                   // x_n
  double* x_new = work.data + 6 * n;  // x_{n+1}
  auto finish = [&](Status status) {
    result.status = status;
    if (x != x_io) std::copy(x, x + n, x_io);
    return result;
  };
  if (!std::isfinite(t0) || !std::isfinite(t_end) || !Group::is_finite(g0) || !hamel::runtime::all_finite(x, n)) {
    return finish(Status::non_finite_state);
  }
  const double span = t_end - t0;
  long count = 0;
  if (const Status grid = hamel::runtime::detail::fixed_step_count(t0, t_end, h, count); grid != Status::ok) {
    return finish(grid);
  }

  observe(t0, static_cast<const double*>(x), static_cast<const Element&>(result.g));
  if (count == 0) {
    return finish(Status::ok);
  }
  const double h_eff = span / static_cast<double>(count);
  const bool left = side == Trivialization::left;

  double* a1 = work.data;  // f at the step start
  double* a2 = a1 + n;     // stage derivatives; a2 also receives f at the step end
  double* a3 = a2 + n;
  double* a4 = a3 + n;
  double* stage = a4 + n;  // stage state
  double* sample = stage + n;

  auto chart = [&](const Element& g, const Vector& eta) {
    return left ? Group::compose(g, Group::exp(eta)) : Group::compose(Group::exp(eta), g);
  };
  // f and xi at (t, xs, g_n exp(eta)); false if either is not finite.
  auto evaluate = [&](double t, const double* xs, const Element& g, const Vector& eta, double* dx, Vector& v) {
    if constexpr (group_dependent) {
      const Element gs = chart(g, eta);
      detail::call_with_optional_group<Element>(f, t, xs, gs, dx);
      detail::call_with_optional_group<Element>(xi, t, xs, gs, v.data());
    } else {
      (void)eta;
      detail::call_with_optional_group<Element>(f, t, xs, g, dx);
      detail::call_with_optional_group<Element>(xi, t, xs, g, v.data());
    }
    ++result.stats.rhs_evals;
    return hamel::runtime::all_finite(dx, n) && all_finite(v);
  };
  auto chart_rate = [&](const Vector& eta, const Vector& v) {
    Vector e = eta;
    if (left) {
      for (double& c : e) c = -c;
    }
    return mat_vec<m>(Group::dexpinv(e), v);
  };

  hamel::runtime::detail::SampleClock clock(t0, t_end, sample_dt);
  double t = t0;
  Element g = g0;
  Vector k1, k2, k3, k4, v, end_rate;
  const Vector zero{};
  if (!evaluate(t, x, g, zero, a1, k1)) {
    return finish(Status::non_finite_state);
  }

  for (long i = 1; i <= count; ++i) {
    const double t_next = (i == count) ? t_end : t0 + static_cast<double>(i) * h_eff;
    const double hs = t_next - t;
    const double half = 0.5 * hs;

    // Stage 1 is (a1, k1); dexp(0)^-1 = I needs no correction.
    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + half * a1[j];
    Vector eta = detail::scaled(half, k1);
    evaluate(t + half, stage, g, eta, a2, v);
    k2 = chart_rate(eta, v);
    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + half * a2[j];
    eta = detail::scaled(half, k2);
    evaluate(t + half, stage, g, eta, a3, v);
    k3 = chart_rate(eta, v);
    for (std::size_t j = 0; j < n; ++j) stage[j] = x[j] + hs * a3[j];
    eta = detail::scaled(hs, k3);
    evaluate(t_next, stage, g, eta, a4, v);
    k4 = chart_rate(eta, v);

    const double sixth = hs / 6.0;
    Vector step;
    for (std::size_t j = 0; j < m; ++j) step[j] = sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
    for (std::size_t j = 0; j < n; ++j) x_new[j] = x[j] + sixth * (a1[j] + 2.0 * (a2[j] + a3[j]) + a4[j]);
    // Non-finite stage values propagate into step and x_new and are caught
    // here, before exp sees them.
    if (!all_finite(step) || !hamel::runtime::all_finite(x_new, n)) {
      return finish(Status::non_finite_state);
    }
    const Element g_next = chart(g, step);
    if (!Group::is_finite(g_next)) {
      return finish(Status::non_finite_state);
    }
    ++result.stats.steps;

    // The derivatives at the step end are the next step's first stage; after
    // the last step they are needed only to interpolate samples.
    const bool sample_due = clock.due(t_next);
    if (i < count || sample_due) {
      if (!evaluate(t_next, x_new, g_next, zero, a2, v)) {
        // The state is fine but cannot be advanced (or interpolated) further.
        result.t = t_next;
        result.g = g_next;
        std::swap(x, x_new);
        return finish(Status::non_finite_state);
      }
    }
    if (sample_due) {
      end_rate = chart_rate(step, v);
      while (clock.due(t_next)) {
        const double s = clock.next();
        const double theta = (s - t) / hs;
        Vector eta_s;
        hamel::runtime::detail::hermite_interpolate(zero.data(), k1.data(), step.data(), end_rate.data(), hs, theta,
                                                    eta_s.data(), m);
        hamel::runtime::detail::hermite_interpolate(x, a1, x_new, a2, hs, theta, sample, n);
        const Element g_s = chart(g, eta_s);
        observe(s, static_cast<const double*>(sample), g_s);
        clock.advance();
      }
    }

    t = t_next;
    g = g_next;
    std::swap(x, x_new);
    std::swap(a1, a2);
    k1 = v;
    result.t = t;
    result.g = g;
    if (!clock.enabled() || i == count) {
      observe(t, static_cast<const double*>(x), static_cast<const Element&>(g));
    }
  }
  return finish(Status::ok);
}

/// Convenience form of integrate_rkmk4_coupled, n = x0.size(): the work space is allocated once, before
/// the first step, and the final vector state is returned in the result's vector. Results are
/// bit-identical to the heap-free form.
template <class Group, class F, class Xi, class Observer>
CoupledIntegrationResult<Group> integrate_rkmk4_coupled(Trivialization side, F&& f, Xi&& xi,
                                                        const typename Group::Element& g0, std::vector<double> x0,
                                                        double t0, double t_end, double h, double sample_dt,
                                                        Observer&& observe) {
  std::vector<double> work(RkmkCoupledWorkspace::doubles(x0.size()));
  const CoupledIntegrationOutcome<Group> outcome =
      integrate_rkmk4_coupled<Group>(side, f, xi, g0, x0.data(), x0.size(), t0, t_end, h, sample_dt, observe,
                                     RkmkCoupledWorkspace{work.data(), work.size()});
  CoupledIntegrationResult<Group> result;
  result.status = outcome.status;
  result.t = outcome.t;
  result.stats = outcome.stats;
  result.g = outcome.g;
  result.x = std::move(x0);
  return result;
}

}  // namespace hamel::runtime::lie
