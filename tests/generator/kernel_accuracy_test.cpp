// Kernel forward error: the 50-digit evaluators against values known exactly, and the
// double kernels of several models against their expressions in 50 digits (numeric/kernel_accuracy.hpp).
#include "numeric/kernel_accuracy.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace {

using GiNaC::numeric;

using hamel::test::source_dir;

// |a − b| < 10^-exponent, in the current precision.
bool close(const numeric& a, const numeric& b, int exponent) {
  return GiNaC::abs(a - b) < GiNaC::pow(numeric(10), numeric(-exponent));
}

TEST(HighPrecision, DoublesConvertExactly) {
  EXPECT_EQ(hamel::exact_rational(0.1), numeric(3602879701896397) / numeric(36028797018963968LL));
  EXPECT_EQ(hamel::exact_rational(-0.75), numeric(-3, 4));
  EXPECT_EQ(hamel::exact_rational(std::ldexp(1.0, -1074)), GiNaC::pow(numeric(2), numeric(-1074)));
  EXPECT_EQ(hamel::ulp_of(1.0), std::ldexp(1.0, -52));
  EXPECT_EQ(hamel::ulp_of(0.0), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(hamel::ulp_error(std::nextafter(1.0, 2.0), 1, 0), 1.0);
  EXPECT_EQ(hamel::ulp_error(-3.0, -3, 0), 0.0);
  EXPECT_TRUE(std::isinf(hamel::ulp_error(std::nan(""), 1, 0)));
  // Below the floor, errors count in ulps of the floor.
  EXPECT_EQ(hamel::ulp_error(std::ldexp(1.0, -60), 0, 1.0), std::ldexp(1.0, -8));
}

// A graph whose double evaluation is 100 % wrong and whose exact value is known: (1 + x)² − 1 − 2x = x².
TEST(HighPrecision, GraphEvaluatorIsExactWhereDoublesCancel) {
  hamel::ExpressionGraph g;
  const int x = g.input(hamel::Argument::state, 0);
  const int s = g.binary(hamel::Op::add, g.constant(1), x);
  const int cancel = g.binary(hamel::Op::sub, g.binary(hamel::Op::sub, g.binary(hamel::Op::mul, s, s), g.constant(1)),
                              g.binary(hamel::Op::mul, g.constant(2), x));
  // π = 4 atan(1), √2 · √2 − 2 = 0, exp(log 3) = 3, sin² + cos² = 1 at an argument of 1e5.
  const int pi =
      g.binary(hamel::Op::mul, g.constant(4), g.unary(hamel::Op::atan, g.input(hamel::Argument::parameter, 1)));
  const int root = g.unary(hamel::Op::sqrt, g.input(hamel::Argument::parameter, 0));
  const int zero =
      g.binary(hamel::Op::sub, g.binary(hamel::Op::mul, root, root), g.input(hamel::Argument::parameter, 0));
  const int three = g.unary(hamel::Op::exp, g.unary(hamel::Op::log, g.input(hamel::Argument::input, 0)));
  const int big = g.input(hamel::Argument::time, 0);
  const int sn = g.unary(hamel::Op::sin, big), cs = g.unary(hamel::Op::cos, big);
  const int one = g.binary(hamel::Op::add, g.binary(hamel::Op::mul, sn, sn), g.binary(hamel::Op::mul, cs, cs));
  const int power = g.binary(hamel::Op::pow, g.input(hamel::Argument::parameter, 0), g.constant(1.5));
  const std::vector<int> outputs{cancel, pi, zero, three, one, power};

  const double xv = std::ldexp(1.0, -30), p[] = {2.0, 1.0}, in = 3.0, t = 1e5;
  hamel::HighPrecisionGraphEvaluator slow(g, outputs);
  const hamel::DigitsGuard digits(50);
  const std::vector<numeric> v = slow.evaluate(t, &xv, p, &in);
  ASSERT_EQ(v.size(), outputs.size());
  EXPECT_TRUE(close(v[0], GiNaC::pow(numeric(2), numeric(-60)), 100));  // exact: 1 + 2^-29 + 2^-60 has 61 bits
  EXPECT_TRUE(close(v[1], GiNaC::ex_to<numeric>(GiNaC::Pi.evalf()), 48));
  EXPECT_TRUE(close(v[2], 0, 48));
  EXPECT_TRUE(close(v[3], 3, 47));
  EXPECT_TRUE(close(v[4], 1, 47));
  EXPECT_TRUE(close(v[5], GiNaC::ex_to<numeric>(GiNaC::ex(GiNaC::sqrt(GiNaC::ex(8))).evalf()), 47));

  // The double evaluation of the same graph: the cancellation loses everything.
  hamel::GraphEvaluator fast(g, outputs);
  std::vector<double> d(outputs.size());
  fast.evaluate(t, &xv, p, &in, d.data());
  EXPECT_EQ(d[0], 0.0);
  EXPECT_GT(hamel::ulp_error(d[0], v[0], 0), 1e15);
  EXPECT_LE(hamel::ulp_error(d[1], v[1], 0), 1.0);  // π from the double atan: within an ulp
}

TEST(HighPrecision, ExpressionEvaluatorKnowsPiAndIdentities) {
  GiNaC::symbol x("x"), y("y");
  hamel::HighPrecisionExpressionEvaluator e;
  e.assign({{x, numeric(7, 10)}, {y, numeric(2)}});
  const hamel::DigitsGuard digits(50);
  EXPECT_TRUE(close(e.value(GiNaC::pow(GiNaC::sin(x), 2) + GiNaC::pow(GiNaC::cos(x), 2)), 1, 48));
  EXPECT_TRUE(close(e.value(GiNaC::pow(y, GiNaC::numeric(1, 2)) * GiNaC::sqrt(y)), 2, 48));
  EXPECT_TRUE(close(e.value(GiNaC::Pi / 4 - GiNaC::atan(GiNaC::ex(1))), 0, 48));
  EXPECT_TRUE(close(e.value(GiNaC::exp(GiNaC::log(y))), 2, 48));
  EXPECT_TRUE(close(e.value(GiNaC::ex(1) / 3 + x), numeric(31, 30), 48));
  // magnitude: the terms of a sum in absolute value.
  EXPECT_TRUE(close(e.magnitude(x - y), numeric(27, 10), 48));
  EXPECT_THROW(e.value(x / (y - 2)), std::domain_error);
}

// The expression evaluator compiles an expression once and re-evaluates it per set of values: a second set must
// give the second set's values (not the first's, cached), and intermediates count through their definitions. The
// reference is GiNaC's own evalf of the fully inlined expression, which shares no code with the evaluator.
TEST(HighPrecision, ExpressionEvaluatorFollowsNewValuesAndIntermediates) {
  GiNaC::symbol x("x"), y("y");
  hamel::Intermediates tape;
  const GiNaC::ex s = tape.define(GiNaC::sin(x) * y + 1);
  const GiNaC::ex u = tape.define(GiNaC::pow(s, 3) - x / s);
  const GiNaC::ex e = u * s + GiNaC::cos(u);
  hamel::HighPrecisionExpressionEvaluator ev;
  ev.define(tape);
  const hamel::DigitsGuard digits(50);
  for (const auto& [xv, yv] : {std::pair{numeric(7, 10), numeric(2)}, std::pair{numeric(-3, 2), numeric(5, 4)}}) {
    ev.assign({{x, xv}, {y, yv}});
    const numeric want = GiNaC::ex_to<numeric>(tape.inline_all(e).subs(GiNaC::lst{x == xv, y == yv}).evalf());
    EXPECT_TRUE(close(ev.value(e), want, 45)) << ev.value(e) << " against " << want;
  }
}

// Intermediates::diff for many variables at once (partials formed once) against GiNaC's derivative of the fully
// inlined expression.
TEST(HighPrecision, ChainRuleThroughIntermediatesMatchesInlinedDerivative) {
  GiNaC::symbol x("x"), y("y"), z("z");
  hamel::Intermediates tape;
  const GiNaC::ex a = tape.define(x * y + GiNaC::sin(z));
  const GiNaC::ex b = tape.define(GiNaC::pow(a, 2) * x - GiNaC::exp(y));
  const GiNaC::ex e = a * b + GiNaC::cos(b) * z;
  const std::vector<GiNaC::symbol> vars{x, y, z};
  const std::vector<GiNaC::ex> d = tape.diff(e, vars);
  ASSERT_EQ(d.size(), vars.size());
  hamel::HighPrecisionExpressionEvaluator ev;
  ev.define(tape);
  const hamel::DigitsGuard digits(50);
  const GiNaC::lst at{x == numeric(3, 10), y == numeric(-7, 10), z == numeric(11, 10)};
  ev.assign({{x, numeric(3, 10)}, {y, numeric(-7, 10)}, {z, numeric(11, 10)}});
  for (std::size_t k = 0; k < vars.size(); ++k) {
    const numeric want = GiNaC::ex_to<numeric>(tape.inline_all(e).diff(vars[k]).subs(at).evalf());
    EXPECT_TRUE(close(ev.value(d[k]), want, 45)) << vars[k];
    EXPECT_TRUE(close(ev.value(tape.diff(e, vars[k])), want, 45)) << vars[k];
  }
}

// evaluate_moved re-evaluates only what depends on one argument; its outputs must equal a fresh evaluator's whole
// evaluation at the moved arguments, bit for bit, and leave the evaluator at its last evaluate()'s values, also
// after a move that hits a pole.
TEST(HighPrecision, MovedArgumentEqualsAWholeEvaluation) {
  hamel::ExpressionGraph g;
  const int x0 = g.input(hamel::Argument::state, 0), x1 = g.input(hamel::Argument::state, 1);
  const int t = g.input(hamel::Argument::time, 0), in = g.input(hamel::Argument::input, 0);
  const int a = g.binary(hamel::Op::mul, g.unary(hamel::Op::sin, x0), x1);
  const int b = g.binary(hamel::Op::add, a, g.unary(hamel::Op::log, in));
  const int c = g.binary(hamel::Op::div, g.unary(hamel::Op::cos, t), x1);
  const std::vector<int> outputs{a, b, c, g.binary(hamel::Op::mul, b, c)};
  const hamel::DigitsGuard digits(50);
  const numeric T = hamel::high_precision(0.25), IN = hamel::high_precision(3.0);
  const std::vector<numeric> X{hamel::high_precision(0.5), hamel::high_precision(-1.25)}, P;
  hamel::HighPrecisionGraphEvaluator moved(g, outputs);
  const std::vector<numeric> base = moved.evaluate(T, X, P, {IN});
  const auto whole = [&](numeric t_, std::vector<numeric> x_, numeric in_) {
    hamel::HighPrecisionGraphEvaluator fresh(g, outputs);
    return fresh.evaluate(t_, x_, P, {in_});
  };
  const numeric v = hamel::high_precision(0.75);
  EXPECT_EQ(moved.evaluate_moved(hamel::Argument::state, 0, v), whole(T, {v, X[1]}, IN));
  EXPECT_EQ(moved.evaluate_moved(hamel::Argument::state, 1, v), whole(T, {X[0], v}, IN));
  EXPECT_EQ(moved.evaluate_moved(hamel::Argument::time, 0, v), whole(v, X, IN));
  EXPECT_THROW(moved.evaluate_moved(hamel::Argument::state, 1, 0), std::domain_error);  // c = cos t / 0
  EXPECT_EQ(moved.evaluate_moved(hamel::Argument::input, 0, v), whole(T, X, v));
  EXPECT_NE(moved.evaluate_moved(hamel::Argument::input, 0, v), base);
  EXPECT_EQ(moved.evaluate_moved(hamel::Argument::state, 0, X[0]), base);  // nothing left moved
}

struct Measured {
  std::vector<hamel::KernelAccuracy> kernels;
  const hamel::KernelAccuracy& get(const std::string& name) const {
    for (const auto& k : kernels)
      if (k.kernel == name) return k;
    throw std::logic_error("no kernel " + name);
  }
};

Measured measure(const std::string& file, int points) {
  const hamel::Model loaded = hamel::load_model(source_dir() + "/models/" + file);
  std::map<std::string, double> all;
  std::vector<double> p;
  for (const auto& q : loaded.parameters) all[q.symbol.get_name()] = q.default_value, p.push_back(q.default_value);
  const hamel::Derivation d = hamel::derive(hamel::fold_parameters(loaded, all));
  const hamel::KernelSet k = hamel::build_kernels(loaded, d);
  hamel::AccuracySettings s;
  s.points = points;
  s.seed = 7;
  return {hamel::measure_kernel_accuracy(loaded, d, k, p, s)};
}

// The bounds. (1) What the form of an expression kernel adds: the error of the double graph against the same
// graph in 50 digits, divided by the output's condition number κ with respect to the state, inputs and t,
// stays below 100 — a well-formed expression loses about as many digits as rounding its arguments does (κ);
// a form with cancellation the function does not have scored 349 (satellite_se3 forcing) before the forcing
// was collected into monomials. rhs and jacobian of a configuration-dependent M end in an LDLᵀ solve, whose
// error is normwise (about ε·S in every output, however small), so κ with respect to the state does not bound
// it; they get (2) only. (2) The error stays below 2/φ = 2000 ulps: an output φ = 1e-3 times smaller than the
// kernel's largest S counts the unavoidable absolute error ε·S as up to 1/φ ulps, and κ adds its own (the
// double pendulum's Jacobian: 1.8e3 at its worst of 2000 points, an entry of 0.004 next to 5.9 off by 1.5e-15).
void expect_accurate(const Measured& m, const char* model) {
  for (const hamel::KernelAccuracy& k : m.kernels) {
    SCOPED_TRACE(std::string(model) + " " + k.kernel);
    EXPECT_TRUE(k.has_reference) << "add the kernel's expressions to references() in numeric/kernel_accuracy.cpp";
    if (k.outputs == 0) continue;
    EXPECT_GT(k.points, 0);
    EXPECT_EQ(k.skipped, 0);
    EXPECT_LT(k.worst_ulps, 2000.0) << k.worst_output;
    if (k.kernel != "rhs" && k.kernel != "jacobian") {
      EXPECT_LT(k.worst_excess, 100.0) << k.worst_excess_output;
    }
    EXPECT_LT(k.mean_ulps(), 20.0);
  }
}

// Condition numbers are formed after all points, only where they can change the report (the worst errors, and
// eval/cond at the points whose eval-only errors could beat the largest, largest first): a regression guard of
// that shortcut, the same tables as with κ formed at every point in the point loop, field for field, on a model
// whose kernels have poles (the rolling ball's 1/cos θ) and one with inputs and a floating base.
TEST(KernelAccuracy, ConditionNumbersOnlyWhereTheyMatterGiveTheSameReport) {
  for (const char* file : {"rolling_ball.yaml", "planar_space_robot.yaml"}) {
    SCOPED_TRACE(file);
    const hamel::Model loaded = hamel::load_model(source_dir() + "/models/" + file);
    std::vector<double> p;
    for (const auto& q : loaded.parameters) p.push_back(q.default_value);
    const hamel::Derivation d = hamel::derive(loaded);
    const hamel::KernelSet k = hamel::build_kernels(loaded, d);
    hamel::AccuracySettings lazy;
    lazy.points = 25;
    hamel::AccuracySettings every = lazy;
    every.condition_at_every_point = true;
    const std::vector<hamel::KernelAccuracy> a = hamel::measure_kernel_accuracy(loaded, d, k, p, lazy);
    const std::vector<hamel::KernelAccuracy> b = hamel::measure_kernel_accuracy(loaded, d, k, p, every);
    ASSERT_EQ(a.size(), b.size());
    int conditioned = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      SCOPED_TRACE(a[i].kernel);
      EXPECT_EQ(a[i].worst_ulps, b[i].worst_ulps);
      EXPECT_EQ(a[i].worst_output, b[i].worst_output);
      EXPECT_EQ(a[i].condition_at_worst, b[i].condition_at_worst);
      EXPECT_EQ(a[i].worst_excess, b[i].worst_excess);
      EXPECT_EQ(a[i].worst_excess_output, b[i].worst_excess_output);
      EXPECT_EQ(a[i].worst_evaluation_ulps, b[i].worst_evaluation_ulps);
      EXPECT_EQ(a[i].sum_ulps, b[i].sum_ulps);
      if (b[i].condition_at_worst > 0) ++conditioned;
    }
    EXPECT_GT(conditioned, 0);  // the comparison covers condition numbers, not only zeros
  }
}

