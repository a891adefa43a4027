// The rolling ball in its two descriptions gives the same orientation:
//  - models/rolling_ball.yaml: general coordinates (ZYX Euler angles psi, theta, phi and the contact
//    point x, y), the rolling constraints as quasi-velocities held at zero, constrained Hamel equations
//    (BHconstr) integrated with dopri5 through the generator's "rhs" kernel; R = Rz(psi) Ry(theta) Rx(phi);
//  - models/rolling_ball_bundle.yaml: shape (x, y) on SO(3) right-trivialized with the kinematic
//    connection; the shape dynamics (ldap form) integrated through its own "rhs" kernel, the orientation
//    reconstructed by compute_phase (KinRec with ω = −A(r) ṙ, RKMK4 on SO(3)) along the shape path.
// Straight line: the bundle model's shape motion is x = vx t, y = vy t at constant speed (checked), and
// both orientations equal exp(t ω̂) with ω = (−vy, vx, 0)/R. Curved path: a prescribed circle of the
// contact point, the core model's kinematics q̇ = B(q) u driven by the same contact velocities (u^I =
// ẋ, ẏ, u^α = 0) against compute_phase along the same path.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include "numeric/graph_evaluator.hpp"
#include "numeric/phase.hpp"

#include <hamel/runtime/dopri5.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;
using Mat3 = std::array<double, 9>;  // row-major

using hamel::test::source_dir;

