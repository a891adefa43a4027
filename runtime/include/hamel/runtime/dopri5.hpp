// SPDX-License-Identifier: MIT
// Adaptive Dormand-Prince 5(4) integrator with dense output, after Hairer's DOPRI5.
//
// Reference: E. Hairer, S. P. Norsett, G. Wanner, "Solving Ordinary Differential
// Equations I", 2nd ed., Springer 1993, Sections II.4-II.6, and the Fortran code
// dopri5.f by Hairer and Wanner, whose coefficients and step-size controller are
// reproduced here.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Settings of integrate_dopri5, in the run's scalar type Real (Dopri5Options for double).
template <class Real>
struct BasicDopri5Options {
  Real rtol = Real(1e-8);     // relative tolerance, per component
  Real atol = Real(1e-10);    // absolute tolerance, per component; keep it > 0 for states near 0
  Real h0 = 0;                // initial step (sign ignored, finite); 0: automatic (Hairer's algorithm)
  Real h_max = 0;             // largest step; 0 (or +infinity): no limit; negative or NaN: invalid_argument
  long max_steps = 10000000;  // limit on step attempts, accepted plus rejected
  // Times the steps end on exactly, ascending (knots of a piecewise-linear input table, where the right-hand side has a
  // kink); those outside (t0, t_end) are ignored. nullptr: none. Not owned: they must outlive the run.
  const Real* stops = nullptr;
  std::size_t n_stops = 0;
};
using Dopri5Options = BasicDopri5Options<double>;

namespace detail::dopri5 {

// Butcher tableau (Dormand & Prince 1980).
constexpr double c2 = 1.0 / 5.0, c3 = 3.0 / 10.0, c4 = 4.0 / 5.0, c5 = 8.0 / 9.0;
constexpr double a21 = 1.0 / 5.0;
constexpr double a31 = 3.0 / 40.0, a32 = 9.0 / 40.0;
constexpr double a41 = 44.0 / 45.0, a42 = -56.0 / 15.0, a43 = 32.0 / 9.0;
constexpr double a51 = 19372.0 / 6561.0, a52 = -25360.0 / 2187.0, a53 = 64448.0 / 6561.0, a54 = -212.0 / 729.0;
constexpr double a61 = 9017.0 / 3168.0, a62 = -355.0 / 33.0, a63 = 46732.0 / 5247.0, a64 = 49.0 / 176.0,
                 a65 = -5103.0 / 18656.0;
// The fifth-order weights double as the last stage row (FSAL).
constexpr double a71 = 35.0 / 384.0, a73 = 500.0 / 1113.0, a74 = 125.0 / 192.0, a75 = -2187.0 / 6784.0,
                 a76 = 11.0 / 84.0;
// Difference between the fifth- and fourth-order weights.
constexpr double e1 = 71.0 / 57600.0, e3 = -71.0 / 16695.0, e4 = 71.0 / 1920.0, e5 = -17253.0 / 339200.0,
                 e6 = 22.0 / 525.0, e7 = -1.0 / 40.0;
// Continuous extension of order 4: the dense output coefficients of dopri5.f
// (due to Shampine, 1986).
constexpr double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
                 d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
                 d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;

// Step-size controller of dopri5.f: PI control with Lund stabilisation.
constexpr double safety = 0.9;
constexpr double fac_min = 0.2;   // h_new / h >= 0.2
constexpr double fac_max = 10.0;  // h_new / h <= 10
constexpr double beta = 0.04;
constexpr double expo1 = 0.2 - beta * 0.75;

}  // namespace detail::dopri5

/// Caller-provided work space of the heap-free integrate_dopri5: a non-owning view of reals(n) reals of type Real (the
/// run's scalar type); Dopri5Workspace for double.
template <class Real>
struct BasicDopri5Workspace {
  /// Reals needed for n states: seven stages, a stage argument, the new state, two dense output
  /// terms and a sample.
  static constexpr std::size_t reals(std::size_t n) { return 12 * n; }
  static constexpr std::size_t doubles(std::size_t n) { return reals(n); }

  Real* data = nullptr;
  std::size_t size = 0;  // reals at data
};
using Dopri5Workspace = BasicDopri5Workspace<double>;

