// The accelerations of tree models from the generated `rhs` kernel (default form ep: Euler–Poincaré for the
// base, Euler–Lagrange for the joints; evaluated with GraphEvaluator) agree with a recursive Newton–Euler
// computation written for this test (tree_reference.hpp: Eigen, long double, body-frame spatial vectors,
// mass matrix from unit accelerations, projection on the group's basis):
//  - the reference itself is first checked against the conservation laws it must satisfy (energy, power of
//    the joint forces, the base's Euler–Poincaré equation from the momentum ∂T/∂V_0 by finite differences);
//  - random trees (random parents, revolute and prismatic joints, random unit axes and joint rotations as
//    exact rationals, offsets, masses, centres of mass, positive definite inertias), written as YAML text
//    from the same numbers and loaded with load_model_from_text: SE(3) bases with n = 1..8 bodies (three
//    trees each), n = 15 and 20, a serial chain of 12, SE(2) bases (planar trees), an SO(3) base (origin
//    fixed) and an R3 base (translation); with joint forces from inputs, springs, dampers and the base velocity, with a
//    potential, and with the masses as parameters;
//  - models/space_robot.yaml (with joint torques), models/planar_swimmer.yaml and
//    models/satellite_se3_tree.yaml, whose reference trees are the loaded files' tree data at the default
//    parameters; and satellite_se3_tree against the hand-written models/satellite_se3.yaml (both ep).
// x = (q, ξ, q̇), rhs = (q̇, ξ̇, q̈); the relative error |a_gen − a_ref| / |a_ref| of (ξ̇, q̈) must be ≤ 1e-10 at
// every random state.
#include "tree_from_model.hpp"
#include "tree_reference.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using tree_ref::Real;
using tree_ref::Tree;
using tree_ref::V6;
using tree_ref::VX;

constexpr double kTolerance = 1e-10;
constexpr int kStates = 10;

std::string model_path(const std::string& name) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/models/" + name + ".yaml";
}

/// Joint forces Q(q, ξ, q̇, inputs) as the reference computes them.
using Forces = std::function<VX(const VX& q, const VX& xi, const VX& qd, const std::vector<double>& in)>;

VX no_forces(const VX& q, const VX&, const VX&, const std::vector<double>&) { return VX::Zero(q.size()); }

struct State {
  VX q, xi, qd;
  std::vector<double> in;
};

State random_state(std::mt19937_64& rng, const Tree& t, int n_inputs) {
  std::uniform_real_distribution<double> u(-1, 1);
  const int m = static_cast<int>(tree_ref::basis(t.group).cols());
  State s{VX(t.n()), VX(m), VX(t.n()), {}};
  for (int i = 0; i < t.n(); ++i) {
    s.q[i] = t.bodies[static_cast<std::size_t>(i)].prismatic ? 0.5 * u(rng) : M_PI * u(rng);
    s.qd[i] = 2 * u(rng);
  }
  for (int a = 0; a < m; ++a) s.xi[a] = u(rng);
  for (int k = 0; k < n_inputs; ++k) s.in.push_back(5 * u(rng));
  return s;
}

// ---------------------------------------------------------------------------------------------------
// The reference against conservation laws (no generator involved).

VX reference_rhs(const Tree& t, const VX& x, const VX& Q) {
  const int n = t.n(), m = static_cast<int>(x.size()) - 2 * n;
  VX f(x.size());
  f.head(n) = x.tail(n);
  f.tail(m + n) = tree_ref::accelerations(t, x.head(n), x.segment(n, m), x.tail(n), Q);
  return f;
}

TEST(NewtonEulerReference, ConservesEnergyAndSatisfiesTheBaseEulerPoincareEquation) {
  std::mt19937_64 rng(7);
  for (int n : {1, 3, 6}) {
    tree_ref::RandomSettings rs;
    rs.n = n;
    const Tree t = tree_ref::random_tree(rng, rs);
    const State s = random_state(rng, t, 0);
    VX x(2 * n + 6);
    x << s.q, s.xi, s.qd;
    // ½ νᵀ H ν is the kinetic energy.
    VX nu(6 + n);
    nu << s.xi, s.qd;
    const Real T = tree_ref::kinetic_energy(t, s.q, s.xi, s.qd);
    EXPECT_LT(std::fabs(nu.dot(tree_ref::mass_matrix(t, s.q) * nu) / 2 - T) / T, 1e-15L);
    // Along the flow: dT/dt = Q·q̇ and ḣ − ad_{V0}ᵀ h = 0 (h = ∂T/∂V_0), by central differences.
    VX Q(n);
    for (int i = 0; i < n; ++i) Q[i] = std::sin(1.0 + i);
    const VX f = reference_rhs(t, x, Q);
    const Real eps = 1e-6L;
    const VX xp = x + eps * f, xm = x - eps * f;
    auto energy = [&](const VX& y) { return tree_ref::kinetic_energy(t, y.head(n), y.segment(n, 6), y.tail(n)); };
    auto momentum = [&](const VX& y) { return tree_ref::body_momentum(t, y.head(n), y.segment(n, 6), y.tail(n)); };
    const Real dT = (energy(xp) - energy(xm)) / (2 * eps);
    EXPECT_LT(std::fabs(dT - Q.dot(s.qd)) / T, 1e-9L) << "n = " << n;
    const V6 h = momentum(x);
    const V6 dh = (momentum(xp) - momentum(xm)) / (2 * eps);
    const V6 ep = dh - tree_ref::ad(s.xi.head<6>()).transpose() * h;
    EXPECT_LT(ep.norm() / h.norm(), 1e-9L) << "n = " << n;
    std::printf("reference n = %d: |dT/dt - Q.qdot|/T = %.1Le, |h' - ad*h|/|h| = %.1Le\n", n,
                std::fabs(dT - Q.dot(s.qd)) / T, ep.norm() / h.norm());
  }
}

