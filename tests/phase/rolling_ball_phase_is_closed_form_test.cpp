// The phase with a kinematic connection and the right trivialization (models/rolling_ball_bundle.yaml:
// a ball of radius ρ rolling without slipping or spinning, ω = (1/ρ) e_z × ṗ spatial, Ṙ = ω̂ R) along
// the circle p(t) = a (cos Ωt − 1, sin Ωt), Ω = 2π, against the closed form: ω(t) is horizontal with
// |ω| = w = aΩ/ρ and turns with Ω about e_z, so in the frame turning with it Q = Rz(Ωt)ᵀ R has the
// constant spatial velocity (−w, 0, −Ω), and R(t) = Rz(Ωt) exp(t (−w, 0, −Ω)). After cycle k the phase is
// the rotation by k |(w, 0, Ω)| about (−w, 0, −Ω) (the ball turns by 2πk a/ρ √(1 + (ρ/a)²) in total).
// The exponential is Eigen's AngleAxis, not the runtime's.
#include "derive/derivation.hpp"
#include "model/load_model.hpp"
#include "numeric/phase.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

Eigen::Matrix3d closed_form(double t, double w, double Om) {
  const Eigen::Vector3d v(-w, 0, -Om);
  return Eigen::AngleAxisd(Om * t, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         Eigen::AngleAxisd(t * v.norm(), v.normalized()).toRotationMatrix();
}

Eigen::Matrix3d R_of(const hamel::GroupPose& p) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = (*p.R)[static_cast<std::size_t>(3 * i + j)];
  return R;
}

TEST(RollingBallPhase, CircleGivesTheClosedFormRotation) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  const hamel::Model model = hamel::load_model(std::string(dir ? dir : ".") + "/models/rolling_ball_bundle.yaml");
  std::vector<double> parameters;
  double rho = 0;
  for (const auto& p : model.parameters) {
    parameters.push_back(p.default_value);
    if (p.symbol.get_name() == "R") rho = p.default_value;
  }
  ASSERT_GT(rho, 0);
  const hamel::Derivation d = hamel::derive(model, hamel::DeriveSettings{"ldap"});

  const double a = 0.37, Om = 2 * M_PI, w = a * Om / rho;
  const GiNaC::ex t = model.time, pi = GiNaC::Pi, A = GiNaC::numeric(37, 100);
  hamel::PhaseRequest req;
  req.path = {A * (cos(2 * pi * t) - 1), A * sin(2 * pi * t)};
  req.cycles = 3;
  std::vector<double> errors;
  for (int steps : {1000, 2000}) {
    req.steps_per_cycle = steps;
    const hamel::PhaseResult r = hamel::compute_phase(model, d, parameters, req);
    ASSERT_EQ(r.cycles.size(), 3u);
    double worst_cycle = 0, worst_path = 0;
    for (std::size_t k = 0; k < r.cycles.size(); ++k)
      worst_cycle = std::max(worst_cycle, (R_of(r.cycles[k]) - closed_form(k + 1.0, w, Om)).norm());
    ASSERT_EQ(r.trajectory.size(), 1u + 3 * 100);
    for (const hamel::GroupPose& p : r.trajectory)
      worst_path = std::max(worst_path, (R_of(p) - closed_form(p.t, w, Om)).norm());
    std::printf(
        "rolling ball, a = %g, rho = %g, %d steps/cycle: max |R - R_exact|_F after each cycle %.2e, "
        "along the path %.2e\n",
        a, rho, steps, worst_cycle, worst_path);
    errors.push_back(std::max(worst_cycle, worst_path));
  }
  // Measured: 7.1e-10 and 4.4e-11, order 4.0.
  const double order = std::log2(errors[0] / errors[1]);
  std::printf("observed order %.2f\n", order);
  EXPECT_NEAR(order, 4.0, 0.3);
  EXPECT_LT(errors[1], 1e-10);
}

}  // namespace