/// Integrates x' = rhs(t, x) from t0 to t_end (t_end may lie before t0) with
/// the adaptive Dormand-Prince 5(4) pair, advancing with the fifth-order
/// solution and reusing the last stage as the next first stage (FSAL).
///
/// A step is accepted when the RMS over components of err_i / (atol + rtol *
/// max(|x_i|, |x_new_i|)) is at most 1. observe(t, x) is called at t0, at every
/// t0 + k*sample_dt strictly inside the interval, and at t_end, once each and in
/// order; samples come from Hairer's order-4 continuous extension at no extra
/// rhs cost. sample_dt <= 0 observes every accepted step instead.
///
/// Failures leave the last accepted state and its time in the result:
/// step_size_underflow when the controller needs h < 1e-14 * max(1, |t|);
/// non_finite_state for a non-finite t0, t_end, initial state or initial
/// derivative, or when non-finite stages persist (they are first treated as a
/// rejected step and retried with a step 5 times smaller) down to that
/// underflow limit; too_many_steps when opt.max_steps attempts do not suffice.
///
/// invalid_argument, before any work: a tolerance that is negative or not
/// finite, opt.h0 not finite, opt.h_max negative or NaN, a sample_dt below the
/// resolution of t or asking for more than 1e15 samples (detail::sampling_valid); in the heap-free form
/// also a work space smaller than Dopri5Workspace::doubles(n) (or null).
///
/// Heap-free form: x holds the n initial values on entry and the state at the
/// returned t on return; nothing in the run allocates, and the observer sees
/// pointers into x and work.
///
/// With a projector (projection.hpp; the last argument, optional): the samples of
/// a step are interpolated from the step as computed and projected one by one
/// before they are observed, then the new state is projected, accepted and
/// observed, and the first stage of the next step is evaluated at it (one more
/// rhs evaluation per step: FSAL's last stage belongs to the unprojected state).
/// A projector status other than ok ends the run with it and the last accepted
/// state.
template <class Rhs, class Real, class Observer, class Projector>
BasicIntegrationOutcome<Real> integrate_dopri5(Rhs&& rhs, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicDopri5Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicDopri5Workspace<Real> work,
                                               Projector&& project) {
  namespace k = detail::dopri5;
  detail::AdaptiveSteps<BasicDopri5Options<Real>> steps(t0, t_end, opt);
  if (!steps.start(x, n, work.data, work.size, BasicDopri5Workspace<Real>::reals(n), sample_dt, observe)) {
    return steps.result;
  }

  // Pointers into the work space are swapped, not data.
  Real* k1 = work.data;
  Real* k2 = k1 + n;
  Real* k3 = k2 + n;
  Real* k4 = k3 + n;
  Real* k5 = k4 + n;
  Real* k6 = k5 + n;
  Real* k7 = k6 + n;
  Real* stage = k7 + n;
  Real* x_new = stage + n;
  Real* r4 = x_new + n;  // dense output coefficients besides x, x_new - x and bspl
  Real* r5 = r4 + n;
  Real* sample = r5 + n;

  if (!steps.first_derivative(rhs, x, k1, n)) {
    return steps.result;
  }
  steps.first_step(rhs, x, k1, 5, stage, k2, n);

  detail::SampleClock<Real> clock(t0, t_end, sample_dt);
  Real fac_old = Real(1e-4);
  const Real inv_n = n > 0 ? Real(1.0) / static_cast<Real>(n) : Real(0.0);

  while (steps.begin_attempt()) {
    const Real t = steps.t, hs = steps.hs, t_next = steps.t_next;

    // Stages 2..7; a non-finite derivative aborts the attempt early.
    bool finite = true;
    auto eval = [&](Real ts, const Real* in, Real* out) {
      rhs(ts, in, out);
      ++steps.result.stats.rhs_evals;
      finite = all_finite(out, n);
      return finite;
    };
    do {
      for (std::size_t i = 0; i < n; ++i) stage[i] = x[i] + hs * Real(k::a21) * k1[i];
      if (!eval(t + Real(k::c2) * hs, stage, k2)) break;
      for (std::size_t i = 0; i < n; ++i) stage[i] = x[i] + hs * (Real(k::a31) * k1[i] + Real(k::a32) * k2[i]);
      if (!eval(t + Real(k::c3) * hs, stage, k3)) break;
      for (std::size_t i = 0; i < n; ++i) {
        stage[i] = x[i] + hs * (Real(k::a41) * k1[i] + Real(k::a42) * k2[i] + Real(k::a43) * k3[i]);
      }
      if (!eval(t + Real(k::c4) * hs, stage, k4)) break;
      for (std::size_t i = 0; i < n; ++i) {
        stage[i] =
            x[i] + hs * (Real(k::a51) * k1[i] + Real(k::a52) * k2[i] + Real(k::a53) * k3[i] + Real(k::a54) * k4[i]);
      }
      if (!eval(t + Real(k::c5) * hs, stage, k5)) break;
      for (std::size_t i = 0; i < n; ++i) {
        stage[i] = x[i] + hs * (Real(k::a61) * k1[i] + Real(k::a62) * k2[i] + Real(k::a63) * k3[i] +
                                Real(k::a64) * k4[i] + Real(k::a65) * k5[i]);
      }
      if (!eval(t_next, stage, k6)) break;
      for (std::size_t i = 0; i < n; ++i) {
        x_new[i] = x[i] + hs * (Real(k::a71) * k1[i] + Real(k::a73) * k3[i] + Real(k::a74) * k4[i] +
                                Real(k::a75) * k5[i] + Real(k::a76) * k6[i]);
      }
      finite = all_finite(x_new, n);
      if (!finite) break;
      eval(t_next, x_new, k7);
    } while (false);

    Real err = Real(0.0);
    if (finite) {
      for (std::size_t i = 0; i < n; ++i) {
        const Real e = hs * (Real(k::e1) * k1[i] + Real(k::e3) * k3[i] + Real(k::e4) * k4[i] + Real(k::e5) * k5[i] +
                             Real(k::e6) * k6[i] + Real(k::e7) * k7[i]);
        const Real sk = opt.atol + opt.rtol * std::max(std::fabs(x[i]), std::fabs(x_new[i]));
        err += (e / sk) * (e / sk);
      }
      err = std::sqrt(err * inv_n);
      finite = std::isfinite(err);
    }
    if (!finite) {
      steps.reject_non_finite(Real(k::fac_min));
      continue;
    }
    const Real fac11 = std::pow(err, Real(k::expo1));
    if (err > Real(1.0)) {
      steps.reject(std::min(Real(1.0) / Real(k::fac_min), fac11 / Real(k::safety)));
      continue;
    }

    // Lund stabilisation: the previous error damps the growth (PI control).
    Real fac = fac11 / std::pow(fac_old, Real(k::beta));
    fac = std::clamp(fac / Real(k::safety), Real(1.0) / Real(k::fac_max), Real(1.0) / Real(k::fac_min));
    const Real h_new = steps.next_step(fac);
    fac_old = std::max(err, Real(1e-4));

    if (clock.due(t_next)) {
      // Dense output of dopri5.f: x + theta*(dx + (1-theta)*(bspl + theta*(r4 + (1-theta)*r5))),
      // with r3 = bspl kept in k2, whose stage value is not needed any more.
      Real* bspl = k2;
      for (std::size_t i = 0; i < n; ++i) {
        const Real dx = x_new[i] - x[i];
        bspl[i] = hs * k1[i] - dx;
        r4[i] = dx - hs * k7[i] - bspl[i];
        r5[i] = hs * (Real(k::d1) * k1[i] + Real(k::d3) * k3[i] + Real(k::d4) * k4[i] + Real(k::d5) * k5[i] +
                      Real(k::d6) * k6[i] + Real(k::d7) * k7[i]);
      }
      while (clock.due(t_next)) {
        const Real s = clock.next();
        const Real theta = (s - t) / hs;
        const Real theta1 = Real(1.0) - theta;
        for (std::size_t i = 0; i < n; ++i) {
          sample[i] = x[i] + theta * ((x_new[i] - x[i]) + theta1 * (bspl[i] + theta * (r4[i] + theta1 * r5[i])));
        }
        if constexpr (detail::projects<Projector>) {
          const Status projected = project(s, sample);
          if (projected != Status::ok) {
            steps.end(projected);
            return steps.result;
          }
        }
        observe(s, sample);
        clock.advance();
      }
    }

    if constexpr (detail::projects<Projector>) {
      const Status projected = project(t_next, x_new);
      if (projected != Status::ok) {
        steps.end(projected);
        return steps.result;
      }
    }
    std::swap(k1, k7);  // first same as last
    if (!steps.accept(x, x_new, n, h_new, clock.enabled(), observe)) {
      break;
    }
    if constexpr (detail::projects<Projector>) {
      if (!steps.first_derivative(rhs, x, k1, n)) {  // at the projected state
        break;
      }
    }
  }
  return steps.result;
}

