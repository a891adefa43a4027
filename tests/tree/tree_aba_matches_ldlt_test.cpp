// `--dynamics aba` (the articulated-body algorithm, rbd/aba.hpp) against two computations that
// do not share its code path:
//  - the M u̇ = f path of the same model (`--dynamics ldlt`: composite inertias, unrolled LDLᵀ), and
//  - the Eigen recursive Newton–Euler reference of tests/tree/tree_reference.hpp (mass matrix from unit
//    accelerations, long double, Eigen's LDLᵀ),
// on random trees: SE(3) bases with n = 1..8, a 12-joint chain and 20 bodies, SE(2), SO(3) and R3 bases,
// prismatic joints, joint forces from inputs, springs and dampers, and a potential; relative error of
// (ξ̇, q̈) ≤ 1e-12 against both. The forward-mode Jacobian (hamel::tangent through the ABA rhs program) is
// checked against central differences of the ldlt rhs and against the `jacobian` kernel of the ldlt path
// (analytical derivatives of the inverse dynamics, rbd/rnea_derivatives.hpp), and so is the aba build's
// kernel (the smaller of the two programs); the analytical kernel also against the chain rule through the
// programs of M and f (the ldlt derivation without its TreeRecursion). Trees on a fixed base
// (`base: world`) under gravity and joints with armature, damping and stiffness (the properties robot files
// give, docs/import.md) go through both paths too, on fixed and floating bases.
#include "tree_from_model.hpp"
#include "tree_reference.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using tree_ref::Real;
using tree_ref::Tree;
using tree_ref::VX;

constexpr double kTolerance = 1e-12;

struct Built {
  hamel::Derivation derivation;
  hamel::KernelSet kernels;
};

Built build(const hamel::Model& model, const std::string& dynamics, const std::set<std::string>& kernels) {
  hamel::Derivation d = hamel::derive(model);
  hamel::KernelSet k = hamel::build_kernels(model, d, kernels, {dynamics});
  return {std::move(d), std::move(k)};
}

// Whether rhs computes u̇ by the articulated-body algorithm (its summary says how).
bool by_recursion(const hamel::KernelSet& k) {
  return k.get("rhs").summary.find("articulated-body algorithm") != std::string::npos;
}

double relative(const std::vector<double>& a, const std::vector<double>& b, std::size_t from) {
  double diff = 0, norm = 0;
  for (std::size_t i = from; i < a.size(); ++i) {
    diff += (a[i] - b[i]) * (a[i] - b[i]);
    norm += b[i] * b[i];
  }
  return std::sqrt(diff / std::max(norm, 1e-300));
}

// Central differences (step 1e-6) of the rhs `f` in the state (`in_inputs` false) or in the inputs at (x, in):
// fd[r · columns + c] = ∂out_r/∂(x or in)_c.
std::vector<double> central_differences(hamel::GraphEvaluator& f, std::size_t rows, const std::vector<double>& x,
                                        const std::vector<double>& p, const std::vector<double>& in,
                                        bool in_inputs = false) {
  const std::size_t columns = in_inputs ? in.size() : x.size();
  const double h = 1e-6;
  std::vector<double> fd(rows * columns), fp(rows), fm(rows);
  for (std::size_t c = 0; c < columns; ++c) {
    std::vector<double> xp = x, xm = x, ip = in, im = in;
    (in_inputs ? ip : xp)[c] += h;
    (in_inputs ? im : xm)[c] -= h;
    f.evaluate(0, xp.data(), p.data(), ip.data(), fp.data());
    f.evaluate(0, xm.data(), p.data(), im.data(), fm.data());
    for (std::size_t r = 0; r < rows; ++r) fd[r * columns + c] = (fp[r] - fm[r]) / (2 * h);
  }
  return fd;
}

// Joint forces of `extra` (see the TEST below) as the reference computes them.
VX joint_forces(int n, bool forced, bool potential, const VX& q, const VX& qd, const std::vector<double>& in) {
  VX f = VX::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (forced) f[i] += in[static_cast<std::size_t>(i)] - 0.5L * q[i] - 0.1L * qd[i];
    if (potential) f[i] -= 0.3L * (i + 1) * q[i];
  }
  if (potential) f[0] += 0.2L * std::sin(static_cast<Real>(q[0]));
  return f;
}

