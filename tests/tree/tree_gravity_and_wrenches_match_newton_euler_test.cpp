// Gravity on floating bases and wrenches applied to bodies (model keys `tree.gravity` and `wrenches`) against the
// Newton–Euler reference of tree_reference.hpp, which writes them as forces on the bodies — each body's weight m g at
// its centre of mass resolved through its pose relative to the base, and the applied force at its point plus the
// torque — and not, as the generator does, as an upward acceleration of the base and as generalized forces Jᵀ f_ext:
//  - random trees on SE(3), SO(3) (origin fixed: a heavy gyrostat), SE(2) with gravity in the plane of motion (the
//    state then carries Γ, gravity in the base's frame, with Γ̇ = Γ × ω) and across it (Γ constant), and R3 (a base
//    that only translates), with wrenches on the base and on bodies whose force and torque depend on inputs, joint
//    angles and rates; rhs by the articulated-body algorithm and by M u̇ = f, relative error of (ξ̇, q̈) ≤ 1e-10 at
//    random states, Γ̇ = Γ × ω to rounding;
//  - the Jacobian (analytical ∂ID/∂x with Γ's columns and the wrenches' generalized forces differentiated through the
//    program, its columns solved by LDLᵀ and by the articulated recursion) against central differences of rhs;
//  - a tree fixed to the world under gravity with a wrench given in the world frame (the reference turns it into the
//    body's frame with its own forward kinematics).
#include "tree_reference.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using tree_ref::M3;
using tree_ref::Real;
using tree_ref::Tree;
using tree_ref::V3;
using tree_ref::V6;
using tree_ref::VX;

// The wrenches every test tree carries, as model text and as the reference computes them: on the base (unless the
// base is the world) a constant force at a point and a torque from input u1; on the last body a force from input u2,
// the angle and rate of its own joint, at another point, and a torque from the rate.
std::string wrench_text(const Tree& t, bool fixed, bool world_frame) {
  const int k = t.n();
  const std::string q = "q" + std::to_string(k);
  std::string s = "inputs: [u1, u2]\nwrenches:\n";
  if (!fixed)
    s += "  - {body: base, point: [0.1, -0.2, 0.05], force: [1.5, -0.5, 2.0], torque: [\"0.3*u1\", 0, -0.2]}\n";
  s += "  - {body: b" + std::to_string(k) + (world_frame ? ", frame: world" : "") +
       ", point: [0.05, 0.1, -0.15], force: [\"0.7*u2 + 0.3*cos(" + q + ")\", \"-0.4*" + q +
       "_dot\", 1.2], torque: [\"0.1*u2\", 0.05, \"-0.2*" + q + "_dot\"]}\n";
  return s;
}

std::vector<tree_ref::Wrench> wrenches(const Tree& t, bool fixed, const VX& q, const VX& qd,
                                       const std::vector<double>& in, const M3& R_world_last) {
  std::vector<tree_ref::Wrench> out;
  if (!fixed) {
    tree_ref::Wrench w;
    w.body = -1;
    w.point << 0.1L, -0.2L, 0.05L;
    w.force << 1.5L, -0.5L, 2.0L;
    w.torque << 0.3L * in[0], 0, -0.2L;
    out.push_back(w);
  }
  const int k = t.n() - 1;
  tree_ref::Wrench w;
  w.body = k;
  w.point << 0.05L, 0.1L, -0.15L;
  w.force << 0.7L * in[1] + 0.3L * std::cos(q[k]), -0.4L * qd[k], 1.2L;
  w.torque << 0.1L * in[1], 0.05L, -0.2L * qd[k];
  // A world-frame wrench: the reference's own pose of the body gives its components in the body's frame.
  w.force = R_world_last.transpose() * w.force;
  w.torque = R_world_last.transpose() * w.torque;
  out.push_back(w);
  return out;
}

double relative(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, norm = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff += (a[i] - b[i]) * (a[i] - b[i]);
    norm += b[i] * b[i];
  }
  return std::sqrt(diff / std::max(norm, 1e-300));
}

struct Case {
  std::string group;
  std::string gravity;  // the model's tree.gravity
  V3 g;                 // its value
  bool gravity_state;   // whether the state carries Γ
  int n;
  std::uint64_t seed;
};

