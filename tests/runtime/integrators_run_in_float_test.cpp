// The heap-free integrators are templates in the scalar type: with float work space, options and state they
// integrate in float (this file compiles with -Wdouble-promotion -Werror, so no float is silently widened to
// double), and every method reaches what float can resolve on the harmonic oscillator x'' = -x, whose solution
// cos t, -sin t is known. The same runs in double agree with the float ones to float's accuracy, and the double
// instantiation is the one the double tests check (Dopri5Workspace is BasicDopri5Workspace<double>, and so on).
// The projection onto position constraints (projection.hpp) is generic too: in float it reaches the closed-form
// nearest point to float rounding, and keeps an RK4 run on its constraint at float's rounding level.
#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/projection.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <type_traits>

namespace {

using namespace hamel::runtime;

template <class Real>
void oscillator(Real, const Real* x, Real* f) {
  f[0] = x[1];
  f[1] = -x[0];
}
template <class Real>
void oscillator_jacobian(Real, const Real*, Real* J) {
  J[0] = Real(0);
  J[1] = Real(1);
  J[2] = Real(-1);
  J[3] = Real(0);
}

/// The largest deviation of x at t = 3 from (cos 3, -sin 3), in double.
template <class Real>
double error_at_3(const Real* x) {
  return std::fmax(std::fabs(static_cast<double>(x[0]) - std::cos(3.0)),
                   std::fabs(static_cast<double>(x[1]) + std::sin(3.0)));
}

/// Runs every method from (1, 0) over [0, 3] in Real; the errors in the order rk4, dopri5, dop853, radau5,
/// radau5 with a finite-difference Jacobian.
template <class Real>
std::array<double, 5> run_all() {
  static Real work[BasicRadau5Workspace<Real>::reals(2) + BasicDop853Workspace<Real>::reals(2)];
  static int pivots[BasicRadau5Workspace<Real>::ints(2)];
  static Real fd_work[FiniteDifferenceJacobian<void (*)(Real, const Real*, Real*), Real>::reals(2)];
  const Real tolerance = std::is_same_v<Real, float> ? Real(1e-6) : Real(1e-10);
  std::array<double, 5> errors{};
  Real x[2];

  x[0] = Real(1), x[1] = Real(0);
  const BasicIntegrationOutcome<Real> rk4 = integrate_rk4(oscillator<Real>, x, 2, Real(0), Real(3), Real(0.01), Real(0),
                                                          NoObserver{}, BasicRk4Workspace<Real>{work, 14});
  EXPECT_EQ(rk4.status, Status::ok);
  errors[0] = error_at_3(x);

  BasicDopri5Options<Real> dopri5;
  dopri5.rtol = dopri5.atol = tolerance;
  x[0] = Real(1), x[1] = Real(0);
  EXPECT_EQ(integrate_dopri5(oscillator<Real>, x, 2, Real(0), Real(3), dopri5, Real(0), NoObserver{},
                             BasicDopri5Workspace<Real>{work, 24})
                .status,
            Status::ok);
  errors[1] = error_at_3(x);

  BasicDop853Options<Real> dop853;
  dop853.rtol = dop853.atol = tolerance;
  x[0] = Real(1), x[1] = Real(0);
  EXPECT_EQ(integrate_dop853(oscillator<Real>, x, 2, Real(0), Real(3), dop853, Real(0), NoObserver{},
                             BasicDop853Workspace<Real>{work, 52})
                .status,
            Status::ok);
  errors[2] = error_at_3(x);

  BasicRadau5Options<Real> radau5;
  radau5.rtol = radau5.atol = tolerance;
  const BasicRadau5Workspace<Real> radau5_work{work, BasicRadau5Workspace<Real>::reals(2), pivots, 8};
  x[0] = Real(1), x[1] = Real(0);
  EXPECT_EQ(integrate_radau5(oscillator<Real>, oscillator_jacobian<Real>, x, 2, Real(0), Real(3), radau5, Real(0),
                             NoObserver{}, radau5_work)
                .status,
            Status::ok);
  errors[3] = error_at_3(x);
  FiniteDifferenceJacobian finite_differences(oscillator<Real>, 2, fd_work);
  static_assert(
      std::is_same_v<decltype(finite_differences), FiniteDifferenceJacobian<void (*)(Real, const Real*, Real*), Real>>);
  x[0] = Real(1), x[1] = Real(0);
  EXPECT_EQ(integrate_radau5(oscillator<Real>, finite_differences, x, 2, Real(0), Real(3), radau5, Real(0),
                             NoObserver{}, radau5_work)
                .status,
            Status::ok);
  errors[4] = error_at_3(x);
  return errors;
}

const char* const methods[5] = {"rk4", "dopri5", "dop853", "radau5", "radau5 (finite differences)"};

TEST(RuntimeFloat, EveryIntegratorReachesFloatAccuracy) {
  const std::array<double, 5> in_float = run_all<float>();
  const std::array<double, 5> in_double = run_all<double>();
  for (int m = 0; m < 5; ++m) {
    std::printf("%-28s error at t = 3: float %.2e, double %.2e\n", methods[m], in_float[static_cast<std::size_t>(m)],
                in_double[static_cast<std::size_t>(m)]);
    // float resolves about 6e-8 relative; a few hundred steps of rounding and a 1e-6 tolerance give 1e-5 at most.
    EXPECT_LT(in_float[static_cast<std::size_t>(m)], 2e-5) << methods[m];
    // ... while the same run in double is limited by its tolerance (1e-10) or RK4's h^4 = 1e-8 truncation:
    // the float run's error is its own rounding, not the method's.
    EXPECT_LT(in_double[static_cast<std::size_t>(m)], 1e-7) << methods[m];
  }
}

TEST(RuntimeFloat, FloatStepsAreNotRoundedToDouble) {
  // The outcome's time is float: the state, the steps and t never pass through double.
  static_assert(std::is_same_v<decltype(BasicIntegrationOutcome<float>{}.t), float>);
  static_assert(std::is_same_v<Dopri5Workspace, BasicDopri5Workspace<double>>);
  static_assert(std::is_same_v<Radau5Options, BasicRadau5Options<double>>);
  static_assert(std::is_same_v<IntegrationOutcome, BasicIntegrationOutcome<double>>);
  // A float run with a step below what float resolves at t: step_size_underflow before any work, as in double.
  float x[2] = {1, 0};
  float work[14];
  const auto o = integrate_rk4(oscillator<float>, x, 2, 1000.0f, 1000.001f, 1e-9f, 0.0f, NoObserver{},
                               BasicRk4Workspace<float>{work, 14});
  EXPECT_EQ(o.status, Status::step_size_underflow);
}

// The circle |q| = 2 and its gradient, in Real.
template <class Real>
void circle(Real, const Real* q, Real* g) {
  g[0] = q[0] * q[0] + q[1] * q[1] - Real(4);
}
template <class Real>
void circle_gradient(Real, const Real* q, Real* G) {
  G[0] = Real(2) * q[0];
  G[1] = Real(2) * q[1];
}

TEST(RuntimeFloat, ProjectionReachesTheNearestPointInFloat) {
  static_assert(std::is_same_v<ProjectionWorkspace, BasicProjectionWorkspace<double>>);
  float work[BasicProjectionWorkspace<float>::reals(2, 1)];
  float x[3] = {3.0f, -1.2f, 7.0f};  // q, then a velocity the projection leaves alone
  const BasicProjectionOutcome<float> o = project_positions(circle<float>, circle_gradient<float>, 0.0f, x, 2, 1,
                                                            BasicProjectionWorkspace<float>{work, std::size(work)});
  ASSERT_EQ(o.status, Status::ok);
  static_assert(std::is_same_v<decltype(o.correction), float>);
  // The closed form 2 q / |q|, in double: the float result is within two ulps of float at 2 (2.4e-7 each).
  const double norm = std::hypot(3.0, -1.2);
  const double ulp = 2.0 * static_cast<double>(std::numeric_limits<float>::epsilon());
  EXPECT_LE(std::fabs(static_cast<double>(x[0]) - 6.0 / norm), 2 * ulp);
  EXPECT_LE(std::fabs(static_cast<double>(x[1]) + 2.4 / norm), 2 * ulp);
  EXPECT_EQ(x[2], 7.0f);
  EXPECT_GE(o.iterations, 3);
  EXPECT_LE(o.iterations, 8);
  std::printf("float projection: %d corrections, q = (%.9g, %.9g), closed form (%.9g, %.9g)\n", o.iterations,
              static_cast<double>(x[0]), static_cast<double>(x[1]), 6.0 / norm, -2.4 / norm);
}

/// RK4 of the growing rotation q' = (-q1, q0) + q / 10 from (2, 0) over [0, 3] with the circle's projector on every
/// step, in Real: |q|^2 - 4 at the end, the distance from (2 cos 3, 2 sin 3) and the largest |g| the projector met.
/// Unprojected, |q| would grow to 2 e^0.3; the projection moves each step's end radially, which undoes the growth
/// and leaves the rotation.
template <class Real>
std::array<double, 3> rotation_with_projection() {
  auto rotation = [](Real, const Real* q, Real* f) {
    f[0] = -q[1] + q[0] / Real(10);
    f[1] = q[0] + q[1] / Real(10);
  };
  static Real work[BasicRk4Workspace<Real>::reals(2)];
  static Real projection_work[BasicProjectionWorkspace<Real>::reals(2, 1)];
  ConstraintProjector project(circle<Real>, circle_gradient<Real>, 2, 1,
                              BasicProjectionWorkspace<Real>{projection_work, std::size(projection_work)});
  Real q[2] = {Real(2), Real(0)};
  const auto o = integrate_rk4(rotation, q, 2, Real(0), Real(3), Real(0.01), Real(0), NoObserver{},
                               BasicRk4Workspace<Real>{work, 14}, project);
  EXPECT_EQ(o.status, Status::ok);
  EXPECT_GT(project.stats().projections, 0);
  const double g = std::fabs(static_cast<double>(q[0]) * static_cast<double>(q[0]) +
                             static_cast<double>(q[1]) * static_cast<double>(q[1]) - 4.0);
  const double error =
      std::hypot(static_cast<double>(q[0]) - 2 * std::cos(3.0), static_cast<double>(q[1]) - 2 * std::sin(3.0));
  return {g, error, static_cast<double>(project.stats().largest_residual)};
}

TEST(RuntimeFloat, ProjectedRunStaysOnItsConstraintInFloat) {
  const std::array<double, 3> in_float = rotation_with_projection<float>();
  const std::array<double, 3> in_double = rotation_with_projection<double>();
  std::printf("projected rk4: |g| float %.2e double %.2e; error float %.2e double %.2e; drift per step float %.2e\n",
              in_float[0], in_double[0], in_float[1], in_double[1], in_float[2]);
  // On the circle to float rounding (|g| = |q|^2 - 4, a few ulps of 4 = 4.8e-7 each) and in double to double's.
  EXPECT_LE(in_float[0], 8 * 4 * static_cast<double>(std::numeric_limits<float>::epsilon()));
  EXPECT_LE(in_double[0], 8 * 4 * std::numeric_limits<double>::epsilon());
  // The float run follows the exact solution to float's accuracy over 300 steps; the double one to RK4's h^4.
  EXPECT_LT(in_float[1], 2e-5);
  EXPECT_LT(in_double[1], 1e-8);
}

}  // namespace
