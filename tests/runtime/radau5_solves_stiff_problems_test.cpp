// SPDX-License-Identifier: MIT
// Radau IIA (radau5.hpp) converges at order 5 on non-stiff problems with
// closed-form solutions, meets its tolerance on the stiff Prothero-Robinson
// problem with a tiny fraction of DOPRI5's steps, reproduces the asymptotic
// period of the Van der Pol relaxation oscillation at mu = 1000, and honours
// the sampling and option contract shared with the explicit integrators.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/radau5.hpp"
#include "kepler_orbit.hpp"
#include "reference_problems.hpp"
#include "stiff_problems.hpp"

namespace {

using hamel::runtime::describe;
using hamel::runtime::Dopri5Options;
using hamel::runtime::FiniteDifferenceJacobian;
using hamel::runtime::integrate_dopri5;
using hamel::runtime::integrate_radau5;
using hamel::runtime::IntegrationResult;
using hamel::runtime::NoObserver;
using hamel::runtime::Radau5Options;
using hamel::runtime::Status;
using hamel_test::kepler_period;

constexpr double kEccentricity = 0.5;

std::vector<double> kepler_start() {
  const auto s = hamel_test::kepler_state(0.0, kEccentricity);
  return {s.begin(), s.end()};
}

// d/ds of the Kepler right-hand side, worked out by hand: the acceleration
// -r / |r|^3 has the derivative -I / |r|^3 + 3 r r^T / |r|^5.
void kepler_jac(double, const double* s, double* J) {
  const double x = s[0], y = s[1];
  const double r2 = x * x + y * y;
  const double r3 = r2 * std::sqrt(r2);
  const double r5 = r3 * r2;
  for (int i = 0; i < 16; ++i) J[i] = 0.0;
  J[0 * 4 + 2] = 1.0;
  J[1 * 4 + 3] = 1.0;
  J[2 * 4 + 0] = -1.0 / r3 + 3 * x * x / r5;
  J[2 * 4 + 1] = 3 * x * y / r5;
  J[3 * 4 + 0] = 3 * x * y / r5;
  J[3 * 4 + 1] = -1.0 / r3 + 3 * y * y / r5;
}

// Riccati equation x' = x^2 cos t, x(0) = 1/2, solved by x(t) = 1 / (2 - sin t).
void riccati_rhs(double t, const double* x, double* f) { f[0] = x[0] * x[0] * std::cos(t); }
void riccati_jac(double t, const double* x, double* J) { J[0] = 2 * x[0] * std::cos(t); }
double riccati_exact(double t) { return 1.0 / (2.0 - std::sin(t)); }

using hamel::runtime_test::kLambda;
using hamel::runtime_test::kMu;
using hamel::runtime_test::prothero_robinson_jac;
using hamel::runtime_test::prothero_robinson_rhs;
using hamel::runtime_test::van_der_pol_jac;
using hamel::runtime_test::van_der_pol_rhs;

Radau5Options tolerance(double tol) {
  Radau5Options opt;
  opt.rtol = tol;
  opt.atol = tol;
  return opt;
}

// Fixed steps with a Newton iteration converged far below the discretisation
// error; the first step starts Newton from zero, hence the extra iterations.
Radau5Options fixed_step(double h) {
  Radau5Options opt = tolerance(1e-13);
  opt.fixed_step = h;
  opt.max_newton_iterations = 30;
  return opt;
}

// Kepler over [0, 2] from periapsis; end errors measured 1.1e-5 .. 3.2e-10,
// pairwise orders 5.02, 5.02, 5.02. Samples at odd multiples of h/2 come from
// the cubic collocation polynomial, whose O(h^4) local error makes them
// converge at order 4 (measured 3.9, 3.9, 4.0).
TEST(RuntimeRadau5, FixedStepConvergesAtOrderFive) {
  const std::vector<double> steps = {0.1, 0.05, 0.025, 0.0125};
  std::vector<double> errors;
  std::vector<double> sample_errors;
  for (const double h : steps) {
    double worst = 0.0;
    const IntegrationResult r =
        integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0, 2.0, fixed_step(h), h / 2,
                         [&](double t, const double* x) {
                           if (std::lround(t / (h / 2)) % 2 == 1) {
                             worst = std::fmax(worst, hamel_test::kepler_error(t, x, kEccentricity));
                           }
                         });
    ASSERT_EQ(r.status, Status::ok) << "h = " << h;
    EXPECT_EQ(r.stats.steps, std::lround(2.0 / h));
    EXPECT_EQ(r.stats.rejected, 0);
    EXPECT_EQ(r.t, 2.0);
    errors.push_back(hamel_test::kepler_error(2.0, r.x.data(), kEccentricity));
    sample_errors.push_back(worst);
    std::printf("fixed h=%-7g end error=%.3e sample error=%.3e rhs=%ld jac=%ld lu=%ld\n", h, errors.back(), worst,
                r.stats.rhs_evals, r.stats.jac_evals, r.stats.lu_decompositions);
  }
  const double order = hamel_test::fitted_slope(steps, errors);
  const double sample_order = hamel_test::fitted_slope(steps, sample_errors);
  std::printf("fitted order %.3f, samples %.3f\n", order, sample_order);
  EXPECT_NEAR(order, 5.0, 0.3);
  EXPECT_NEAR(sample_order, 4.0, 0.4);
}

