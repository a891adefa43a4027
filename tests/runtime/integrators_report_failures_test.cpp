// SPDX-License-Identifier: MIT
// The integrators stop with a failure status, never a silent NaN, when the
// solution blows up, the right-hand side produces NaN, or the inputs are bad,
// and they hand back the last finite state. The implicit Radau integrator also
// reports a Newton iteration that a wrong Jacobian keeps from converging, and
// a singular iteration matrix, as newton_failure.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace {

using hamel::runtime::all_finite;
using hamel::runtime::describe;
using hamel::runtime::Dop853Options;
using hamel::runtime::Dopri5Options;
using hamel::runtime::integrate_dop853;
using hamel::runtime::integrate_dopri5;
using hamel::runtime::integrate_radau5;
using hamel::runtime::integrate_rk4;
using hamel::runtime::IntegrationResult;
using hamel::runtime::NoObserver;
using hamel::runtime::Radau5Options;
using hamel::runtime::Status;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// x' = x^2, x(0) = 1 has the solution 1 / (1 - t), which blows up at t = 1.
void blow_up_rhs(double, const double* x, double* f) { f[0] = x[0] * x[0]; }

// x' = 1 while t <= 0.5; beyond that the "model" is undefined and yields NaN.
void nan_after_half_rhs(double t, const double*, double* f) { f[0] = t <= 0.5 ? 1.0 : kNaN; }

void always_nan_rhs(double, const double*, double* f) { f[0] = kNaN; }

// Exact Jacobians of the problems above, for the implicit integrator.
void blow_up_jac(double, const double* x, double* J) { J[0] = 2 * x[0]; }
void zero_jac(double, const double*, double* J) { J[0] = 0.0; }

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
    EXPECT_EQ(r.status, Status::invalid_argument) << h;
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

// --- Radau IIA -------------------------------------------------------------

TEST(RuntimeFailure, Radau5StopsAtTheBlowUp) {
  long observed_non_finite = 0;
  const IntegrationResult r =
      integrate_radau5(blow_up_rhs, blow_up_jac, {1.0}, 0.0, 2.0, Radau5Options{}, 0.0, [&](double, const double* x) {
        if (!std::isfinite(x[0])) ++observed_non_finite;
      });
  std::printf("radau5 x'=x^2: %s at t=%.15f, x=%.3e after %ld steps, %ld rejected\n", describe(r.status), r.t, r.x[0],
              r.stats.steps, r.stats.rejected);
  EXPECT_NE(r.status, Status::ok);
  EXPECT_LT(r.t, 1.0001);
  EXPECT_GT(r.t, 0.9);
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_TRUE(all_finite(r.x.data(), r.x.size()));
  EXPECT_EQ(observed_non_finite, 0);
  EXPECT_NEAR(r.t + 1.0 / r.x[0], 1.0, 1e-4);
}

TEST(RuntimeFailure, Radau5ReportsNaNFromTheRightHandSide) {
  const IntegrationResult r =
      integrate_radau5(nan_after_half_rhs, zero_jac, {0.0}, 0.0, 1.0, Radau5Options{}, 0.0, NoObserver{});
  std::printf("radau5 NaN beyond t=0.5: %s at t=%.15f after %ld steps, %ld rejected\n", describe(r.status), r.t,
              r.stats.steps, r.stats.rejected);
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_LE(r.t, 0.5);
  EXPECT_GT(r.t, 0.5 - 1e-6);
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_NEAR(r.x[0], r.t, 1e-12);
}

TEST(RuntimeFailure, Radau5ReportsNaNFromTheFirstEvaluation) {
  const IntegrationResult r =
      integrate_radau5(always_nan_rhs, zero_jac, {1.0}, 0.0, 1.0, Radau5Options{}, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{1.0});
  EXPECT_EQ(r.stats.rhs_evals, 1);
  EXPECT_EQ(r.stats.jac_evals, 0);
}

