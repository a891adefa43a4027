// Issue 46, classes 3 and 6: no input makes hamel hang, run in time or memory beyond a linear bound, or hide its
// problems one at a time.
//   - checks work on the program, never on its expansion: 60 definitions d_k = d_{k-1}^2 + d_{k-1} in the
//     Lagrangian or in A load (the kinetic-energy check inlined them: 2^60 terms);
//   - loading is linear: 10 000 definitions and a URDF chain of 2 000 links load (the time is measured in the
//     notes, not here: this guards against the hang, with the ctest timeout), on the default stack: substituting
//     through definitions does not recurse per definition;
//   - every input is bounded: a device, a FIFO or a folder as a model, robot, include or CSV file is refused before
//     anything is read, and a file beyond its size limit is refused with the limit in the message;
//   - input laws run compiled in the IR's interpreter, with GiNaC's values;
//   - an MJCF file with several elements hamel has no place for is refused once, with every element and its line.
#include <gtest/gtest.h>

#include "algebra/intermediates.hpp"
#include "import/tree_import.hpp"
#include "model/input_error.hpp"
#include "model/input_file.hpp"
#include "model/load_model.hpp"
#include "numeric/input_sources.hpp"

#include <sys/stat.h>
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The message of the InputError `f` throws ("" when it throws none).
std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const hamel::InputError& e) {
    return e.what();
  }
  return "";
}

// A model whose Lagrangian (use = "L") or A (use = "A") goes through `n` definitions d_k = d_{k-1}^2 + d_{k-1}.
std::string chain_model(int n, const std::string& use, const std::string& sign = "") {
  std::string s = "schema: 1\nname: chain\nparameters:\n  m: 1.0\ncoordinates: [x]\nquasi_velocities:\n  names: [u]\n";
  s += use == "A" ? "  A:\n    - [\"1 + d" + std::to_string(n) + "^2\"]\n" : "  A:\n    - [1]\n";
  s += "definitions:\n  d0: \"x/1000\"\n";
  for (int k = 1; k <= n; ++k)
    s += "  d" + std::to_string(k) + ": \"d" + std::to_string(k - 1) + "^2 + d" + std::to_string(k - 1) + "\"\n";
  if (use == "L")
    s += "lagrangian: \"" + sign + "1/2*m*(1 + d" + std::to_string(n) + "^2)*x_dot^2\"\n";
  else
    s += "lagrangian: \"1/2*m*u^2 - d" + std::to_string(n) + "\"\n";
  return s;
}

}  // namespace

TEST(ChecksOnTheProgram, SixtyNestedDefinitionsInTheLagrangianLoad) {
  const hamel::Model m = hamel::load_model_from_text(chain_model(60, "L"), "chain.yaml");
  EXPECT_EQ(m.definitions.size(), 61u);
}

TEST(ChecksOnTheProgram, SixtyNestedDefinitionsInALoad) {
  const hamel::Model m = hamel::load_model_from_text(chain_model(60, "A"), "chain.yaml");
  EXPECT_EQ(m.definitions.size(), 61u);
}