TEST(RuntimeRadau5, FixedStepConvergesAtOrderFiveOnRiccati) {
  const std::vector<double> steps = {0.2, 0.1, 0.05, 0.025};  // errors 5e-8 .. 1.6e-12
  std::vector<double> errors;
  for (const double h : steps) {
    const IntegrationResult r =
        integrate_radau5(riccati_rhs, riccati_jac, {0.5}, 0.0, 10.0, fixed_step(h), 0.0, NoObserver{});
    ASSERT_EQ(r.status, Status::ok);
    errors.push_back(std::fabs(r.x[0] - riccati_exact(10.0)));
  }
  const double order = hamel_test::fitted_slope(steps, errors);
  std::printf("riccati fitted order %.3f\n", order);
  EXPECT_NEAR(order, 5.0, 0.3);
}

// Under error control the tolerance bounds the local error; on the Kepler
// orbit the global error after one period comes out at 0.1 .. 5 times the
// tolerance (measured), and the work grows like a fifth-order method's.
TEST(RuntimeRadau5, KeplerErrorFollowsTheTolerance) {
  std::vector<double> tols;
  std::vector<double> errors;
  std::vector<long> steps;
  for (double tol = 1e-3; tol > 0.5e-11; tol /= 100) {
    const IntegrationResult r = integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0, kepler_period,
                                                 tolerance(tol), 0.0, NoObserver{});
    ASSERT_EQ(r.status, Status::ok);
    const double e = hamel_test::kepler_error(kepler_period, r.x.data(), kEccentricity);
    std::printf("tol=%.0e: steps=%ld rejected=%ld rhs=%ld jac=%ld lu=%ld error=%.3e (%.2f x tol)\n", tol, r.stats.steps,
                r.stats.rejected, r.stats.rhs_evals, r.stats.jac_evals, r.stats.lu_decompositions, e, e / tol);
    EXPECT_LT(e, 10 * tol) << "tol " << tol;
    EXPECT_GT(e, 0.01 * tol) << "tol " << tol;  // far below would mean wasted work
    EXPECT_LE(r.stats.jac_evals, r.stats.steps + r.stats.rejected);
    EXPECT_LE(r.stats.lu_decompositions, r.stats.steps + r.stats.rejected);
    tols.push_back(tol);
    errors.push_back(e);
    steps.push_back(r.stats.steps);
  }
  const double p = hamel_test::fitted_slope(tols, errors);
  std::printf("fitted error ~ tol^%.3f\n", p);
  EXPECT_GT(p, 0.9);
  EXPECT_LT(p, 1.4);
  // The O(h^4) estimate sets h ~ tol^(1/4): steps ~ tol^(-1/4), measured -0.23.
  const double q = hamel_test::fitted_slope(tols, std::vector<double>(steps.begin(), steps.end()));
  std::printf("fitted steps ~ tol^%.3f\n", q);
  EXPECT_NEAR(q, -0.25, 0.05);
}

