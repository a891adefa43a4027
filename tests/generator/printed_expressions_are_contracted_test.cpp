// What `hamel derive` prints is the derivation's normal form with sin/cos contracted back to multiple and sum angles
// (contract_trig): sin(3t), not 4 sin t cos² t − sin t; cos(2ψ), not 2 cos² ψ − 1; zero sums print as 0. The
// contraction must be exact (identically_zero of the difference) and never make an expression larger; the text,
// JSON and LaTeX output use it, and the printed strings read back equal the model's expressions.
#include "algebra/contract_trig.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"

#include "support/command.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using GiNaC::ex;

using hamel::test::Outcome;
using hamel::test::run;
using hamel::test::slurp;
using hamel::test::source;

Outcome hamel(const std::string& args) { return run(std::string(HAMEL_BINARY) + " " + args + " 2>&1"); }

// Exactly zero as a function of its symbols (algebra/identity_test.hpp).
bool zero(const ex& e) { return hamel::identically_zero(e, hamel::Intermediates{}) == hamel::Identity::zero; }

class ContractTrig : public ::testing::Test {
 protected:
  GiNaC::realsymbol t{"t"}, psi{"psi"}, a{"a"}, b{"b"}, m{"m"}, l{"l"};
  ex parse(const std::string& s) {
    GiNaC::symtab table{{"t", t}, {"psi", psi}, {"a", a}, {"b", b}, {"m", m}, {"l", l}};
    return GiNaC::parser(table)(s);
  }
  // The printed form of `s`: its normal form, contracted; checked to equal `s` exactly and to be no larger than
  // the normal form.
  ex printed(const std::string& s) {
    const ex original = parse(s);
    const ex normal = hamel::simplify(original);
    const ex shown = hamel::contract_trig(normal);
    EXPECT_TRUE(zero(shown - original)) << s << " printed as " << shown;
    EXPECT_LE(hamel::node_count(shown, 100000), hamel::node_count(normal, 100000)) << s;
    return shown;
  }
};

TEST_F(ContractTrig, MultipleAnglesComeBack) {
  EXPECT_EQ(printed("sin(3*t)"), parse("sin(3*t)"));
  EXPECT_EQ(printed("cos(2*psi)"), parse("cos(2*psi)"));
  EXPECT_EQ(printed("sin(2*t)"), parse("sin(2*t)"));
  EXPECT_EQ(printed("cos(5*a)"), parse("cos(5*a)"));
  EXPECT_EQ(printed("m*l*sin(4*t)"), parse("m*l*sin(4*t)"));
  // sin(3t) beside a zero sum: the zero sum goes, sin(3t) stays.
  EXPECT_EQ(printed("sin(3*t) + sin(psi)^2 + cos(psi)^2 - 1"), parse("sin(3*t)"));
  EXPECT_EQ(printed("sin(3*t) + cos(2*psi)"), parse("sin(3*t) + cos(2*psi)"));
}

TEST_F(ContractTrig, SumAnglesComeBack) {
  // Whichever sign the angle comes out with (the printer writes it with its first term positive): compare values
  // exactly and sizes.
  for (const char* s : {"cos(a - b)", "m*l^2*cos(a + b)", "sin(a + 2*b)", "l*sin(a - b)"}) {
    const ex shown = printed(s), expected = parse(s);
    EXPECT_TRUE(zero(shown - expected)) << s << " printed as " << shown;
    EXPECT_EQ(hamel::node_count(shown, 1000), hamel::node_count(expected, 1000)) << s << " printed as " << shown;
  }
}

TEST_F(ContractTrig, ZeroSumsAreZero) {
  EXPECT_EQ(hamel::contract_trig(parse("sin(psi)^2 + cos(psi)^2 - 1")), ex(0));
  EXPECT_EQ(hamel::contract_trig(parse("m*sin(a)^2 + m*cos(a)^2 - m")), ex(0));
  EXPECT_EQ(hamel::contract_trig(parse("cos(a)*cos(b) - sin(a)*sin(b) - cos(a + b)")), ex(0));
}

