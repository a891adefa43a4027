// The expression graph's canonical order: the printed kernel is a function of the mathematical
// expressions only, not of the order in which GiNaC iterates over the terms of a sum or the factors of a
// product (hash values that depend on symbol serial numbers and addresses) nor of the order in which graph
// nodes were created. Emitted packages are byte-identical because of this, with no pinned address layout.
#include "emit/expression_graph.hpp"
#include "emit/kernel_printer.hpp"

#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;
using hamel::Argument;
using hamel::ExpressionGraph;
using hamel::Op;

using Leaves = std::map<ex, int, GiNaC::ex_is_less>;

// The kernel `f` computing `outputs`, printed as the package source would print it.
std::string print(const ExpressionGraph& g, const std::vector<int>& outputs) {
  hamel::Kernel k;
  k.name = "f";
  k.outputs = outputs;
  for (std::size_t i = 0; i < outputs.size(); ++i) k.output_names.push_back("f" + std::to_string(i));
  return hamel::kernel_text(g, k, 4, 0, 0);
}

// Symbols a, b, c, d standing for x[0..3], created in the order `names` gives: a different creation order
// gives different serial numbers, so GiNaC stores and iterates the terms of the same sum in another order.
struct Symbols {
  std::map<std::string, GiNaC::realsymbol> s;
  explicit Symbols(const std::string& names) {
    for (char c : names) s.emplace(std::string(1, c), GiNaC::realsymbol(std::string(1, c)));
  }
  ex operator()(const char* name) const { return s.at(name); }
  Leaves leaves(ExpressionGraph& g) const {
    Leaves l;
    for (const auto& [name, symbol] : s) l[symbol] = g.input(Argument::state, name[0] - 'a');
    return l;
  }
};

// Test expressions in the symbols of `v`.
std::vector<ex> expressions(const Symbols& v) {
  const ex a = v("a"), b = v("b"), c = v("c"), d = v("d");
  return {
      a + b + c,
      c * a * b,
      a * b * c + a * b - c / (a + b) + GiNaC::pow(GiNaC::sin(a * c), 2) + GiNaC::pow(GiNaC::sqrt(b * c), 3),
      (a - 2 * b + 3 * c * d) / (d * d * c - a * b) - GiNaC::cos(d + c - b) * GiNaC::pow(a + d, -3),
      GiNaC::exp(a * b * c * d) - a * d + b * c - 4 * a * c * GiNaC::pow(b, 5),
  };
}

// Whether GiNaC iterates over some sum or product of `x` and `y` (the same expressions in differently
// created symbols) in a different order of symbol names: the premise that makes the comparison meaningful.
bool iteration_orders_differ(const ex& x, const ex& y) {
  const auto names = [](const ex& e) {
    std::string s;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      std::ostringstream os;
      os << e.op(i);
      s += os.str() + "|";
    }
    return s;
  };
  if (x.nops() != y.nops()) return false;
  if ((GiNaC::is_a<GiNaC::add>(x) || GiNaC::is_a<GiNaC::mul>(x)) && names(x) != names(y)) return true;
  for (std::size_t i = 0; i < x.nops(); ++i)
    if (iteration_orders_differ(x.op(i), y.op(i))) return true;
  return false;
}

TEST(CanonicalOrder, SameExpressionsPrintTheSameWhateverGinacsTermOrder) {
  const Symbols first("abcd"), second("dcba"), third("cadb");
  std::vector<std::string> printed;
  bool orders_differ = false;
  for (const Symbols* v : {&first, &second, &third}) {
    ExpressionGraph g;
    const Leaves leaves = v->leaves(g);
    std::vector<int> outputs;
    for (const ex& e : expressions(*v)) outputs.push_back(g.from_expression(e, leaves));
    printed.push_back(print(g, outputs));
    const std::vector<ex> x = expressions(first), y = expressions(*v);
    for (std::size_t i = 0; i < x.size(); ++i) orders_differ = orders_differ || iteration_orders_differ(x[i], y[i]);
  }
  ASSERT_TRUE(orders_differ) << "GiNaC iterates all test expressions in the same order: the test proves nothing";
  EXPECT_EQ(printed[0], printed[1]);
  EXPECT_EQ(printed[0], printed[2]);
}

TEST(CanonicalOrder, SameExpressionsPrintTheSameWhateverTheNodeCreationOrder) {
  const Symbols v("abcd");
  const std::vector<ex> es = expressions(v);
  // Graph 1: the expressions in order. Graph 2: unrelated nodes and the expressions' parts first, then the
  // expressions in reverse order (outputs still in the same order).
  ExpressionGraph g1, g2;
  std::vector<int> out1, out2(es.size());
  {
    const Leaves leaves = v.leaves(g1);
    for (const ex& e : es) out1.push_back(g1.from_expression(e, leaves));
  }
  {
    g2.unary(Op::cos, g2.input(Argument::parameter, 7));
    g2.binary(Op::mul, g2.constant(3.5), g2.input(Argument::state, 2));
    Leaves leaves;
    for (int k = 3; k >= 0; --k)
      leaves[v(std::string(1, static_cast<char>('a' + k)).c_str())] = g2.input(Argument::state, k);
    g2.from_expression(v("c") * v("b"), leaves);
    g2.from_expression(GiNaC::sin(v("a") * v("c")), leaves);
    g2.from_expression(v("d") + v("c") - v("b"), leaves);
    for (std::size_t i = es.size(); i-- > 0;) out2[i] = g2.from_expression(es[i], leaves);
  }
  EXPECT_EQ(print(g1, out1), print(g2, out2));
}

