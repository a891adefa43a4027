// A jacobian whose solves are printed as one function called per pair of columns (Kernel::calls) against
// computations that do not go through that printing: the generator's own evaluation of the flat program
// (GraphEvaluator over the kernel's outputs, the same solve inline), the columns solved the other way (the LDLᵀ of
// M for a package solved by the articulated-body recursion, and back), and central differences of the compiled
// rhs. Three trees emitted with --jacobian-solve aba --split 40 (the stage and the called solve split into parts
// too): a floating base with two branches and a fixed base under gravity (no base directions), each with
// prismatic joints, armature, damping and a spring, and a planar floating base whose 9 columns do not fill the
// last call (it solves some columns twice). And the shipped space robot, whose default jacobian calls the LDLᵀ's
// substitutions.
#include "calls_fixed.hpp"
#include "calls_floating.hpp"
#include "calls_planar.hpp"
#include "space_robot.hpp"
#include "support/command.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using KernelFn = void (*)(double, const double*, const double*, const double*, double*);

struct Package {
  const char* name;
  std::string yaml;          ///< model file, relative to the source folder
  std::string cpp;           ///< the emitted package's source
  hamel::ColumnSolve solve;  ///< what it was emitted with (--jacobian-solve aba: articulated; default: smaller)
  bool folded;               ///< emitted with --fold all
  int n_state, n_inputs;
  KernelFn rhs, jacobian;
};

using hamel::test::source_dir;

double largest_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double scale = 1, worst = 0;
  for (double v : b) scale = std::max(scale, std::fabs(v));
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::fabs(a[k] - b[k]));
  return worst / scale;
}

void check(const Package& pkg) {
  SCOPED_TRACE(pkg.name);
  const hamel::Model loaded = hamel::load_model(source_dir() + "/" + pkg.yaml);
  std::map<std::string, double> defaults;
  for (const auto& q : loaded.parameters) defaults[q.symbol.get_name()] = q.default_value;
  const hamel::Model model = pkg.folded ? hamel::fold_parameters(loaded, defaults) : loaded;
  std::vector<double> p;  // folded kernels ignore p; the test models have no parameters
  for (const auto& q : loaded.parameters) p.push_back(q.default_value);
  p.push_back(0);  // never empty: p.data() is then not null
  const hamel::Derivation d = hamel::derive(model);
  const std::set<std::string> kernels = {"rhs", "jacobian"};
  const hamel::KernelSet emitted = hamel::build_kernels(model, d, kernels, {"", pkg.solve});
  // The other route: the LDLᵀ of M for a package solved by the recursion, the recursion for one solved by the LDLᵀ.
  const hamel::KernelSet other = hamel::build_kernels(
      model, d, kernels,
      {"", pkg.solve == hamel::ColumnSolve::articulated ? hamel::ColumnSolve::ldlt : hamel::ColumnSolve::articulated});
  // What the package was emitted from: the solve as a subroutine, called for every column (some columns twice
  // when their number is not a multiple of the columns per call).
  const hamel::Kernel& jacobian = emitted.get("jacobian");
  ASSERT_TRUE(jacobian.calls) << "the jacobian is not printed with calls: this test would not test them";
  const std::size_t rows = static_cast<std::size_t>(pkg.n_state) - d.system.coordinates.size();  // of a column b
  const std::size_t per_call = jacobian.calls->calls.front().arguments.size() / rows;
  ASSERT_GE(per_call, 1u);
  ASSERT_EQ(jacobian.calls->calls.size(), (static_cast<std::size_t>(pkg.n_state) + per_call - 1) / per_call);
  {
    std::ifstream file(pkg.cpp);
    std::stringstream text;
    text << file.rdbuf();
    ASSERT_NE(text.str().find("jacobian_column(t, scratch"), std::string::npos) << "emitted without calls: " << pkg.cpp;
  }
  hamel::GraphEvaluator flat(emitted.graph, jacobian.outputs), by_other(other.graph, other.get("jacobian").outputs);

  const std::size_t nx = static_cast<std::size_t>(pkg.n_state), nn = nx * nx;
  std::mt19937 rng(20261125);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_flat = 0, worst_other = 0, worst_fd = 0;
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<double> x(nx), in(static_cast<std::size_t>(pkg.n_inputs));
    for (double& v : x) v = 1.2 * u(rng);
    for (double& v : in) v = u(rng);
    const double t = u(rng);
    std::vector<double> J(nn), J_flat(nn), J_other(nn), J_fd(nn);
    pkg.jacobian(t, x.data(), p.data(), in.data(), J.data());
    flat.evaluate(t, x.data(), p.data(), in.data(), J_flat.data());
    by_other.evaluate(t, x.data(), p.data(), in.data(), J_other.data());
    for (std::size_t k = 0; k < nx; ++k) {
      const double h = 1e-6;
      std::vector<double> plus = x, minus = x, fp(nx), fm(nx);
      plus[k] += h;
      minus[k] -= h;
      pkg.rhs(t, plus.data(), p.data(), in.data(), fp.data());
      pkg.rhs(t, minus.data(), p.data(), in.data(), fm.data());
      for (std::size_t r = 0; r < nx; ++r) J_fd[r * nx + k] = (fp[r] - fm[r]) / (2 * h);
    }
    worst_flat = std::max(worst_flat, largest_difference(J, J_flat));
    worst_other = std::max(worst_other, largest_difference(J, J_other));
    worst_fd = std::max(worst_fd, largest_difference(J, J_fd));
  }
  std::printf(
      "%s: jacobian with calls vs the flat program %.1e, vs the columns solved the other way %.1e, vs central "
      "differences %.1e\n",
      pkg.name, worst_flat, worst_other, worst_fd);
  EXPECT_LE(worst_flat, 1e-12);
  EXPECT_LE(worst_other, 1e-12);
  EXPECT_LE(worst_fd, 1e-7);
}