TEST_F(ContractTrig, NothingLongerIsPrinted) {
  // Forms whose linearization is longer print as they are.
  for (const char* s : {"cos(psi)^2", "sin(t)*cos(t)", "m*l*cos(a)*sin(b)", "cos(a)^2*m + l", "sin(a)/cos(b)",
                        "sqrt(sin(a)) + cos(a)^2"}) {
    const ex e = parse(s);
    const ex shown = hamel::contract_trig(e);
    std::ostringstream before, after;
    before << e;
    after << shown;
    EXPECT_EQ(after.str(), before.str()) << s;
  }
}

TEST_F(ContractTrig, RandomTrigonometricPolynomialsAreContractedExactly) {
  // Sums of products of sin/cos of small integer combinations of a, b with symbolic coefficients, through the
  // normal form: the printed form equals the input and is never larger than the normal form.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> small(-2, 2), terms(1, 4), factors(1, 3), coin(0, 1);
  const std::array<ex, 3> coefficients{m, l, m * l};
  for (int trial = 0; trial < 60; ++trial) {
    ex e = 0;
    for (int k = terms(rng); k > 0; --k) {
      ex term = coefficients[static_cast<std::size_t>(trial + k) % 3] * small(rng);
      for (int f = factors(rng); f > 0; --f) {
        const ex angle = small(rng) * a + small(rng) * b;
        term *= coin(rng) ? GiNaC::sin(angle) : GiNaC::cos(angle);
      }
      e += term;
    }
    const ex normal = hamel::simplify(e);
    const ex shown = hamel::contract_trig(normal);
    EXPECT_TRUE(zero(shown - e)) << e << " printed as " << shown;
    EXPECT_LE(hamel::node_count(shown, 100000), hamel::node_count(normal, 100000)) << e;
  }
}

// The command line: a model whose forces are multiple angles and a zero sum.
class PrintedDerive : public ::testing::Test {
 protected:
  fs::path model;
  void SetUp() override {
    const fs::path dir = fs::temp_directory_path() / ("hamel_contract_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    model = dir / "trig_forces.yaml";
    std::ofstream(model) << R"yaml(schema: 1
name: trig_forces
description: two free coordinates under forces that are multiple angles of t and psi and a zero sum
parameters:
  m: 2.0
coordinates: [x, psi]
quasi_velocities:
  names: [v, w]
  A:
    - [1, 0]
    - [0, 1]
lagrangian: "1/2*m*x_dot^2 + 1/2*m*psi_dot^2"
forces: ["sin(3*t) + sin(psi)^2 + cos(psi)^2 - 1 + m*x*sin(psi)^2", "cos(2*psi) + x*(cos(psi)^2 + sin(psi)^2)"]
)yaml";
  }
  void TearDown() override { fs::remove_all(model.parent_path()); }
};

TEST_F(PrintedDerive, TextShowsMultipleAnglesAndNoZeroSums) {
  const Outcome o = hamel("derive " + model.string());
  ASSERT_EQ(o.status, 0) << o.out;
  const auto line = [&](const std::string& start) {
    const std::size_t at = o.out.find(start);
    return at == std::string::npos ? std::string() : o.out.substr(at, o.out.find('\n', at) - at);
  };
  const std::string f_v = line("f[v] = "), f_w = line("f[w] = ");
  EXPECT_NE(f_v.find("sin(3*t)"), std::string::npos) << o.out;
  EXPECT_EQ(f_v.find("sin(t)"), std::string::npos) << f_v;
  EXPECT_EQ(f_v.find("cos(t)"), std::string::npos) << f_v;
  EXPECT_NE(f_w.find("cos(2*psi)"), std::string::npos) << o.out;
  EXPECT_EQ(f_w.find("cos(psi)"), std::string::npos) << f_w;
  EXPECT_EQ(f_w.find("sin(psi)"), std::string::npos) << f_w;
}