// rhs of both dynamics routes against the reference, and each route's Jacobian against central differences.
void check(const Case& c) {
  std::mt19937_64 rng(c.seed);
  tree_ref::RandomSettings rs;
  rs.group = c.group;
  rs.n = c.n;
  const Tree t = tree_ref::random_tree(rng, rs);
  const std::string name = "loads_" + c.group + "_" + std::to_string(c.n) + "_" + std::to_string(c.seed);
  std::string text = tree_ref::yaml(t, name, wrench_text(t, false, false));
  text.replace(text.find("tree:\n"), 6, "tree:\n  gravity: " + c.gravity + "\n");
  const hamel::Model model = hamel::load_model_from_text(text, name + ".yaml");
  ASSERT_EQ(model.bundle->tree->gravity_state.size(), c.gravity_state ? 3u : 0u) << text;
  const int n = c.n, m = static_cast<int>(tree_ref::basis(c.group).cols()), G = c.gravity_state ? 3 : 0;
  const std::size_t nx = static_cast<std::size_t>(2 * n + G + m);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const char* dynamics : {"aba", "ldlt"}) {
    const hamel::Derivation d = hamel::derive(model);
    const hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs", "jacobian"}, {dynamics});
    const hamel::KernelSet recursive =
        hamel::build_kernels(model, d, {"jacobian"}, {dynamics, hamel::ColumnSolve::articulated});
    ASSERT_EQ(k.get("rhs").outputs.size(), nx) << name;
    hamel::GraphEvaluator rhs(k.graph, k.get("rhs").outputs), jac(k.graph, k.get("jacobian").outputs),
        jac_rec(recursive.graph, recursive.get("jacobian").outputs);
    double worst = 0, worst_gamma = 0, worst_jac = 0, worst_rec = 0;
    for (int trial = 0; trial < 6; ++trial) {
      std::vector<double> x(nx), out(nx), in{2 * u(rng), 2 * u(rng)};
      for (std::size_t i = 0; i < nx; ++i) x[i] = 1.5 * u(rng);
      V3 gamma = c.g;
      if (G) {  // a base turned away from the world: Γ = Rᵀ g for a random R (length |g|)
        const M3 R = tree_ref::random_rotation(rng, false).value();
        gamma = R.transpose() * c.g;
        for (int j = 0; j < 3; ++j) x[static_cast<std::size_t>(n + j)] = static_cast<double>(gamma[j]);
      }
      rhs.evaluate(0, x.data(), nullptr, in.data(), out.data());
      VX q(n), xi(m), qd(n);
      for (int i = 0; i < n; ++i) {
        q[i] = x[static_cast<std::size_t>(i)];
        qd[i] = x[static_cast<std::size_t>(n + G + m + i)];
      }
      for (int a = 0; a < m; ++a) xi[a] = x[static_cast<std::size_t>(n + G + a)];
      tree_ref::Loads loads;
      loads.gravity = gamma;
      loads.wrenches = wrenches(t, false, q, qd, in, M3::Identity());
      const VX a = tree_ref::accelerations(t, q, xi, qd, VX::Zero(n), loads);
      std::vector<double> generated, reference;
      for (int i = 0; i < m + n; ++i) {
        generated.push_back(out[static_cast<std::size_t>(n + G + i)]);
        reference.push_back(static_cast<double>(a[i]));
      }
      worst = std::max(worst, relative(generated, reference));
      if (G) {  // Γ̇ = Γ × ω, ω the base's angular velocity
        const V6 twist = tree_ref::basis(c.group) * xi;
        const V3 rate = gamma.cross(V3(twist[0], twist[1], twist[2]));
        for (int j = 0; j < 3; ++j)
          worst_gamma =
              std::max(worst_gamma, std::fabs(out[static_cast<std::size_t>(n + j)] - static_cast<double>(rate[j])));
      }
      // The Jacobian against central differences of rhs.
      std::vector<double> J(nx * nx), Jr(nx * nx), fd(nx * nx), fp(nx), fm(nx);
      jac.evaluate(0, x.data(), nullptr, in.data(), J.data());
      jac_rec.evaluate(0, x.data(), nullptr, in.data(), Jr.data());
      const double h = 1e-6;
      for (std::size_t col = 0; col < nx; ++col) {
        std::vector<double> xp = x, xm = x;
        xp[col] += h;
        xm[col] -= h;
        rhs.evaluate(0, xp.data(), nullptr, in.data(), fp.data());
        rhs.evaluate(0, xm.data(), nullptr, in.data(), fm.data());
        for (std::size_t r = 0; r < nx; ++r) fd[r * nx + col] = (fp[r] - fm[r]) / (2 * h);
      }
      worst_jac = std::max(worst_jac, relative(J, fd));
      worst_rec = std::max(worst_rec, relative(Jr, fd));
    }
    std::printf(
        "%-26s %-4s (xi', q'') vs Newton-Euler %.1e, Gamma' %.1e; jacobian vs central differences %.1e, "
        "solved by the recursion %.1e\n",
        name.c_str(), dynamics, worst, worst_gamma, worst_jac, worst_rec);
    EXPECT_LE(worst, 1e-10) << name << " " << dynamics << "\n" << text;
    EXPECT_LE(worst_gamma, 1e-14) << name;
    EXPECT_LE(worst_jac, 1e-7) << name << " " << dynamics;
    EXPECT_LE(worst_rec, 1e-7) << name << " " << dynamics;
  }
}

