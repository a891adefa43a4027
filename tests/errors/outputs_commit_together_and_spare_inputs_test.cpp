// One output transaction for every verb (report/atomic_file.hpp, OutputTransaction): all outputs of a run are
// committed together after everything succeeded; an output that names an input of the run (model, scene,
// --input-file, robot file) or another output is refused with exit 2 before anything is written; a read-only file
// is not replaced; a closed stdout pipe is a failed write (exit 1), not SIGPIPE.
#include "run_hamel.hpp"

#include <sys/stat.h>

#include <gtest/gtest.h>

#include <set>

namespace {

using namespace hamel_test;

const char* spring =
    "name: spring\n"
    "parameters: {m: 1, k: 4}\n"
    "coordinates: [x]\n"
    "quasi_velocities: {names: [u], A: [[1]]}\n"
    "lagrangian: \"m/2*x_dot^2 - k/2*x^2\"\n"
    "forces: [tau]\n"
    "inputs: [tau]\n";

const char* arm =
    "<robot name=\"arm\">\n"
    "  <link name=\"base\"/>\n"
    "  <link name=\"upper\"><inertial><mass value=\"1\"/>"
    "<inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial></link>\n"
    "  <joint name=\"shoulder\" type=\"continuous\"><parent link=\"base\"/><child link=\"upper\"/>"
    "<axis xyz=\"0 0 1\"/></joint>\n"
    "</robot>\n";

bool has_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.find(".tmp-") != std::string::npos || n.find(".old-") != std::string::npos) return true;
  }
  return false;
}

class Transaction : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = scratch_dir(std::string("tx_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    spit(dir / "spring.yaml", spring);
  }
  void TearDown() override {
    fs::permissions(dir, fs::perms::owner_all, fs::perm_options::add);
    fs::remove_all(dir);
  }
  std::string path(const std::string& name) const { return shell_quote((dir / name).string()); }
  fs::path dir;
};

TEST_F(Transaction, LinearizeKeepsTheOldTableWhenThePlotCannotBeWritten) {
  spit(dir / "table.csv", "old table\n");
  fs::create_directory(dir / "plot.svg");  // a folder: the plot cannot be written
  Outcome r = hamel("linearize " + path("spring.yaml") + " --sweep k=1:2:0.5 --out " + path("table.csv") + " --plot " +
                        path("plot.svg"),
                    dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(slurp(dir / "table.csv"), "old table\n") << "the table was replaced before the plot failed";
  // A plot in a folder that does not exist: the same.
  r = hamel("linearize " + path("spring.yaml") + " --sweep k=1:2:0.5 --out " + path("table.csv") + " --plot " +
                path("missing/plot.svg"),
            dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(slurp(dir / "table.csv"), "old table\n");
  EXPECT_FALSE(has_temporaries(dir));
  // Both on one path: refused, nothing written.
  r = hamel("linearize " + path("spring.yaml") + " --sweep k=1:2:0.5 --out " + path("both") + " --plot " + path("both"),
            dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is also the output --out"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "both"));
  // And when everything succeeds, both are written.
  fs::remove(dir / "plot.svg");
  r = hamel("linearize " + path("spring.yaml") + " --sweep k=1:2:0.5 --out " + path("table.csv") + " --plot " +
                path("plot.svg"),
            dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir / "table.csv").rfind("k,re1", 0), 0u);
  EXPECT_NE(slurp(dir / "plot.svg").find("<svg"), std::string::npos);
}

TEST_F(Transaction, AnOutputNeverReplacesAnInput) {
  const std::string model_text = slurp(dir / "spring.yaml");
  Outcome r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out " + path("spring.yaml"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is the model file of this run"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "spring.yaml"), model_text);

  spit(dir / "in.csv", "t,tau\n0,1\n1,2\n");
  r = hamel(
      "simulate " + path("spring.yaml") + " --t-end 1 --input-file " + path("in.csv") + " --out " + path("in.csv"),
      dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is the --input-file of this run"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "in.csv"), "t,tau\n0,1\n1,2\n");

  // Through another name of the same file (a symbolic link, a hard link).
  fs::create_symlink("spring.yaml", dir / "link.yaml");
  fs::create_hard_link(dir / "spring.yaml", dir / "hard.yaml");
  for (const char* other : {"link.yaml", "hard.yaml"}) {
    r = hamel("linearize " + path("spring.yaml") + " --out " + path(other), dir);
    EXPECT_EQ(r.status, 2) << other << ": " << r.err;
    EXPECT_EQ(slurp(dir / "spring.yaml"), model_text) << other;
  }

  spit(dir / "arm.urdf", arm);
  r = hamel("import " + path("arm.urdf") + " -o " + path("arm.urdf"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is the robot file of this run"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "arm.urdf"), arm);
  EXPECT_FALSE(has_temporaries(dir));
}

// A file an MJCF robot file includes (<include file=...>) is an input of the run like the robot file itself: import's
// -o onto it, by its name or through another path to it, is refused and the file kept.
TEST_F(Transaction, AnIncludedFileIsAnInputToo) {
  const std::string included =
      "<mujoco>\n  <worldbody><body name=\"b\"><joint name=\"h\" type=\"hinge\" axis=\"0 1 0\"/>"
      "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body></worldbody>\n"
      "</mujoco>\n";
  fs::create_directory(dir / "parts");
  spit(dir / "parts" / "body.xml", included);
  spit(dir / "robot.xml", "<mujoco model=\"r\">\n  <include file=\"parts/body.xml\"/>\n</mujoco>\n");
  for (const std::string& target : {path("parts/body.xml"), path("parts/../parts/body.xml")}) {
    const Outcome r = hamel("import " + path("robot.xml") + " -o " + target, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("is a file the robot file names (file=\"parts/body.xml\") of this run"), std::string::npos)
        << r.err;
    EXPECT_EQ(slurp(dir / "parts" / "body.xml"), included);
  }
  // Elsewhere, the import works.
  const Outcome r = hamel("import " + path("robot.xml") + " -o " + path("robot.yaml"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(has_temporaries(dir));
}

TEST_F(Transaction, AReadOnlyOutputIsNotReplaced) {
  spit(dir / "kept.csv", "mine\n");
  fs::permissions(dir / "kept.csv", fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const Outcome r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out " + path("kept.csv"), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is read-only"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "kept.csv"), "mine\n");
  EXPECT_EQ(fs::status(dir / "kept.csv").permissions() & fs::perms::owner_write, fs::perms::none);
  EXPECT_FALSE(has_temporaries(dir));
}

TEST_F(Transaction, AReplacedOutputKeepsItsPermissions) {
  spit(dir / "shared.csv", "old\n");
  fs::permissions(dir / "shared.csv", fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  const Outcome r = hamel("simulate " + path("spring.yaml") + " --t-end 1 --out " + path("shared.csv"), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(fs::status(dir / "shared.csv").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(Transaction, AClosedStdoutPipeIsAFailedWriteNotSigpipe) {
  // `head -c 1` closes the pipe after one byte; hamel's status is taken from the pipeline's first command.
  const Outcome r = run_command("bash -c 'set -o pipefail; " + shell_quote(hamel_binary()) + " simulate " +
                                    shell_quote((dir / "spring.yaml").string()) +
                                    " --t-end 100 --dt 1e-4 --integrator rk4 --out - | head -c 1 >/dev/null; "
                                    "echo status=${PIPESTATUS[0]} >&2'",
                                dir);
  EXPECT_NE(r.err.find("status=1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cannot write standard output"), std::string::npos) << r.err;
}

}  // namespace
