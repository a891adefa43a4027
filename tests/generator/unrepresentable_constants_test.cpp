// Constants a double cannot hold: A = diag(1e200, 1e-200) derives exactly, but its mass matrix B^T B holds
// 1e-400 and 1e400 and its energy 5e399, constants no double holds. They were emitted as real(0.0) and
// real(HUGE_VAL). Now a kernel reaching such a constant is never emitted: `emit` leaves it out of the default
// set with a note on stderr and keeps the others (rhs is fine: B's 1e±200 fit); asked for by --kernels it is
// an input error (exit 2, nothing written). The expression graph marks such constants, also ones that a fold
// in doubles overflows or underflows, and never folds them or takes them for 0 or 1.
#include "emit/expression_graph.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;
using hamel::test::Outcome;
using hamel::test::run;
using hamel::test::slurp;

const char* const kDiagonal =
    "name: s\ncoordinates: [x, y]\nquasi_velocities:\n  names: [u, w]\n"
    "  A: [[\"1e200\", 0], [0, \"1e-200\"]]\nlagrangian: \"1/2*x_dot^2 + 1/2*y_dot^2 - x^2/2\"\n";

fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / ("hamel_unrepresentable_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "diag.yaml") << kDiagonal;
  return dir;
}

TEST(UnrepresentableConstants, DefaultEmitLeavesOutTheKernelsThatNeedThemWithANote) {
  const fs::path dir = scratch();
  const Outcome r = run(std::string(HAMEL_BINARY) + " emit " + (dir / "diag.yaml").string() + " -o " +
                        (dir / "out").string() + " 2>&1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("left out kernel 'mass_matrix', output M[u][u], needs the constant 1.0e-400"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("left out kernel 'energy', output E, needs the constant 5.0e399"), std::string::npos) << r.out;
  const std::string cpp = slurp(dir / "out" / "s.cpp"), hpp = slurp(dir / "out" / "s.hpp");
  ASSERT_FALSE(cpp.empty());
  EXPECT_EQ(cpp.find("HUGE_VAL"), std::string::npos);
  EXPECT_EQ(hpp.find("void mass_matrix("), std::string::npos);
  EXPECT_EQ(hpp.find("void energy("), std::string::npos);
  // rhs and the other kernels stay, with B's constants, which fit.
  EXPECT_NE(hpp.find("void rhs("), std::string::npos);
  EXPECT_NE(hpp.find("void forcing("), std::string::npos);
  EXPECT_NE(cpp.find("real(1e+200)"), std::string::npos);
  fs::remove_all(dir);
}

TEST(UnrepresentableConstants, AKernelAskedForIsAnInputErrorAndNothingIsWritten) {
  const fs::path dir = scratch();
  const Outcome r = run(std::string(HAMEL_BINARY) + " emit " + (dir / "diag.yaml").string() + " -o " +
                        (dir / "out").string() + " --kernels rhs,mass_matrix 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("diag.yaml: error: kernel 'mass_matrix', output M[u][u], needs the constant 1.0e-400, "
                       "beyond the range of a double"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("internal error"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out"));
  // Without it, the rest is emitted.
  const Outcome ok = run(std::string(HAMEL_BINARY) + " emit " + (dir / "diag.yaml").string() + " -o " +
                         (dir / "out").string() + " --kernels rhs 2>&1");
  EXPECT_EQ(ok.status, 0) << ok.out;
  // simulate evaluates energy (its drift monitor): refused the same way, not run with an infinite energy.
  const Outcome sim = run(std::string(HAMEL_BINARY) + " simulate " + (dir / "diag.yaml").string() +
                          " --t-end 1 --out " + (dir / "run.csv").string() + " 2>&1");
  EXPECT_EQ(sim.status, 2) << sim.out;
  EXPECT_NE(sim.out.find("kernel 'energy', output E, needs the constant 5.0e399"), std::string::npos) << sim.out;
  fs::remove_all(dir);
}

TEST(UnrepresentableConstants, GraphMarksThemAndNeverFoldsThem) {
  hamel::ExpressionGraph g;
  const std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves;
  const GiNaC::numeric big = GiNaC::numeric(10).power(400), tiny = GiNaC::numeric(10).power(-400);
  const int b = g.from_expression(big, leaves), t = g.from_expression(tiny, leaves);
  EXPECT_TRUE(g.is_unrepresentable(b));
  EXPECT_TRUE(g.is_unrepresentable(t));
  EXPECT_EQ(g.unrepresentable_value(b), "1.0e400");
  EXPECT_EQ(g.unrepresentable_value(t), "1.0e-400");
  EXPECT_NE(t, g.constant(0));                                             // not the zero constant
  EXPECT_NE(g.from_expression(GiNaC::numeric(10).power(500), leaves), b);  // distinct values stay distinct
  EXPECT_EQ(g.from_expression(big, leaves), b);
  // x·1e-400 is not folded to 0: the product reaches the marked constant.
  const int x = g.input(hamel::Argument::state, 0);
  const int product = g.binary(hamel::Op::mul, x, t);
  EXPECT_EQ(g.first_unrepresentable({x, product}), std::make_pair(1, t));
  // Folds in doubles that overflow or underflow are marked too; ordinary ones are not.
  EXPECT_TRUE(g.is_unrepresentable(g.binary(hamel::Op::mul, g.constant(1e200), g.constant(1e200))));
  EXPECT_TRUE(g.is_unrepresentable(g.binary(hamel::Op::div, g.constant(1e-200), g.constant(1e200))));
  EXPECT_FALSE(g.is_unrepresentable(g.binary(hamel::Op::sub, g.constant(1e200), g.constant(1e200))));
  EXPECT_FALSE(g.is_unrepresentable(g.from_expression(GiNaC::numeric(10).power(300), leaves)));
  EXPECT_EQ(g.first_unrepresentable({x}), std::make_pair(-1, -1));
}

}  // namespace
