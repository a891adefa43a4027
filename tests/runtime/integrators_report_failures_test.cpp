// SPDX-License-Identifier: MIT
// The integrators stop with a failure status, never a silent NaN, when the
// solution blows up, the right-hand side produces NaN, or the inputs are bad,
// and they hand back the last finite state.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace {

using hamel::runtime::all_finite;
using hamel::runtime::describe;
using hamel::runtime::Dop853Options;
using hamel::runtime::Dopri5Options;
using hamel::runtime::integrate_dop853;
using hamel::runtime::integrate_dopri5;
using hamel::runtime::integrate_rk4;
using hamel::runtime::IntegrationResult;
using hamel::runtime::NoObserver;
using hamel::runtime::Status;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// x' = x^2, x(0) = 1 has the solution 1 / (1 - t), which blows up at t = 1.
void blow_up_rhs(double, const double* x, double* f) { f[0] = x[0] * x[0]; }

// x' = 1 while t <= 0.5; beyond that the "model" is undefined and yields NaN.
void nan_after_half_rhs(double t, const double*, double* f) { f[0] = t <= 0.5 ? 1.0 : kNaN; }

void always_nan_rhs(double, const double*, double* f) { f[0] = kNaN; }

void expect_stopped_before_blow_up(const IntegrationResult& r) {
  EXPECT_TRUE(r.status == Status::non_finite_state || r.status == Status::step_size_underflow) << describe(r.status);
  EXPECT_LT(r.t, 1.0001);
  EXPECT_GT(r.t, 0.9);
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_TRUE(all_finite(r.x.data(), r.x.size()));
}

TEST(RuntimeFailure, Rk4StopsAtTheBlowUp) {
  long observed_non_finite = 0;
  const IntegrationResult r = integrate_rk4(blow_up_rhs, {1.0}, 0.0, 2.0, 1e-5, 0.0, [&](double, const double* x) {
    if (!std::isfinite(x[0])) ++observed_non_finite;
  });
  std::printf("rk4 x'=x^2: %s at t=%.9f, x=%.3e after %ld steps\n", describe(r.status), r.t, r.x[0], r.stats.steps);
  expect_stopped_before_blow_up(r);
  EXPECT_EQ(observed_non_finite, 0);
}

TEST(RuntimeFailure, Dopri5StopsAtTheBlowUp) {
  long observed_non_finite = 0;
  const IntegrationResult r =
      integrate_dopri5(blow_up_rhs, {1.0}, 0.0, 2.0, Dopri5Options{}, 0.0, [&](double, const double* x) {
        if (!std::isfinite(x[0])) ++observed_non_finite;
      });
  std::printf("dopri5 x'=x^2: %s at t=%.15f, x=%.3e after %ld steps, %ld rejected\n", describe(r.status), r.t, r.x[0],
              r.stats.steps, r.stats.rejected);
  expect_stopped_before_blow_up(r);
  EXPECT_EQ(observed_non_finite, 0);
  // Up to the last accepted point the solution is still x = 1 / (1 - t), so
  // t + 1/x locates the singularity; 1 - t itself is all rounding by now.
  EXPECT_NEAR(r.t + 1.0 / r.x[0], 1.0, 1e-6);
}