void check(std::uint64_t seed, tree_ref::RandomSettings rs, bool forced = false, bool potential = false,
           bool jacobian = false, bool all_prismatic = false) {
  std::mt19937_64 rng(seed);
  Tree t = tree_ref::random_tree(rng, rs);
  for (tree_ref::Body& b : t.bodies) b.prismatic = b.prismatic || all_prismatic;
  const int n = t.n(), m = static_cast<int>(tree_ref::basis(t.group).cols());
  std::string extra;
  if (forced) {
    std::string forces = "forces: [", inputs = "inputs: [";
    for (int i = 1; i <= n; ++i) {
      const std::string k = std::to_string(i);
      forces += std::string(i > 1 ? ", " : "") + "\"u" + k + " - 0.5*q" + k + " - 0.1*q" + k + "_dot\"";
      inputs += std::string(i > 1 ? ", " : "") + "u" + k;
    }
    extra += forces + "]\n" + inputs + "]\n";
  }
  if (potential) {
    extra += "potential: \"0.2*cos(q1)";
    for (int i = 1; i <= n; ++i) extra += " + " + tree_ref::number_text(0.3 * i) + "*q" + std::to_string(i) + "^2/2";
    extra += "\"\n";
  }
  const std::string name = "aba_" + rs.group + "_" + std::to_string(n) + "_" + std::to_string(seed);
  const hamel::Model model = hamel::load_model_from_text(tree_ref::yaml(t, name, extra, false), name + ".yaml");
  std::set<std::string> kernels = {"rhs"};
  if (jacobian) kernels.insert({"jacobian", "linearization"});
  const Built aba = build(model, "aba", kernels), ldlt = build(model, "ldlt", kernels);
  ASSERT_TRUE(by_recursion(aba.kernels)) << name;
  ASSERT_FALSE(by_recursion(ldlt.kernels)) << name;
  // The ldlt build's Jacobian takes ∂ID/∂x analytically (rbd/rnea_derivatives.hpp); without the recursion
  // it falls back to the chain rule through the programs of M and f (every M_IJ differentiated).
  hamel::Derivation without_recursion = ldlt.derivation;
  without_recursion.equations.tree.reset();
  const hamel::KernelSet chain_rule =
      jacobian ? hamel::build_kernels(model, without_recursion, kernels) : hamel::KernelSet{};
  // The analytical columns solved with the articulated-body recursion instead of the LDLᵀ of M (the default
  // keeps whichever is smaller; small trees keep the LDLᵀ).
  const hamel::KernelSet recursive =
      jacobian ? hamel::build_kernels(model, ldlt.derivation, kernels, {"ldlt", hamel::ColumnSolve::articulated})
               : hamel::KernelSet{};
  const std::size_t nx = static_cast<std::size_t>(2 * n + m);
  hamel::GraphEvaluator fa(aba.kernels.graph, aba.kernels.get("rhs").outputs);
  hamel::GraphEvaluator fl(ldlt.kernels.graph, ldlt.kernels.get("rhs").outputs);
  const std::vector<double> p = tree_ref::default_parameters(model);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_ldlt = 0, worst_ref = 0, worst_fd = 0, worst_sym = 0, worst_kernel = 0, worst_chain = 0,
         worst_recursive = 0, worst_linearization = 0, worst_inputs = 0;
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<double> x(nx), in(forced ? static_cast<std::size_t>(n) : 0), a(nx), l(nx);
    for (int i = 0; i < n; ++i)
      x[static_cast<std::size_t>(i)] = t.bodies[static_cast<std::size_t>(i)].prismatic ? 0.5 * u(rng) : M_PI * u(rng);
    for (std::size_t i = static_cast<std::size_t>(n); i < nx; ++i) x[i] = 2 * u(rng);
    for (double& v : in) v = 5 * u(rng);
    fa.evaluate(0, x.data(), p.data(), in.data(), a.data());
    fl.evaluate(0, x.data(), p.data(), in.data(), l.data());
    worst_ldlt = std::max(worst_ldlt, relative(a, l, static_cast<std::size_t>(n)));
    VX q(n), xi(m), qd(n);
    for (int i = 0; i < n; ++i) q[i] = x[static_cast<std::size_t>(i)], qd[i] = x[static_cast<std::size_t>(n + m + i)];
    for (int i = 0; i < m; ++i) xi[i] = x[static_cast<std::size_t>(n + i)];
    const VX r = tree_ref::accelerations(t, q, xi, qd, joint_forces(n, forced, potential, q, qd, in));
    std::vector<double> ref(a.begin(), a.begin() + n);
    for (int i = 0; i < m + n; ++i) ref.push_back(static_cast<double>(r[i]));
    worst_ref = std::max(worst_ref, relative(a, ref, static_cast<std::size_t>(n)));
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i)
      EXPECT_EQ(a[i], x[static_cast<std::size_t>(n + m) + i]);
    if (!jacobian) continue;
    // The forward-mode Jacobian itself (hamel::tangent on the ABA rhs program), whichever of the two
    // programs build_kernels kept for the `jacobian` kernel.
    hamel::ExpressionGraph graph = aba.kernels.graph;
    std::vector<int> forward(nx * nx);
    for (std::size_t c = 0; c < nx; ++c) {
      const std::vector<int> column =
          hamel::tangent(graph, aba.kernels.get("rhs").outputs,
                         {{graph.input(hamel::Argument::state, static_cast<int>(c)), graph.constant(1)}});
      for (std::size_t r = 0; r < nx; ++r) forward[r * nx + c] = column[r];
    }
    hamel::GraphEvaluator ja(graph, forward), jk(aba.kernels.graph, aba.kernels.get("jacobian").outputs);
    std::vector<double> Jk(nx * nx);
    jk.evaluate(0, x.data(), p.data(), in.data(), Jk.data());
    hamel::GraphEvaluator jl(ldlt.kernels.graph, ldlt.kernels.get("jacobian").outputs);
    hamel::GraphEvaluator jc(chain_rule.graph, chain_rule.get("jacobian").outputs);
    std::vector<double> Jc(nx * nx), Jr(nx * nx);
    jc.evaluate(0, x.data(), p.data(), in.data(), Jc.data());
    hamel::GraphEvaluator(recursive.graph, recursive.get("jacobian").outputs)
        .evaluate(0, x.data(), p.data(), in.data(), Jr.data());
    std::vector<double> J(nx * nx), Js(nx * nx);
    ja.evaluate(0, x.data(), p.data(), in.data(), J.data());
    jl.evaluate(0, x.data(), p.data(), in.data(), Js.data());
    const std::vector<double> fd = central_differences(fl, nx, x, p, in);  // of the other path's rhs
    worst_fd = std::max(worst_fd, relative(J, fd, 0));
    worst_sym = std::max(worst_sym, relative(J, Js, 0));
    worst_kernel = std::max(worst_kernel, relative(Jk, Js, 0));
    worst_chain = std::max(worst_chain, relative(Js, Jc, 0));
    worst_recursive = std::max(worst_recursive, relative(Jr, J, 0));
    // linearization = (A, B): A shares the analytical columns; B (forward mode over the inputs) against
    // central differences of the ldlt rhs in the inputs.
    const std::size_t ni = in.size();
    hamel::GraphEvaluator lin(ldlt.kernels.graph, ldlt.kernels.get("linearization").outputs);
    std::vector<double> AB(nx * nx + nx * ni);
    lin.evaluate(0, x.data(), p.data(), in.data(), AB.data());
    const std::vector<double> A(AB.begin(), AB.begin() + static_cast<std::ptrdiff_t>(nx * nx));
    worst_linearization = std::max(worst_linearization, relative(A, J, 0));
    const std::vector<double> B(AB.begin() + static_cast<std::ptrdiff_t>(nx * nx), AB.end());
    const std::vector<double> fdB = central_differences(fl, nx, x, p, in, true);
    if (ni > 0) worst_inputs = std::max(worst_inputs, relative(B, fdB, 0));
  }
  std::printf("%-22s n = %2d: aba vs ldlt %.1e, vs Newton-Euler %.1e", name.c_str(), n, worst_ldlt, worst_ref);
  if (jacobian)
    std::printf(
        "; forward-mode jacobian vs central differences %.1e, vs analytical %.1e; kernel %.1e; "
        "analytical vs chain rule %.1e; solved by the recursion %.1e; linearization A %.1e, B vs central "
        "differences %.1e",
        worst_fd, worst_sym, worst_kernel, worst_chain, worst_recursive, worst_linearization, worst_inputs);
  std::printf("\n");
  EXPECT_LE(worst_ldlt, kTolerance) << name;
  EXPECT_LE(worst_ref, kTolerance) << name;
  if (jacobian) {
    EXPECT_LE(worst_fd, 1e-7) << name;  // central differences: O(h²) plus rounding/h
    EXPECT_LE(worst_sym, 1e-11) << name;
    EXPECT_LE(worst_kernel, 1e-11) << name;
    EXPECT_LE(worst_chain, 1e-11) << name;
    EXPECT_LE(worst_recursive, 1e-11) << name;
    EXPECT_LE(worst_linearization, 1e-11) << name;
    EXPECT_LE(worst_inputs, 1e-7) << name;
  }
}