TEST(GravityAndWrenches, FloatingSpatialBasesCarryGravityInTheirFrame) {
  const V3 g(0.7L, -1.3L, -9.81L);
  for (int n : {1, 2, 4, 6}) check({"SE3", "[0.7, -1.3, -9.81]", g, true, n, 100u + static_cast<unsigned>(n)});
}

TEST(GravityAndWrenches, HeavyGyrostatOnABaseWithFixedOrigin) {
  check({"SO3", "[0, 0, -9.81]", V3(0, 0, -9.81L), true, 2, 7});
}

TEST(GravityAndWrenches, PlanarBaseWithGravityInAndAcrossItsPlane) {
  check({"SE2", "[0, -9.81, 0]", V3(0, -9.81L, 0), true, 3, 11});
  check({"SE2", "[0, 0, -9.81]", V3(0, 0, -9.81L), false, 3, 12});
}

TEST(GravityAndWrenches, TranslatingBaseFeelsConstantGravity) {
  check({"R3", "[0.5, 0, -9.81]", V3(0.5L, 0, -9.81L), false, 3, 13});
}

// A tree fixed to the world, under gravity, with a wrench resolved in the world's frame.
TEST(GravityAndWrenches, FixedBaseWithAWorldFrameWrench) {
  std::mt19937_64 rng(21);
  tree_ref::RandomSettings rs;
  rs.n = 4;
  const Tree t = tree_ref::random_tree(rng, rs);
  std::string text = tree_ref::yaml(t, "loads_fixed", wrench_text(t, true, true));
  const std::size_t from = text.find("group: "), to = text.find("  bodies:\n");
  text.replace(from, to - from, "tree:\n  base: world\n  gravity: [0.7, -1.3, -9.81]\n");
  for (std::size_t at = text.find("parent: base\n"); at != std::string::npos; at = text.find("parent: base\n", at))
    text.replace(at, 13, "parent: world\n");
  const hamel::Model model = hamel::load_model_from_text(text, "loads_fixed.yaml");
  ASSERT_TRUE(model.tree) << text;
  const int n = t.n();
  std::uniform_real_distribution<double> u(-1, 1);
  for (const char* dynamics : {"aba", "ldlt"}) {
    const hamel::Derivation d = hamel::derive(model);
    const hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs", "jacobian"}, {dynamics});
    hamel::GraphEvaluator rhs(k.graph, k.get("rhs").outputs), jac(k.graph, k.get("jacobian").outputs);
    double worst = 0, worst_jac = 0;
    const std::size_t nx = static_cast<std::size_t>(2 * n);
    for (int trial = 0; trial < 6; ++trial) {
      std::vector<double> x(nx), out(nx), in{2 * u(rng), 2 * u(rng)};
      for (double& v : x) v = 1.5 * u(rng);
      rhs.evaluate(0, x.data(), nullptr, in.data(), out.data());
      VX q(n), qd(n);
      for (int i = 0; i < n; ++i) {
        q[i] = x[static_cast<std::size_t>(i)];
        qd[i] = x[static_cast<std::size_t>(n + i)];
      }
      tree_ref::Loads loads;
      loads.gravity = V3(0.7L, -1.3L, -9.81L);
      loads.wrenches = wrenches(t, true, q, qd, in, tree_ref::base_poses(t, q).back().R);
      const VX a = tree_ref::fixed_base_accelerations(t, q, qd, VX::Zero(n), loads);
      std::vector<double> generated(out.begin() + n, out.end()), reference;
      for (int i = 0; i < n; ++i) reference.push_back(static_cast<double>(a[i]));
      worst = std::max(worst, relative(generated, reference));
      std::vector<double> J(nx * nx), fd(nx * nx), fp(nx), fm(nx);
      jac.evaluate(0, x.data(), nullptr, in.data(), J.data());
      for (std::size_t col = 0; col < nx; ++col) {
        std::vector<double> xp = x, xm = x;
        xp[col] += 1e-6;
        xm[col] -= 1e-6;
        rhs.evaluate(0, xp.data(), nullptr, in.data(), fp.data());
        rhs.evaluate(0, xm.data(), nullptr, in.data(), fm.data());
        for (std::size_t r = 0; r < nx; ++r) fd[r * nx + col] = (fp[r] - fm[r]) / 2e-6;
      }
      worst_jac = std::max(worst_jac, relative(J, fd));
    }
    std::printf(
        "fixed base, world-frame wrench, %-4s: q'' vs Newton-Euler %.1e, jacobian vs central differences "
        "%.1e\n",
        dynamics, worst, worst_jac);
    EXPECT_LE(worst, 1e-10) << dynamics;
    EXPECT_LE(worst_jac, 1e-7) << dynamics;
  }
}

}  // namespace
