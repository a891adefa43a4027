// The operation table (algebra/operations.hpp) is the one place an operation's derivative rule is written: the
// expression graph's forward-mode pass, tangent, applies the table's rule to every node. Each rule is checked here
// against a central difference of the table's own double evaluation, for each operand of every operation (pow
// with a constant exponent, which has a rule of its own, and with a variable one), at points inside its domain.
#include "algebra/operations.hpp"
#include "emit/expression_graph.hpp"
#include "emit/interpreter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using hamel::Argument;
using hamel::ExpressionGraph;
using hamel::Op;

// The value of `node` with x[0] = a, x[1] = b, through the IR's interpreter in double.
double value_at(const ExpressionGraph& g, int node, double a, double b) {
  hamel::Interpreter<hamel::DoubleArithmetic> program(g);
  const int slot = program.compile({node}).front();
  program.run([&](Argument, int index) { return index == 0 ? a : b; });
  return program.value(slot);
}

// d op(x0, x1) / d x<k> at (a, b) by the tangent pass, against a central difference of op itself.
void expect_rule_matches(Op op, int k, double a, double b, bool constant_exponent = false) {
  SCOPED_TRACE(std::string(hamel::operation(op).cpp) + ", operand " + std::to_string(k) + ", at " + std::to_string(a) +
               ", " + std::to_string(b));
  ExpressionGraph g;
  const int x0 = g.input(Argument::state, 0), x1 = g.input(Argument::state, 1);
  const int second = constant_exponent ? g.constant(b) : x1;
  const int y = hamel::operation(op).operands == 2 ? g.binary(op, x0, second) : g.unary(op, x0);
  const int dy = hamel::tangent(g, {y}, {{k == 0 ? x0 : x1, g.constant(1)}}).front();
  const double h = 1e-6;
  const double central = k == 0 ? (value_at(g, y, a + h, b) - value_at(g, y, a - h, b)) / (2 * h)
                                : (value_at(g, y, a, b + h) - value_at(g, y, a, b - h)) / (2 * h);
  EXPECT_NEAR(value_at(g, dy, a, b), central, 1e-7 * (1 + std::abs(central)));
}

TEST(OperationTable, EveryOperationHasItsEntry) {
  for (int i = 0; i <= static_cast<int>(Op::pow); ++i) {
    const Op op = static_cast<Op>(i);
    EXPECT_EQ(hamel::operation(op).op, op) << i;
    const bool operation = op != Op::constant && op != Op::input;
    EXPECT_EQ(hamel::operation(op).derivative != nullptr, operation) << i;
    EXPECT_EQ(hamel::operation(op).notation != hamel::Notation::none, operation) << i;
    EXPECT_EQ(hamel::function_of(op) != nullptr, hamel::operation(op).name != nullptr) << i;
  }
  for (const hamel::Function& f : hamel::functions())
    EXPECT_EQ(hamel::function_named(f.name), hamel::function_of(f.op));
}

TEST(OperationTable, EveryDerivativeRuleMatchesACentralDifference) {
  for (int i = 0; i <= static_cast<int>(Op::pow); ++i) {
    const Op op = static_cast<Op>(i);
    if (!hamel::operation(op).derivative) continue;
    // Inside every domain: asin, acos need |a| < 1, log, sqrt and a^b a > 0, abs a ≠ 0.
    for (double a : {0.3, 0.7}) {
      expect_rule_matches(op, 0, a, 1.9);
      if (hamel::operation(op).operands == 2) expect_rule_matches(op, 1, a, 1.9);
    }
    expect_rule_matches(op, 0, op == Op::abs ? -0.4 : 0.45, -1.3);
  }
  expect_rule_matches(Op::pow, 0, 0.6, 2.5, true);
  expect_rule_matches(Op::pow, 0, 1.7, -3, true);
}

}  // namespace