TEST(RuntimeFailure, Rk4ReportsNaNFromTheRightHandSide) {
  const IntegrationResult r = integrate_rk4(nan_after_half_rhs, {0.0}, 0.0, 1.0, 0.1, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_DOUBLE_EQ(r.t, 0.5);  // the last step that stayed where the model is defined
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_DOUBLE_EQ(r.x[0], 0.5);
}

TEST(RuntimeFailure, Dopri5ReportsNaNFromTheRightHandSide) {
  const IntegrationResult r = integrate_dopri5(nan_after_half_rhs, {0.0}, 0.0, 1.0, Dopri5Options{}, 0.0, NoObserver{});
  std::printf("dopri5 NaN beyond t=0.5: %s at t=%.15f after %ld steps, %ld rejected\n", describe(r.status), r.t,
              r.stats.steps, r.stats.rejected);
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_LE(r.t, 0.5);
  EXPECT_GT(r.t, 0.5 - 1e-6);  // it crept up to the edge before giving up
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_NEAR(r.x[0], r.t, 1e-12);
}

TEST(RuntimeFailure, Dopri5ReportsNaNFromTheFirstEvaluation) {
  const IntegrationResult r = integrate_dopri5(always_nan_rhs, {1.0}, 0.0, 1.0, Dopri5Options{}, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{1.0});
  EXPECT_EQ(r.stats.rhs_evals, 1);
}

TEST(RuntimeFailure, Rk4ReportsNaNFromTheFirstEvaluation) {
  const IntegrationResult r = integrate_rk4(always_nan_rhs, {1.0}, 0.0, 1.0, 0.1, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{1.0});
}

// A derivative that turns NaN at a step end, although the state there is
// finite, is caught before it is used. With h = 0.25 the evaluations are the
// start (1), steps of three stages each followed by the end derivative (2-5,
// 6-9, ...), so evaluation 9 is the derivative at t = 0.5.
TEST(RuntimeFailure, Rk4ReportsNaNDerivativeAtAStepEnd) {
  int calls = 0;
  const IntegrationResult r = integrate_rk4(
      [&](double t, const double*, double* f) {
        ++calls;
        f[0] = calls == 9 ? kNaN : 2 * t;
      },
      {0.0}, 0.0, 1.0, 0.25, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.5);
  EXPECT_DOUBLE_EQ(r.x[0], 0.25);
  EXPECT_EQ(calls, 9);
}

TEST(RuntimeFailure, NonFiniteInitialStateIsRejectedBeforeAnyWork) {
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  const IntegrationResult a = integrate_rk4(blow_up_rhs, {kNaN}, 0.0, 1.0, 0.1, 0.0, count);
  const IntegrationResult b = integrate_dopri5(blow_up_rhs, {kNaN}, 0.0, 1.0, Dopri5Options{}, 0.0, count);
  EXPECT_EQ(a.status, Status::non_finite_state);
  EXPECT_EQ(b.status, Status::non_finite_state);
  EXPECT_EQ(a.stats.rhs_evals + b.stats.rhs_evals, 0);
  EXPECT_EQ(observed, 0);
}

TEST(RuntimeFailure, Rk4RejectsNonPositiveStep) {
  for (const double h : {0.0, -0.1, kNaN}) {
    const IntegrationResult r = integrate_rk4(blow_up_rhs, {1.0}, 0.0, 0.5, h, 0.0, NoObserver{});
    EXPECT_EQ(r.status, Status::step_size_underflow) << h;
    EXPECT_EQ(r.stats.rhs_evals, 0);
  }
}

TEST(RuntimeFailure, Dopri5StopsAfterMaxSteps) {
  Dopri5Options opt;
  opt.max_steps = 5;
  const IntegrationResult r = integrate_dopri5([](double t, const double*, double* f) { f[0] = std::cos(t); }, {0.0},
                                               0.0, 100.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::too_many_steps);
  EXPECT_EQ(r.stats.steps + r.stats.rejected, 5);
  EXPECT_LT(r.t, 100.0);
  EXPECT_NEAR(r.x[0], std::sin(r.t), 1e-8);
}

// --- DOP853 ---------------------------------------------------------------

TEST(RuntimeFailure, Dop853StopsAtTheBlowUp) {
  long observed_non_finite = 0;
  const IntegrationResult r =
      integrate_dop853(blow_up_rhs, {1.0}, 0.0, 2.0, Dop853Options{}, 0.0, [&](double, const double* x) {
        if (!std::isfinite(x[0])) ++observed_non_finite;
      });
  std::printf("dop853 x'=x^2: %s at t=%.15f, x=%.3e after %ld steps, %ld rejected\n", describe(r.status), r.t, r.x[0],
              r.stats.steps, r.stats.rejected);
  expect_stopped_before_blow_up(r);
  EXPECT_EQ(observed_non_finite, 0);
  EXPECT_NEAR(r.t + 1.0 / r.x[0], 1.0, 1e-6);
}

TEST(RuntimeFailure, Dop853ReportsNaNFromTheRightHandSide) {
  const IntegrationResult r = integrate_dop853(nan_after_half_rhs, {0.0}, 0.0, 1.0, Dop853Options{}, 0.0, NoObserver{});
  std::printf("dop853 NaN beyond t=0.5: %s at t=%.15f after %ld steps, %ld rejected\n", describe(r.status), r.t,
              r.stats.steps, r.stats.rejected);
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_LE(r.t, 0.5);
  EXPECT_GT(r.t, 0.5 - 1e-6);
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_NEAR(r.x[0], r.t, 1e-12);
}

TEST(RuntimeFailure, Dop853ReportsNaNFromTheFirstEvaluation) {
  const IntegrationResult r = integrate_dop853(always_nan_rhs, {1.0}, 0.0, 1.0, Dop853Options{}, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{1.0});
  EXPECT_EQ(r.stats.rhs_evals, 1);
}

// With one fixed step h = 1 from t = 0, only the first extra stage of the
// continuous extension is evaluated at t = 0.2 exactly (no stage of the step
// is). A NaN there must not reach the observer: the attempt is rejected and
// the shorter steps that follow avoid t = 0.2. Without sampling the extra
// stages are never evaluated and the step goes through.
TEST(RuntimeFailure, Dop853RejectsANonFiniteDenseOutputStage) {
  auto rhs = [](double t, const double*, double* f) { f[0] = t == 0.2 ? kNaN : std::cos(t); };
  Dop853Options opt;
  opt.rtol = opt.atol = 1e6;
  opt.h0 = opt.h_max = 1.0;
  long observed = 0;
  const IntegrationResult sampled = integrate_dop853(rhs, {0.0}, 0.0, 1.0, opt, 0.5, [&](double t, const double* x) {
    ++observed;
    EXPECT_TRUE(std::isfinite(x[0]));
    EXPECT_NEAR(x[0], std::sin(t), 1e-8) << t;
  });
  EXPECT_EQ(sampled.status, Status::ok);
  EXPECT_EQ(sampled.stats.rejected, 1);
  EXPECT_EQ(observed, 3);
  const IntegrationResult plain = integrate_dop853(rhs, {0.0}, 0.0, 1.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(plain.status, Status::ok);
  EXPECT_EQ(plain.stats.rejected, 0);
  EXPECT_EQ(plain.stats.steps, 1);
}

TEST(RuntimeFailure, Dop853StopsAfterMaxSteps) {
  Dop853Options opt;
  opt.max_steps = 5;
  const IntegrationResult r = integrate_dop853([](double t, const double*, double* f) { f[0] = std::cos(t); }, {0.0},
                                               0.0, 100.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::too_many_steps);
  EXPECT_EQ(r.stats.steps + r.stats.rejected, 5);
  EXPECT_LT(r.t, 100.0);
  EXPECT_NEAR(r.x[0], std::sin(r.t), 1e-10);
}

TEST(RuntimeFailure, NewIntegratorsRejectANonFiniteInitialStateBeforeAnyWork) {
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  const IntegrationResult a = integrate_dop853(blow_up_rhs, {kNaN}, 0.0, 1.0, Dop853Options{}, 0.0, count);
  EXPECT_EQ(a.status, Status::non_finite_state);
  EXPECT_EQ(a.stats.rhs_evals, 0);
  EXPECT_EQ(observed, 0);
}

}  // namespace