// ---------------------------------------------------------------------------------------------------
// Generated kernels against the reference.

struct Generated {
  hamel::Model model;
  hamel::Derivation derivation;
  hamel::KernelSet kernels;
};

std::unique_ptr<Generated> generate(hamel::Model model) {
  const auto start = std::chrono::steady_clock::now();
  hamel::Derivation d = hamel::derive(model);
  hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs"});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("  %s: derived and built in %.2f s\n", model.name.c_str(), seconds);
  return std::unique_ptr<Generated>(new Generated{std::move(model), std::move(d), std::move(k)});
}

/// Largest relative error of (ξ̇, q̈) over kStates random states.
double worst_error(const std::string& what, const Tree& t, Generated& g, const std::vector<double>& p, int n_inputs,
                   const Forces& forces, std::mt19937_64& rng) {
  const int n = t.n(), m = static_cast<int>(tree_ref::basis(t.group).cols());
  const std::vector<int>& outputs = g.kernels.get("rhs").outputs;
  EXPECT_EQ(static_cast<int>(outputs.size()), 2 * n + m) << what;
  EXPECT_EQ(static_cast<int>(g.model.coordinates.size()), n) << what;
  EXPECT_EQ(static_cast<int>(g.model.inputs.size()), n_inputs) << what;
  if (static_cast<int>(outputs.size()) != 2 * n + m) return INFINITY;
  hamel::GraphEvaluator rhs(g.kernels.graph, outputs);
  double worst = 0;
  for (int k = 0; k < kStates; ++k) {
    const State s = random_state(rng, t, n_inputs);
    std::vector<double> x;
    for (const VX* v : {&s.q, &s.xi, &s.qd})
      for (int i = 0; i < v->size(); ++i) x.push_back(static_cast<double>((*v)[i]));
    std::vector<double> out(x.size());
    rhs.evaluate(0.0, x.data(), p.data(), s.in.data(), out.data());
    for (int i = 0; i < n; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)], x[static_cast<std::size_t>(n + m + i)]);
    const VX a = tree_ref::accelerations(t, s.q, s.xi, s.qd, forces(s.q, s.xi, s.qd, s.in));
    Real diff = 0, norm = 0;
    for (int i = 0; i < m + n; ++i) {
      const Real e = static_cast<Real>(out[static_cast<std::size_t>(n + i)]) - a[i];
      diff += e * e;
      norm += a[i] * a[i];
    }
    const double err = static_cast<double>(std::sqrt(diff / norm));
    if (!(err <= kTolerance)) {
      std::printf("  %s, state %d: relative error %.3e\n    generated:", what.c_str(), k, err);
      for (int i = 0; i < m + n; ++i) std::printf(" %.15g", out[static_cast<std::size_t>(n + i)]);
      std::printf("\n    reference:");
      for (int i = 0; i < m + n; ++i) std::printf(" %.15Lg", a[i]);
      std::printf("\n");
    }
    worst = std::max(worst, std::isnan(err) ? INFINITY : err);
  }
  std::printf("%-40s n = %2d  max relative error of (xi', q'') over %d states: %.2e\n", what.c_str(), n, kStates,
              worst);
  return worst;
}

/// Joints of each kind that the random trees so far contained.
struct Kinds {
  int revolute = 0, prismatic = 0, rotated = 0, on_base = 0, deeper = 0;
} kinds;

