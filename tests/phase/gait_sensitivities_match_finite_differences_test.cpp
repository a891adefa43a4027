// The exact sensitivities of the gait designer (numeric/gait.cpp: forward sensitivity equations integrated with the
// RKMK4 steps, ∂𝒜/∂r from the expression graph) against central differences of the phase that `hamel phase`
// computes (numeric/phase.cpp: the path as a GiNaC expression, its own reconstruction), for every Fourier
// coefficient of a gait with a non-trivial target (so that dexp⁻¹ of the residual matters):
//  - the falling cat (SO(3), left, mechanical connection from `kinetic`), two harmonics and a free centre;
//  - the planar space robot (SE(2), left, from `bodies`);
//  - the planar swimmer (SE(2), a kinematic tree: 𝒜 solved from L𝒜 = K in the graph);
//  - a right-trivialized model written here: a rigid body with two rotors on SO(3), whose connection
//    (kinematic, given) depends on the rotor angles.
// Also: the gait's own phase equals compute_phase's on the same path (same method, two code paths), and the
// curvature height the plot draws is the phase of a small counter-clockwise loop per enclosed area (Stokes), sign
// included, on SO(3) (where the bracket term matters) and SE(2).
#include "derive/derivation.hpp"
#include "model/load_model.hpp"
#include "numeric/gait.hpp"
#include "numeric/phase.hpp"
#include "support/command.hpp"

#include <hamel/runtime/lie/se2.hpp>
#include <hamel/runtime/lie/so3.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;
using hamel::test::source;
namespace lie = hamel::runtime::lie;

struct Case {
  hamel::Model model;
  hamel::Derivation derivation;
  std::vector<double> parameters;
};

Case load(const hamel::Model& model) {
  Case c{model, {}, {}};
  const bool tree = model.bundle->tree.has_value();
  c.derivation = hamel::derive(model, hamel::DeriveSettings{tree                       ? "ep"
                                                            : model.bundle->mechanical ? "momentum"
                                                                                       : "ldap"});
  for (const auto& p : model.parameters) c.parameters.push_back(p.default_value);
  return c;
}

const char* kRightRotors = R"(name: right_rotors
group: SO3
trivialization: right
group_velocity: [wx, wy, wz]
shape: [a, b]
connection: {kinematic: [[0.3*cos(b), 0.1], [0.2, 0.4 + 0.1*sin(a)], [0.05*a, 0.2*cos(a + b)]]}
kinetic: 1/2*(wx^2 + wy^2 + wz^2) + 1/2*(a_dot^2 + b_dot^2)
)";

// The gait's path as a GiNaC expression in the model's t, written from the coefficients (not FourierGait's text).
std::vector<ex> path_of(const hamel::FourierGait& g, const hamel::Model& model) {
  std::vector<ex> out;
  for (unsigned I = 0; I < g.n(); ++I) {
    ex r = g.center[I];
    for (int k = 1; k <= g.harmonics; ++k) {
      const std::size_t at = I * static_cast<std::size_t>(g.harmonics) + static_cast<std::size_t>(k - 1);
      const ex arg = 2 * GiNaC::Pi * k * model.time / ex(g.period);
      r += ex(g.cosine[at]) * GiNaC::cos(arg) + ex(g.sine[at]) * GiNaC::sin(arg);
    }
    out.push_back(r);
  }
  return out;
}

hamel::GroupPose phase_end(const Case& c, const hamel::FourierGait& g, int steps) {
  hamel::PhaseRequest req;
  req.path = path_of(g, c.model);
  req.period = g.period;
  req.steps_per_cycle = steps;
  req.samples_per_cycle = 1;
  return hamel::compute_phase(c.model, c.derivation, c.parameters, req).cycles.back();
}

// e = log(g*⁻¹ g) (left) or log(g g*⁻¹) (right) from a pose of phase, written with the runtime's groups.
std::vector<double> residual(const hamel::Model& model, const hamel::GroupPose& pose, const std::vector<double>& v) {
  const bool right = model.bundle->right;
  if (model.bundle->group == "SO3") {
    const lie::Mat3 goal = lie::SO3::exp({v[0], v[1], v[2]});
    const lie::Mat3 e = right ? lie::SO3::compose(*pose.R, lie::SO3::inverse(goal))
                              : lie::SO3::compose(lie::SO3::inverse(goal), *pose.R);
    const lie::Vec3 w = lie::SO3::log(e);
    return {w[0], w[1], w[2]};
  }
  const lie::SE2::Element g{*pose.theta, pose.p[0], pose.p[1]};
  const lie::SE2::Element goal = lie::SE2::exp({v[0], v[1], v[2]});
  const lie::SE2::Element e =
      right ? lie::SE2::compose(g, lie::SE2::inverse(goal)) : lie::SE2::compose(lie::SE2::inverse(goal), g);
  const lie::Vec3 w = lie::SE2::log(e);
  return {w[0], w[1], w[2]};
}

hamel::FourierGait gait(unsigned n, int harmonics, std::vector<double> center) {
  hamel::FourierGait g;
  g.period = 1.3;
  g.harmonics = harmonics;
  g.center = std::move(center);
  const std::size_t N = n * static_cast<std::size_t>(harmonics);
  for (std::size_t k = 0; k < N; ++k) {
    g.cosine.push_back(0.4 * std::cos(1.7 * static_cast<double>(k) + 0.3) / static_cast<double>(1 + k % 2));
    g.sine.push_back(0.35 * std::sin(2.3 * static_cast<double>(k) + 1.1) / static_cast<double>(1 + k % 2));
  }
  return g;
}

