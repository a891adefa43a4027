// Issue 46, the third hostile round (tests/errors/cases 316-328 hold the cases with a file position): values at the
// edges of their ranges get the right answer or a message that names them.
//   - linearize balances A before its eigenvalues: a spring of stiffness 1e20 (A = [[0, 1], [-1e20, 0]]) had its 1
//     taken for 0 against 1e20 and printed the eigenvalues 0, 0 instead of +-1e10 i;
//   - simulate's energy line from rest (E0 = 0) gives the absolute drift, not the absolute drift over the smallest
//     double ("max relative drift 3.63e+307");
//   - an --input law's parse error keeps GiNaC's substance, not its C++ function names and source lines;
//   - a CSV number beyond the range of a double says so (it said "expected a finite number" of 1e-320);
//   - a scene given as --out is named as the scene file, not as the model file.
#include "run_hamel.hpp"

#include <gtest/gtest.h>

namespace {

using namespace hamel_test;

const char* driven =
    "name: driven\n"
    "parameters: {m: 1, k: 4}\n"
    "coordinates: [x]\n"
    "quasi_velocities: {names: [u], A: [[1]]}\n"
    "lagrangian: \"m/2*x_dot^2 - k/2*x^2\"\n"
    "forces: [tau]\n"
    "inputs: [tau]\n";

class Edges : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = scratch_dir(std::string("edges_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    spit(dir / "driven.yaml", driven);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string path(const std::string& name) const { return shell_quote((dir / name).string()); }
  fs::path dir;
};

TEST_F(Edges, AStiffOrASoftSpringKeepsItsEigenvalues) {
  for (const auto& [k, imag] :
       {std::pair{"1e20", "10000000000i"}, std::pair{"1e-20", "1e-10i"}, std::pair{"4", "2i"}}) {
    const Outcome r = hamel("linearize " + path("driven.yaml") + " --param k=" + k, dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find(std::string("0 - ") + imag), std::string::npos) << k << "\n" << r.out;
    EXPECT_NE(r.out.find(std::string("0 + ") + imag), std::string::npos) << k << "\n" << r.out;
    EXPECT_EQ(r.out.find("exactly zero"), std::string::npos) << k << "\n" << r.out;
  }
  // And in a sweep across 40 orders of magnitude: no row of zeros.
  const Outcome r = hamel("linearize " + path("driven.yaml") + " --sweep k=1e20:1e21:5e20", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find(",0,0,0,0\n"), std::string::npos) << r.out;
}

TEST_F(Edges, EnergyFromRestHasAnAbsoluteDrift) {
  const Outcome r = hamel("simulate " + path("driven.yaml") + " --t-end 1 --input tau=1 --out -", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("energy: initial 0, max drift 0.354"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("e+307"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("max relative drift"), std::string::npos) << r.err;
}

TEST_F(Edges, AnInputLawThatDoesNotParseIsDescribedWithoutInternals) {
  for (const char* law : {"tau=sin(t", "tau=", "tau=Digamma(t)", "tau=x_dot"}) {
    const Outcome r =
        hamel("simulate " + path("driven.yaml") + " --t-end 1 --input " + shell_quote(law) + " --out -", dir);
    EXPECT_EQ(r.status, 2) << law << ": " << r.err;
    EXPECT_NE(r.err.find("--input: the law of 'tau'"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("parser.cpp"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("line 0, column 0"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("find_or_insert_symbol"), std::string::npos) << r.err;
  }
}

TEST_F(Edges, ACsvNumberBeyondTheRangeOfADoubleSaysSo) {
  for (const char* value : {"1e-320", "1e400"}) {
    spit(dir / "in.csv", std::string("t,tau\n0,") + value + "\n1,2\n");
    const Outcome r =
        hamel("simulate " + path("driven.yaml") + " --t-end 1 --input-file " + path("in.csv") + " --out -", dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(
        r.err.find("in.csv:2:3: error: 'tau': the number '" + std::string(value) + "' is beyond the range of a double"),
        std::string::npos)
        << r.err;
  }
}

TEST_F(Edges, ASceneAsTheOutputIsNamedAsTheScene) {
  spit(dir / "run.yaml", "schema: 1\nscene: run\nmodel: driven.yaml\nt_end: 1\n");
  const Outcome r = hamel("simulate " + path("run.yaml") + " --out " + path("run.yaml"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is the scene file of this run"), std::string::npos) << r.err;
}

}  // namespace