double check_random(std::uint64_t seed, const tree_ref::RandomSettings& rs, const std::string& extra = "",
                    int n_inputs = 0, const Forces& forces = no_forces, bool mass_parameters = false) {
  std::mt19937_64 rng(seed);
  const Tree t = tree_ref::random_tree(rng, rs);
  for (const tree_ref::Body& b : t.bodies) {
    ++(b.prismatic ? kinds.prismatic : kinds.revolute);
    kinds.rotated += b.has_rotation;
    ++(b.parent < 0 ? kinds.on_base : kinds.deeper);
  }
  const std::string name = "random_" + rs.group + "_" + std::to_string(rs.n) + "_" + std::to_string(seed);
  const std::string text = tree_ref::yaml(t, name, extra, mass_parameters);
  std::unique_ptr<Generated> g;
  try {
    g = generate(hamel::load_model_from_text(text, name + ".yaml"));
  } catch (const std::exception& e) {
    ADD_FAILURE() << name << ": " << e.what() << "\n" << text;
    return INFINITY;
  }
  const std::vector<double> p = tree_ref::default_parameters(g->model);
  const double err = worst_error(name, t, *g, p, n_inputs, forces, rng);
  EXPECT_LE(err, kTolerance) << text;
  return err;
}

TEST(TreeAccelerations, RandomSpatialTreesOneToEightBodies) {
  kinds = Kinds{};
  for (int n = 1; n <= 8; ++n)
    for (std::uint64_t seed : {100u, 200u, 300u}) {
      tree_ref::RandomSettings rs;
      rs.n = n;
      check_random(seed + static_cast<std::uint64_t>(n), rs);
    }
  std::printf("joints: %d revolute, %d prismatic, %d with a rotation; %d on the base, %d on other bodies\n",
              kinds.revolute, kinds.prismatic, kinds.rotated, kinds.on_base, kinds.deeper);
  EXPECT_GT(kinds.prismatic, 10);
  EXPECT_GT(kinds.rotated, 10);
  EXPECT_GT(kinds.deeper, 10);
}

TEST(TreeAccelerations, RandomSpatialTreesOfFifteenAndTwentyBodies) {
  for (int n : {15, 20}) {
    tree_ref::RandomSettings rs;
    rs.n = n;
    check_random(1000 + static_cast<std::uint64_t>(n), rs);
  }
}

TEST(TreeAccelerations, RandomSerialChainOfTwelveBodies) {
  tree_ref::RandomSettings rs;
  rs.n = 12;
  rs.chain = true;
  check_random(1112, rs);
}

TEST(TreeAccelerations, RandomSpatialTreeWithoutJointRotationsOrPrismaticJoints) {
  tree_ref::RandomSettings rs;
  rs.n = 5;
  rs.rotations = false;
  rs.prismatic = false;
  check_random(301, rs);
}

// Q_i = u_i − k_i q_i − c_i q̇_i (+ 0.2 ξ_1 on joint 1): inputs, springs, dampers and the base velocity.
TEST(TreeAccelerations, JointForcesFromInputsSpringsAndDampers) {
  const int n = 5;
  std::string forces = "forces: [", inputs = "inputs: [";
  for (int i = 1; i <= n; ++i) {
    const std::string k = std::to_string(i);
    forces += std::string(i > 1 ? ", " : "") + "\"u" + k + " - " + tree_ref::number_text(0.5 + 0.25 * i) + "*q" + k +
              " - " + tree_ref::number_text(0.1 * i) + "*q" + k + "_dot" + (i == 1 ? " + 0.2*wx" : "") + "\"";
    inputs += std::string(i > 1 ? ", " : "") + "u" + k;
  }
  const Forces Q = [](const VX& q, const VX& xi, const VX& qd, const std::vector<double>& in) {
    VX f(q.size());
    for (int i = 0; i < q.size(); ++i)
      f[i] = in[static_cast<std::size_t>(i)] - (0.5L + 0.25L * (i + 1)) * q[i] - 0.1L * (i + 1) * qd[i];
    f[0] += 0.2L * xi[0];
    return f;
  };
  tree_ref::RandomSettings rs;
  rs.n = n;
  check_random(401, rs, forces + "]\n" + inputs + "]\n", n, Q);
}

// V = Σ k_i q_i² / 2 + 0.3 cos q_1: Q_i = −k_i q_i + 0.3 sin q_1 δ_i1.
TEST(TreeAccelerations, Potential) {
  const int n = 4;
  std::string V = "potential: \"0.3*cos(q1)";
  for (int i = 1; i <= n; ++i) V += " + " + tree_ref::number_text(0.5 * i) + "*q" + std::to_string(i) + "^2/2";
  const Forces Q = [](const VX& q, const VX&, const VX&, const std::vector<double>&) {
    VX f(q.size());
    for (int i = 0; i < q.size(); ++i) f[i] = -0.5L * (i + 1) * q[i];
    f[0] += 0.3L * std::sin(q[0]);
    return f;
  };
  tree_ref::RandomSettings rs;
  rs.n = n;
  check_random(501, rs, V + "\"\n", 0, Q);
}

