// The free-floating space robot (models/space_robot.yaml: SE(3) bus with a full inertia and its centre of
// mass off the base frame, 7-joint arm), integrated with the generated `rhs` kernel (default form ep, state
// x = (q, ξ, q̇)) and DOP853 at tight tolerance from a state with a tumbling bus and moving joints. The bus
// pose g = (R, p) is integrated in this test alongside x (Ṙ = R [ω]×, ṗ = R v, with (ω, v) = ξ the body twist).
// Everything checked is computed here, from the file's tree data with the Eigen reference of
// tree_reference.hpp, none of it from generator output other than the rhs:
//  - the inertial spatial momentum μ = Ad*_{g⁻¹} h = (R l + p × R P, R P), where h = (l, P) = ∂T/∂ξ is the
//    body momentum about the origin of F_b (Σ Ad_{g_0i⁻¹}ᵀ 𝕀_i V_i), stays constant;
//  - the kinetic energy ½ Σ V_iᵀ 𝕀_i V_i stays constant;
//  - the total centre of mass p + R c(q) moves on a straight line with the velocity μ_v / M;
//  - with constant joint torques τ (inputs) the momentum is still conserved (the torques are internal) and
//    the energy grows by the work τ·(q(t) − q(0)).
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
#include <memory>
#include <string>
#include <vector>

namespace {

using tree_ref::M3;
using tree_ref::Real;
using tree_ref::V3;
using tree_ref::V6;
using tree_ref::VX;

constexpr int kJoints = 7;
constexpr int kState = 2 * kJoints + 6;  // (q, ξ, q̇)
constexpr double kEnd = 5.0, kSample = 0.05;

struct Robot {
  hamel::Model model;
  hamel::Derivation derivation;
  hamel::KernelSet kernels;
  tree_ref::Tree tree;
  std::vector<double> parameters;
};

Robot* robot = nullptr;

class SpaceRobot : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const char* dir = std::getenv("HAMEL_SOURCE_DIR");
    hamel::Model model = hamel::load_model(std::string(dir ? dir : ".") + "/models/space_robot.yaml");
    hamel::Derivation d = hamel::derive(model);
    hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs"});
    tree_ref::Tree t = tree_ref::tree_of(model);
    std::vector<double> p = tree_ref::default_parameters(model);
    robot = new Robot{std::move(model), std::move(d), std::move(k), std::move(t), std::move(p)};
  }
  static void TearDownTestSuite() {
    delete robot;
    robot = nullptr;
  }
};

// Tumbling bus (|ω| ≈ 0.2 rad/s, |v| ≈ 0.05 m/s) and every joint moving at up to 1.5 rad/s.
const double kStart[kState] = {0.3,  -0.6,  0.2,  1.1,  -0.4, 0.7,   0.1,   // q
                               0.12, -0.08, 0.15, 0.02, 0.03, -0.04,        // ξ = (ω, v)
                               0.8,  -0.6,  1.0,  0.9,  -1.2, 0.7,   1.5};  // q̇

struct Observed {
  double t;
  VX q, xi, qd;
  M3 R;
  V3 p;
};

/// Integrates (x, R, p) with DOP853 at rtol = atol = tol; returns the samples.
std::vector<Observed> integrate(const std::vector<double>& tau, double tol) {
  hamel::GraphEvaluator rhs(robot->kernels.graph, robot->kernels.get("rhs").outputs);
  EXPECT_EQ(robot->kernels.get("rhs").outputs.size(), static_cast<std::size_t>(kState));
  std::vector<double> y(kStart, kStart + kState);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) y.push_back(i == j ? 1.0 : 0.0);  // R, row-major
  for (int i = 0; i < 3; ++i) y.push_back(0.0);                   // p
  const double* par = robot->parameters.data();
  auto f = [&](double t, const double* x, double* dx) {
    rhs.evaluate(t, x, par, tau.data(), dx);
    const double* w = x + kJoints;
    const double* v = x + kJoints + 3;
    const double* R = x + kState;
    double* dR = dx + kState;
    double* dp = dx + kState + 9;
    for (int i = 0; i < 3; ++i) {
      const double* r = R + 3 * i;  // row i of R
      // (R [ω]×)_i = (r_1 ω_2 − r_2 ω_1, r_2 ω_0 − r_0 ω_2, r_0 ω_1 − r_1 ω_0), ṗ_i = r · v
      dR[3 * i + 0] = r[1] * w[2] - r[2] * w[1];
      dR[3 * i + 1] = r[2] * w[0] - r[0] * w[2];
      dR[3 * i + 2] = r[0] * w[1] - r[1] * w[0];
      dp[i] = r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    }
  };
  std::vector<Observed> out;
  hamel::runtime::Dop853Options opt;
  opt.rtol = tol;
  opt.atol = tol;
  const auto result = hamel::runtime::integrate_dop853(f, y, 0.0, kEnd, opt, kSample, [&](double t, const double* x) {
    Observed o{t, VX(kJoints), VX(6), VX(kJoints), M3(), V3()};
    for (int i = 0; i < kJoints; ++i) {
      o.q[i] = x[i];
      o.qd[i] = x[kJoints + 6 + i];
    }
    for (int a = 0; a < 6; ++a) o.xi[a] = x[kJoints + a];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) o.R(i, j) = x[kState + 3 * i + j];
      o.p[i] = x[kState + 9 + i];
    }
    out.push_back(o);
  });
  EXPECT_EQ(result.status, hamel::runtime::Status::ok);
  std::printf("DOP853 tol %.0e: %ld steps, %ld rhs evaluations\n", tol, result.stats.steps, result.stats.rhs_evals);
  return out;
}