TEST(CanonicalOrder, CommutativeOperandsAndScheduleFollowStructureNotIndices) {
  // Graph 1 builds sin(x0)·cos(x1) + x2·x3; graph 2 the same from the other end, with other nodes between.
  ExpressionGraph g1, g2;
  const int s1 = g1.unary(Op::sin, g1.input(Argument::state, 0));
  const int c1 = g1.unary(Op::cos, g1.input(Argument::state, 1));
  const int p1 = g1.binary(Op::mul, s1, c1);
  const int q1 = g1.binary(Op::mul, g1.input(Argument::state, 2), g1.input(Argument::state, 3));
  const int r1 = g1.binary(Op::add, p1, q1);

  const int q2 = g2.binary(Op::mul, g2.input(Argument::state, 3), g2.input(Argument::state, 2));
  g2.unary(Op::exp, q2);
  const int c2 = g2.unary(Op::cos, g2.input(Argument::state, 1));
  g2.binary(Op::div, c2, q2);
  const int s2 = g2.unary(Op::sin, g2.input(Argument::state, 0));
  const int p2 = g2.binary(Op::mul, c2, s2);
  const int r2 = g2.binary(Op::add, q2, p2);

  EXPECT_EQ(g1.key(r1), g2.key(r2));
  EXPECT_EQ(g2.binary(Op::add, p2, q2), r2);  // value numbering sees the commuted operands
  EXPECT_EQ(print(g1, {r1, p1}), print(g2, {r2, p2}));
  EXPECT_NE(g1.key(p1), g1.key(q1));
  EXPECT_NE(g1.structurally_less(p1, q1), g1.structurally_less(q1, p1));
  EXPECT_FALSE(g1.structurally_less(p1, p1));
}

TEST(CanonicalOrder, TermsThatAreTheSameNodeAreCollected) {
  // Distinct GiNaC terms can be one node (here two symbols for one input; in a derivation the same value
  // written differently, which depends on GiNaC's order in earlier steps): x - x vanishes, x + x is 2·x.
  ExpressionGraph g;
  const GiNaC::realsymbol a("a"), b("b"), c("c");
  const int x0 = g.input(Argument::state, 0), x2 = g.input(Argument::state, 2);
  const Leaves leaves{{a, x0}, {b, x0}, {c, x2}};
  EXPECT_EQ(g.from_expression(a - b + c, leaves), x2);
  EXPECT_EQ(g.from_expression(a + b, leaves), g.binary(Op::mul, g.constant(2), x0));
  EXPECT_EQ(g.from_expression(c - a - b, leaves), g.binary(Op::sub, x2, g.binary(Op::mul, g.constant(2), x0)));
}

TEST(CanonicalOrder, TermsThatAreZeroDoNotDecideTheSign) {
  // A term with a factor the graph knows to be 0 (a constrained velocity) is nothing; GiNaC writes it +z·c or −z·c
  // depending on its term order. Before such terms were left out, one sorting first gave the sum its sign, and a
  // product holding the sum became (b − a)·d, negated, in one run and (a − b)·d in another (falling_cat's jacobian).
  ExpressionGraph g;
  const int zero = g.constant(0);
  std::vector<int> inputs;  // two inputs that sort after the constant 0, so a zero term would come first
  for (int k = 0; inputs.size() < 2 && k < 64; ++k) {
    const int x = g.input(Argument::state, k);
    if (g.structurally_less(zero, x)) inputs.push_back(x);
  }
  ASSERT_EQ(inputs.size(), 2u);
  const GiNaC::realsymbol a("a"), b("b"), c("c"), d("d"), z("z");
  const Leaves leaves{{a, inputs[0]},
                      {b, inputs[1]},
                      {c, g.input(Argument::parameter, 0)},
                      {d, g.input(Argument::parameter, 1)},
                      {z, zero}};
  const int plain = g.from_expression((a - b) * d, leaves);
  EXPECT_EQ(g.from_expression((a - b + z * c) * d, leaves), plain);
  EXPECT_EQ(g.from_expression((a - b - z * c) * d, leaves), plain);
  EXPECT_EQ(g.from_expression((a - b - 2 * z * c - z * d) * d, leaves), plain);
  EXPECT_EQ(g.from_expression(GiNaC::sin(b - a - z * c), leaves), g.from_expression(GiNaC::sin(b - a), leaves));
  EXPECT_EQ(g.from_expression(z * c - z * d, leaves), zero);
}

TEST(CanonicalOrder, ScheduleIsTopologicalAndComplete) {
  ExpressionGraph g;
  const Symbols v("abcd");
  const Leaves leaves = v.leaves(g);
  std::vector<int> outputs;
  for (const ex& e : expressions(v)) outputs.push_back(g.from_expression(e, leaves));
  const std::vector<int> order = g.schedule(outputs);
  std::map<int, std::size_t> position;
  for (std::size_t k = 0; k < order.size(); ++k) EXPECT_TRUE(position.emplace(order[k], k).second) << "repeated";
  for (int i : order) {
    const hamel::Node& n = g.node(i);
    for (int operand : {n.a, n.b}) {
      if (operand < 0) continue;
      ASSERT_TRUE(position.count(operand)) << "operand not scheduled";
      EXPECT_LT(position[operand], position[i]);
    }
  }
  for (int o : outputs) EXPECT_TRUE(position.count(o));
}

}  // namespace