// The random tree of `seed` with joint armature, damping, stiffness and reference on every joint, and, with
// `fixed`, hung from the world under gravity instead of floating on an SE(3) base: aba against ldlt (the path
// tests/import checks against MuJoCo), and the forward-mode Jacobian of the aba program against central
// differences of the ldlt rhs.
void check_joint_properties(std::uint64_t seed, int n, bool fixed) {
  std::mt19937_64 rng(seed);
  tree_ref::RandomSettings rs;
  rs.n = n;
  const Tree t = tree_ref::random_tree(rng, rs);
  const std::string name =
      std::string(fixed ? "aba_fixed_" : "aba_props_") + std::to_string(n) + "_" + std::to_string(seed);
  std::string text = tree_ref::yaml(t, name, "", false);
  auto replace_all = [&](const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  if (fixed) {  // drop the group and the base body: the world carries the tree, gravity along a tilted axis
    const std::size_t from = text.find("group: "), to = text.find("  bodies:\n");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(to, std::string::npos);
    text.replace(from, to - from, "tree:\n  base: world\n  gravity: [0.7, -1.3, -9.81]\n");
    replace_all("parent: base\n", "parent: world\n");
  }
  // Joint properties after each joint's offset, different per joint (some zero).
  std::size_t joint = 0;
  for (std::size_t at = text.find("        offset: "); at != std::string::npos;
       at = text.find("        offset: ", at + 1), ++joint) {
    const std::size_t end = text.find('\n', at) + 1;
    const double k = static_cast<double>(joint);
    const std::string properties = "        armature: " + tree_ref::number_text(0.05 + 0.1 * k) +
                                   "\n        damping: " + tree_ref::number_text(joint % 3 == 2 ? 0 : 0.2 + 0.05 * k) +
                                   "\n        stiffness: " + tree_ref::number_text(joint % 2 ? 0 : 1.5 + k) +
                                   "\n        reference: " + tree_ref::number_text(0.1 * k - 0.2) + "\n";
    text.insert(end, properties);
  }
  const hamel::Model model = hamel::load_model_from_text(text, name + ".yaml");
  ASSERT_EQ(static_cast<bool>(model.tree), fixed) << text;
  const int m = fixed ? 0 : 6;
  const std::set<std::string> kernels = {"rhs", "energy", "jacobian"};
  const Built aba = build(model, "aba", kernels), ldlt = build(model, "ldlt", kernels);
  ASSERT_TRUE(by_recursion(aba.kernels)) << name;
  ASSERT_FALSE(by_recursion(ldlt.kernels)) << name;
  const std::size_t nx = static_cast<std::size_t>(2 * n + m);
  hamel::GraphEvaluator fa(aba.kernels.graph, aba.kernels.get("rhs").outputs);
  hamel::GraphEvaluator fl(ldlt.kernels.graph, ldlt.kernels.get("rhs").outputs);
  hamel::ExpressionGraph graph = aba.kernels.graph;
  std::vector<int> forward(nx * nx);
  for (std::size_t c = 0; c < nx; ++c) {
    const std::vector<int> column =
        hamel::tangent(graph, aba.kernels.get("rhs").outputs,
                       {{graph.input(hamel::Argument::state, static_cast<int>(c)), graph.constant(1)}});
    for (std::size_t r = 0; r < nx; ++r) forward[r * nx + c] = column[r];
  }
  hamel::GraphEvaluator ja(graph, forward), jk(ldlt.kernels.graph, ldlt.kernels.get("jacobian").outputs);
  const hamel::KernelSet recursive =
      hamel::build_kernels(model, aba.derivation, kernels, {"aba", hamel::ColumnSolve::articulated});
  hamel::GraphEvaluator jr(recursive.graph, recursive.get("jacobian").outputs);
  const std::vector<double> p = tree_ref::default_parameters(model);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_ldlt = 0, worst_fd = 0, worst_analytical = 0, worst_recursive = 0;
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<double> x(nx), a(nx), l(nx), J(nx * nx);
    for (std::size_t i = 0; i < nx; ++i) x[i] = (i < static_cast<std::size_t>(n) ? 2.0 : 1.5) * u(rng);
    fa.evaluate(0, x.data(), p.data(), nullptr, a.data());
    fl.evaluate(0, x.data(), p.data(), nullptr, l.data());
    worst_ldlt = std::max(worst_ldlt, relative(a, l, static_cast<std::size_t>(n)));
    ja.evaluate(0, x.data(), p.data(), nullptr, J.data());
    const std::vector<double> fd = central_differences(fl, nx, x, p, {});
    worst_fd = std::max(worst_fd, relative(J, fd, 0));
    std::vector<double> Jk(nx * nx);  // the kernel: analytical ∂ID/∂x (gravity, armature, springs, dampers)
    jk.evaluate(0, x.data(), p.data(), nullptr, Jk.data());
    worst_analytical = std::max(worst_analytical, relative(Jk, J, 0));
    jr.evaluate(0, x.data(), p.data(), nullptr, Jk.data());  // columns solved by the articulated recursion
    worst_recursive = std::max(worst_recursive, relative(Jk, J, 0));
  }
  std::printf(
      "%-22s n = %2d: aba vs ldlt %.1e; forward-mode jacobian vs central differences %.1e, vs analytical "
      "kernel %.1e, solved by the recursion %.1e\n",
      name.c_str(), n, worst_ldlt, worst_fd, worst_analytical, worst_recursive);
  EXPECT_LE(worst_ldlt, kTolerance) << name;
  EXPECT_LE(worst_fd, 1e-7) << name;
  EXPECT_LE(worst_analytical, 1e-11) << name;
  EXPECT_LE(worst_recursive, 1e-11) << name;
}