TEST(RuntimeFailure, Radau5ReportsANonFiniteJacobian) {
  const IntegrationResult r = integrate_radau5(
      blow_up_rhs, [](double, const double*, double* J) { J[0] = kNaN; }, {1.0}, 0.0, 0.5, Radau5Options{}, 0.0,
      NoObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{1.0});
  EXPECT_EQ(r.stats.jac_evals, 1);
}

// x' = -1000 (x - cos t), x(0) = 2, with the Jacobian +1e12 instead of -1000:
// the iteration matrix I - h A J is then dominated by the wrong term, the
// simplified Newton iteration barely moves and barely contracts (theta ~ 1)
// at any step above ~1e-12, and every attempt fails. The integrator must give
// up with newton_failure and the untouched initial state, not accept the
// tiny increments as convergence (which returns x ~ 2 at t = 1: a silently
// wrong answer), run on, or return NaN. The same problem with the right
// Jacobian is solved, so the Jacobian alone is to blame.
void relaxation_rhs(double t, const double* x, double* f) { f[0] = -1000.0 * (x[0] - std::cos(t)); }

TEST(RuntimeFailure, Radau5ReportsNewtonFailureForAWrongJacobian) {
  long observed = 0;
  const IntegrationResult r = integrate_radau5(
      relaxation_rhs, [](double, const double*, double* J) { J[0] = 1e12; }, {2.0}, 0.0, 1.0, Radau5Options{}, 0.0,
      [&](double, const double*) { ++observed; });
  std::printf("radau5 wrong Jacobian: %s at t=%g after %ld steps, %ld rejected, %ld jac, %ld lu\n", describe(r.status),
              r.t, r.stats.steps, r.stats.rejected, r.stats.jac_evals, r.stats.lu_decompositions);
  EXPECT_EQ(r.status, Status::newton_failure);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, std::vector<double>{2.0});
  EXPECT_EQ(r.stats.steps, 0);
  EXPECT_EQ(r.stats.rejected, Radau5Options{}.max_newton_failures);
  EXPECT_EQ(observed, 1);  // t0 only

  const IntegrationResult good = integrate_radau5(
      relaxation_rhs, [](double, const double*, double* J) { J[0] = -1000.0; }, {2.0}, 0.0, 1.0, Radau5Options{}, 0.0,
      NoObserver{});
  EXPECT_EQ(good.status, Status::ok);
  // x(t) = (1e6 cos t + 1e3 sin t) / (1e6 + 1) + C e^(-1000 t), and the transient has died out by t = 1.
  const double exact = (1e6 * std::cos(1.0) + 1e3 * std::sin(1.0)) / (1e6 + 1.0);
  EXPECT_NEAR(good.x[0], exact, 1e-5);
}

