// The command-line contract, exercised on the real binary: JSON shape of `derive`, CSV header of
// `simulate`, byte-identical regeneration by `emit`, exit status 2 and no output on bad input.
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <vector>

#include <sys/wait.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;

using hamel::test::Outcome;
using hamel::test::run;
using hamel::test::slurp;
using hamel::test::source;

// Runs `hamel ARGS`, capturing stdout (stderr discarded unless redirected in args).
Outcome hamel(const std::string& args) { return run(std::string(HAMEL_BINARY) + " " + args); }

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hamel_cli_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

TEST(Cli, DeriveJsonNamesEntriesAndCarriesValues) {
  const Outcome r = hamel("derive " + source("models/rolling_ball.yaml") +
                          " --json --at psi=0.3,theta=0.2,phi=0.1,x=0,y=0,vx=1,vy=2 2>/dev/null");
  ASSERT_EQ(r.status, 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "rolling_ball");
  bool found = false;
  for (const auto& h : j["hamel"]) {
    ASSERT_TRUE(h.contains("upper") && h.contains("lower") && h.contains("expr") && h.contains("value"));
    if (h["upper"] == "u3" && h["lower"] == nlohmann::json{"vy", "vx"}) {
      found = true;
      EXPECT_DOUBLE_EQ(h["value"].get<double>(), 100.0);  // 1/R² with R = 0.1
    }
  }
  EXPECT_TRUE(found);
  ASSERT_TRUE(j.contains("mass_matrix") && j.contains("forcing"));
  for (const auto& e : j["mass_matrix"]) EXPECT_TRUE(e.contains("row") && e.contains("col") && e.contains("value"));
  for (const auto& e : j["forcing"]) EXPECT_TRUE(e.contains("value"));
}

// --riemann adds the key "riemann" and changes nothing else; its entries carry values under --at.
TEST(Cli, DeriveRiemannAddsOneKey) {
  const std::string args =
      "derive " + source("models/double_pendulum.yaml") + " --json --at theta1=0.3,theta2=-0.4,omega1=1.5,omega2=-0.5";
  const Outcome plain = hamel(args + " 2>/dev/null"), riemann = hamel(args + " --riemann 2>/dev/null");
  ASSERT_EQ(plain.status, 0);
  ASSERT_EQ(riemann.status, 0);
  nlohmann::json with = nlohmann::json::parse(riemann.out);
  const nlohmann::json without = nlohmann::json::parse(plain.out);
  EXPECT_FALSE(without.contains("riemann"));
  ASSERT_TRUE(with.contains("riemann"));
  const nlohmann::json r = with["riemann"];
  with.erase("riemann");
  EXPECT_EQ(with, without);
  for (const char* key : {"metric", "christoffel", "christoffel_first_kind", "curvature", "connection_rate",
                          "force_gradient", "stiffness", "forces"})
    for (const auto& e : r[key]) EXPECT_TRUE(e.contains("expr") && e.contains("value")) << key;
  // g_11 = (m1 + m2) l1² = 2, g_12 = m2 l1 l2 cos(theta1 - theta2) with unit masses and lengths.
  for (const auto& e : r["metric"]) {
    if (e["row"] == "theta1" && e["col"] == "theta1") {
      EXPECT_NEAR(e["value"].get<double>(), 2.0, 1e-15);
    }
    if (e["row"] == "theta1" && e["col"] == "theta2") {
      EXPECT_NEAR(e["value"].get<double>(), std::cos(0.7), 1e-15);
    }
  }
  ASSERT_EQ(r["curvature"].size(), 1u);
  EXPECT_EQ(r["curvature"][0]["indices"], (nlohmann::json{"theta1", "theta2", "theta1", "theta2"}));
  EXPECT_FALSE(r["flat"].get<bool>());
  // Conservative forces: K_ab = R_cbda q_dot^c q_dot^d + Hess(V)_ab is symmetric.
  double K12 = 0, K21 = 0;
  for (const auto& e : r["stiffness"]) {
    if (e["row"] == "theta1" && e["col"] == "theta2") K12 = e["value"].get<double>();
    if (e["row"] == "theta2" && e["col"] == "theta1") K21 = e["value"].get<double>();
  }
  EXPECT_NE(K12, 0.0);
  EXPECT_NEAR(K12, K21, 1e-12 * std::fabs(K12));
  const Outcome text = hamel("derive " + source("models/double_pendulum.yaml") + " --riemann 2>/dev/null");
  ASSERT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("Riemann-Christoffel tensor R_abcd"), std::string::npos);
  EXPECT_NE(text.out.find("R_(theta1,theta2,theta1,theta2) = "), std::string::npos);
}

