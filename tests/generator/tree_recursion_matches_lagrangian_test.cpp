// The recursive derivation of kinematic trees (derive/kinematic_tree.cpp: composite inertias and the
// outward/inward recursion of twists and wrenches, through intermediate symbols) against the generator's
// other formulation of the same equations: the tree's kinetic energy inlined into one expression and
// differentiated as a Lagrangian by the one Hamel-equation builder (hamel_equations, eq. HEorig1/2).
// The two derivations share the model loader and the tree's kinetic energy (tree_kinetic_energy, which walks the
// same tree to write ½⟨V, 𝕀V⟩ per body), not the recursion; the kernels of both are built by build_kernels and
// evaluated by the same GraphEvaluator. Compared numerically (GraphEvaluator of the mass_matrix, forcing,
// rhs, jacobian and energy kernels) at random states of random small trees: revolute and prismatic
// joints, rotated joint frames, every base group a tree may have, joint forces and a potential.
#include "derive/derivation.hpp"
#include "derive/kinematic_tree.hpp"
#include "emit/kernels.hpp"
#include "lie/lie_algebra.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>
#include <string>

namespace {

struct Kernels {
  hamel::Model model;
  hamel::Derivation derivation;
  hamel::KernelSet set;
};

std::vector<double> evaluate(const Kernels& k, const std::string& name, const std::vector<double>& x,
                             const std::vector<double>& in) {
  const hamel::Kernel& kernel = k.set.get(name);
  hamel::GraphEvaluator ev(k.set.graph, kernel.outputs);
  std::vector<double> out(kernel.outputs.size());
  ev.evaluate(0.3, x.data(), nullptr, in.empty() ? nullptr : in.data(), out.data());
  return out;
}

// Short decimals: the loader reads them as exact rationals, which keeps the expanded path fast.
std::string number(std::mt19937& rng, double lo, double hi) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << std::uniform_real_distribution<double>(lo, hi)(rng);
  return s.str();
}

int small(std::mt19937& rng) { return std::uniform_int_distribution<int>(-3, 3)(rng); }

// An exact unit vector: inverse stereographic projection of a rational point, (2a, 2b, 1 − a² − b²)/(1 + a² + b²).
std::string unit_axis(std::mt19937& rng) {
  const int a = small(rng), b = small(rng), c = 2;  // (a/c, b/c)
  const int s = c * c + a * a + b * b;
  std::ostringstream o;
  o << "[" << 2 * a * c << "/" << s << ", " << 2 * b * c << "/" << s << ", " << (c * c - a * a - b * b) << "/" << s
    << "]";
  return o.str();
}

// An exact rotation from a quaternion with integer components, R = (1/|q|²)(...).
std::string rotation(std::mt19937& rng) {
  const int w = small(rng) + 4, x = small(rng), y = small(rng), z = small(rng);
  const int s = w * w + x * x + y * y + z * z;
  const int R[3][3] = {{w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)},
                       {2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)},
                       {2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z}};
  std::ostringstream o;
  o << "[";
  for (int r = 0; r < 3; ++r)
    o << (r ? ", " : "") << "[" << R[r][0] << "/" << s << ", " << R[r][1] << "/" << s << ", " << R[r][2] << "/" << s
      << "]";
  return o.str() + "]";
}

std::string inertia(std::mt19937& rng) {
  // S = B Bᵀ + 0.2 1 with B of short decimals is the second moment of some mass distribution; the inertia
  // tr(S) 1 - S of it is positive definite and meets the triangle inequality, as the loader requires.
  double B[3][3];
  for (auto& row : B)
    for (double& v : row) v = std::round(std::uniform_real_distribution<double>(-5, 5)(rng)) / 10;
  std::ostringstream s;
  s << "[";
  for (int r = 0; r < 3; ++r) {
    s << (r ? ", " : "") << "[";
    for (int c = 0; c < 3; ++c) {
      double v = r == c ? 0.2 : 0.0;
      for (int k = 0; k < 3; ++k) v += B[r][k] * B[c][k];
      double trace = 0.6;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) trace += B[i][k] * B[i][k];
      v = (r == c ? trace : 0.0) - v;
      s << (c ? ", " : "") << std::round(v * 100) / 100;
    }
    s << "]";
  }
  return s.str() + "]";
}