TEST(ChecksOnTheProgram, ANegativeKineticEnergyThroughSixtyDefinitionsIsStillFound) {
  const std::string e = input_error([] { hamel::load_model_from_text(chain_model(60, "L", "-"), "chain.yaml"); });
  EXPECT_NE(e.find("chain.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("the kinetic energy is not positive semi-definite"), std::string::npos) << e;
}

TEST(LinearLoading, TenThousandDefinitionsLoad) {
  std::string s =
      "schema: 1\nname: many\nparameters:\n  m: 1.0\ncoordinates: [x]\nquasi_velocities:\n"
      "  names: [u]\n  A:\n    - [1]\ndefinitions:\n  d0: \"x\"\n";
  for (int k = 1; k <= 10000; ++k) s += "  d" + std::to_string(k) + ": \"d" + std::to_string(k - 1) + " + m*x\"\n";
  s += "lagrangian: \"1/2*m*x_dot^2 - d10000\"\n";
  EXPECT_EQ(hamel::load_model_from_text(s, "many.yaml").definitions.size(), 10001u);
}

// Intermediates::substitute goes through a chain of definitions with a stack of its own, not by recursion: 100 000
// definitions d_k = d_{k-1} + x on the 8 MiB of the main thread (the recursion took a frame of 256 bytes per
// definition at -O2, 25 MB here; under AddressSanitizer 10 000 overflowed). Each changed definition becomes a new one.
TEST(LinearLoading, SubstitutionThroughADeepChainNeedsNoDeepStack) {
  hamel::Intermediates program;
  const GiNaC::realsymbol x("x"), y("y");
  GiNaC::ex last = program.define(x + y);
  const std::size_t n = 100000;
  for (std::size_t k = 1; k < n; ++k) last = program.define(last + x);
  hamel::Intermediates::SubstitutionMemo memo;
  const GiNaC::ex replaced = program.substitute(last + 1, {{x, GiNaC::ex(2)}}, memo);
  EXPECT_EQ(program.size(), 2 * n);  // every definition uses x: each one replaced
  hamel::Intermediates::ValueMemo values;
  const GiNaC::ex v = program.value_at(replaced, {{y, GiNaC::ex(5)}}, values);
  ASSERT_TRUE(GiNaC::is_a<GiNaC::numeric>(v)) << v;
  EXPECT_EQ(GiNaC::ex_to<GiNaC::numeric>(v).to_double(), 2.0 * n + 6);  // d_0 = 7, then + 2 per definition, + 1
}

TEST(LinearLoading, AUrdfChainOfTwoThousandLinksImports) {
  std::string s = "<robot name=\"chain\">\n";
  const int n = 2000;
  for (int k = 0; k <= n; ++k)
    s += "<link name=\"l" + std::to_string(k) +
         "\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" "
         "izz=\"1\"/></inertial></link>\n";
  for (int k = 1; k <= n; ++k)
    s += "<joint name=\"j" + std::to_string(k) + "\" type=\"continuous\"><parent link=\"l" + std::to_string(k - 1) +
         "\"/><child link=\"l" + std::to_string(k) + "\"/><origin xyz=\"0 0 0.1\"/><axis xyz=\"0 1 0\"/></joint>\n";
  s += "</robot>\n";
  const std::string path = write_temp("chain.urdf", s);
  const hamel::ImportedTree t = hamel::import_urdf(path, {}, [](const std::string&) {});
  ASSERT_EQ(t.bodies.size(), static_cast<std::size_t>(n));
  const hamel::Model m = hamel::load_model_from_text(hamel::tree_model_yaml(t), "chain.yaml");
  EXPECT_EQ(m.coordinates.size(), static_cast<std::size_t>(n));
}

// ---------------------------------------------------------------------------------------------------------
// Size and file-type limits on every input.

namespace {

// A FIFO (no writer: reading it would block forever), a folder and a device, each refused by `read`.
void expect_refused_before_reading(const std::function<void(const std::string&)>& read, const std::string& what) {
  const std::string fifo = testing::TempDir() + "bounded_fifo_" + what;
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path : {fifo, testing::TempDir(), std::string("/dev/zero")}) {
    const std::string e = input_error([&] { read(path); });
    EXPECT_NE(e.find(path + ": error:"), std::string::npos) << what << ": " << e;
    EXPECT_NE(e.find("is not a regular file"), std::string::npos) << what << ": " << e;
  }
  ::unlink(fifo.c_str());
}

// A sparse file one byte beyond `limit`: refused with the limit in the message.
void expect_size_limit(const std::function<void(const std::string&)>& read, std::uintmax_t limit,
                       const std::string& name) {
  const std::string path = testing::TempDir() + name;
  { std::ofstream(path, std::ios::binary) << "x"; }
  ASSERT_EQ(::truncate(path.c_str(), static_cast<off_t>(limit + 1)), 0);
  const std::string e = input_error([&] { read(path); });
  EXPECT_NE(e.find(path + ": error:"), std::string::npos) << e;
  EXPECT_NE(e.find("more than the limit of " + std::to_string(limit) + " bytes"), std::string::npos) << e;
  ::unlink(path.c_str());
}

const hamel::Warn quiet = [](const std::string&) {};

}  // namespace

TEST(InputLimits, ModelFiles) {
  expect_refused_before_reading([](const std::string& p) { hamel::load_model(p); }, "model");
  expect_size_limit([](const std::string& p) { hamel::load_model(p); }, hamel::kMaxInputFileBytes, "big.yaml");
}

TEST(InputLimits, RobotFiles) {
  expect_refused_before_reading([](const std::string& p) { hamel::import_urdf(p, {}, quiet); }, "urdf");
  expect_refused_before_reading([](const std::string& p) { hamel::import_mjcf(p, {}, quiet); }, "mjcf");
  expect_size_limit([](const std::string& p) { hamel::import_urdf(p, {}, quiet); }, hamel::kMaxRobotFileBytes,
                    "big.urdf");
  expect_size_limit([](const std::string& p) { hamel::import_mjcf(p, {}, quiet); }, hamel::kMaxRobotFileBytes,
                    "big.xml");
}

TEST(InputLimits, MjcfIncludes) {
  const std::string fifo = testing::TempDir() + "included_fifo.xml";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string main = write_temp("includes_fifo.xml", R"(<mujoco model="m">
  <include file="included_fifo.xml"/>
  <worldbody><body name="a"><joint name="j" type="hinge"/><geom type="sphere" size=".1"/></body></worldbody>
</mujoco>
)");
  const std::string e = input_error([&] { hamel::import_mjcf(main, {}, quiet); });
  EXPECT_NE(e.find(fifo + ": error: the robot file is not a regular file (it is a pipe (FIFO)"), std::string::npos)
      << e;
  ::unlink(fifo.c_str());
}

TEST(InputLimits, CsvInputFiles) {
  const std::string model_path = write_temp("driven.yaml", R"(schema: 1
name: driven
coordinates: [x]
quasi_velocities:
  names: [v]
  A:
    - [1]
inputs: [f]
lagrangian: "1/2*x_dot^2"
forces: ["f"]
)");
  const hamel::Model model = hamel::load_model(model_path);
  const auto read = [&](const std::string& p) {
    hamel::InputSources sources(model, {"x", "v"}, {});
    sources.load_csv(p);
  };
  expect_refused_before_reading(read, "csv");
  expect_size_limit(read, hamel::kMaxTableFileBytes, "big.csv");
  // What stays as it was: a table, CRLF line ends, comments, interpolation.
  const std::string csv = write_temp("table.csv", "# a comment\r\nt, f\r\n0, 1\r\n\r\n2, 3\r\n");
  hamel::InputSources sources(model, {"x", "v"}, {});
  sources.load_csv(csv);
  double x[2] = {0, 0}, in = 0;
  sources.evaluate(1.0, x, &in);
  EXPECT_EQ(in, 2.0);
  sources.evaluate(5.0, x, &in);
  EXPECT_EQ(in, 3.0);
}

// ---------------------------------------------------------------------------------------------------------
// Input laws run compiled, with the values GiNaC gives.

TEST(InputLaws, AreCompiledAndAgreeWithGiNaC) {
  const std::string model_path = write_temp("driven2.yaml", R"(schema: 1
name: driven
parameters:
  k: 2.5
coordinates: [x]
quasi_velocities:
  names: [v]
  A:
    - [1]
inputs: [f, g]
lagrangian: "1/2*x_dot^2"
forces: ["f + g"]
)");
  const hamel::Model model = hamel::load_model(model_path);
  hamel::InputSources sources(model, {"x", "v"}, {2.5});
  sources.add_assignments({"f=sin(t) - k*x + v^2/3", "g=exp(-t)*cos(2*x)"}, "--input");
  EXPECT_TRUE(sources.compiled(0));
  EXPECT_TRUE(sources.compiled(1));
  for (const double t : {0.0, 0.3, 1.7}) {
    const double x[2] = {0.25 + t, -1.5 * t};
    double in[2];
    sources.evaluate(t, x, in);
    EXPECT_NEAR(in[0], std::sin(t) - 2.5 * x[0] + x[1] * x[1] / 3, 1e-14) << t;
    EXPECT_NEAR(in[1], std::exp(-t) * std::cos(2 * x[0]), 1e-14) << t;
  }
}

// ---------------------------------------------------------------------------------------------------------
// Import errors all at once.

TEST(ImportErrors, EveryUnsupportedElementInOneMessage) {
  const std::string path = write_temp("everything.xml", R"(<mujoco model="m">
  <worldbody>
    <body name="a">
      <joint name="hinge" type="hinge" limited="true" range="-1 1"/>
      <geom name="ball" type="sphere" size=".1"/>
      <body name="b" pos="0 0 .3">
        <joint name="shoulder" type="ball"/>
        <geom type="sphere" size=".1" contype="0" conaffinity="0"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <fixed name="tie"><joint joint="hinge" coef="1"/></fixed>
  </tendon>
  <actuator>
    <position name="servo" joint="hinge"/>
  </actuator>
</mujoco>
)");
  const std::string e = input_error([&] { hamel::import_mjcf(path, {}, quiet); });
  EXPECT_EQ(e.rfind(path + ":13:", 0), 0u) << e;  // the first element's location starts the message
  for (const std::string& part :
       {path + ":13:12: tendon 'tie'", path + ":5:13: geom 'ball' (contacts)", path + ":4:14: joint 'hinge' (range)",
        path + ":7:16: joint 'shoulder' (body 'b')", std::string("no --ignore leaves it out"),
        path + ":16:15: actuator 'servo'", std::string("pass --ignore tendons,contacts,limits,actuators")})
    EXPECT_NE(e.find(part), std::string::npos) << part << "\n" << e;
  // Leaving out what can be left out leaves the ball joint.
  hamel::ImportOptions o;
  o.ignore = {"tendons", "contacts", "limits", "actuators"};
  const std::string rest = input_error([&] { hamel::import_mjcf(path, o, quiet); });
  EXPECT_NE(rest.find(path + ":7:"), std::string::npos) << rest;
  EXPECT_NE(rest.find("ball joints"), std::string::npos) << rest;
  EXPECT_EQ(rest.find("--ignore"), std::string::npos) << rest;
}
