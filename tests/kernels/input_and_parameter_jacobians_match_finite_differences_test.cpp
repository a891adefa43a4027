// The kernels by inputs and parameters (input_jacobian = d(x')/d(in), parameter_jacobian = d(x')/dp over the
// parameters not folded), emitted, compiled as firmware would compile them and checked against central differences
// of the compiled rhs, which computes u̇ by its own route (the articulated-body algorithm, or an LDLᵀ of M) and no
// derivative: a floating-base tree whose inputs are a body wrench (the quadrotor with its slung load), a fixed-base
// branched arm with every kind of tree parameter (tests/kernels/sensitivity/sensitivity_arm.yaml: masses, centre of
// mass, inertia, offsets, armature, damping, stiffness, spring reference, gravity; inputs in joint forces,
// nonlinearly, and in a wrench; emitted with --jacobian-solve aba: the right sides solved by the articulated-body
// recursion as called functions, while rhs solves with the LDLᵀ of M; split into parts and shared stages),
// a model in general coordinates with a nonholonomic constraint whose kinematics depend on a parameter (the Chaplygin
// sleigh), a bundle model (the snakeboard), a tree with a closed loop whose lengths enter the constraints (the
// four-bar; no inputs) and the double pendulum with g folded (its column left out). At random states, inputs and
// parameters (the defaults scaled by 0.8-1.2), each kernel against its differences. And the arm with --dynamics aba,
// where both kernels take forward mode through rhs (the smaller program), by the generator's evaluation of its graph.
#include "chaplygin_sleigh.hpp"
#include "double_pendulum.hpp"
#include "four_bar_tree.hpp"
#include "quadrotor_slung_load.hpp"
#include "sensitivity_arm.hpp"
#include "snakeboard.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace {

using KernelFn = std::function<void(double, const double*, const double*, const double*, double*)>;

struct Package {
  const char* name;
  int n_state, n_parameters, n_inputs;
  const double* defaults;  ///< default_parameters
  KernelFn rhs;
  KernelFn input_jacobian;  ///< null when the package has none (no inputs)
  int n_out_input_jacobian;
  KernelFn parameter_jacobian;
  int n_out_parameter_jacobian;
  std::vector<int> columns;  ///< parameter_jacobian_parameters
};

// Largest difference between the kernel's n_state x columns output and central differences of rhs by the entries
// `which` of `moved` (p or in; the other arguments held), relative to the largest difference quotient (at least 1).
double worst_against_differences(const Package& pkg, const std::vector<double>& kernel, double t,
                                 const std::vector<double>& x, std::vector<double>& p, std::vector<double>& in,
                                 std::vector<double>& moved, const std::vector<int>& which) {
  const std::size_t nx = static_cast<std::size_t>(pkg.n_state), nc = which.size();
  EXPECT_EQ(kernel.size(), nx * nc);
  double scale = 1, worst = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    double& w = moved[static_cast<std::size_t>(which[c])];
    const double w0 = w, h = 1e-6 * std::max(1.0, std::fabs(w0));
    std::vector<double> fp(nx), fm(nx);
    w = w0 + h;
    pkg.rhs(t, x.data(), p.data(), in.data(), fp.data());
    w = w0 - h;
    pkg.rhs(t, x.data(), p.data(), in.data(), fm.data());
    w = w0;
    for (std::size_t r = 0; r < nx; ++r) {
      const double fd = (fp[r] - fm[r]) / (2 * h);
      scale = std::max(scale, std::fabs(fd));
      worst = std::max(worst, std::fabs(fd - kernel[r * nc + c]));
    }
  }
  return worst / scale;
}

void check(const Package& pkg) {
  SCOPED_TRACE(pkg.name);
  ASSERT_EQ(pkg.n_out_parameter_jacobian, pkg.n_state * static_cast<int>(pkg.columns.size()));
  if (pkg.input_jacobian) {
    ASSERT_EQ(pkg.n_out_input_jacobian, pkg.n_state * pkg.n_inputs);
  }
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> u(-1, 1), scale(0.8, 1.2);
  std::vector<int> inputs(static_cast<std::size_t>(pkg.n_inputs));
  for (int k = 0; k < pkg.n_inputs; ++k) inputs[static_cast<std::size_t>(k)] = k;
  double worst_in = 0, worst_p = 0;
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<double> x(static_cast<std::size_t>(pkg.n_state)), p(static_cast<std::size_t>(pkg.n_parameters) + 1),
        in(static_cast<std::size_t>(pkg.n_inputs) + 1);  // never empty: .data() is then not null
    for (double& v : x) v = 0.8 * u(rng);
    for (int k = 0; k < pkg.n_parameters; ++k) p[static_cast<std::size_t>(k)] = pkg.defaults[k] * scale(rng);
    for (double& v : in) v = u(rng);
    const double t = 0.3 * trial;
    if (pkg.input_jacobian) {
      std::vector<double> B(static_cast<std::size_t>(pkg.n_out_input_jacobian));
      pkg.input_jacobian(t, x.data(), p.data(), in.data(), B.data());
      worst_in = std::max(worst_in, worst_against_differences(pkg, B, t, x, p, in, in, inputs));
    }
    std::vector<double> P(static_cast<std::size_t>(pkg.n_out_parameter_jacobian));
    pkg.parameter_jacobian(t, x.data(), p.data(), in.data(), P.data());
    worst_p = std::max(worst_p, worst_against_differences(pkg, P, t, x, p, in, p, pkg.columns));
  }
  if (pkg.input_jacobian) std::printf("%s: input_jacobian vs central differences of rhs %.1e\n", pkg.name, worst_in);
  std::printf("%s: parameter_jacobian vs central differences of rhs %.1e\n", pkg.name, worst_p);
  // Central differences with h = 1e-6 are good to about 1e-9 relative here; a wrong entry is O(1).
  EXPECT_LE(worst_in, 1e-6);
  EXPECT_LE(worst_p, 1e-6);
}