TEST(JacobianCalls, FloatingBranchedTreeMatchesFlatProgramLdltAndFiniteDifferences) {
  check({"calls_floating", "tests/kernels/calls/calls_floating.yaml",
         std::string(HAMEL_CALLS_DIR) + "/calls_floating/calls_floating.cpp", hamel::ColumnSolve::articulated, false,
         calls_floating::n_state, calls_floating::n_inputs, calls_floating::rhs, calls_floating::jacobian});
}

TEST(JacobianCalls, PlanarBaseWithAnOddNumberOfColumnsMatchesFlatProgramLdltAndFiniteDifferences) {
  ASSERT_EQ(calls_planar::n_state % 2, 1);
  check({"calls_planar", "tests/kernels/calls/calls_planar.yaml",
         std::string(HAMEL_CALLS_DIR) + "/calls_planar/calls_planar.cpp", hamel::ColumnSolve::articulated, false,
         calls_planar::n_state, calls_planar::n_inputs, calls_planar::rhs, calls_planar::jacobian});
}

TEST(JacobianCalls, FixedBaseArmUnderGravityMatchesFlatProgramLdltAndFiniteDifferences) {
  check({"calls_fixed", "tests/kernels/calls/calls_fixed.yaml",
         std::string(HAMEL_CALLS_DIR) + "/calls_fixed/calls_fixed.cpp", hamel::ColumnSolve::articulated, false,
         calls_fixed::n_state, calls_fixed::n_inputs, calls_fixed::rhs, calls_fixed::jacobian});
}

// The shipped space robot's package (tests/kernels, --fold all), whose default jacobian takes the LDLᵀ of M and
// prints its substitutions as calls.
TEST(JacobianCalls, SpaceRobotLdltSubstitutionsMatchFlatProgramRecursionAndFiniteDifferences) {
  check({"space_robot", "models/space_robot.yaml", std::string(HAMEL_KERNELS_DIR) + "/space_robot/space_robot.cpp",
         hamel::ColumnSolve::smaller, true, space_robot::n_state, space_robot::n_inputs, space_robot::rhs,
         space_robot::jacobian});
}

}  // namespace
