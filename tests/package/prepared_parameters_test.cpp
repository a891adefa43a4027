// Prepared parameters: the parameter-only work of rhs and jacobian done once per parameter set.
//  - The graph passes on a small program written here: group_invariants, parameter_frontier and substitute
//    leave no operation on parameters alone in the per-call program, and it evaluates to the original;
//    polynomial_form rewrites a quadratic as Σ coefficient · monomial, drops a coefficient that vanishes
//    identically (but not one that only looks small) and leaves non-polynomials and cubics alone.
//  - The satellites with their parameters symbolic: rhs_prepared and jacobian_prepared at P =
//    prepare_parameters(p) equal rhs and jacobian at p, and equal the rhs of a derivation with the same
//    parameter values folded (its mass matrix inverted exactly at generation time: another code path), at
//    random states and parameters away from the defaults; the per-call program is smaller.
//  - The emitted package: a C caller (gcc -std=c11 -Wall -Wextra -Werror -pedantic) of
//    <name>_prepare_parameters and <name>_rhs_prepared against the package compiled with g++ -Werror gives the
//    rhs of <name>_rhs.
#include "package_support.hpp"

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "emit/polynomial_form.hpp"
#include "emit/zero_test.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace hamel::package_test {
namespace {

double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::fabs(a[i] - b[i]));
    scale = std::max(scale, std::fabs(b[i]));
  }
  return diff / std::max(scale, 1e-300);
}

std::vector<double> evaluate(const ExpressionGraph& g, const std::vector<int>& outputs, const std::vector<double>& x,
                             const std::vector<double>& p) {
  std::vector<double> out(outputs.size());
  GraphEvaluator(g, outputs).evaluate(0.0, x.data(), p.data(), nullptr, out.data());
  return out;
}

TEST(PreparedParameters, GraphPassesLeaveNoParameterOnlyOperationPerCall) {
  ExpressionGraph g;
  const int p0 = g.input(Argument::parameter, 0), p1 = g.input(Argument::parameter, 1),
            p2 = g.input(Argument::parameter, 2), p3 = g.input(Argument::parameter, 3);
  const int x0 = g.input(Argument::state, 0), x1 = g.input(Argument::state, 1);
  // (x0·p0)·p1 + x1/(p2 + p3) − sin(p0)·(x0·x1·p3), and p0·p1 as an output of its own.
  const int a = g.binary(Op::mul, g.binary(Op::mul, x0, p0), p1);
  const int b = g.binary(Op::div, x1, g.binary(Op::add, p2, p3));
  const int c = g.binary(Op::mul, g.unary(Op::sin, p0), g.binary(Op::mul, g.binary(Op::mul, x0, x1), p3));
  const std::vector<int> outputs = {g.binary(Op::sub, g.binary(Op::add, a, b), c), g.binary(Op::mul, p0, p1)};

  const std::vector<int> grouped = group_invariants(g, outputs);
  const std::vector<int> frontier = parameter_frontier(g, grouped);
  std::map<int, int> replace;
  for (std::size_t j = 0; j < frontier.size(); ++j)
    replace[frontier[j]] = g.input(Argument::parameter, 4 + static_cast<int>(j));
  const std::vector<int> per_call = substitute(g, grouped, replace);

  // No operation of the per-call program reads parameters (or constants) alone.
  const auto parameter_only = [&](int i) {
    const Node& n = g.node(i);
    return n.op == Op::constant || (n.op == Op::input && n.argument == Argument::parameter);
  };
  int divisions = 0;
  for (int i : g.schedule(per_call)) {
    const Node& n = g.node(i);
    if (n.op == Op::input || n.op == Op::constant) continue;
    EXPECT_FALSE(parameter_only(n.a) && (n.b < 0 || parameter_only(n.b))) << "node " << i;
    divisions += n.op == Op::div;
  }
  EXPECT_EQ(divisions, 0);  // x1/(p2+p3) became x1·(1/(p2+p3)), the reciprocal prepared
  // The second output is parameter-only: prepared whole.
  EXPECT_EQ(g.node(per_call[1]).op, Op::input);

  const std::vector<double> x = {0.7, -1.3}, p = {1.1, 0.4, 2.5, -0.6};
  std::vector<double> P = evaluate(g, frontier, x, p);
  P.insert(P.begin(), p.begin(), p.end());
  const std::vector<double> expected = {0.7 * 1.1 * 0.4 + -1.3 / (2.5 - 0.6) - std::sin(1.1) * 0.7 * -1.3 * -0.6,
                                        1.1 * 0.4};
  EXPECT_LE(relative_difference(evaluate(g, per_call, x, P), expected), 1e-15);
  EXPECT_LE(relative_difference(evaluate(g, outputs, x, p), expected), 1e-15);
}