/// Heap-free form without a projector.
template <class Rhs, class Real, class Observer>
BasicIntegrationOutcome<Real> integrate_dopri5(Rhs&& rhs, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicDopri5Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicDopri5Workspace<Real> work) {
  return integrate_dopri5(rhs, x, n, t0, t_end, opt, sample_dt, observe, work, NoProjector{});
}

/// Convenience form of integrate_dopri5: the work space is allocated once, before the first step, and
/// the final state is returned in the result's vector. Results are bit-identical to the heap-free form.
template <class Rhs, class Observer, class Projector>
IntegrationResult integrate_dopri5(Rhs&& rhs, std::vector<double> x, double t0, double t_end, const Dopri5Options& opt,
                                   double sample_dt, Observer&& observe, Projector&& project) {
  return detail::run_with_allocated_work<Dopri5Workspace>(
      std::move(x), [&](double* xs, std::size_t n, Dopri5Workspace w) {
        return integrate_dopri5(rhs, xs, n, t0, t_end, opt, sample_dt, observe, w, project);
      });
}

/// Convenience form without a projector.
template <class Rhs, class Observer>
IntegrationResult integrate_dopri5(Rhs&& rhs, std::vector<double> x, double t0, double t_end, const Dopri5Options& opt,
                                   double sample_dt, Observer&& observe) {
  return integrate_dopri5(rhs, std::move(x), t0, t_end, opt, sample_dt, observe, NoProjector{});
}

}  // namespace hamel::runtime