// A Jacobian with entries of 1e300 and rank one makes I - h (A (x) J)
// singular to working precision at every step size the integrator may try:
// halving h five times does not help, and the run ends in newton_failure.
TEST(RuntimeFailure, Radau5ReportsASingularIterationMatrix) {
  const IntegrationResult r = integrate_radau5(
      [](double, const double* x, double* f) {
        f[0] = -x[0];
        f[1] = -x[1];
      },
      [](double, const double*, double* J) { J[0] = J[1] = J[2] = J[3] = 1e300; }, {1.0, 1.0}, 0.0, 1.0,
      Radau5Options{}, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::newton_failure);
  EXPECT_EQ(r.t, 0.0);
  EXPECT_EQ(r.x, (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(r.stats.lu_decompositions, 5);
  EXPECT_EQ(r.stats.jac_evals, 1);  // J is current at t0: only the step changes
}

// In fixed-step mode there is no step to shrink: the first failure ends the run.
TEST(RuntimeFailure, Radau5FixedStepModeFailsAtOnce) {
  Radau5Options opt;
  opt.fixed_step = 0.1;
  const IntegrationResult r = integrate_radau5(
      relaxation_rhs, [](double, const double*, double* J) { J[0] = 1e12; }, {2.0}, 0.0, 1.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::newton_failure);
  EXPECT_EQ(r.stats.rejected, 1);
  const IntegrationResult nan = integrate_radau5(nan_after_half_rhs, zero_jac, {0.0}, 0.0, 1.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(nan.status, Status::non_finite_state);
  EXPECT_NEAR(nan.t, 0.5, 1e-12);
  EXPECT_NEAR(nan.x[0], 0.5, 1e-12);
}

TEST(RuntimeFailure, Radau5StopsAfterMaxSteps) {
  Radau5Options opt;
  opt.max_steps = 5;
  const IntegrationResult r = integrate_radau5([](double t, const double*, double* f) { f[0] = std::cos(t); }, zero_jac,
                                               {0.0}, 0.0, 100.0, opt, 0.0, NoObserver{});
  EXPECT_EQ(r.status, Status::too_many_steps);
  EXPECT_EQ(r.stats.steps + r.stats.rejected, 5);
  EXPECT_LT(r.t, 100.0);
  EXPECT_NEAR(r.x[0], std::sin(r.t), 1e-6);
}

TEST(RuntimeFailure, NewIntegratorsRejectANonFiniteInitialStateBeforeAnyWork) {
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  const IntegrationResult a = integrate_dop853(blow_up_rhs, {kNaN}, 0.0, 1.0, Dop853Options{}, 0.0, count);
  const IntegrationResult b = integrate_radau5(blow_up_rhs, blow_up_jac, {kNaN}, 0.0, 1.0, Radau5Options{}, 0.0, count);
  EXPECT_EQ(a.status, Status::non_finite_state);
  EXPECT_EQ(b.status, Status::non_finite_state);
  EXPECT_EQ(a.stats.rhs_evals + b.stats.rhs_evals + b.stats.jac_evals, 0);
  EXPECT_EQ(observed, 0);
}

// Settings that make no sense are the caller's mistake, reported as invalid_argument before any
// work, not as a step size underflow (or silently replaced by a default).
TEST(RuntimeFailure, AdaptiveIntegratorsRejectSettingsThatMakeNoSense) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Bad {
    const char* what;
    double rtol, atol, h0, h_max;
  };
  const Bad cases[] = {
      {"h_max < 0", 1e-6, 1e-8, 0.0, -0.1}, {"h_max NaN", 1e-6, 1e-8, 0.0, kNaN}, {"h0 NaN", 1e-6, 1e-8, kNaN, 0.0},
      {"h0 inf", 1e-6, 1e-8, kInf, 0.0},    {"h0 -inf", 1e-6, 1e-8, -kInf, 0.0},  {"rtol < 0", -1e-6, 1e-8, 0.0, 0.0},
      {"rtol NaN", kNaN, 1e-8, 0.0, 0.0},   {"atol < 0", 1e-6, -1e-8, 0.0, 0.0},  {"atol inf", 1e-6, kInf, 0.0, 0.0}};
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  for (const Bad& c : cases) {
    Dopri5Options o5;
    o5.rtol = c.rtol, o5.atol = c.atol, o5.h0 = c.h0, o5.h_max = c.h_max;
    Dop853Options o8;
    o8.rtol = c.rtol, o8.atol = c.atol, o8.h0 = c.h0, o8.h_max = c.h_max;
    Radau5Options orad;
    orad.rtol = c.rtol, orad.atol = c.atol, orad.h0 = c.h0, orad.h_max = c.h_max;
    const IntegrationResult a = integrate_dopri5(blow_up_rhs, {0.5}, 0.0, 0.1, o5, 0.0, count);
    const IntegrationResult b = integrate_dop853(blow_up_rhs, {0.5}, 0.0, 0.1, o8, 0.0, count);
    const IntegrationResult r = integrate_radau5(blow_up_rhs, blow_up_jac, {0.5}, 0.0, 0.1, orad, 0.0, count);
    for (const IntegrationResult* x : {&a, &b, &r}) {
      EXPECT_EQ(x->status, Status::invalid_argument) << c.what;
      EXPECT_EQ(x->stats.rhs_evals, 0) << c.what;
      EXPECT_EQ(x->t, 0.0) << c.what;
      EXPECT_EQ(x->x, std::vector<double>{0.5}) << c.what;
    }
  }
  for (const double fixed_step : {-0.01, kNaN}) {
    Radau5Options o;
    o.fixed_step = fixed_step;
    const IntegrationResult r = integrate_radau5(blow_up_rhs, blow_up_jac, {0.5}, 0.0, 0.1, o, 0.0, count);
    EXPECT_EQ(r.status, Status::invalid_argument) << fixed_step;
  }
  EXPECT_EQ(observed, 0);

  // What stays valid: a negative h0 (its sign is ignored) and an infinite h_max (no limit).
  Dopri5Options o5;
  o5.h0 = -1e-3;
  o5.h_max = kInf;
  Dop853Options o8;
  o8.h0 = -1e-3;
  o8.h_max = kInf;
  Radau5Options orad;
  orad.h0 = -1e-3;
  orad.h_max = kInf;
  // x' = x^2 from 0.5: x = 1 / (2 - t).
  EXPECT_NEAR(integrate_dopri5(blow_up_rhs, {0.5}, 0.0, 1.0, o5, 0.0, NoObserver{}).x[0], 1.0, 1e-7);
  EXPECT_NEAR(integrate_dop853(blow_up_rhs, {0.5}, 0.0, 1.0, o8, 0.0, NoObserver{}).x[0], 1.0, 1e-9);
  EXPECT_NEAR(integrate_radau5(blow_up_rhs, blow_up_jac, {0.5}, 0.0, 1.0, orad, 0.0, NoObserver{}).x[0], 1.0, 1e-5);
}

}  // namespace

// A sampling interval below the resolution of t (t + dt == t: the next sample never moves) or asking for more
// samples than any run can observe never returned (issue 46); it is the caller's mistake, invalid_argument before
// any work.
TEST(RuntimeFailure, IntegratorsRejectASamplingIntervalBelowTheResolutionOfTime) {
  struct Bad {
    const char* what;
    double t0, t_end, sample_dt;
  };
  const Bad cases[] = {{"1e-300 on [0, 1]", 0.0, 1.0, 1e-300},
                       {"1e-17 at t0 = 1", 1.0, 1.001, 1e-17},
                       {"1e-17 at t0 = 1, backwards", 1.0, 0.999, 1e-17},
                       {"denormal", 0.0, 1.0, 5e-324}};
  int observed = 0;
  auto count = [&](double, const double*) { ++observed; };
  for (const Bad& c : cases) {
    const IntegrationResult k = integrate_rk4(blow_up_rhs, {0.5}, c.t0, c.t_end, 1e-3, c.sample_dt, count);
    const IntegrationResult a =
        integrate_dopri5(blow_up_rhs, {0.5}, c.t0, c.t_end, Dopri5Options{}, c.sample_dt, count);
    const IntegrationResult b =
        integrate_dop853(blow_up_rhs, {0.5}, c.t0, c.t_end, Dop853Options{}, c.sample_dt, count);
    const IntegrationResult r =
        integrate_radau5(blow_up_rhs, blow_up_jac, {0.5}, c.t0, c.t_end, Radau5Options{}, c.sample_dt, count);
    for (const IntegrationResult* x : {&k, &a, &b, &r}) {
      EXPECT_EQ(x->status, Status::invalid_argument) << c.what;
      EXPECT_EQ(x->stats.rhs_evals, 0) << c.what;
      EXPECT_EQ(x->t, c.t0) << c.what;
    }
  }
  EXPECT_EQ(observed, 0);
  // What stays valid: no sampling (0, negative, NaN), an interval of a few ulps of t, one longer than the run.
  for (const double dt : {0.0, -1.0, kNaN, 1e-15, 10.0}) {
    const IntegrationResult k = integrate_rk4(blow_up_rhs, {0.5}, 1.0, 1.0 + 1e-12, 1e-13, dt, NoObserver{});
    EXPECT_EQ(k.status, Status::ok) << dt;
  }
}
