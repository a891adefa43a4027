// The Chaplygin sleigh's asymptotic approach to straight-line motion (models/chaplygin_sleigh.yaml, no inputs)
// against its closed form, for every integrator. With E = 1/2 m v^2 + 1/2 (J + m a^2) omega^2 conserved,
// v' = a omega^2 becomes v' = a m (v_inf^2 - v^2) / (J + m a^2), so
//   v(t) = v_inf tanh(s),  omega(t) = sign(omega0) sqrt(m / (J + m a^2)) v_inf sech(s),  s = lambda t + s0,
//   theta(t) = theta0 + sign(omega0) sqrt((J + m a^2) / m) / a (gd(s) - gd(s0)),
// with v_inf = sqrt(2E/m), lambda = a m v_inf / (J + m a^2), s0 = atanh(v0 / v_inf), gd(s) = atan(sinh s):
// omega decays like exp(-lambda t), the heading converges to theta0 + sign(omega0) sqrt((J + m a^2)/m)/a
// (pi/2 - gd(s0)), and a sleigh started backwards (v0 < 0) turns round and ends moving forwards.
#include "scene_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

namespace {

using hamel::runtime::Status;

struct Sleigh {
  double m = 1.0, J = 0.02, a = 0.2;  // the model's defaults
  double theta0, v0, w0, v_inf, lambda, s0, sign;
  Sleigh(double theta, double v, double w) : theta0(theta), v0(v), w0(w) {
    const double inertia = J + m * a * a, E = 0.5 * m * v * v + 0.5 * inertia * w * w;
    v_inf = std::sqrt(2 * E / m);
    lambda = a * m * v_inf / inertia;
    s0 = std::atanh(v / v_inf);
    sign = w > 0 ? 1.0 : -1.0;
  }
  double inertia() const { return J + m * a * a; }
  double v(double t) const { return v_inf * std::tanh(lambda * t + s0); }
  double omega(double t) const { return sign * std::sqrt(m / inertia()) * v_inf / std::cosh(lambda * t + s0); }
  double theta(double t) const {
    return theta0 +
           sign * std::sqrt(inertia() / m) / a * (std::atan(std::sinh(lambda * t + s0)) - std::atan(std::sinh(s0)));
  }
  double theta_limit() const {
    return theta0 + sign * std::sqrt(inertia() / m) / a * (M_PI / 2 - std::atan(std::sinh(s0)));
  }
};

TEST(ChaplyginSleigh, ApproachesStraightLineMotionAsTheClosedFormSays) {
  hamel::test::SceneModel sleigh("chaplygin_sleigh.yaml");
  for (double v0 : {0.5, -0.5}) {
    const Sleigh exact(0.5, v0, 2.0);
    const double t_end = 40.0 / exact.lambda;  // omega down to sech(40) ~ 1e-17 of its scale
    for (const std::string& name : hamel::test::scene_integrators()) {
      SCOPED_TRACE(name + (v0 > 0 ? " forward start" : " backward start"));
      const std::vector<double> x0 = sleigh.state({{"x", 0.3}, {"y", -0.1}, {"theta", 0.5}, {"v", v0}, {"omega", 2.0}});
      const double e0 = sleigh.energy(x0.data());
      double error = 0, energy_drift = 0, residual = 0;
      const auto result =
          sleigh.run(name, name == "rk4" ? 1e-3 : 1e-11, x0, t_end, t_end / 400, [&](double t, const double* x) {
            error = std::max({error, std::fabs(x[2] - exact.theta(t)), std::fabs(x[3] - exact.v(t)),
                              std::fabs(x[4] - exact.omega(t))});
            energy_drift = std::max(energy_drift, std::fabs(sleigh.energy(x) - e0) / e0);
            for (double r : sleigh.constraint_residual(x)) residual = std::max(residual, std::fabs(r));
          });
      ASSERT_EQ(result.status, Status::ok);
      const double theta_end = result.x[2], v_end = result.x[3], w_end = result.x[4];
      EXPECT_LT(error, 1e-8);
      EXPECT_LT(std::fabs(w_end), 1e-9);                  // omega -> 0
      EXPECT_NEAR(theta_end, exact.theta_limit(), 1e-8);  // the heading converges
      EXPECT_NEAR(v_end, exact.v_inf, 1e-9);              // forwards, at the energy's speed
      EXPECT_LT(energy_drift, 1e-9);                      // the first integral
      EXPECT_LT(residual, 1e-15);                         // the knife edge holds by construction
      std::cout << "[ sleigh ] v0=" << v0 << " " << name << ": " << result.stats.steps << " steps, max error " << error
                << ", omega(end) " << w_end << ", theta(end) - theta_inf " << theta_end - exact.theta_limit()
                << ", energy drift " << energy_drift << "\n";
    }
  }
}

}  // namespace
