// A floating tree under gravity obeys the laws of a free fall in the inertial frame. The space robot of
// models/space_robot.yaml with `tree.gravity` added (a tilted g), integrated with its generated `rhs` (state
// x = (q, Γ, ξ, q̇), Γ = Rᵀ g gravity in the bus frame with Γ̇ = Γ × ω) and DOP853; the bus pose g = (R, p) is
// integrated in this test alongside x (Ṙ = R [ω]×, ṗ = R v). Computed here from the file's tree data with the Eigen
// reference of tree_reference.hpp, none of it from generator output other than the rhs:
//  - the advected Γ stays Rᵀ g, so the reduced state and the reconstructed pose describe one motion;
//  - the inertial linear momentum grows as M g t, and the angular momentum about the moving centre of mass is
//    conserved (gravity acts at the centre of mass; the joint torques are internal);
//  - the centre of mass falls on the parabola c(0) + v_c(0) t + ½ g t²;
//  - the energy T − M g·c is conserved without torques and changes by their work τ·(q(t) − q(0)) with them.
#include "tree_from_model.hpp"
#include "tree_reference.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <hamel/runtime/dop853.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using tree_ref::M3;
using tree_ref::Real;
using tree_ref::V3;
using tree_ref::V6;
using tree_ref::VX;

constexpr int kJoints = 7;
constexpr int kState = 2 * kJoints + 3 + 6;  // (q, Γ, ξ, q̇)
constexpr double kEnd = 3.0, kSample = 0.05;
const V3 kGravity(0.3L, -0.5L, -9.81L);

struct Observed {
  double t;
  VX q, xi, qd;
  V3 gamma;
  M3 R;
  V3 p;
};

struct Run {
  std::vector<Observed> samples;
  tree_ref::Tree tree;
};

Run fall(const std::vector<double>& tau) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  std::ifstream file(std::string(dir ? dir : ".") + "/models/space_robot.yaml");
  std::stringstream text;
  text << file.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("\ntree:\n"), 7, "\ntree:\n  gravity: [0.3, -0.5, -9.81]\n");
  const hamel::Model model = hamel::load_model_from_text(yaml, "space_robot_gravity.yaml");
  const hamel::Derivation d = hamel::derive(model);
  const hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs"});
  EXPECT_EQ(k.get("rhs").outputs.size(), static_cast<std::size_t>(kState));
  hamel::GraphEvaluator rhs(k.graph, k.get("rhs").outputs);
  const std::vector<double> p = tree_ref::default_parameters(model);
  // A tumbling bus, moving joints; the bus starts aligned with the world (Γ = g).
  std::vector<double> y = {0.3,  -0.6, 0.2,  1.1,   -0.4, 0.7,  0.1, 0.3, -0.5, -9.81, 0.12, -0.08,
                           0.15, 0.02, 0.03, -0.04, 0.8,  -0.6, 1.0, 0.9, -1.2, 0.7,   1.5};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) y.push_back(i == j ? 1.0 : 0.0);  // R, row-major
  for (int i = 0; i < 3; ++i) y.push_back(0.0);                   // p
  auto f = [&](double t, const double* x, double* dx) {
    rhs.evaluate(t, x, p.data(), tau.data(), dx);
    const double* w = x + kJoints + 3;
    const double* v = x + kJoints + 6;
    const double* R = x + kState;
    for (int i = 0; i < 3; ++i) {
      const double* r = R + 3 * i;
      dx[kState + 3 * i + 0] = r[1] * w[2] - r[2] * w[1];
      dx[kState + 3 * i + 1] = r[2] * w[0] - r[0] * w[2];
      dx[kState + 3 * i + 2] = r[0] * w[1] - r[1] * w[0];
      dx[kState + 9 + i] = r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    }
  };
  Run run{{}, tree_ref::tree_of(model)};
  hamel::runtime::Dop853Options opt;
  opt.rtol = opt.atol = 1e-12;
  const auto result = hamel::runtime::integrate_dop853(f, y, 0.0, kEnd, opt, kSample, [&](double t, const double* x) {
    Observed o{t, VX(kJoints), VX(6), VX(kJoints), V3(), M3(), V3()};
    for (int i = 0; i < kJoints; ++i) {
      o.q[i] = x[i];
      o.qd[i] = x[kJoints + 9 + i];
    }
    for (int i = 0; i < 3; ++i) o.gamma[i] = x[kJoints + i];
    for (int a = 0; a < 6; ++a) o.xi[a] = x[kJoints + 3 + a];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) o.R(i, j) = x[kState + 3 * i + j];
      o.p[i] = x[kState + 9 + i];
    }
    run.samples.push_back(o);
  });
  EXPECT_EQ(result.status, hamel::runtime::Status::ok);
  return run;
}