std::string random_tree(std::mt19937& rng, const std::string& group, int n, bool forces) {
  static const std::map<std::string, std::string> velocities{
      {"SE3", "[wx, wy, wz, vx, vy, vz]"}, {"SO3", "[wx, wy, wz]"}, {"SE2", "[w, vx, vy]"}, {"R2", "[vx, vy]"}};
  std::ostringstream y;
  y << "name: random_tree\ngroup: " << group << "\ngroup_velocity: " << velocities.at(group)
    << "\nconnection: mechanical\ntree:\n  base: {name: b0, mass: " << number(rng, 1, 5) << ", com: ["
    << number(rng, -0.3, 0.3) << ", " << number(rng, -0.3, 0.3) << ", " << number(rng, -0.3, 0.3)
    << "], inertia: " << inertia(rng) << "}\n  bodies:\n";
  for (int i = 1; i <= n; ++i) {
    const int parent = std::uniform_int_distribution<int>(0, i - 1)(rng);
    const bool prismatic = std::uniform_int_distribution<int>(0, 3)(rng) == 0;
    y << "    - name: b" << i << "\n      parent: b" << parent << "\n      joint: {name: q" << i
      << ", type: " << (prismatic ? "prismatic" : "revolute") << ", axis: " << unit_axis(rng) << ", offset: ["
      << number(rng, -0.5, 0.5) << ", " << number(rng, -0.5, 0.5) << ", " << number(rng, -0.5, 0.5) << "]"
      << (i % 2 ? ", rotation: " + rotation(rng) : "") << "}\n      mass: " << number(rng, 0.5, 3) << "\n      com: ["
      << number(rng, -0.3, 0.3) << ", " << number(rng, -0.3, 0.3) << ", " << number(rng, -0.3, 0.3)
      << "]\n      inertia: " << inertia(rng) << "\n";
  }
  if (forces) {
    y << "inputs: [tau]\nforces: [";
    for (int i = 1; i <= n; ++i) y << (i > 1 ? ", " : "") << "tau*" << i << " - 0.1*q" << i << "_dot";
    y << "]\npotential: 0.5*q1^2 + cos(q1)\n";
  }
  return y.str();
}

// The Euler–Poincaré + Euler–Lagrange system in u = (ξ, ṙ) (HEorig1/2) with the inlined kinetic energy as
// its Lagrangian and γ = c from the group's basis, built here rather than by derive(), whose bundle
// geometry would also invert the shape-dependent locked inertia symbolically (slow and not needed).
Kernels kernels_of(const hamel::Model& model, bool expanded) {
  Kernels k;
  k.model = model;
  if (!expanded) {
    k.derivation = hamel::derive(k.model, hamel::DeriveSettings{"ep"});
  } else {
    const hamel::Bundle& b = *model.bundle;
    hamel::HamelSystem& sys = k.derivation.system;
    sys.coordinates = model.coordinates;
    sys.velocities = b.group_velocity;
    sys.velocities.insert(sys.velocities.end(), model.rates.begin(), model.rates.end());
    const unsigned m = static_cast<unsigned>(b.group_velocity.size()), n = static_cast<unsigned>(model.n());
    sys.B = GiNaC::matrix(n, m + n);
    for (unsigned I = 0; I < n; ++I) sys.B(I, m + I) = 1;
    sys.lagrangian = hamel::tree_kinetic_energy(model) - b.potential;
    sys.forces = model.forces;
    for (const hamel::StructureConstant& c : hamel::structure_constants(hamel::lie_algebra(b.group)))
      sys.gamma.push_back({c.upper, c.lower_a, c.lower_b, c.value});
    k.derivation.equations = hamel::hamel_equations(sys, model.time);
  }
  k.set = hamel::build_kernels(k.model, k.derivation, {"mass_matrix", "forcing", "rhs", "jacobian", "energy"});
  return k;
}

double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0, scale = 1e-300;
  for (std::size_t i = 0; i < a.size(); ++i) scale = std::max(scale, std::abs(b[i]));
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]) / scale);
  return worst;
}

TEST(TreeRecursion, MatchesLagrangianDifferentiationOnRandomTrees) {
  std::mt19937 rng(7);
  std::map<std::string, double> worst;
  for (const std::string group : {"SE3", "SO3", "SE2", "R2"})
    for (int n : {1, 2, 3}) {
      const bool forces = n == 2;
      const std::string text = random_tree(rng, group, n, forces);
      SCOPED_TRACE(text);
      const hamel::Model model = hamel::load_model_from_text(text, "random_tree.yaml");
      const Kernels recursive = kernels_of(model, false), lagrangian = kernels_of(model, true);
      ASSERT_FALSE(recursive.derivation.equations.intermediates.empty());
      ASSERT_TRUE(lagrangian.derivation.equations.intermediates.empty());
      const std::size_t nx =
          recursive.derivation.system.coordinates.size() + recursive.derivation.equations.independent.size();
      for (int trial = 0; trial < 3; ++trial) {
        std::vector<double> x(nx);
        for (double& v : x) v = std::uniform_real_distribution<double>(-2, 2)(rng);
        const std::vector<double> in = forces ? std::vector<double>{0.7} : std::vector<double>{};
        for (const char* kernel : {"mass_matrix", "forcing", "rhs", "jacobian", "energy"}) {
          const double e = relative_difference(evaluate(recursive, kernel, x, in), evaluate(lagrangian, kernel, x, in));
          EXPECT_LT(e, 1e-12) << group << " n=" << n << " kernel " << kernel;
          worst[kernel] = std::max(worst[kernel], e);
        }
      }
    }
  for (const auto& [kernel, e] : worst) std::printf("worst relative difference, %s: %.3g\n", kernel.c_str(), e);
}

}  // namespace