TEST(TreeAccelerations, MassesAsParameters) {
  tree_ref::RandomSettings rs;
  rs.n = 4;
  check_random(601, rs, "", 0, no_forces, true);
}

TEST(TreeAccelerations, RandomPlanarTrees) {
  for (int n : {1, 2, 3, 5, 8}) {
    tree_ref::RandomSettings rs;
    rs.group = "SE2";
    rs.n = n;
    check_random(700 + static_cast<std::uint64_t>(n), rs);
  }
}

TEST(TreeAccelerations, RandomTreeOnARotatingBaseWithFixedOrigin) {
  tree_ref::RandomSettings rs;
  rs.group = "SO3";
  rs.n = 4;
  check_random(801, rs);
}

TEST(TreeAccelerations, RandomTreeOnATranslatingBase) {
  tree_ref::RandomSettings rs;
  rs.group = "R3";
  rs.n = 4;
  check_random(901, rs);
}

double check_file(const std::string& name, std::uint64_t seed) {
  const hamel::Model model = hamel::load_model(model_path(name));
  const Tree t = tree_ref::tree_of(model);
  const int n_inputs = static_cast<int>(model.inputs.size());
  // The files with inputs map input k to joint k: Q = τ.
  if (n_inputs > 0) {
    EXPECT_EQ(n_inputs, t.n());
  }
  const Forces tau = [](const VX& q, const VX&, const VX&, const std::vector<double>& in) {
    VX f = VX::Zero(q.size());
    for (std::size_t i = 0; i < in.size(); ++i) f[static_cast<int>(i)] = in[i];
    return f;
  };
  std::unique_ptr<Generated> g = generate(model);
  std::mt19937_64 rng(seed);
  return worst_error(name, t, *g, tree_ref::default_parameters(model), n_inputs, tau, rng);
}

TEST(TreeAccelerations, SpaceRobot) { EXPECT_LE(check_file("space_robot", 11), kTolerance); }

TEST(TreeAccelerations, PlanarSwimmer) { EXPECT_LE(check_file("planar_swimmer", 12), kTolerance); }

TEST(TreeAccelerations, SatelliteAsTree) { EXPECT_LE(check_file("satellite_se3_tree", 13), kTolerance); }

// The same satellite as a tree and as the hand-written bundle model (its bodies' twists written out in
// models/satellite_se3.yaml), both in the ep form with the parameters folded: the same state derivative.
TEST(TreeAccelerations, SatelliteAsTreeEqualsHandWrittenBundleModel) {
  // Folded at the defaults (the hand-written model's ep derivation is slow with symbolic parameters).
  auto folded = [](const std::string& name) {
    const hamel::Model raw = hamel::load_model(model_path(name));
    std::map<std::string, double> values;
    for (const auto& q : raw.parameters) values[q.symbol.get_name()] = q.default_value;
    return hamel::fold_parameters(raw, values);
  };
  const hamel::Model hand = folded("satellite_se3"), tree = folded("satellite_se3_tree");
  const hamel::Derivation dh = hamel::derive(hand, hamel::DeriveSettings{"ep"});
  const hamel::Derivation dt = hamel::derive(tree, hamel::DeriveSettings{"ep"});
  const hamel::KernelSet kh = hamel::build_kernels(hand, dh, {"rhs"}), kt = hamel::build_kernels(tree, dt, {"rhs"});
  hamel::GraphEvaluator fh(kh.graph, kh.get("rhs").outputs), ft(kt.graph, kt.get("rhs").outputs);
  ASSERT_EQ(kh.get("rhs").outputs.size(), 12u);  // (φ, ξ, φ̇)
  ASSERT_EQ(kt.get("rhs").outputs.size(), 12u);
  const std::vector<double> p = tree_ref::default_parameters(hand);
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (int k = 0; k < kStates; ++k) {
    std::vector<double> x(12), a(12), b(12);
    for (double& v : x) v = 3 * u(rng);
    fh.evaluate(0.0, x.data(), p.data(), nullptr, a.data());
    ft.evaluate(0.0, x.data(), p.data(), nullptr, b.data());
    double diff = 0, norm = 0;
    for (std::size_t i = 3; i < 12; ++i) {
      diff += (a[i] - b[i]) * (a[i] - b[i]);
      norm += a[i] * a[i];
    }
    worst = std::max(worst, std::sqrt(diff / norm));
  }
  std::printf("satellite_se3 (hand-written) vs satellite_se3_tree, ep rhs: max relative difference %.2e\n", worst);
  EXPECT_LE(worst, kTolerance);
}

}  // namespace