TEST(ArticulatedBodyAlgorithm, FixedBaseUnderGravityWithArmatureDampingStiffness) {
  for (int n : {1, 2, 5, 9}) check_joint_properties(900 + static_cast<std::uint64_t>(n), n, true);
}

TEST(ArticulatedBodyAlgorithm, FloatingBaseWithArmatureDampingStiffness) {
  for (int n : {1, 4, 7}) check_joint_properties(950 + static_cast<std::uint64_t>(n), n, false);
}

TEST(ArticulatedBodyAlgorithm, RandomSpatialTreesOneToEightBodies) {
  for (int n = 1; n <= 8; ++n)
    for (std::uint64_t seed : {10u, 20u}) {
      tree_ref::RandomSettings rs;
      rs.n = n;
      check(seed + static_cast<std::uint64_t>(n), rs);
    }
}

TEST(ArticulatedBodyAlgorithm, ChainOfTwelveAndTreeOfTwenty) {
  tree_ref::RandomSettings chain;
  chain.n = 12;
  chain.chain = true;
  check(1212, chain);
  tree_ref::RandomSettings tree;
  tree.n = 20;
  check(2020, tree);
}

TEST(ArticulatedBodyAlgorithm, PlanarRotatingAndTranslatingBases) {
  for (const char* group : {"SE2", "SO3", "R3"})
    for (int n : {1, 3, 6}) {
      tree_ref::RandomSettings rs;
      rs.group = group;
      rs.n = n;
      check(300 + static_cast<std::uint64_t>(n), rs);
    }
}

