// Analytic solution of the rolling ball (paper Sec. 4, with the sign of the rolling condition corrected: the
// paper's 0 = ρ̃ṗ + R²ω − ρρᵀω has its ω-terms reversed, so ω = +(1/R²)ρ̃ṗ): the
// contact point moves on a straight line at constant velocity v and the ball turns about the fixed
// horizontal axis e_z × v/|v| at the rate |v|/R, so R(t) = exp(t |v|/R [e_z × v̂]^) R(0). The emitted
// rhs, integrated in Euler angles, must reproduce that rotation — which checks the model file's A and
// the whole pipeline against physics, not against another formulation of the same A.
#include "compiled_models.hpp"

#include <hamel/runtime/dopri5.hpp>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>

namespace {

Eigen::Matrix3d zyx(double psi, double theta, double phi) {
  return (Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(RollingBall, OrientationFollowsAnalyticRolling) {
  const hamel::test::CompiledModel& ball = hamel::test::compiled_model("rolling_ball");
  const double radius = ball.default_parameters[1];
  const Eigen::Vector3d v(0.3, -0.15, 0.0);
  const double psi0 = 0.2, theta0 = -0.1, phi0 = 0.4;
  // state: psi, theta, phi, x, y, vx, vy
  std::vector<double> x0{psi0, theta0, phi0, 0.5, -0.25, v.x(), v.y()};
  const double t_end = 0.35;  // the ball turns ~1.2 rad; the Euler chart stays regular
  const std::vector<double> p(ball.default_parameters, ball.default_parameters + ball.n_parameters);
  hamel::runtime::Dopri5Options opt;
  opt.rtol = opt.atol = 1e-12;
  const auto result = hamel::runtime::integrate_dopri5(
      [&](double t, const double* x, double* xdot) { ball.rhs(t, x, p.data(), nullptr, xdot); }, x0, 0.0, t_end, opt,
      0.0, hamel::runtime::NoObserver{});
  ASSERT_EQ(result.status, hamel::runtime::Status::ok);
  const std::vector<double>& x = result.x;

  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(v).normalized();
  const double angle = v.norm() / radius * t_end;
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix() * zyx(psi0, theta0, phi0);
  const Eigen::Matrix3d actual = zyx(x[0], x[1], x[2]);
  EXPECT_LT((actual - expected).norm(), 1e-9) << "actual\n" << actual << "\nexpected\n" << expected;
  // Rolling the other way round would give the transpose rotation: make sure the test can tell.
  const Eigen::Matrix3d wrong = Eigen::AngleAxisd(-angle, axis).toRotationMatrix() * zyx(psi0, theta0, phi0);
  EXPECT_GT((wrong - expected).norm(), 0.1);

  EXPECT_NEAR(x[3], 0.5 + v.x() * t_end, 1e-12);
  EXPECT_NEAR(x[4], -0.25 + v.y() * t_end, 1e-12);
  EXPECT_DOUBLE_EQ(x[5], v.x());
  EXPECT_DOUBLE_EQ(x[6], v.y());
}

}  // namespace