// Inertial momenta: linear P = R P_b and angular about the centre of mass c, from the body momentum h = (l, P_b)
// about the bus origin.
void momenta(const tree_ref::Tree& t, const Observed& o, V3& P, V3& L_com, V3& c) {
  const V6 h = tree_ref::body_momentum(t, o.q, o.xi, o.qd);
  P = o.R * h.tail<3>();
  c = o.p + o.R * tree_ref::centre_of_mass(t, o.q);
  L_com = o.R * h.head<3>() + o.p.cross(P) - c.cross(P);
}

void check(const std::vector<double>& tau, double& energy_drift) {
  const Run run = fall(tau);
  const tree_ref::Tree& t = run.tree;
  const Real M = tree_ref::total_mass(t);
  V3 P0, L0, c0;
  momenta(t, run.samples.front(), P0, L0, c0);
  const Observed& o0 = run.samples.front();
  const Real E0 = tree_ref::kinetic_energy(t, o0.q, o0.xi, o0.qd) - M * kGravity.dot(c0);
  double gamma = 0, linear = 0, angular = 0, parabola = 0;
  energy_drift = 0;
  for (const Observed& o : run.samples) {
    V3 P, L, c;
    momenta(t, o, P, L, c);
    const Real time = static_cast<Real>(o.t);
    gamma = std::max(gamma, static_cast<double>((o.gamma - o.R.transpose() * kGravity).norm() / kGravity.norm()));
    linear = std::max(linear, static_cast<double>((P - P0 - M * kGravity * time).norm() / (M * kGravity.norm())));
    angular = std::max(angular, static_cast<double>((L - L0).norm() / L0.norm()));
    parabola = std::max(parabola, static_cast<double>((c - c0 - P0 / M * time - kGravity * time * time / 2).norm()));
    VX tau_v(kJoints);
    for (int i = 0; i < kJoints; ++i) tau_v[i] = tau[static_cast<std::size_t>(i)];
    const Real E = tree_ref::kinetic_energy(t, o.q, o.xi, o.qd) - M * kGravity.dot(c) - tau_v.dot(o.q - o0.q);
    energy_drift = std::max(energy_drift, static_cast<double>(std::fabs(E - E0) / std::fabs(E0)));
  }
  std::printf(
      "over %.0f s: |Gamma - R^T g|/|g| %.1e, |P - P0 - M g t|/(M |g|) %.1e, |L_c - L_c0|/|L_c0| %.1e, "
      "centre of mass off the parabola %.1e m, energy %.1e\n",
      kEnd, gamma, linear, angular, parabola, energy_drift);
  EXPECT_LE(gamma, 1e-9);
  EXPECT_LE(linear, 1e-9);
  EXPECT_LE(angular, 1e-8);
  EXPECT_LE(parabola, 1e-8);
  EXPECT_LE(energy_drift, 1e-8);
}

TEST(FloatingTreeUnderGravity, FallsFreelyWithItsMomentaAndEnergyAsInTheInertialFrame) {
  double energy = 0;
  check(std::vector<double>(kJoints, 0.0), energy);
}

TEST(FloatingTreeUnderGravity, JointTorquesDoWorkButKeepTheFall) {
  double energy = 0;
  check({0.4, -0.3, 0.2, 0.1, -0.2, 0.05, 0.1}, energy);
}

}  // namespace