TEST(Cli, SimulateWritesCsvWithStateHeader) {
  const fs::path out = scratch("sleigh.csv");
  const Outcome r =
      hamel("simulate " + source("models/chaplygin_sleigh.yaml") +
            " --t-end 1 --integrator rk4 --dt 0.01 --init v=1,omega=0.5 --out " + out.string() + " 2>/dev/null");
  ASSERT_EQ(r.status, 0);
  std::istringstream lines(slurp(out));
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "t,x,y,theta,v,omega");
  int rows = 0;
  std::string line, last;
  while (std::getline(lines, line)) ++rows, last = line;
  EXPECT_EQ(rows, 101);
  EXPECT_EQ(last.substr(0, 2), "1,");
}

TEST(Cli, EmitIsByteIdenticalOnRegeneration) {
  const fs::path a = scratch("emit_a"), b = scratch("emit_b");
  ASSERT_EQ(hamel("emit " + source("models/rolling_disk.yaml") + " -o " + a.string() + " 2>/dev/null").status, 0);
  ASSERT_EQ(hamel("emit " + source("models/rolling_disk.yaml") + " -o " + b.string() + " 2>/dev/null").status, 0);
  for (const char* file : {"rolling_disk.hpp", "rolling_disk.cpp"}) {
    const std::string x = slurp(a / file);
    EXPECT_FALSE(x.empty());
    EXPECT_EQ(x, slurp(b / file)) << file;
  }
  // Regenerating into an existing folder replaces it, leaving no staging folders behind.
  ASSERT_EQ(hamel("emit " + source("models/rolling_disk.yaml") + " -o " + a.string() + " 2>/dev/null").status, 0);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(a.parent_path()))
    entries += e.path().filename().string().rfind("emit_a", 0) == 0;
  EXPECT_EQ(entries, 1);
}