TEST_F(PrintedDerive, JsonExpressionsReadBackEqualToTheForces) {
  const Outcome o = hamel("derive " + model.string() + " --json");
  ASSERT_EQ(o.status, 0) << o.out;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  GiNaC::realsymbol x("x"), psi("psi"), t("t"), m("m");
  GiNaC::symtab table{{"x", x}, {"psi", psi}, {"t", t}, {"m", m}};
  const std::array<ex, 2> forces{
      GiNaC::sin(3 * t) + GiNaC::pow(GiNaC::sin(psi), 2) + GiNaC::pow(GiNaC::cos(psi), 2) - 1 +
          m * x * GiNaC::pow(GiNaC::sin(psi), 2),
      GiNaC::cos(2 * psi) + x * (GiNaC::pow(GiNaC::cos(psi), 2) + GiNaC::pow(GiNaC::sin(psi), 2))};
  ASSERT_EQ(j["forcing"].size(), 2u);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> value(-3.0, 3.0);
  for (std::size_t r = 0; r < 2; ++r) {
    const std::string text = j["forcing"][r]["expr"].get<std::string>();
    EXPECT_EQ(text.find("cos(t)"), std::string::npos) << text;
    EXPECT_EQ(text.find("sin(t)"), std::string::npos) << text;
    const ex shown = GiNaC::parser(table)(text);
    EXPECT_TRUE(zero(shown - forces[r])) << text;
    for (int k = 0; k < 20; ++k) {
      const GiNaC::exmap at{{x, value(rng)}, {psi, value(rng)}, {t, value(rng)}, {m, value(rng)}};
      const double printed_value = GiNaC::ex_to<GiNaC::numeric>(shown.subs(at).evalf()).to_double();
      const double model_value = GiNaC::ex_to<GiNaC::numeric>(forces[r].subs(at).evalf()).to_double();
      EXPECT_NEAR(printed_value, model_value, 1e-14 * std::max(1.0, std::abs(model_value))) << text;
    }
  }
  EXPECT_NE(j["forcing"][0]["expr"].get<std::string>().find("sin(3*t)"), std::string::npos);
  EXPECT_NE(j["forcing"][1]["expr"].get<std::string>().find("cos(2*psi)"), std::string::npos);
  EXPECT_EQ(j["forcing"][1]["expr"].get<std::string>().find("cos(psi)"), std::string::npos);
}

TEST_F(PrintedDerive, LatexShowsMultipleAngles) {
  const Outcome o = hamel("derive " + model.string() + " --latex");
  ASSERT_EQ(o.status, 0) << o.out;
  EXPECT_NE(o.out.find("\\sin(3 t)"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("\\cos(2 \\psi)"), std::string::npos) << o.out;
  EXPECT_EQ(o.out.find("\\cos(t)"), std::string::npos) << o.out;
}

// A shipped model: the double pendulum's coupling m2 l1 l2 cos(theta1 - theta2) prints as one cosine of the angle
// difference, not as cos cos + sin sin.
TEST(PrintedShippedModel, DoublePendulumCouplingIsOneCosine) {
  const Outcome o = hamel("derive " + source("models/double_pendulum.yaml") + " --json");
  ASSERT_EQ(o.status, 0) << o.out;
  const nlohmann::json j = nlohmann::json::parse(o.out);
  for (const auto& e : j["mass_matrix"])
    if (e["row"] != e["col"]) {
      const std::string text = e["expr"].get<std::string>();
      EXPECT_EQ(text.find("sin("), std::string::npos) << text;
      EXPECT_TRUE(text.find("cos(theta1-theta2)") != std::string::npos ||
                  text.find("cos(-theta2+theta1)") != std::string::npos ||
                  text.find("cos(theta2-theta1)") != std::string::npos ||
                  text.find("cos(-theta1+theta2)") != std::string::npos)
          << text;
    }
}

}  // namespace