// The stiff test. Radau's step ends stay within the tolerance (measured 0.01x
// at 1e-4, 0.82x at 1e-6; at tighter tolerances 2.1x and 1.9x, where the
// estimate, filtered by (I - h gamma0 J)^-1, sees only part of the O(h^3 /
// |lambda|) error of the stiff component), with 9 .. 64 steps for the whole of
// [0, 10]. Samples between steps are judged elsewhere: the steps grow to ~7
// here, far beyond what a cubic can follow of sin t, because the error test
// controls the step ends only.
TEST(RuntimeRadau5, ProtheroRobinsonMeetsTheToleranceAtTheSteps) {
  for (const double tol : {1e-4, 1e-6, 1e-8, 1e-10}) {
    double worst = 0.0;
    const IntegrationResult r =
        integrate_radau5(prothero_robinson_rhs, prothero_robinson_jac, {0.0}, 0.0, 10.0, tolerance(tol), 0.0,
                         [&](double t, const double* x) { worst = std::fmax(worst, std::fabs(x[0] - std::sin(t))); });
    ASSERT_EQ(r.status, Status::ok);
    std::printf("prothero-robinson tol=%.0e: steps=%ld rejected=%ld jac=%ld lu=%ld worst error=%.3e (%.2f x tol)\n",
                tol, r.stats.steps, r.stats.rejected, r.stats.jac_evals, r.stats.lu_decompositions, worst, worst / tol);
    EXPECT_LT(worst, (tol >= 1e-6 ? 1.0 : 4.0) * tol) << "tol " << tol;
    EXPECT_LT(r.stats.steps, 100);
  }
}

// DOPRI5 is stable only for |h lambda| below ~3.3, so it needs ~3e5 steps per
// unit time whatever the tolerance; Radau IIA is L-stable and needs a handful
// (measured 8 against 302399: a ratio of 2.6e-5).
TEST(RuntimeRadau5, StiffProblemTakesAFractionOfDopri5Steps) {
  const double tol = 1e-6;
  double radau_worst = 0.0;
  const IntegrationResult r = integrate_radau5(
      prothero_robinson_rhs, prothero_robinson_jac, {0.0}, 0.0, 1.0, tolerance(tol), 0.0,
      [&](double t, const double* x) { radau_worst = std::fmax(radau_worst, std::fabs(x[0] - std::sin(t))); });
  Dopri5Options opt;
  opt.rtol = opt.atol = tol;
  double dopri5_worst = 0.0;
  const IntegrationResult d = integrate_dopri5(
      prothero_robinson_rhs, {0.0}, 0.0, 1.0, opt, 0.0,
      [&](double t, const double* x) { dopri5_worst = std::fmax(dopri5_worst, std::fabs(x[0] - std::sin(t))); });
  ASSERT_EQ(r.status, Status::ok);
  ASSERT_EQ(d.status, Status::ok);
  const double ratio = static_cast<double>(r.stats.steps) / static_cast<double>(d.stats.steps);
  std::printf(
      "radau5: %ld steps (%ld rhs, %ld jac, %ld lu), worst error %.2e; dopri5: %ld steps, worst error %.2e;"
      " step ratio %.2e\n",
      r.stats.steps, r.stats.rhs_evals, r.stats.jac_evals, r.stats.lu_decompositions, radau_worst, d.stats.steps,
      dopri5_worst, ratio);
  EXPECT_LT(radau_worst, tol);
  EXPECT_LT(ratio, 1.0 / 20);
  EXPECT_LT(ratio, 1e-3);
  // The problem is linear and J exact: Newton converges at once, theta stays
  // tiny, and the first Jacobian serves the whole run.
  EXPECT_EQ(r.stats.jac_evals, 1);
}

// Half-period of the relaxation oscillation from the zero crossings of x,
// located by linear interpolation between samples 1e-3 apart.
struct VanDerPolRun {
  IntegrationResult result;
  std::vector<double> crossings;
};

template <class Jac>
VanDerPolRun run_van_der_pol(Jac&& jac, double tol) {
  VanDerPolRun run;
  double t_prev = 0.0;
  double x_prev = 2.0;
  run.result = integrate_radau5(van_der_pol_rhs, jac, {2.0, 0.0}, 0.0, 1700.0, tolerance(tol), 1e-3,
                                [&](double t, const double* y) {
                                  if ((x_prev > 0) != (y[0] > 0)) {
                                    run.crossings.push_back(t_prev + (t - t_prev) * x_prev / (x_prev - y[0]));
                                  }
                                  t_prev = t;
                                  x_prev = y[0];
                                });
  return run;
}