/// μ = Ad*_{g⁻¹} h: angular momentum about the inertial origin, then linear momentum, inertial axes.
V6 inertial_momentum(const Observed& o) {
  const V6 h = tree_ref::body_momentum(robot->tree, o.q, o.xi, o.qd);
  V6 mu;
  mu.head<3>() = o.R * h.head<3>() + o.p.cross(o.R * h.tail<3>());
  mu.tail<3>() = o.R * h.tail<3>();
  return mu;
}

struct Drift {
  double momentum = 0, energy = 0, com = 0, orthogonality = 0;
  V6 mu0;
  double e0 = 0;
};

Drift drift(const std::vector<Observed>& run, const std::vector<double>& tau) {
  const tree_ref::Tree& t = robot->tree;
  const Real M = tree_ref::total_mass(t);
  Drift d;
  const Observed& o0 = run.front();
  d.mu0 = inertial_momentum(o0);
  d.e0 = static_cast<double>(tree_ref::kinetic_energy(t, o0.q, o0.xi, o0.qd));
  const V3 pc0 = o0.p + o0.R * tree_ref::centre_of_mass(t, o0.q);
  const V3 vc = d.mu0.tail<3>() / M;
  VX tau_v(kJoints);
  for (int i = 0; i < kJoints; ++i) tau_v[i] = tau[static_cast<std::size_t>(i)];
  for (const Observed& o : run) {
    d.momentum = std::max(d.momentum, static_cast<double>((inertial_momentum(o) - d.mu0).norm() / d.mu0.norm()));
    const Real work = tau_v.dot(o.q - o0.q);
    const Real e = tree_ref::kinetic_energy(t, o.q, o.xi, o.qd);
    d.energy = std::max(d.energy, static_cast<double>(std::fabs(e - d.e0 - work) / d.e0));
    const V3 pc = o.p + o.R * tree_ref::centre_of_mass(t, o.q);
    d.com = std::max(d.com, static_cast<double>((pc - pc0 - static_cast<Real>(o.t) * vc).norm()));
    d.orthogonality = std::max(d.orthogonality, static_cast<double>((o.R.transpose() * o.R - M3::Identity()).norm()));
  }
  return d;
}

TEST_F(SpaceRobot, SpatialMomentumEnergyAndCentreOfMassLineAreConserved) {
  const std::vector<double> tau(kJoints, 0.0);
  for (double tol : {1e-10, 1e-12}) {
    const std::vector<Observed> run = integrate(tau, tol);
    ASSERT_GT(run.size(), 90u);
    const Drift d = drift(run, tau);
    // The motion is not trivial: the bus turns and the arm folds.
    const Observed& end = run.back();
    const double turned = std::acos(std::min<Real>(1, (end.R.trace() - 1) / 2));
    std::printf(
        "tol %.0e over %g s: drift of momentum %.2e, energy %.2e (relative), centre-of-mass line %.2e m, "
        "|R^T R - I| %.1e; |mu0| = %.4f, E0 = %.4f J, bus turned %.3f rad, |q(T) - q(0)| = %.3f\n",
        tol, kEnd, d.momentum, d.energy, d.com, d.orthogonality, static_cast<double>(d.mu0.norm()), d.e0, turned,
        static_cast<double>((end.q - run.front().q).norm()));
    EXPECT_GT(turned, 0.2);
    if (tol == 1e-12) {
      EXPECT_LT(d.momentum, 1e-9);
      EXPECT_LT(d.energy, 1e-9);
      EXPECT_LT(d.com, 1e-9);
    }
  }
}

TEST_F(SpaceRobot, JointTorquesKeepTheMomentumAndDoWork) {
  const std::vector<double> tau = {0.5, -0.4, 0.3, 0.2, -0.15, 0.1, 0.05};
  const std::vector<Observed> run = integrate(tau, 1e-12);
  const Drift d = drift(run, tau);
  const Observed& end = run.back();
  const double e_end = static_cast<double>(tree_ref::kinetic_energy(robot->tree, end.q, end.xi, end.qd));
  std::printf(
      "constant joint torques over %g s: drift of momentum %.2e, of E - work %.2e (relative to E0), centre-of-mass "
      "line %.2e m; E0 = %.4f J, E(T) = %.4f J\n",
      kEnd, d.momentum, d.energy, d.com, d.e0, e_end);
  EXPECT_GT(std::fabs(e_end - d.e0), 0.1 * d.e0);  // the torques do change the energy
  EXPECT_LT(d.momentum, 1e-9);
  EXPECT_LT(d.energy, 1e-9);
  EXPECT_LT(d.com, 1e-9);
}

}  // namespace