TEST(ArticulatedBodyAlgorithm, PrismaticOnlyJoints) {
  tree_ref::RandomSettings rs;
  rs.n = 5;
  check(55, rs, false, false, false, true);
}

TEST(ArticulatedBodyAlgorithm, JointForcesAndPotential) {
  tree_ref::RandomSettings rs;
  rs.n = 5;
  check(61, rs, true, false);
  check(62, rs, false, true);
  check(63, rs, true, true);
}

TEST(ArticulatedBodyAlgorithm, ForwardModeJacobian) {
  for (int n : {1, 3, 6}) {
    tree_ref::RandomSettings rs;
    rs.n = n;
    check(700 + static_cast<std::uint64_t>(n), rs, true, true, true);
  }
  tree_ref::RandomSettings planar;
  planar.group = "SE2";
  planar.n = 4;
  check(740, planar, false, true, true);
}

// The analytical ∂ID/∂x on every kind of base and joint: rotating-only and translating-only bases (their
// directions are not all of se(3)), prismatic joints, and a chain deep enough that most pairs of joints are
// ancestor and descendant.
TEST(ArticulatedBodyAlgorithm, AnalyticalJacobianOnEveryBaseAndJointKind) {
  for (const char* group : {"SO3", "R3"}) {
    tree_ref::RandomSettings rs;
    rs.group = group;
    rs.n = 3;
    check(810, rs, true, false, true);
  }
  tree_ref::RandomSettings prismatic;
  prismatic.n = 4;
  check(820, prismatic, true, true, true, true);
  tree_ref::RandomSettings chain;
  chain.n = 9;
  chain.chain = true;
  check(830, chain, true, true, true);
}

