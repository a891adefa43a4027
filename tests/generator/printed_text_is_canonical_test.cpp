// What hamel prints of an expression (algebra/expression_text.hpp: `derive`'s text, JSON and LaTeX, error messages)
// depends only on the expression, not on GiNaC's term order, which follows hash values that include symbol serial
// numbers and addresses: the same formula built from symbols created in another order, or with its signs placed
// otherwise (N/D or (−N)/(−D), sin(b − a) or −sin(a − b)), prints alike; the text reads back equal with GiNaC's
// parser and keeps GiNaC's notation.
#include "algebra/expression_text.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/intermediates.hpp"

#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;

const std::vector<std::string> names{"a", "b", "c", "m", "l1", "l2", "theta1", "theta2", "R", "x"};

// The symbols of `names`, created in the given order (their serial numbers, hence GiNaC's term order, follow it).
GiNaC::symtab symbols(bool reversed) {
  GiNaC::symtab table;
  std::vector<std::string> order = names;
  if (reversed) order.assign(names.rbegin(), names.rend());
  for (const std::string& n : order) table[n] = GiNaC::realsymbol(n);
  return table;
}

ex parse(const std::string& s, const GiNaC::symtab& table) { return GiNaC::parser(table)(s); }

std::string ginac_text(const ex& e) {
  std::ostringstream os;
  os << e;
  return os.str();
}

const std::vector<std::string> formulas{
    "l2*cos(theta2-theta1)*m*l1",
    "(a-b)/(c-a)+(b-a)^3*m-(c-b)^2",
    "m*l1^2*sin(theta1-theta2)-sin(theta2-theta1)*l2+cos(b-a)*tan(c-a)",
    "1/2*m*(a*x^2+b*x+c)^(-1)+sqrt(a-b)*R^(-2)-7/5*m*x",
    "sin(a)^2*(x-l1)*(l2-x)/(R-a)/(b-c)+exp(a-b)",
};

TEST(PrintedText, DoesNotDependOnTheOrderSymbolsWereCreatedIn) {
  const GiNaC::symtab forward = symbols(false), backward = symbols(true);
  bool ginac_differs = false;
  for (const std::string& f : formulas) {
    const ex e1 = parse(f, forward), e2 = parse(f, backward);
    EXPECT_EQ(hamel::to_text(e1), hamel::to_text(e2)) << f;
    const auto tex = [](const std::string& n) { return "\\mathrm{" + n + "}"; };
    EXPECT_EQ(hamel::to_latex(e1, tex), hamel::to_latex(e2, tex)) << f;
    ginac_differs = ginac_differs || ginac_text(e1) != ginac_text(e2);
  }
  // The premise: GiNaC's own printing does follow the creation order, else this test proves nothing.
  EXPECT_TRUE(ginac_differs);
}

TEST(PrintedText, SignsOfSumsArePlacedStructurally) {
  const GiNaC::symtab t = symbols(false);
  const ex a = t.at("a"), b = t.at("b"), c = t.at("c"), x = t.at("x");
  const std::vector<std::pair<ex, ex>> same{
      {(a - b) / (c - x), (b - a) / (x - c)},
      {GiNaC::sin(b - a), -GiNaC::sin(a - b)},
      {GiNaC::cos(b - a), GiNaC::cos(a - b)},
      {x * GiNaC::pow(b - a, 3), -x * GiNaC::pow(a - b, 3)},
      {GiNaC::pow(b - a, 2) * GiNaC::tan(c - a), -GiNaC::pow(a - b, 2) * GiNaC::tan(a - c)},
  };
  for (const auto& [e1, e2] : same) EXPECT_EQ(hamel::to_text(e1), hamel::to_text(e2)) << e1 << " and " << e2;
  EXPECT_EQ(hamel::to_text(GiNaC::sin(b - a)), "-sin(a-b)");
  EXPECT_EQ(hamel::to_text((b - a) / (x - c)), "(a-b)*(c-x)^(-1)");
}

TEST(PrintedText, ReadsBackEqual) {
  const GiNaC::symtab t = symbols(false);
  for (const std::string& f : formulas) {
    const ex e = parse(f, t);
    const ex back = parse(hamel::to_text(e), t);
    EXPECT_EQ(hamel::identically_zero(back - e, hamel::Intermediates{}), hamel::Identity::zero)
        << f << " printed as " << hamel::to_text(e);
  }
}

TEST(PrintedText, KeepsGinacNotationWithFactorsByBaseAndTermsByMonomial) {
  const GiNaC::symtab t = symbols(false);
  const auto text = [&](const std::string& s) { return hamel::to_text(parse(s, t)); };
  EXPECT_EQ(text("l2*cos(theta2-theta1)*m*l1"), "l1*l2*m*cos(theta1-theta2)");
  EXPECT_EQ(text("-R^(-2)"), "-R^(-2)");
  EXPECT_EQ(text("7/5*m"), "7/5*m");
  EXPECT_EQ(text("m*l1^2+m*l2^2"), "l1^2*m+l2^2*m");
  EXPECT_EQ(text("x^(3/2)*sqrt(a)+1"), "1+sqrt(a)*x^(3/2)");
  EXPECT_EQ(text("x*b+a+x*a"), "a+a*x+b*x");
  EXPECT_EQ(text("-(a+b)^2/c"), "-c^(-1)*(a+b)^2");  // symbols before sums
  const auto tex = [&](const std::string& s) {
    return hamel::to_latex(parse(s, t), [](const std::string& n) { return n == "theta1" ? "\\theta_{1}" : n; });
  };
  EXPECT_EQ(tex("-R^(-2)"), "-\\frac{1}{R^{2}}");
  EXPECT_EQ(tex("7/5*m*x/(a+b)"), "\\frac{7}{5} \\frac{ m x}{a+b}");  // spaces as GiNaC writes them
  EXPECT_EQ(tex("sqrt(a)*sin(theta1)"), " \\sqrt{a} \\sin(\\theta_{1})");
  EXPECT_EQ(tex("(a+b)^2*m"), " m {(a+b)}^{2}");
}

TEST(PrintedText, StructuralOrderIsTotalOnDistinctTexts) {
  const GiNaC::symtab t = symbols(false);
  std::vector<ex> all;
  for (const std::string& f : formulas) all.push_back(parse(f, t));
  for (const std::string& n : names) all.push_back(t.at(n));
  std::set<std::string> texts;
  for (const ex& e : all) texts.insert(hamel::to_text(e));
  for (const ex& e1 : all)
    for (const ex& e2 : all) {
      const bool alike = hamel::to_text(e1) == hamel::to_text(e2);
      EXPECT_EQ(!hamel::structurally_less(e1, e2) && !hamel::structurally_less(e2, e1), alike) << e1 << " and " << e2;
    }
  EXPECT_EQ(texts.size(), all.size());
}

}  // namespace
