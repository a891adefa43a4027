// emit/zero_test: values that vanish identically are found (trigonometric identities included), values that do not
// are kept, and the kernels print such values as 0 — checked against finite differences of the rhs, which do not
// pass through the test.
#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "emit/zero_test.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace hamel;

using hamel::test::source_dir;

struct Builder {
  ExpressionGraph g;
  int add(int a, int b) { return g.binary(Op::add, a, b); }
  int sub(int a, int b) { return g.binary(Op::sub, a, b); }
  int mul(int a, int b) { return g.binary(Op::mul, a, b); }
  int div(int a, int b) { return g.binary(Op::div, a, b); }
  int sin(int a) { return g.unary(Op::sin, a); }
  int cos(int a) { return g.unary(Op::cos, a); }
  int c(double v) { return g.constant(v); }
};

TEST(ZeroTest, FindsTrigonometricIdentitiesInEveryKindOfArgument) {
  Builder b;
  const int x = b.g.input(Argument::state, 0), y = b.g.input(Argument::parameter, 2);
  const int t = b.g.input(Argument::time, 0), u = b.g.input(Argument::input, 1);
  ZeroTest zero(b.g);
  // sin² + cos² − 1, of an argument that is itself a sum
  const int s = b.sin(b.add(x, u)), co = b.cos(b.add(x, u));
  EXPECT_TRUE(zero(b.sub(b.add(b.mul(s, s), b.mul(co, co)), b.c(1))));
  // sin 2x − 2 sin x cos x
  EXPECT_TRUE(zero(b.sub(b.sin(b.mul(b.c(2), x)), b.mul(b.c(2), b.mul(b.sin(x), b.cos(x))))));
  // cos(x − y) − (cos x cos y + sin x sin y)
  EXPECT_TRUE(zero(b.sub(b.cos(b.sub(x, y)), b.add(b.mul(b.cos(x), b.cos(y)), b.mul(b.sin(x), b.sin(y))))));
  // tan t − sin t / cos t
  EXPECT_TRUE(zero(b.sub(b.g.unary(Op::tan, t), b.div(b.sin(t), b.cos(t)))));
  // (x + y)(x − y) − (x² − y²), with a double that is an exact rational: (0.1 x)·10 is not x in doubles
  EXPECT_TRUE(zero(b.sub(b.mul(b.add(x, y), b.sub(x, y)), b.sub(b.mul(x, x), b.mul(y, y)))));
  EXPECT_FALSE(zero(b.sub(b.mul(b.mul(b.c(0.1), x), b.c(10)), x)));

  // Values that do not vanish are kept.
  EXPECT_FALSE(zero(b.sub(b.sin(x), x)));
  EXPECT_FALSE(zero(b.sub(b.mul(b.sin(x), b.sin(x)), b.sin(x))));
  EXPECT_FALSE(zero(b.sub(b.cos(b.mul(b.c(2), x)), b.c(1))));
  EXPECT_FALSE(zero(b.sub(b.sin(x), b.sin(y))));
  EXPECT_FALSE(zero(b.mul(t, u)));
  EXPECT_FALSE(zero(b.c(1e-300)));
  // Other functions are free variables: relations through them are not used, so the test misses such a zero
  // rather than inventing one (√x · √x − x), and a division by a vanishing value is not decided.
  const int r = b.g.unary(Op::sqrt, x);
  EXPECT_FALSE(zero(b.sub(b.mul(r, r), x)));
  const int vanishing = b.sub(b.mul(b.add(x, y), b.sub(x, y)), b.sub(b.mul(x, x), b.mul(y, y)));
  EXPECT_FALSE(zero(b.div(b.c(1), vanishing)));
  EXPECT_TRUE(zero(b.mul(b.g.unary(Op::exp, x), vanishing)));
}

TEST(ZeroTest, VanishingWorkIsRemovedAndTheRestComputesTheSame) {
  Builder b;
  const int x0 = b.g.input(Argument::state, 0), x1 = b.g.input(Argument::state, 1);
  const int p0 = b.g.input(Argument::parameter, 0);
  const int s = b.sin(x0), c = b.cos(x0);
  const int vanishing = b.sub(b.add(b.mul(s, s), b.mul(c, c)), b.c(1));
  // y0 = x1·p0 + exp(x1)·vanishing, y1 = vanishing / p0 − 0·x0, y2 = sin x0 (kept as it is)
  const int y0 = b.add(b.mul(x1, p0), b.mul(b.g.unary(Op::exp, x1), vanishing));
  const int y1 = b.div(vanishing, p0);
  const std::vector<int> before{y0, y1, s};
  const std::vector<int> after = without_identical_zeros(b.g, before);
  EXPECT_EQ(after[0], b.mul(x1, p0));
  EXPECT_TRUE(b.g.is_constant(after[1], 0));
  EXPECT_EQ(after[2], s);
  EXPECT_LT(b.g.count(b.g.schedule(after)).total(), b.g.count(b.g.schedule(before)).total());
  GraphEvaluator old_program(b.g, before), new_program(b.g, after);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-2, 2);
  for (int trial = 0; trial < 10; ++trial) {
    const double x[2] = {uniform(rng), uniform(rng)}, p[1] = {uniform(rng)};
    double o[3], n[3];
    old_program.evaluate(0, x, p, nullptr, o);
    new_program.evaluate(0, x, p, nullptr, n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], o[k], 1e-12 * (1 + std::fabs(o[k])));
  }
}

// The heavy symmetric top does not depend on its spin angle c (the top is axisymmetric): the derivation reads c
// through the body's rotation, and the Jacobian's column of c differentiates through all of it. Its acceleration
// rows are printed as 0, and central differences of rhs, which know nothing of the test, agree.
TEST(ZeroTest, TheColumnOfACyclicCoordinateIsPrintedAsZero) {
  const Model model = load_model(source_dir() + "/models/heavy_top.yaml");
  const KernelSet k = build_kernels(model, derive(model));
  const Kernel& jacobian = k.get("jacobian");
  const std::size_t n = k.get("rhs").outputs.size();
  ASSERT_EQ(n, 6u);
  const std::size_t c = 2;  // coordinates a, b, c
  for (std::size_t row = 3; row < n; ++row)
    EXPECT_TRUE(k.graph.is_constant(jacobian.outputs[row * n + c], 0)) << jacobian.output_names[row * n + c];
  EXPECT_FALSE(k.graph.is_constant(jacobian.outputs[3 * n + 0], 0));  // ∂wa'/∂a: gravity

  std::vector<double> p;
  for (const auto& q : model.parameters) p.push_back(q.default_value);
  GraphEvaluator rhs(k.graph, k.get("rhs").outputs);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<double> x(n), fp(n), fm(n);
    for (double& v : x) v = uniform(rng);
    const double h = 1e-5;
    std::vector<double> xp = x, xm = x;
    xp[c] += h;
    xm[c] -= h;
    rhs.evaluate(0, xp.data(), p.data(), nullptr, fp.data());
    rhs.evaluate(0, xm.data(), p.data(), nullptr, fm.data());
    for (std::size_t row = 3; row < n; ++row) EXPECT_NEAR((fp[row] - fm[row]) / (2 * h), 0.0, 1e-8) << row;
  }
}

}  // namespace