Mat3 multiply(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

// Rz(psi) Ry(theta) Rx(phi), as in the description of models/rolling_ball.yaml.
Mat3 euler_zyx(double psi, double theta, double phi) {
  const Mat3 Rz = {std::cos(psi), -std::sin(psi), 0, std::sin(psi), std::cos(psi), 0, 0, 0, 1};
  const Mat3 Ry = {std::cos(theta), 0, std::sin(theta), 0, 1, 0, -std::sin(theta), 0, std::cos(theta)};
  const Mat3 Rx = {1, 0, 0, 0, std::cos(phi), -std::sin(phi), 0, std::sin(phi), std::cos(phi)};
  return multiply(Rz, multiply(Ry, Rx));
}

// exp(ŵ) by Rodrigues' formula.
Mat3 rotation(const std::array<double, 3>& w) {
  const double a = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  const Mat3 K = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
  const Mat3 K2 = multiply(K, K);
  const double s = a > 0 ? std::sin(a) / a : 1, c = a > 0 ? (1 - std::cos(a)) / (a * a) : 0.5;
  Mat3 R{};
  for (int i = 0; i < 9; ++i) R[i] = (i % 4 == 0 ? 1 : 0) + s * K[i] + c * K2[i];
  return R;
}

double max_difference(const Mat3& a, const Mat3& b) {
  double d = 0;
  for (int i = 0; i < 9; ++i) d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

// A model with its derivation, kernels and default parameters.
struct Loaded {
  hamel::Model model;
  hamel::Derivation derivation;
  std::unique_ptr<hamel::KernelSet> kernels;
  std::vector<double> parameters;
  explicit Loaded(const std::string& file) : model(hamel::load_model(source_dir() + "/models/" + file)) {
    derivation = hamel::derive(model);
    kernels = std::make_unique<hamel::KernelSet>(hamel::build_kernels(model, derivation));
    for (const auto& p : model.parameters) parameters.push_back(p.default_value);
  }
  double parameter(const std::string& name) const {
    for (std::size_t k = 0; k < model.parameters.size(); ++k)
      if (model.parameters[k].symbol.get_name() == name) return parameters[k];
    ADD_FAILURE() << "no parameter " << name;
    return 0;
  }
  // x' = rhs(t, x) over the whole state (q, u_I).
  auto rhs() const {
    auto eval = std::make_shared<hamel::GraphEvaluator>(kernels->graph, kernels->get("rhs").outputs);
    return [this, eval](double t, const double* x, double* xdot) {
      eval->evaluate(t, x, parameters.data(), nullptr, xdot);
    };
  }
  // q' = B(q) u (kinematics kernel) over the coordinates only, u_I = velocity(t) prescribed.
  template <class Velocity>
  auto kinematics(Velocity velocity) const {
    auto eval = std::make_shared<hamel::GraphEvaluator>(kernels->graph, kernels->get("kinematics").outputs);
    return [this, eval, velocity](double t, const double* q, double* qdot) {
      std::vector<double> x(q, q + model.coordinates.size());
      for (double u : velocity(t)) x.push_back(u);
      eval->evaluate(t, x.data(), parameters.data(), nullptr, qdot);
    };
  }
  std::size_t state_size() const { return model.coordinates.size() + derivation.equations.independent.size(); }
};

const Loaded& core() {
  static const Loaded m("rolling_ball.yaml");
  return m;
}
const Loaded& bundle() {
  static const Loaded m("rolling_ball_bundle.yaml");
  return m;
}

// Integrates x' = f(t, x) from x0 at t = 0 and returns the state at each time in `times` (restarting at
// every time, so that no dense-output interpolation is involved).
template <class F>
std::vector<std::vector<double>> integrate(F f, std::vector<double> x, const std::vector<double>& times) {
  hamel::runtime::Dopri5Options opt;
  opt.rtol = 1e-13;
  opt.atol = 1e-15;
  std::vector<std::vector<double>> out;
  double t = 0;
  for (double t1 : times) {
    if (t1 > t) {
      const auto r = hamel::runtime::integrate_dopri5(f, x, t, t1, opt, 0.0, hamel::runtime::NoObserver{});
      EXPECT_EQ(r.status, hamel::runtime::Status::ok) << "at t = " << r.t;
      x = r.x;
      t = t1;
    }
    out.push_back(x);
  }
  return out;
}

hamel::PhaseResult reconstruct(const std::vector<ex>& path, double period, int samples, int steps) {
  hamel::PhaseRequest req;
  req.path = path;
  req.period = period;
  req.samples_per_cycle = samples;
  req.steps_per_cycle = steps;
  return hamel::compute_phase(bundle().model, bundle().derivation, bundle().parameters, req);
}

TEST(RollingBall, StraightLineInBothDescriptionsGivesTheSameOrientation) {
  const double vx = 0.1, vy = -0.25, T = 2.0;
  const int samples = 8;
  std::vector<double> times;
  for (int k = 0; k <= samples; ++k) times.push_back(T * k / samples);
  const double R = core().parameter("R");
  ASSERT_EQ(R, bundle().parameter("R"));

  // The bundle model's own dynamics: x, y, x_dot, y_dot; straight and at constant speed.
  ASSERT_EQ(bundle().state_size(), 4u);
  const auto shape = integrate(bundle().rhs(), {0, 0, vx, vy}, times);
  double shape_error = 0;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const std::vector<double>& s = shape[k];
    shape_error = std::max({shape_error, std::fabs(s[0] - vx * times[k]), std::fabs(s[1] - vy * times[k]),
                            std::fabs(s[2] - vx), std::fabs(s[3] - vy)});
  }
  EXPECT_LE(shape_error, 1e-13);

  // The core model: psi, theta, phi, x, y, vx, vy from rest orientation (identity) at the origin.
  ASSERT_EQ(core().state_size(), 7u);
  const auto state = integrate(core().rhs(), {0, 0, 0, 0, 0, vx, vy}, times);

  const ex t = bundle().model.time;
  const hamel::PhaseResult phase = reconstruct({vx * t, vy * t}, T, samples, 4000);
  ASSERT_EQ(phase.trajectory.size(), times.size());

  double worst = 0, worst_exact = 0, contact = 0;
  for (std::size_t k = 0; k < times.size(); ++k) {
    ASSERT_NEAR(phase.trajectory[k].t, times[k], 1e-12);
    const std::vector<double>& q = state[k];
    const Mat3 euler = euler_zyx(q[0], q[1], q[2]);
    const Mat3 exact = rotation({-vy * times[k] / R, vx * times[k] / R, 0});
    worst = std::max(worst, max_difference(euler, *phase.trajectory[k].R));
    worst_exact = std::max(worst_exact, max_difference(euler, exact));
    contact = std::max({contact, std::fabs(q[3] - vx * times[k]), std::fabs(q[4] - vy * times[k]), std::fabs(q[5] - vx),
                        std::fabs(q[6] - vy)});
  }
  std::printf("straight line: |R_euler - R_bundle| %.2e, |R_euler - exp| %.2e, contact %.2e, shape %.2e\n", worst,
              worst_exact, contact, shape_error);
  EXPECT_LE(worst, 1e-9);
  EXPECT_LE(worst_exact, 1e-9);
  EXPECT_LE(contact, 1e-12);
}

TEST(RollingBall, CircularContactPathGivesTheSameOrientationInBothDescriptions) {
  // Contact point on a circle of radius rho through the origin, once around in T = 2 pi / Omega.
  const double rho = 0.12, Omega = 2.0, T = 2 * M_PI / Omega;
  const int samples = 16;
  std::vector<double> times;
  for (int k = 0; k <= samples; ++k) times.push_back(T * k / samples);

  // Core kinematics q̇ = B(q) u with u^I = (ẋ, ẏ) of the path, q = (psi, theta, phi, x, y).
  auto velocity = [=](double s) {
    return std::array<double, 2>{rho * Omega * std::cos(Omega * s), rho * Omega * std::sin(Omega * s)};
  };
  const auto state = integrate(core().kinematics(velocity), {0, 0, 0, 0, 0}, times);

  const ex t = bundle().model.time;
  const hamel::PhaseResult phase =
      reconstruct({rho * GiNaC::sin(Omega * t), rho * (1 - GiNaC::cos(Omega * t))}, T, samples, 16000);
  ASSERT_EQ(phase.trajectory.size(), times.size());

  double worst = 0, contact = 0, cos_theta = 1, turned = 0;
  for (std::size_t k = 0; k < times.size(); ++k) {
    ASSERT_NEAR(phase.trajectory[k].t, times[k], 1e-12);
    const std::vector<double>& q = state[k];
    const Mat3 euler = euler_zyx(q[0], q[1], q[2]);
    worst = std::max(worst, max_difference(euler, *phase.trajectory[k].R));
    contact = std::max({contact, std::fabs(q[3] - rho * std::sin(Omega * times[k])),
                        std::fabs(q[4] - rho * (1 - std::cos(Omega * times[k])))});
    cos_theta = std::min(cos_theta, std::cos(q[1]));
    turned = std::max(turned, max_difference(euler, euler_zyx(0, 0, 0)));
  }
  std::printf("circle: |R_euler - R_bundle| %.2e, contact %.2e, min cos(theta) %.3f, max |R - I| %.3f\n", worst,
              contact, cos_theta, turned);
  EXPECT_GT(cos_theta, 0.2);  // the Euler angles stay away from their singularity
  EXPECT_GT(turned, 0.5);     // and the ball does turn
  EXPECT_LE(worst, 1e-9);
  EXPECT_LE(contact, 1e-12);
}

}  // namespace