// --split N: kernels longer than N operations become functions <kernel>_part<k>; --split 0 prints every kernel
// whole (rhs and rhs_with_pivots each in full); a value that is not a whole number of operations exits 2 naming the
// flag and writes nothing.
TEST(Cli, EmitSplitPrintsLongKernelsInParts) {
  const fs::path whole = scratch("split_whole"), parts = scratch("split_parts"), never = scratch("split_never");
  ASSERT_EQ(hamel("emit " + source("models/double_pendulum.yaml") + " -o " + whole.string() + " --split 0 2>/dev/null")
                .status,
            0);
  ASSERT_EQ(hamel("emit " + source("models/double_pendulum.yaml") + " -o " + parts.string() + " --split 30 2>/dev/null")
                .status,
            0);
  const std::string a = slurp(whole / "double_pendulum.cpp"), b = slurp(parts / "double_pendulum.cpp");
  EXPECT_EQ(a.find("_part0("), std::string::npos);
  // The first line of every file records the options emit was given.
  EXPECT_NE(a.substr(0, a.find('\n')).find("; emit --split 0). Do not edit."), std::string::npos) << a.substr(0, 200);
  EXPECT_NE(b.substr(0, b.find('\n')).find("; emit --split 30). Do not edit."), std::string::npos) << b.substr(0, 200);
  EXPECT_NE(b.find("void jacobian_part0(real t, const real* x, const real* p, const real* in, real* v, real* out) {"),
            std::string::npos);
  EXPECT_NE(b.find("  jacobian_part1(t, x, p, in, v, out);"), std::string::npos);
  // A split rhs is printed once, as rhs_with_pivots, which rhs and rhs_status call.
  EXPECT_NE(b.find("void rhs_with_pivots_part0("), std::string::npos);
  EXPECT_NE(b.find("  rhs_with_pivots(t, x, p, in, out, pivots);"), std::string::npos);
  EXPECT_EQ(a.find("  rhs_with_pivots(t, x, p, in, out, pivots);"), std::string::npos);
  for (const char* value : {"-1", "1.5", "many"}) {
    const Outcome r = hamel("emit " + source("models/double_pendulum.yaml") + " -o " + never.string() + " --split " +
                            value + " 2>&1");
    EXPECT_EQ(r.status, 2) << value;
    EXPECT_NE(r.out.find("--split"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(never));
  }
}

// --share N --share-ratio R: work of N or more statements that several kernels use is printed once, as functions
// shared_<k> the kernels call; --share 0 never; a value that is not a whole number exits 2 naming the flag.
TEST(Cli, EmitSharePrintsSharedWorkOnce) {
  const fs::path none = scratch("share_none"), shared = scratch("share_all"), never = scratch("share_never");
  ASSERT_EQ(
      hamel("emit " + source("models/double_pendulum.yaml") + " -o " + none.string() + " --share 0 2>/dev/null").status,
      0);
  ASSERT_EQ(hamel("emit " + source("models/double_pendulum.yaml") + " -o " + shared.string() +
                  " --share 5 --share-ratio 0 2>/dev/null")
                .status,
            0);
  const std::string a = slurp(none / "double_pendulum.cpp"), b = slurp(shared / "double_pendulum.cpp");
  EXPECT_EQ(a.find("shared_0("), std::string::npos);
  EXPECT_NE(b.find("void shared_0(real t, const real* x, const real* p, const real* in, real* out"), std::string::npos);
  EXPECT_NE(b.substr(0, b.find('\n')).find("; emit --share 5 --share-ratio 0). Do not edit."), std::string::npos)
      << b.substr(0, 200);
  for (const char* flag : {"--share", "--share-ratio"})
    for (const char* value : {"-1", "many"}) {
      const Outcome r = hamel("emit " + source("models/double_pendulum.yaml") + " -o " + never.string() + " " + flag +
                              " " + value + " 2>&1");
      EXPECT_EQ(r.status, 2) << flag << " " << value;
      EXPECT_NE(r.out.find(flag), std::string::npos) << r.out;
      EXPECT_FALSE(fs::exists(never));
    }
  // auto, the default, by name: the package of no flag, stamped as such.
  const fs::path automatic = scratch("share_auto"), plain = scratch("share_default");
  ASSERT_EQ(hamel("emit " + source("models/double_pendulum.yaml") + " -o " + automatic.string() +
                  " --share 5 --share-ratio auto 2>/dev/null")
                .status,
            0);
  ASSERT_EQ(hamel("emit " + source("models/double_pendulum.yaml") + " -o " + plain.string() + " --share 5 2>/dev/null")
                .status,
            0);
  EXPECT_EQ(slurp(automatic / "double_pendulum.cpp"), slurp(plain / "double_pendulum.cpp"));
  EXPECT_NE(slurp(plain / "double_pendulum.cpp").find("; emit --share 5). Do not edit."), std::string::npos);
}

TEST(Cli, BadInputExitsTwoAndWritesNothing) {
  const fs::path bad = scratch("bad.yaml");
  {
    std::ofstream f(bad);
    f << "name: broken\ncoordinates: [x]\nquasi_velocities: {names: [u], A: [[1]]}\nlagrangian: \"x_dot^2 + k\"\n";
  }
  const fs::path out = scratch("never");
  const Outcome r = hamel("emit " + bad.string() + " -o " + out.string() + " 2>&1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("bad.yaml:4:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unknown name 'k'"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(hamel("simulate " + bad.string() + " --t-end 1 2>/dev/null").status, 2);
  EXPECT_EQ(hamel("derive /nonexistent/model.yaml 2>/dev/null").status, 2);
  EXPECT_EQ(hamel("simulate " + source("models/chaplygin_sleigh.yaml") + " --t-end 1 --init nope=1 2>/dev/null").status,
            2);
  EXPECT_EQ(hamel("frobnicate 2>/dev/null").status, 2);
}

// `hamel linearize ... --json`: its contract keys; the double pendulum hanging at rest has A = [[0, I], [-K, 0]]
// with eigenvalues ±i ω, the linearized normal modes of a double pendulum (m1 = m2, l1 = l2: ω² = (2 ∓ √2) g/l).
TEST(Cli, LinearizeJsonShapeAndPendulumModes) {
  const Outcome r = hamel("linearize " + source("models/double_pendulum.yaml") + " --json 2>/dev/null");
  ASSERT_EQ(r.status, 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["model"], "double_pendulum");
  EXPECT_EQ(j["state"], (nlohmann::json{"theta1", "theta2", "omega1", "omega2"}));
  EXPECT_TRUE(j["inputs"].is_array());
  ASSERT_EQ(j["A"].size(), 4u);
  EXPECT_EQ(j["A"][0].size(), 4u);
  EXPECT_EQ(j["B"].size(), 4u);
  EXPECT_EQ(j["residual"].size(), 4u);
  ASSERT_EQ(j["eigenvalues"].size(), 4u);
  std::vector<double> frequencies;
  for (const auto& e : j["eigenvalues"]) {
    EXPECT_NEAR(e[0].get<double>(), 0.0, 1e-12);
    if (e[1].get<double>() > 0) frequencies.push_back(e[1].get<double>());
  }
  std::sort(frequencies.begin(), frequencies.end());
  ASSERT_EQ(frequencies.size(), 2u);
  EXPECT_NEAR(frequencies[0], std::sqrt((2 - std::sqrt(2.0)) * 9.81), 1e-12);
  EXPECT_NEAR(frequencies[1], std::sqrt((2 + std::sqrt(2.0)) * 9.81), 1e-12);
  EXPECT_EQ(hamel("linearize " + source("models/double_pendulum.yaml") + " --at nope=1 2>/dev/null").status, 2);
  EXPECT_EQ(hamel("linearize " + source("models/double_pendulum.yaml") + " --sweep g=1:0:1 2>/dev/null").status, 2);
}

TEST(Cli, HelpForEveryVerb) {
  for (const char* verb : {"derive", "emit", "simulate", "linearize", "animate"}) {
    const Outcome r = hamel(std::string(verb) + " --help");
    EXPECT_EQ(r.status, 0) << verb;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << verb;
  }
}

// --quiet (-q) silences what a command says it is doing (derivation, reconstruction: "hamel: ... ..."), and only
// that: emit still prints what it wrote, phase its result.
TEST(Cli, QuietSilencesProgressOnly) {
  const fs::path out = scratch("quiet");
  const std::string emit = "emit " + source("models/double_pendulum.yaml") + " -o " + out.string() + " 2>&1";
  const Outcome loud = hamel(emit);
  ASSERT_EQ(loud.status, 0) << loud.out;
  EXPECT_NE(loud.out.find("hamel: deriving double_pendulum ..."), std::string::npos) << loud.out;
  for (const char* flag : {"--quiet ", "-q "}) {
    const Outcome quiet = hamel(flag + emit);
    ASSERT_EQ(quiet.status, 0) << quiet.out;
    EXPECT_EQ(quiet.out.find("deriving"), std::string::npos) << quiet.out;
    EXPECT_NE(quiet.out.find("hamel: wrote "), std::string::npos) << quiet.out;
  }
  const std::string phase = "phase " + source("models/planar_space_robot.yaml") +
                            " --path \"0.5*sin(2*pi*t); 0.5*(1-cos(2*pi*t))\" --steps-per-cycle 200 --no-files 2>&1";
  const Outcome phase_loud = hamel(phase);
  ASSERT_EQ(phase_loud.status, 0) << phase_loud.out;
  EXPECT_NE(phase_loud.out.find("hamel: reconstructing 1 cycle(s) on SE2 ..."), std::string::npos) << phase_loud.out;
  const Outcome phase_quiet = hamel("--quiet " + phase);
  ASSERT_EQ(phase_quiet.status, 0) << phase_quiet.out;
  EXPECT_EQ(phase_quiet.out.find("hamel: "), std::string::npos) << phase_quiet.out;
  EXPECT_NE(phase_quiet.out.find("cycle 1 (t = 1)"), std::string::npos) << phase_quiet.out;
  fs::remove_all(out);
}

}  // namespace

namespace {

// Every verb runs one pipeline with one set of defaults (generator/cli/pipeline.hpp): derive, like emit and
// simulate, derives a floating tree of several bodies by the articulated-body algorithm unless --dynamics says
// otherwise, and takes a scene as the other verbs do (its name, its fixed parameters).
TEST(Cli, DeriveHasTheDefaultsOfEveryVerb) {
  const Outcome aba = hamel("derive " + source("models/space_robot.yaml") + " --json 2>/dev/null");
  ASSERT_EQ(aba.status, 0);
  EXPECT_TRUE(nlohmann::json::parse(aba.out).contains("accelerations"));
  const Outcome ldlt = hamel("derive " + source("models/space_robot.yaml") + " --dynamics ldlt --json 2>/dev/null");
  ASSERT_EQ(ldlt.status, 0);
  EXPECT_FALSE(nlohmann::json::parse(ldlt.out).contains("accelerations"));
  const Outcome scene = hamel("derive " + source("scenes/space_robot_arm.yaml") + " --json 2>/dev/null");
  ASSERT_EQ(scene.status, 0);
  EXPECT_EQ(nlohmann::json::parse(scene.out)["model"], "space_robot_arm");
  const Outcome accuracy =
      hamel("accuracy " + source("models/double_pendulum.yaml") + " --points 2 --json 2>/dev/null");
  ASSERT_EQ(accuracy.status, 0);
  EXPECT_EQ(nlohmann::json::parse(accuracy.out)["fold"], "none");
}

}  // namespace