void expect_sensitivities(const Case& c, const hamel::FourierGait& g, const std::vector<double>& target) {
  const int steps = 400;
  const hamel::GaitPhase at = hamel::gait_phase(c.model, c.derivation, c.parameters, g, target, steps, true);
  const std::vector<double> coefficients = g.coefficients();
  const std::size_t N = coefficients.size(), m = target.size();
  ASSERT_EQ(at.jacobian.size(), m * N);
  // The residual itself: the same reconstruction method, two code paths.
  const std::vector<double> e0 = residual(c.model, phase_end(c, g, steps), target);
  for (std::size_t a = 0; a < m; ++a) EXPECT_NEAR(at.residual[a], e0[a], 1e-12) << "residual " << a;
  double largest = 0;
  for (std::size_t col = 0; col < N; ++col) {
    const double h = 1e-5;
    hamel::FourierGait plus = g, minus = g;
    std::vector<double> cp = coefficients, cm = coefficients;
    cp[col] += h;
    cm[col] -= h;
    plus.set_coefficients(cp);
    minus.set_coefficients(cm);
    const std::vector<double> ep = residual(c.model, phase_end(c, plus, steps), target);
    const std::vector<double> em = residual(c.model, phase_end(c, minus, steps), target);
    for (std::size_t a = 0; a < m; ++a) {
      const double fd = (ep[a] - em[a]) / (2 * h);
      largest = std::max(largest, std::abs(fd));
      // Central differences: O(h²) truncation (~1e-10 here) and rounding ~1e-16/h.
      EXPECT_NEAR(at.jacobian[a * N + col], fd, 2e-8 * std::max(1.0, std::abs(fd)))
          << c.model.name << ": de^" << a << "/dc_" << col;
    }
  }
  EXPECT_GT(largest, 1e-3);  // the sensitivities are not all zero (1e5 times the tolerance)
}

TEST(GaitSensitivities, FallingCatMatchesFiniteDifferencesOfPhase) {
  const Case c = load(hamel::load_model(source("models/falling_cat.yaml")));
  expect_sensitivities(c, gait(2, 2, {0.2, -0.3}), {0.3, -0.2, 2.5});
}

TEST(GaitSensitivities, PlanarSpaceRobotMatchesFiniteDifferencesOfPhase) {
  const Case c = load(hamel::load_model(source("models/planar_space_robot.yaml")));
  expect_sensitivities(c, gait(2, 2, {0.5, 0.3}), {0.4, 0.1, -0.2});
}

TEST(GaitSensitivities, TreeMatchesFiniteDifferencesOfPhase) {
  // A kinematic tree: 𝒜 solves L𝒜 = K inside the expression graph, and ∂𝒜/∂r differentiates that solve.
  const Case c = load(hamel::load_model(source("models/planar_swimmer.yaml")));
  ASSERT_FALSE(c.derivation.bundle->connection_derived);
  std::vector<double> centre(c.model.coordinates.size(), 0.0);
  centre[0] = 0.3;
  expect_sensitivities(c, gait(static_cast<unsigned>(centre.size()), 1, centre), {0.2, 0.1, 0.05});
}

TEST(GaitSensitivities, RightTrivializationMatchesFiniteDifferencesOfPhase) {
  const Case c = load(hamel::load_model_from_text(kRightRotors, "right_rotors.yaml"));
  ASSERT_TRUE(c.model.bundle->right);
  expect_sensitivities(c, gait(2, 1, {0.1, 0.2}), {0.2, 0.5, -1.0});
}

// A circle of radius ρ about r0, counter-clockwise in (r^0, r^1): its phase is π ρ² F(r0) + O(ρ³).
void expect_stokes(const Case& c, std::vector<double> r0, unsigned alpha) {
  const std::vector<double> F =
      hamel::curvature_height(c.model, c.derivation, c.parameters, r0, 0, 1, alpha, {r0[0]}, {r0[1]});
  ASSERT_GT(std::abs(F[0]), 1e-3);
  double previous = 0;
  for (const double rho : {0.02, 0.01}) {
    hamel::FourierGait g;
    g.harmonics = 1;
    g.center = r0;
    g.cosine = {rho, 0.0};
    g.sine = {0.0, rho};
    const hamel::GaitPhase p =
        hamel::gait_phase(c.model, c.derivation, c.parameters, g, std::vector<double>(3, 0.0), 400, false);
    const double per_area = p.log_end[alpha] / (M_PI * rho * rho);
    EXPECT_NEAR(per_area, F[0], 0.05 * std::abs(F[0])) << c.model.name << " rho " << rho;
    if (previous != 0) {
      EXPECT_LT(std::abs(per_area - F[0]), std::abs(previous - F[0]));  // converges as ρ → 0
    }
    previous = per_area;
  }
}

TEST(GaitCurvature, HeightIsThePhasePerAreaOfSmallLoops) {
  expect_stokes(load(hamel::load_model(source("models/falling_cat.yaml"))), {0.4, 0.7}, 2);
  expect_stokes(load(hamel::load_model(source("models/falling_cat.yaml"))), {0.4, 0.7}, 0);
  expect_stokes(load(hamel::load_model(source("models/planar_space_robot.yaml"))), {0.8, -0.5}, 0);
  expect_stokes(load(hamel::load_model_from_text(kRightRotors, "right_rotors.yaml")), {0.3, 0.6}, 1);
}

}  // namespace