std::vector<int> all_parameters(int n) {
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) all[static_cast<std::size_t>(k)] = k;
  return all;
}

template <int N>
std::vector<int> columns_of(const int (&columns)[N]) {
  return std::vector<int>(columns, columns + N);
}

// A compiled package, its namespace the model's name; without inputs it has no input_jacobian.
#define PACKAGE(ns, by_inputs, n_out_by_inputs)                                                                      \
  Package {                                                                                                          \
    (#ns), ns::n_state, ns::n_parameters, ns::n_inputs, ns::default_parameters, ns::rhs, by_inputs, n_out_by_inputs, \
        ns::parameter_jacobian, ns::n_out_parameter_jacobian, columns_of(ns::parameter_jacobian_parameters)          \
  }
#define WITH_INPUTS(ns) PACKAGE(ns, ns::input_jacobian, ns::n_out_input_jacobian)
#define WITHOUT_INPUTS(ns) PACKAGE(ns, nullptr, 0)

TEST(InputAndParameterJacobians, FloatingTreeWithAWrenchOfInputsMatchesDifferences) {
  EXPECT_EQ(columns_of(quadrotor_slung_load::parameter_jacobian_parameters),
            all_parameters(quadrotor_slung_load::n_parameters));
  check(WITH_INPUTS(quadrotor_slung_load));
}

TEST(InputAndParameterJacobians, FixedBaseArmWithEveryKindOfTreeParameterMatchesDifferences) {
  check(WITH_INPUTS(sensitivity_arm));
}

TEST(InputAndParameterJacobians, NonholonomicSleighMatchesDifferences) { check(WITH_INPUTS(chaplygin_sleigh)); }

TEST(InputAndParameterJacobians, BundleSnakeboardMatchesDifferences) { check(WITH_INPUTS(snakeboard)); }

TEST(InputAndParameterJacobians, ClosedLoopFourBarParametersMatchDifferences) { check(WITHOUT_INPUTS(four_bar_tree)); }

// Emitted with --fold g: the columns are the other parameters, in file order.
TEST(InputAndParameterJacobians, FoldedParameterHasNoColumn) {
  namespace m = double_pendulum;
  std::vector<int> unfolded;
  for (int k = 0; k < m::n_parameters; ++k)
    if (std::string(m::parameter_names[k]) != "g") unfolded.push_back(k);
  ASSERT_EQ(unfolded.size() + 1, static_cast<std::size_t>(m::n_parameters));
  EXPECT_EQ(columns_of(m::parameter_jacobian_parameters), unfolded);
  check(WITHOUT_INPUTS(double_pendulum));
}

// With the articulated-body algorithm in rhs, the arm's columns by inputs and parameters take forward mode through
// rhs's program (fewer operations than the symbolic route): evaluated by the generator's interpreter of the graph,
// against central differences of its rhs.
TEST(InputAndParameterJacobians, ForwardModeThroughTheArticulatedBodyAlgorithmMatchesDifferences) {
  const hamel::Model model = hamel::load_model(hamel::test::source("tests/kernels/sensitivity/sensitivity_arm.yaml"));
  const hamel::KernelSet k =
      hamel::build_kernels(model, hamel::derive(model), {"rhs", "input_jacobian", "parameter_jacobian"}, {"aba", {}});
  const hamel::Kernel &B = k.get("input_jacobian"), &P = k.get("parameter_jacobian");
  EXPECT_NE(B.summary.find("forward mode"), std::string::npos) << B.summary;
  EXPECT_NE(P.summary.find("forward mode"), std::string::npos) << P.summary;
  hamel::GraphEvaluator rhs(k.graph, k.get("rhs").outputs), by_inputs(k.graph, B.outputs),
      by_parameters(k.graph, P.outputs);
  const auto evaluator = [](hamel::GraphEvaluator& e) {
    return [&e](double t, const double* x, const double* p, const double* in, double* out) {
      e.evaluate(t, x, p, in, out);
    };
  };
  std::vector<double> defaults;
  for (const hamel::Parameter& p : model.parameters) defaults.push_back(p.default_value);
  const int n_state = static_cast<int>(k.get("rhs").outputs.size()), n_p = static_cast<int>(defaults.size());
  const int n_in = static_cast<int>(model.inputs.size());
  check({"sensitivity_arm (aba, forward mode)", n_state, n_p, n_in, defaults.data(), evaluator(rhs),
         evaluator(by_inputs), n_state * n_in, evaluator(by_parameters), n_state * n_p, all_parameters(n_p)});
}

}  // namespace