// Dorodnitsyn's asymptotic period (1947; Bender & Orszag, Sect. 11.2):
// T = (3 - 2 ln 2) mu + 3 alpha mu^(-1/3) - (2/3) ln(mu) / mu + O(1/mu),
// alpha = 2.338107... the first zero of Ai(-x). For mu = 1000: T/2 = 807.2012,
// with an O(1/mu) remainder of order 1e-3. Measured: 807.2006.
TEST(RuntimeRadau5, VanDerPolRelaxationOscillationHasTheAsymptoticPeriod) {
  const double alpha = 2.338107410459767;
  const double half_period =
      0.5 * ((3 - 2 * std::log(2.0)) * kMu + 3 * alpha * std::cbrt(1 / kMu) - (2.0 / 3.0) * std::log(kMu) / kMu);
  const VanDerPolRun run = run_van_der_pol(van_der_pol_jac, 1e-6);
  const auto& s = run.result.stats;
  std::printf("van der pol mu=1e3 tol=1e-6: %s, steps=%ld rejected=%ld rhs=%ld jac=%ld lu=%ld\n",
              describe(run.result.status), s.steps, s.rejected, s.rhs_evals, s.jac_evals, s.lu_decompositions);
  ASSERT_EQ(run.result.status, Status::ok);
  EXPECT_EQ(run.result.t, 1700.0);
  ASSERT_EQ(run.crossings.size(), 2u);
  const double measured = run.crossings[1] - run.crossings[0];
  std::printf("half period %.5f, asymptotic %.5f\n", measured, half_period);
  EXPECT_NEAR(measured, half_period, 0.005);
  // A stiff problem over 1700 time units in a few hundred steps (measured
  // 590): an explicit method would need ~1e6.
  EXPECT_LT(s.steps, 2000);

  // The same run with a finite-difference Jacobian: the Jacobian only steers
  // Newton, so the trajectory agrees to within the tolerance's effect.
  FiniteDifferenceJacobian fd(van_der_pol_rhs, 2);  // class template argument deduction
  const VanDerPolRun with_fd = run_van_der_pol(fd, 1e-6);
  ASSERT_EQ(with_fd.result.status, Status::ok);
  ASSERT_EQ(with_fd.crossings.size(), 2u);
  std::printf("finite-difference Jacobian: steps=%ld jac=%ld (+%ld rhs), half period %.5f\n",
              with_fd.result.stats.steps, with_fd.result.stats.jac_evals, fd.rhs_evals(),
              with_fd.crossings[1] - with_fd.crossings[0]);
  EXPECT_NEAR(with_fd.crossings[1] - with_fd.crossings[0], measured, 1e-3);
  EXPECT_EQ(fd.rhs_evals(), 3 * with_fd.result.stats.jac_evals);
}

TEST(RuntimeRadau5, FiniteDifferenceJacobianMatchesTheAnalyticOne) {
  FiniteDifferenceJacobian<void (*)(double, const double*, double*)> fd(hamel_test::kepler_rhs, 4);
  for (const double t : {0.0, 1.0, 2.5}) {
    const auto s = hamel_test::kepler_state(t, kEccentricity);
    double exact[16];
    double approx[16];
    kepler_jac(t, s.data(), exact);
    fd(t, s.data(), approx);
    for (int i = 0; i < 16; ++i) {
      EXPECT_NEAR(approx[i], exact[i], 1e-6 * (1 + std::fabs(exact[i]))) << "t " << t << ", entry " << i;
    }
  }
  EXPECT_EQ(fd.rhs_evals(), 3 * 5);
}