// A chain long enough that the default solves the Jacobian's columns by the articulated-body recursion (its
// L is dense, so the LDLᵀ substitutions cost more): the kernel against central differences of rhs and against
// the same columns solved with the LDLᵀ of M.
TEST(ArticulatedBodyAlgorithm, LongChainJacobianSolvedByTheRecursion) {
  std::mt19937_64 rng(1616);
  tree_ref::RandomSettings rs;
  rs.n = 16;
  rs.chain = true;
  const Tree t = tree_ref::random_tree(rng, rs);
  const hamel::Model model = hamel::load_model_from_text(tree_ref::yaml(t, "long_chain", "", false), "long_chain.yaml");
  const std::set<std::string> kernels = {"rhs", "jacobian"};
  const Built built = build(model, "aba", kernels);
  const hamel::Kernel& kernel = built.kernels.get("jacobian");
  EXPECT_NE(kernel.summary.find("articulated-body recursion"), std::string::npos) << kernel.summary;
  const hamel::KernelSet by_ldlt =
      hamel::build_kernels(model, built.derivation, kernels, {"aba", hamel::ColumnSolve::ldlt});
  EXPECT_EQ(by_ldlt.get("jacobian").summary.find("articulated-body recursion"), std::string::npos);
  const std::size_t nx = 2 * 16 + 6;
  hamel::GraphEvaluator f(built.kernels.graph, built.kernels.get("rhs").outputs),
      jk(built.kernels.graph, kernel.outputs), jl(by_ldlt.graph, by_ldlt.get("jacobian").outputs);
  const std::vector<double> p = tree_ref::default_parameters(model);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_fd = 0, worst_ldlt = 0;
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> x(nx), J(nx * nx), Jl(nx * nx);
    for (std::size_t i = 0; i < nx; ++i) x[i] = (i < 16 ? M_PI : 2.0) * u(rng);
    jk.evaluate(0, x.data(), p.data(), nullptr, J.data());
    jl.evaluate(0, x.data(), p.data(), nullptr, Jl.data());
    const std::vector<double> fd = central_differences(f, nx, x, p, {});
    worst_fd = std::max(worst_fd, relative(J, fd, 0));
    worst_ldlt = std::max(worst_ldlt, relative(J, Jl, 0));
  }
  std::printf(
      "16-joint chain: jacobian (columns by the recursion) vs central differences %.1e, vs LDL^T columns %.1e\n",
      worst_fd, worst_ldlt);
  EXPECT_LE(worst_fd, 1e-7);
  EXPECT_LE(worst_ldlt, 1e-11);
}

}  // namespace
