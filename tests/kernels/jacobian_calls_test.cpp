// A jacobian printed as one solve called per column (Kernel::calls: emit --jacobian-solve aba on a kinematic
// tree) against computations that do not go through that printing: the generator's own evaluation of the flat
// program (GraphEvaluator over the kernel's outputs, the same recursion inline), the columns solved by the
// LDLᵀ of M instead, and central differences of the compiled rhs. Two trees: a floating base with two branches
// and a fixed base under gravity (no base directions), each with prismatic joints, armature, damping and a
// spring, emitted with --split 40 so that the stage and the called solve are split into parts as well.
#include "calls_fixed.hpp"
#include "calls_floating.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using KernelFn = void (*)(double, const double*, const double*, const double*, double*);

struct Package {
  const char* name;
  int n_state, n_inputs;
  KernelFn rhs, jacobian;
};

std::string source_dir() {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return dir ? dir : HAMEL_SOURCE_DIR_DEFAULT;
}

double largest_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double scale = 1, worst = 0;
  for (double v : b) scale = std::max(scale, std::fabs(v));
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::fabs(a[k] - b[k]));
  return worst / scale;
}

void check(const Package& pkg) {
  SCOPED_TRACE(pkg.name);
  const std::string yaml = source_dir() + "/tests/kernels/calls/" + pkg.name + ".yaml";
  const hamel::Model model = hamel::load_model(yaml);
  const hamel::Derivation d = hamel::derive(model);
  const std::set<std::string> kernels = {"rhs", "jacobian"};
  const hamel::KernelSet recursion = hamel::build_kernels(model, d, kernels, hamel::ColumnSolve::articulated);
  const hamel::KernelSet ldlt = hamel::build_kernels(model, d, kernels, hamel::ColumnSolve::ldlt);
  // What the package was emitted from: the recursion as a subroutine, one call per state component.
  const hamel::Kernel& jacobian = recursion.get("jacobian");
  ASSERT_TRUE(jacobian.calls) << "the jacobian is not printed with calls: this test would not test them";
  ASSERT_EQ(jacobian.calls->calls.size(), static_cast<std::size_t>(pkg.n_state));
  ASSERT_FALSE(ldlt.get("jacobian").calls);
  {
    std::ifstream emitted(std::string(HAMEL_CALLS_DIR) + "/" + pkg.name + "/" + pkg.name + ".cpp");
    std::stringstream text;
    text << emitted.rdbuf();
    ASSERT_NE(text.str().find("jacobian_column(t, scratch"), std::string::npos) << "emitted without calls";
  }
  hamel::GraphEvaluator flat(recursion.graph, jacobian.outputs), by_ldlt(ldlt.graph, ldlt.get("jacobian").outputs);

  const std::size_t nx = static_cast<std::size_t>(pkg.n_state), nn = nx * nx;
  std::mt19937 rng(20261125);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_flat = 0, worst_ldlt = 0, worst_fd = 0;
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<double> x(nx), in(static_cast<std::size_t>(pkg.n_inputs));
    for (double& v : x) v = 1.2 * u(rng);
    for (double& v : in) v = u(rng);
    const double t = u(rng);
    std::vector<double> J(nn), J_flat(nn), J_ldlt(nn), J_fd(nn);
    pkg.jacobian(t, x.data(), nullptr, in.data(), J.data());
    flat.evaluate(t, x.data(), nullptr, in.data(), J_flat.data());
    by_ldlt.evaluate(t, x.data(), nullptr, in.data(), J_ldlt.data());
    for (std::size_t k = 0; k < nx; ++k) {
      const double h = 1e-6;
      std::vector<double> plus = x, minus = x, fp(nx), fm(nx);
      plus[k] += h;
      minus[k] -= h;
      pkg.rhs(t, plus.data(), nullptr, in.data(), fp.data());
      pkg.rhs(t, minus.data(), nullptr, in.data(), fm.data());
      for (std::size_t r = 0; r < nx; ++r) J_fd[r * nx + k] = (fp[r] - fm[r]) / (2 * h);
    }
    worst_flat = std::max(worst_flat, largest_difference(J, J_flat));
    worst_ldlt = std::max(worst_ldlt, largest_difference(J, J_ldlt));
    worst_fd = std::max(worst_fd, largest_difference(J, J_fd));
  }
  std::printf("%s: jacobian with calls vs the flat program %.1e, vs the LDL^T columns %.1e, vs central differences "
              "%.1e\n",
              pkg.name, worst_flat, worst_ldlt, worst_fd);
  EXPECT_LE(worst_flat, 1e-12);
  EXPECT_LE(worst_ldlt, 1e-12);
  EXPECT_LE(worst_fd, 1e-7);
}

TEST(JacobianCalls, FloatingBranchedTreeMatchesFlatProgramLdltAndFiniteDifferences) {
  check({"calls_floating", calls_floating::n_state, calls_floating::n_inputs, calls_floating::rhs, calls_floating::jacobian});
}

TEST(JacobianCalls, FixedBaseArmUnderGravityMatchesFlatProgramLdltAndFiniteDifferences) {
  check({"calls_fixed", calls_fixed::n_state, calls_fixed::n_inputs, calls_fixed::rhs, calls_fixed::jacobian});
}

}  // namespace