// Away from the stiff toy problem the collocation polynomial samples to about
// the tolerance. Its O(h^4) interpolation error is not what the error test
// controls, so samples fall somewhat behind the step ends at loose tolerances
// (measured on the Kepler orbit: 1.9 tol at 1e-6, 0.47 tol at 1e-9).
TEST(RuntimeRadau5, SamplesMatchTheOrbitAndCostNothing) {
  for (const double tol : {1e-6, 1e-9}) {
    double worst = 0.0;
    std::vector<double> times;
    const IntegrationResult sampled =
        integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0, kepler_period, tolerance(tol), 0.5,
                         [&](double t, const double* x) {
                           times.push_back(t);
                           worst = std::fmax(worst, hamel_test::kepler_error(t, x, kEccentricity));
                         });
    const IntegrationResult plain = integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0,
                                                     kepler_period, tolerance(tol), 0.0, NoObserver{});
    ASSERT_EQ(sampled.status, Status::ok);
    std::printf("tol=%.0e: worst sample error %.3e\n", tol, worst);
    EXPECT_LT(worst, 10 * tol);
    EXPECT_EQ(sampled.stats.steps, plain.stats.steps);
    EXPECT_EQ(sampled.stats.rhs_evals, plain.stats.rhs_evals);
    std::vector<double> expected = {0.0};
    for (int k = 1; k <= 12; ++k) expected.push_back(0.5 * k);
    expected.push_back(kepler_period);
    EXPECT_EQ(times, expected);
  }
}

TEST(RuntimeRadau5, EveryAcceptedStepIsObservedWithoutSampling) {
  std::vector<double> times;
  const IntegrationResult r =
      integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0, kepler_period, tolerance(1e-8), 0.0,
                       [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(static_cast<long>(times.size()), r.stats.steps + 1);
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_LT(times[i - 1], times[i]);
  EXPECT_EQ(times.back(), kepler_period);
}

TEST(RuntimeRadau5, IntegratesBackwardInTime) {
  const auto end = hamel_test::kepler_state(kepler_period, kEccentricity);
  std::vector<double> times;
  const IntegrationResult r =
      integrate_radau5(hamel_test::kepler_rhs, kepler_jac, {end.begin(), end.end()}, kepler_period, 0.0,
                       tolerance(1e-9), 1.0, [&](double t, const double* x) {
                         times.push_back(t);
                         EXPECT_LT(hamel_test::kepler_error(t, x, kEccentricity), 10 * 1e-9) << t;
                       });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.t, 0.0);
  ASSERT_EQ(times.size(), 8u);  // 2 pi, 2 pi - k for k = 1..6, 0
  EXPECT_EQ(times[1], kepler_period - 1.0);
}

TEST(RuntimeRadau5, MaximumAndInitialStepAreRespected) {
  Radau5Options opt = tolerance(1e-6);
  opt.h_max = 0.05;
  opt.h0 = 1e-3;
  std::vector<double> times;
  const IntegrationResult r = integrate_radau5(hamel_test::kepler_rhs, kepler_jac, kepler_start(), 0.0, kepler_period,
                                               opt, 0.0, [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  ASSERT_GE(times.size(), 2u);
  EXPECT_DOUBLE_EQ(times[1], 1e-3);
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_LE(times[i] - times[i - 1], 0.05 * (1 + 1e-12));
  EXPECT_GE(r.stats.steps, 126);  // ceil(2 pi / 0.05)
}

TEST(RuntimeRadau5, FixedStepModeUsesEqualStepsThatLandOnTheEnd) {
  std::vector<double> times;
  const IntegrationResult r = integrate_radau5(riccati_rhs, riccati_jac, {0.5}, 0.0, 1.0, fixed_step(0.3), 0.0,
                                               [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.stats.steps, 4);  // ceil(1 / 0.3) steps of 0.25
  EXPECT_EQ(times, (std::vector<double>{0.0, 0.25, 0.5, 0.75, 1.0}));
  EXPECT_NEAR(r.x[0], riccati_exact(1.0), 1e-6);
}

TEST(RuntimeRadau5, EmptyIntervalObservesOnceAndDoesNoWork) {
  int observed = 0;
  const IntegrationResult r = integrate_radau5(riccati_rhs, riccati_jac, {0.5}, 1.0, 1.0, tolerance(1e-6), 0.1,
                                               [&](double, const double*) { ++observed; });
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_EQ(observed, 1);
  EXPECT_EQ(r.stats.rhs_evals + r.stats.jac_evals, 0);
}

}  // namespace
