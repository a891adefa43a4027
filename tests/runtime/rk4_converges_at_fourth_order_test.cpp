// SPDX-License-Identifier: MIT
// RK4 converges at order 4 against closed-form solutions of nonlinear problems,
// both at the steps and at Hermite-interpolated samples, and honours its step
// and sampling contract.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/rk4.hpp"
#include "kepler_orbit.hpp"

namespace {

using hamel::runtime::integrate_rk4;
using hamel::runtime::IntegrationResult;
using hamel::runtime::NoObserver;
using hamel::runtime::Status;

constexpr double kEccentricity = 0.5;

// Riccati equation x' = x^2 cos t, x(0) = 1/2, solved by x(t) = 1 / (2 - sin t).
void riccati_rhs(double t, const double* x, double* f) { f[0] = x[0] * x[0] * std::cos(t); }
double riccati_exact(double t) { return 1.0 / (2.0 - std::sin(t)); }

std::vector<double> kepler_start() {
  const auto s = hamel_test::kepler_state(0.0, kEccentricity);
  return {s.begin(), s.end()};
}

double kepler_error_at_2(double h) {
  const IntegrationResult r = integrate_rk4(hamel_test::kepler_rhs, kepler_start(), 0.0, 2.0, h, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.t, 2.0);
  return hamel_test::kepler_error(2.0, r.x.data(), kEccentricity);
}

double riccati_error_at_2(double h) {
  const IntegrationResult r = integrate_rk4(riccati_rhs, {0.5}, 0.0, 2.0, h, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::ok);
  return std::fabs(r.x[0] - riccati_exact(2.0));
}

void expect_fourth_order(const char* name, double (*error_at)(double)) {
  const double steps[] = {0.1, 0.05, 0.025, 0.0125};
  double previous = error_at(steps[0]);
  std::printf("%s: h=%-7g error=%.3e\n", name, steps[0], previous);
  for (int i = 1; i < 4; ++i) {
    const double e = error_at(steps[i]);
    const double order = std::log2(previous / e);
    std::printf("%s: h=%-7g error=%.3e order=%.3f\n", name, steps[i], e, order);
    EXPECT_NEAR(order, 4.0, 0.3) << name << " at h = " << steps[i];
    previous = e;
  }
}

TEST(RuntimeRk4, KeplerOrbitConvergesAtOrderFour) { expect_fourth_order("kepler e=0.5", kepler_error_at_2); }

TEST(RuntimeRk4, RiccatiEquationConvergesAtOrderFour) { expect_fourth_order("riccati", riccati_error_at_2); }

// Samples between steps come from the cubic Hermite interpolant, whose O(h^4)
// error must keep the samples fourth-order accurate too. t0 and t_end are left
// out so that only interpolated values are judged.
double worst_sample_error(double h) {
  double worst = 0.0;
  int samples = 0;
  const IntegrationResult r =
      integrate_rk4(hamel_test::kepler_rhs, kepler_start(), 0.0, 2.0, h, 0.0317, [&](double t, const double* x) {
        if (t > 0.0 && t < 2.0) {
          worst = std::fmax(worst, hamel_test::kepler_error(t, x, kEccentricity));
        }
        ++samples;
      });
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_EQ(samples, 1 + 63 + 1);  // t0, 0.0317 k for k = 1..63, t_end
  return worst;
}

TEST(RuntimeRk4, InterpolatedSamplesConvergeAtOrderFour) { expect_fourth_order("kepler samples", worst_sample_error); }

// RK4 on x' = 3t^2 is Simpson's rule, exact for the cubic x = t^3, and the
// cubic Hermite interpolant reproduces a cubic exactly: every sample between
// steps must then be exact up to rounding.
TEST(RuntimeRk4, HermiteSamplesAreExactForACubicSolution) {
  int samples = 0;
  const IntegrationResult r =
      integrate_rk4([](double t, const double*, double* f) { f[0] = 3 * t * t; }, {0.0}, 0.0, 2.0, 0.25, 0.03,
                    [&](double t, const double* x) {
                      EXPECT_NEAR(x[0], t * t * t, 1e-14 * (1 + t * t * t)) << t;
                      ++samples;
                    });
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_EQ(samples, 1 + 66 + 1);
}

TEST(RuntimeRk4, StepThatDividesTheIntervalIsUsedExactly) {
  long observed = 0;
  double last_t = -1.0;
  const IntegrationResult r = integrate_rk4(riccati_rhs, {0.5}, 0.0, 2.0, 0.1, 0.0, [&](double t, const double*) {
    ++observed;
    last_t = t;
  });
  EXPECT_EQ(r.stats.steps, 20);
  EXPECT_EQ(r.stats.rejected, 0);
  EXPECT_EQ(r.stats.rhs_evals, 4 * 20);  // the end derivative is reused as the next first stage
  EXPECT_EQ(observed, 21);               // t0 and every step
  EXPECT_EQ(last_t, 2.0);
  EXPECT_EQ(r.t, 2.0);
}

// 2.1 / 0.3 evaluates to 7.000000000000001; the step still divides the
// interval and must not turn into 8 slightly shorter steps.
TEST(RuntimeRk4, RoundingOfTheStepCountDoesNotAddAStep) {
  const IntegrationResult r = integrate_rk4(riccati_rhs, {0.5}, 0.0, 2.1, 0.3, 0.0, NoObserver{});
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.stats.steps, 7);
  EXPECT_EQ(r.t, 2.1);
}