TEST(KernelAccuracy, CoreModelsStayWithinTheirConditioning) {
  const Measured sleigh = measure("chaplygin_sleigh.yaml", 60);
  expect_accurate(sleigh, "chaplygin_sleigh");
  // diag(m, J + m a²) folded: correctly rounded numbers.
  EXPECT_LE(sleigh.get("mass_matrix").worst_ulps, 0.5);
  const Measured pendulum = measure("double_pendulum.yaml", 60);
  expect_accurate(pendulum, "double_pendulum");
  // The rolling ball's kinematics carry 1/cos(theta): conditioning, not the form (the ratio stays small).
  const Measured ball = measure("rolling_ball.yaml", 60);
  expect_accurate(ball, "rolling_ball");
  // Its constraint residual is zero; errors count against the size of the terms that cancel.
  EXPECT_LT(ball.get("constraint_residual").worst_ulps, 8.0);
}

TEST(KernelAccuracy, BundleModelsAfterTheFormImprovements) {
  const Measured body = measure("free_rigid_body.yaml", 60);
  expect_accurate(body, "free_rigid_body");
  // Euler's equations: a few roundings at most.
  EXPECT_LT(body.get("rhs").worst_ulps, 4.0);
  const Measured satellite = measure("satellite_se3.yaml", 30);
  expect_accurate(satellite, "satellite_se3");
  // Before: rhs 4.2e3 ulps (LDLᵀ of M⁻¹ at run time and uncollected forcing), jacobian 1.3e3. With M⁻¹
  // formed at generation time rhs and jacobian are expressions like the others, and so is their bound.
  for (const char* kernel : {"rhs", "jacobian"}) {
    EXPECT_LT(satellite.get(kernel).worst_ulps, 1000.0) << kernel;
    EXPECT_LT(satellite.get(kernel).worst_excess, 100.0) << kernel;
  }
  // A constant locked inertia folds to correctly rounded numbers.
  EXPECT_LE(satellite.get("locked_inertia").worst_ulps, 0.5);
}

}  // namespace