TEST(PreparedParameters, PolynomialFormDropsIdenticallyZeroCoefficients) {
  ExpressionGraph g;
  const int p0 = g.input(Argument::parameter, 0), p1 = g.input(Argument::parameter, 1);
  const int x0 = g.input(Argument::state, 0), x1 = g.input(Argument::state, 1);
  const auto mul = [&](int a, int b) { return g.binary(Op::mul, a, b); };
  const auto add = [&](int a, int b) { return g.binary(Op::add, a, b); };
  const auto sub = [&](int a, int b) { return g.binary(Op::sub, a, b); };
  // (p0 + p1)(p0 − p1) − (p0² − p1²) is 0 for all parameters; value numbering does not see it.
  const int vanishing = sub(mul(add(p0, p1), sub(p0, p1)), sub(mul(p0, p0), mul(p1, p1)));
  ASSERT_NE(g.node(vanishing).op, Op::constant);
  ZeroTest zero(g);
  EXPECT_TRUE(zero(vanishing));
  EXPECT_FALSE(zero(sub(mul(p0, p0), mul(p1, p1))));
  EXPECT_FALSE(zero(sub(p0, g.binary(Op::div, g.constant(1), g.binary(Op::div, g.constant(1), p1)))));
  EXPECT_FALSE(zero(g.constant(1e-300)));
  EXPECT_FALSE(zero(g.unary(Op::sqrt, vanishing)));  // sqrt is read as a free variable: not shown zero, so kept

  // y = (x0·p0 + x1)·(x1 − x0/p1) + x0·x1·vanishing + 2, a quadratic; sin(x0) and x0³ are not rewritten.
  const int y = add(add(mul(add(mul(x0, p0), x1), sub(x1, g.binary(Op::div, x0, p1))), mul(mul(x0, x1), vanishing)),
                    g.constant(2));
  const int s = g.unary(Op::sin, x0), cubic = mul(mul(x0, x0), mul(x0, p0));
  const std::vector<int> out = polynomial_form(g, {y, s, cubic});
  EXPECT_EQ(out[1], s);
  EXPECT_EQ(out[2], cubic);
  // Terms: x0², x0·x1, x1², 1 — the x0·x1 coefficient p0·1 − 1/p1 + 0 has the vanishing part dropped.
  // The terms of the sum: the leaves of its tree of additions (operands are in structural order, not a chain).
  const std::function<int(int)> terms = [&](int i) {
    return g.node(i).op == Op::add ? terms(g.node(i).a) + terms(g.node(i).b) : 1;
  };
  EXPECT_EQ(terms(out[0]), 4);
  const std::vector<double> x = {0.7, -1.3}, p = {1.1, 0.4};
  const double expected = (0.7 * 1.1 - 1.3) * (-1.3 - 0.7 / 0.4) + 2;
  EXPECT_NEAR(evaluate(g, {out[0]}, x, p)[0], expected, 1e-14);
  EXPECT_NEAR(evaluate(g, {y}, x, p)[0], expected, 1e-14);
}

void check_model(const std::string& file) {
  SCOPED_TRACE(file);
  const Model model = load_model(source(file));
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> state(-0.45, 0.45), scale(0.9, 1.15);
  std::vector<double> p;
  std::map<std::string, double> values;
  for (const auto& par : model.parameters) {
    p.push_back(par.default_value * scale(rng));
    values[par.symbol.get_name()] = p.back();
  }
  const KernelSet kernels = build_kernels(model, derive(model));
  ASSERT_TRUE(kernels.prepared.has_value()) << "no prepared parameters for a constant symbolic mass matrix";
  const KernelSet::Prepared& prepared = *kernels.prepared;
  ASSERT_EQ(prepared.kernels.size(), 2u);
  const ExpressionGraph& g = kernels.graph;
  const int per_call = g.count(g.schedule(prepared.kernels[0].outputs)).total();
  EXPECT_LT(per_call * 3, prepared.rhs.total()) << per_call << " of " << prepared.rhs.total() << " operations left";

  const Model folded_model = fold_parameters(model, values);
  const KernelSet folded = build_kernels(folded_model, derive(folded_model), {"rhs"});

  const int n_x = static_cast<int>(kernels.get("rhs").outputs.size());
  const std::vector<double> P = evaluate(g, prepared.prepare.outputs, std::vector<double>(n_x, 0.0), p);
  ASSERT_EQ(P.size(), static_cast<std::size_t>(prepared.prepare.outputs.size()));
  double worst_prepared = 0, worst_jacobian = 0, worst_folded = 0;
  for (int s = 0; s < 10; ++s) {
    std::vector<double> x(static_cast<std::size_t>(n_x));
    for (double& v : x) v = state(rng);
    const std::vector<double> rhs = evaluate(g, kernels.get("rhs").outputs, x, p);
    worst_prepared = std::max(worst_prepared, relative_difference(evaluate(g, prepared.kernels[0].outputs, x, P), rhs));
    worst_jacobian = std::max(worst_jacobian, relative_difference(evaluate(g, prepared.kernels[1].outputs, x, P),
                                                                  evaluate(g, kernels.get("jacobian").outputs, x, p)));
    worst_folded = std::max(worst_folded, relative_difference(evaluate(g, prepared.kernels[0].outputs, x, P),
                                                              evaluate(folded.graph, folded.get("rhs").outputs, x, p)));
  }
  EXPECT_LE(worst_prepared, 1e-13);
  EXPECT_LE(worst_jacobian, 1e-12);
  EXPECT_LE(worst_folded, 1e-12);
  std::printf("%s: rhs %d -> %d operations per call; prepared vs rhs %.1e, jacobian %.1e, vs folded %.1e\n",
              file.c_str(), prepared.rhs.total(), per_call, worst_prepared, worst_jacobian, worst_folded);
}