TEST(RuntimeRk4, StepThatDoesNotDivideTheIntervalShrinksToLandOnTheEnd) {
  std::vector<double> times;
  const IntegrationResult r =
      integrate_rk4(riccati_rhs, {0.5}, 0.0, 1.0, 0.3, 0.0, [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.stats.steps, 4);  // ceil(1 / 0.3) steps of 0.25
  ASSERT_EQ(times.size(), 5u);
  EXPECT_EQ(times[1], 0.25);
  EXPECT_EQ(times.back(), 1.0);
  EXPECT_NEAR(r.x[0], riccati_exact(1.0), 1e-4);
}

TEST(RuntimeRk4, ObserverSeesStartSamplesAndEndExactlyOnce) {
  std::vector<double> times;
  const IntegrationResult r = integrate_rk4(riccati_rhs, {0.5}, 0.0, 0.3, 0.01, 0.1, [&](double t, const double* x) {
    times.push_back(t);
    EXPECT_NEAR(x[0], riccati_exact(t), 1e-10) << t;
  });
  ASSERT_EQ(r.status, Status::ok);
  // 3 * 0.1 rounds above 0.3; it must not appear next to t_end as a near-duplicate.
  ASSERT_EQ(times.size(), 4u);
  EXPECT_EQ(times[0], 0.0);
  EXPECT_EQ(times[1], 0.1);
  EXPECT_EQ(times[2], 2 * 0.1);
  EXPECT_EQ(times[3], 0.3);
  EXPECT_EQ(r.stats.rhs_evals, 4 * 30);  // no sample inside the last step: no extra evaluation
}

// 3 * 0.3 evaluates to 0.8999999999999999, just below t_end = 0.9: that is
// t_end up to rounding and must not be observed a second time.
TEST(RuntimeRk4, SampleThatRoundsBelowTheEndIsNotObservedTwice) {
  std::vector<double> times;
  const IntegrationResult r =
      integrate_rk4(riccati_rhs, {0.5}, 0.0, 0.9, 0.1, 0.3, [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(times, (std::vector<double>{0.0, 0.3, 2 * 0.3, 0.9}));
}

TEST(RuntimeRk4, SampleInsideTheLastStepCostsOneExtraEvaluation) {
  std::vector<double> times;
  const IntegrationResult r =
      integrate_rk4(riccati_rhs, {0.5}, 0.0, 1.0, 0.5, 0.75, [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(times, (std::vector<double>{0.0, 0.75, 1.0}));
  EXPECT_EQ(r.stats.rhs_evals, 4 * 2 + 1);
}

TEST(RuntimeRk4, IntegratesBackwardInTime) {
  std::vector<double> times;
  const IntegrationResult r = integrate_rk4(riccati_rhs, {riccati_exact(2.0)}, 2.0, 0.0, 0.01, 0.5,
                                            [&](double t, const double*) { times.push_back(t); });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_NEAR(r.x[0], 0.5, 1e-9);
  EXPECT_EQ(times, (std::vector<double>{2.0, 1.5, 1.0, 0.5, 0.0}));
}

TEST(RuntimeRk4, EmptyIntervalObservesOnceAndDoesNoWork) {
  int observed = 0;
  const IntegrationResult r =
      integrate_rk4(riccati_rhs, {0.5}, 1.0, 1.0, 0.1, 0.1, [&](double, const double*) { ++observed; });
  EXPECT_EQ(r.status, Status::ok);
  EXPECT_EQ(observed, 1);
  EXPECT_EQ(r.stats.rhs_evals, 0);
  EXPECT_EQ(r.x, std::vector<double>{0.5});
}

}  // namespace
