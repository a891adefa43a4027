// Robot files with bad structure or bad numbers are refused at their own element (file:line, exit 2), never
// imported as a different robot nor reported as an internal error about the model hamel would have written: joints
// that form a cycle or a joint whose parent is its child (a SIGSEGV after deep recursion), an <inertial> urdfdom
// drops (no mass, no inertia, nan, 1e400, hex), negative mass, a triangle violation, negative damping, a massless
// moving link, a mass that moves nothing along its joint (a point mass on a hinge's axis, coaxial hinges on a massless
// link), non-finite gravity. Merged mass properties neither cancel nor overflow silently (a body of mass 1e200 far from
// its frame's origin). Warnings escape names as errors do; a newline in the robot file's path stays inside the YAML
// header's comment and string. A UTF-8 byte order mark at the start of an --input-file, a URDF or MJCF file and a
// model file is read, and errors on line 1 keep their columns.
#include "run_hamel.hpp"

#include <gtest/gtest.h>

namespace {

using namespace hamel_test;

std::string robot(const std::string& body) { return "<robot name=\"arm\">\n" + body + "</robot>\n"; }

std::string link(const std::string& name, const std::string& inertial =
                                              "<inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\" "
                                              "ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial>") {
  return "  <link name=\"" + name + "\">" + inertial + "</link>\n";
}

std::string joint(const std::string& name, const std::string& parent, const std::string& child,
                  const std::string& extra = "") {
  return "  <joint name=\"" + name + "\" type=\"continuous\"><parent link=\"" + parent + "\"/><child link=\"" + child +
         "\"/><axis xyz=\"0 0 1\"/>" + extra + "</joint>\n";
}

class Robot : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = scratch_dir(std::string("robot_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir); }
  // Imports `text` as NAME; expects exit 2 with the error at `line` of the file, naming `key` and `message`.
  void expect_refused(const std::string& name, const std::string& text, int line, const std::string& key,
                      const std::string& message) {
    SCOPED_TRACE(name);
    spit(dir / name, text);
    const Outcome r =
        hamel("import " + shell_quote((dir / name).string()) + " -o " + shell_quote((dir / "out.yaml").string()), dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find((dir / name).string() + ":" + std::to_string(line) + ":"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'" + key), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.yaml"));
  }
  fs::path dir;
};

TEST_F(Robot, JointsThatFormACycleAreRefusedNotRecursedInto) {
  expect_refused("cycle.urdf",
                 robot(link("base", "") + link("a") + link("b") + joint("j1", "base", "a") + joint("j2", "a", "b") +
                       joint("j3", "b", "a")),
                 7, "joint 'j3'", "expected the joints to form a tree");
  expect_refused("self.urdf", robot(link("base", "") + link("a") + joint("j1", "base", "a") + joint("j2", "a", "a")), 5,
                 "joint 'j2'", "its parent and child are the same link 'a'");
}

TEST_F(Robot, AnInertialUrdfdomWouldDropIsRefused) {
  const std::string inertia = "<inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/>";
  const auto arm = [&](const std::string& inertial) {
    return robot(link("base", "") + link("upper", inertial) + joint("shoulder", "base", "upper"));
  };
  expect_refused("no_mass.urdf", arm("<inertial>" + inertia + "</inertial>"), 3, "link 'upper' <inertial>",
                 "has no <mass value=...>");
  expect_refused("no_inertia.urdf", arm("<inertial><mass value=\"1\"/></inertial>"), 3, "link 'upper' <inertial>",
                 "has no <inertia");
  for (const char* bad : {"nan", "1e400", "0x10", "-inf"})
    expect_refused(std::string("mass_") + bad + ".urdf",
                   arm("<inertial><mass value=\"" + std::string(bad) + "\"/>" + inertia + "</inertial>"), 3,
                   "link 'upper' <inertial>", "is not a finite decimal number");
  expect_refused("ixx_nan.urdf",
                 arm("<inertial><mass value=\"1\"/><inertia ixx=\"nan\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" "
                     "izz=\"0.1\"/></inertial>"),
                 3, "link 'upper' <inertial>", "<inertia ixx='nan'>");
}

TEST_F(Robot, BadMassPropertiesAndDampingAreTheRobotFilesErrors) {
  const auto arm = [&](const std::string& mass, const std::string& moments, const std::string& extra = "") {
    return robot(link("base", "") +
                 link("upper", "<inertial><mass value=\"" + mass + "\"/><inertia " + moments + "/></inertial>") +
                 joint("shoulder", "base", "upper", extra));
  };
  const std::string fine = "ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"";
  expect_refused("negative_mass.urdf", arm("-1", fine), 4, "body 'upper'", "expected a mass of at least 0");
  expect_refused("triangle.urdf", arm("1", "ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"3\""), 4,
                 "body 'upper'", "violate the triangle inequality");
  expect_refused("negative_inertia.urdf", arm("1", "ixx=\"-1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\""), 4,
                 "body 'upper'", "negative principal moment");
  expect_refused("negative_damping.urdf", arm("1", fine, "<dynamics damping=\"-2\"/>"), 4, "joint 'shoulder' damping",
                 "expected a value of at least 0");
  expect_refused("massless.urdf", robot(link("base", "") + link("upper", "") + joint("shoulder", "base", "upper")), 4,
                 "joint 'shoulder'", "moves nothing");
}

TEST_F(Robot, AMassThatMovesNothingAlongItsJointIsRefused) {
  const std::string point_mass =
      "<inertial><origin xyz=\"0 0 0.5\"/><mass value=\"1\"/>"
      "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>";
  expect_refused("on_axis.urdf",
                 robot(link("base", "") + link("upper", point_mass) + joint("shoulder", "base", "upper")), 4,
                 "joint 'shoulder'", "moves no mass or inertia along its motion");
  // Coaxial hinges: the outer body has inertia, the spacer none; the inner joint only repeats the outer one.
  expect_refused("coaxial.urdf",
                 robot(link("base", "") + link("spacer", "") + link("wheel") + joint("inner", "base", "spacer") +
                       joint("outer", "spacer", "wheel")),
                 5, "joint 'inner'", "so the mass matrix would be singular");
}

TEST_F(Robot, AHeavyMergedBodyKeepsItsInertia) {
  // Body b: mass M at (3, 0, 0), inertia diag(1, 1, 1); its fixed child c: mass 1 at (0, 0, 1), diag(1, 1, 1). Merged
  // about the centre of mass (3, 0, 0): 2 I + (M / (M + 1)) (|d|^2 I - d d'), d = (-3, 0, 1).
  const auto heavy = [](const std::string& m1, const std::string& m2) {
    return "<mujoco model=\"heavy\">\n  <worldbody>\n    <body name=\"b\">\n"
           "      <joint name=\"h\" type=\"hinge\" axis=\"0 1 0\"/>\n"
           "      <inertial pos=\"3 0 0\" mass=\"" +
           m1 +
           "\" diaginertia=\"1 1 1\"/>\n"
           "      <body name=\"c\" pos=\"0 0 1\"><inertial pos=\"0 0 0\" mass=\"" +
           m2 + "\" diaginertia=\"1 1 1\"/></body>\n    </body>\n  </worldbody>\n</mujoco>\n";
  };
  spit(dir / "heavy.xml", heavy("1e200", "1"));
  const Outcome r = hamel("import " + shell_quote((dir / "heavy.xml").string()) + " -o -", dir);
  ASSERT_EQ(r.status, 0) << r.err;  // was: "a negative principal moment (-1.85)", the inertia lost to cancellation
  EXPECT_NE(r.out.find("inertia: [[3, 0, 3], [0, 12, 0], [3, 0, 11]]"), std::string::npos) << r.out;
  // Beyond the range of a double: refused at the body, not written as inf or nan.
  expect_refused("overflow.xml", heavy("1.7e308", "1e308"), 4, "body 'b'", "beyond the range of a double");
}

TEST_F(Robot, AByteOrderMarkStartsARobotOrModelFile) {
  const std::string bom = "\xEF\xBB\xBF";
  spit(dir / "arm.urdf", bom + robot(link("base", "") + link("upper") + joint("shoulder", "base", "upper")));
  Outcome r = hamel(
      "import " + shell_quote((dir / "arm.urdf").string()) + " -o " + shell_quote((dir / "arm.yaml").string()), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  const std::string mjcf_body =
      "<worldbody><body name=\"b\"><joint name=\"h\" type=\"ball\"/><geom type=\"sphere\" size=\"0.1\" "
      "mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body></worldbody></mujoco>\n";
  spit(dir / "ok.xml", bom + "<mujoco model=\"r\">\n" + mjcf_body);
  std::string text = slurp(dir / "ok.xml");
  text.replace(text.find("ball"), 4, "hinge");
  spit(dir / "ok.xml", text);
  r = hamel("import " + shell_quote((dir / "ok.xml").string()) + " -o -", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  // An error on line 1 has the column of the text after the mark (52, as without it; was 55).
  expect_refused("ball.xml", bom + "<mujoco model=\"r\">" + mjcf_body, 1, "joint 'h'", "ball joints");
  spit(dir / "ball.xml", bom + "<mujoco model=\"r\">" + mjcf_body);
  r = hamel("import " + shell_quote((dir / "ball.xml").string()) + " -o -", dir);
  EXPECT_NE(r.err.find("ball.xml:1:52:"), std::string::npos) << r.err;
  // A model file: read, and an error on line 1 is at column 1.
  const std::string model =
      "parameters: {m: 1, k: 4}\ncoordinates: [x]\nquasi_velocities: {names: [u], A: [[1]]}\n"
      "lagrangian: \"m/2*x_dot^2 - k/2*x^2\"\n";
  spit(dir / "m.yaml", bom + "name: spring\n" + model);
  r = hamel("derive " + shell_quote((dir / "m.yaml").string()), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  spit(dir / "bad.yaml", bom + "nam: spring\n" + model);
  r = hamel("derive " + shell_quote((dir / "bad.yaml").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("bad.yaml:1:1: error: 'nam'"), std::string::npos) << r.err;
}

TEST_F(Robot, NonFiniteGravityInMjcfIsNamed) {
  spit(dir / "g.xml",
       "<mujoco model=\"g\">\n"
       "  <option gravity=\"0 0 nan\"/>\n"
       "  <worldbody><body name=\"b\"><joint name=\"h\" type=\"hinge\" axis=\"0 1 0\"/>"
       "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body></worldbody>\n"
       "</mujoco>\n");
  const Outcome r =
      hamel("import " + shell_quote((dir / "g.xml").string()) + " -o " + shell_quote((dir / "out.yaml").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'gravity'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.yaml"));
}

TEST_F(Robot, WarningsEscapeNamesAsErrorsDo) {
  spit(dir / "ref.xml",
       "<mujoco model=\"r\">\n"
       "  <worldbody><body name=\"b\"><joint name=\"h&#x1b;[31mred\" type=\"hinge\" axis=\"0 1 0\" ref=\"0.5\"/>"
       "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body></worldbody>\n"
       "</mujoco>\n");
  const Outcome r = hamel("import " + shell_quote((dir / "ref.xml").string()) + " -o -", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << "a raw escape character reached the terminal";
  EXPECT_NE(r.err.find("\\x1b"), std::string::npos) << r.err;
}

TEST_F(Robot, ANewlineInThePathStaysInsideTheYamlHeader) {
  const fs::path odd = dir / "arm\nschema: 2\n\x1b.urdf";
  spit(odd, robot(link("base", "") + link("upper") + joint("shoulder", "base", "upper")));
  const Outcome r =
      hamel("import " + shell_quote(odd.string()) + " -o " + shell_quote((dir / "out.yaml").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string yaml = slurp(dir / "out.yaml");
  EXPECT_EQ(yaml.find("\nschema: 2"), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find('\x1b'), std::string::npos) << yaml;
  const Outcome d = hamel("derive " + shell_quote((dir / "out.yaml").string()), dir);
  EXPECT_EQ(d.status, 0) << d.err;
}

TEST_F(Robot, AByteOrderMarkStartsAnInputFile) {
  spit(dir / "m.yaml",
       "name: driven\nparameters: {m: 1, k: 4}\ncoordinates: [x]\nquasi_velocities: {names: [u], A: [[1]]}\n"
       "lagrangian: \"m/2*x_dot^2 - k/2*x^2\"\nforces: [tau]\ninputs: [tau]\n");
  spit(dir / "in.csv", "\xEF\xBB\xBFt,tau\n0,1\n1,1\n");
  const Outcome r =
      hamel("simulate " + shell_quote((dir / "m.yaml").string()) + " --t-end 1 --sample 0.5 --input-file " +
                shell_quote((dir / "in.csv").string()) + " --out -",
            dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("t,x,u\n", 0), 0u) << r.out;
}

}  // namespace