TEST(PreparedParameters, SatellitesEqualTheirRhsAndTheFoldedDerivation) {
  check_model("models/satellite_so3xr3.yaml");
  check_model("models/satellite_se3.yaml");
}

TEST(PreparedParameters, NamedAloneTheyAreBuiltWithoutTheirOriginals) {
  const Model model = load_model(source("models/satellite_so3xr3.yaml"));
  const Derivation derivation = derive(model);
  const KernelSet only_jacobian = build_kernels(model, derivation, {"jacobian_prepared"});
  ASSERT_TRUE(only_jacobian.prepared.has_value());
  ASSERT_EQ(only_jacobian.prepared->kernels.size(), 1u);
  EXPECT_EQ(only_jacobian.prepared->kernels[0].name, "jacobian_prepared");
  EXPECT_TRUE(only_jacobian.kernels.empty());  // jacobian itself was not named
  const KernelSet only_rhs = build_kernels(model, derivation, {"rhs_prepared"});
  ASSERT_TRUE(only_rhs.prepared.has_value());
  ASSERT_EQ(only_rhs.prepared->kernels.size(), 1u);
  EXPECT_EQ(only_rhs.prepared->kernels[0].name, "rhs_prepared");
}

TEST(PreparedParameters, FoldedModelsGetNone) {
  const Model model = load_model(source("models/satellite_so3xr3.yaml"));
  std::map<std::string, double> values;
  for (const auto& par : model.parameters) values[par.symbol.get_name()] = par.default_value;
  const Model folded = fold_parameters(model, values);
  EXPECT_FALSE(build_kernels(folded, derive(folded)).prepared.has_value());
}

const char* caller = R"(#include "satellite_so3xr3.h"

#include <stdio.h>

int main(void) {
  double x[SATELLITE_SO3XR3_N_STATE];
  double p[SATELLITE_SO3XR3_N_PARAMETERS];
  double prepared[SATELLITE_SO3XR3_N_PREPARED_PARAMETERS];
  double a[SATELLITE_SO3XR3_N_OUT_RHS], b[SATELLITE_SO3XR3_N_OUT_RHS];
  int i;
  for (i = 0; i < SATELLITE_SO3XR3_N_STATE; ++i) x[i] = 0.1 * (i % 7) - 0.3;
  for (i = 0; i < SATELLITE_SO3XR3_N_PARAMETERS; ++i) p[i] = 0.5 + 0.05 * i;
  satellite_so3xr3_prepare_parameters(p, prepared);
  satellite_so3xr3_rhs_prepared(0.0, x, prepared, NULL, a);
  satellite_so3xr3_rhs(0.0, x, p, NULL, b);
  for (i = 0; i < SATELLITE_SO3XR3_N_OUT_RHS; ++i) printf("%.17g %.17g\n", a[i], b[i]);
  return 0;
}
)";

TEST(PreparedParameters, EmittedCEntryPointsGiveTheRhs) {
  Scratch dir("prepared_parameters");
  std::ofstream(dir.path() / "main.c") << caller;
  const Outcome e = emit(source("models/satellite_so3xr3.yaml"), "", dir.path() / "pkg");
  ASSERT_EQ(e.status, 0) << e.out;
  const std::string header = slurp(dir.path() / "pkg" / "satellite_so3xr3.hpp");
  EXPECT_NE(header.find("constexpr int n_prepared_parameters = "), std::string::npos);
  EXPECT_NE(header.find("void prepare_parameters(const real* p, real* prepared);"), std::string::npos);
  const std::string d = quote(dir.path().string());
  const Outcome cc = run("cd " + d + " && gcc -std=c11 -Wall -Wextra -Werror -pedantic -Ipkg -c main.c -o main.o");
  ASSERT_EQ(cc.status, 0) << cc.out;
  const Outcome cxx = run(
      "cd " + d + " && g++ -std=c++17 -O1 -Wall -Wextra -Werror -pedantic -Ipkg -c pkg/satellite_so3xr3.cpp -o pkg.o");
  ASSERT_EQ(cxx.status, 0) << cxx.out;
  const Outcome link = run("cd " + d + " && g++ main.o pkg.o -o caller -lm && ./caller");
  ASSERT_EQ(link.status, 0) << link.out;
  std::istringstream lines(link.out);
  std::vector<double> a, b;
  double u, v;
  while (lines >> u >> v) {
    a.push_back(u);
    b.push_back(v);
  }
  ASSERT_EQ(a.size(), 12u) << link.out;
  EXPECT_LE(relative_difference(a, b), 1e-13) << link.out;
}

}  // namespace
}  // namespace hamel::package_test
