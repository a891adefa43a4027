// The heap-free integrators are templates in the scalar type: with float work space, options and state they
// integrate in float (this file compiles with -Wdouble-promotion -Werror, so no float is silently widened to
// double), and every method reaches what float can resolve on the harmonic oscillator x'' = -x, whose solution
// cos t, -sin t is known. The same runs in double agree with the float ones to float's accuracy, and the double
// instantiation is the one the double tests check (Dopri5Workspace is BasicDopri5Workspace<double>, and so on).
#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/radau5.hpp"
#include "hamel/runtime/rk4.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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

}  // namespace
