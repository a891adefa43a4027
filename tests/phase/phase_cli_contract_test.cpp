// The `hamel phase` command-line contract, on the real binary:
//  - `--json` prints {"cycles": [{"cycle", "t", ...}]} with one entry per cycle: R and p for SE(3) (and
//    SO(3)×R³), R alone for SO(3), theta, x and y for SE(2); `--momentum rest` adds `dynamic`;
//  - the values are right for two small models with closed-form phases, written here: a rigid body with
//    one rotor about its z axis on SO(3), and a planar body whose frame F_b is a distance a from its
//    centre of mass, with one rotor, on SE(2). With zero momentum the body turns about its centre of
//    mass at ω = −(J/I) φ̇, so φ = 2πt gives θ_k = −2πk J/I after cycle k (I about the centre of mass);
//    on SE(2) the centre of mass stays at (a, 0), so F_b is at (a − a cos θ, −a sin θ);
//  - a path with the wrong number of entries exits with status 2, prints nothing on stdout and names
//    --path on stderr;
//  - <model>_phase.csv (trajectory) and <model>_phase.svg (x–y plot when the group has a translation, the
//    rotation vector over time on SO(3)) are written into --out; nothing is written with --no-files.
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
#include <sstream>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using hamel::test::slurp;
using hamel::test::source;

fs::path scratch_root() { return fs::temp_directory_path() / ("hamel_phase_cli_test_" + std::to_string(::getpid())); }

fs::path scratch(const std::string& name) {
  const fs::path dir = scratch_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Removes the scratch folder after the last test.
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override { fs::remove_all(scratch_root()); }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

struct Outcome {
  int status;
  std::string out, err;
};

// Runs `hamel ARGS`, capturing stdout and stderr.
Outcome hamel(const std::string& args) {
  const fs::path err_file = scratch("stderr") / "err.txt";
  const hamel::test::Outcome r = hamel::test::run(std::string(HAMEL_BINARY) + " " + args + " 2>" + err_file.string());
  return {r.status, r.out, slurp(err_file)};
}

// The paper's Sec. 6c path.
const std::string kSatellitePath = "\"pi*(cos(2*pi*t) - 1);pi*sin(2*pi*t);pi/2*sin(4*pi*t)\"";

constexpr double kPi = 3.14159265358979323846;

fs::path write_model(const std::string& name, const std::string& text) {
  const fs::path p = scratch("models") / (name + ".yaml");
  std::ofstream(p) << text;
  return p;
}

// I3 = 3, J = 1: θ_k = −2πk/3.
const char* const kBodyWithRotor = R"(schema: 1
name: body_with_rotor
description: rigid body with one rotor spinning about the body z axis
parameters:
  I1: 1.0
  I2: 2.0
  I3: 3.0
  J: 1.0
group: SO3
trivialization: left
group_velocity: [wx, wy, wz]
shape: [phi]
connection: mechanical
kinetic: "1/2*(I1*wx^2 + I2*wy^2 + I3*wz^2) + J*wz*phi_dot + 1/2*J*phi_dot^2"
)";

// F_b at distance a from the centre of mass: the centre of mass moves with (vx, vy + a w) in F_b.
// Iz = 2 about the centre of mass, J = 0.5: θ_k = −πk/2.
const char* const kPlanarBodyWithRotor = R"(schema: 1
name: planar_body_with_rotor
description: planar body with a rotor, frame off the centre of mass
parameters:
  m: 4.0
  Iz: 2.0
  J: 0.5
  a: 0.3
group: SE2
trivialization: left
group_velocity: [w, vx, vy]
shape: [phi]
connection: mechanical
kinetic: "1/2*m*(vx^2 + (vy + a*w)^2) + 1/2*Iz*w^2 + J*w*phi_dot + 1/2*J*phi_dot^2"
)";

void expect_keys(const json& entry, std::initializer_list<const char*> present,
                 std::initializer_list<const char*> absent) {
  for (const char* k : present) EXPECT_TRUE(entry.contains(k)) << k << " in " << entry.dump();
  for (const char* k : absent) EXPECT_FALSE(entry.contains(k)) << k << " in " << entry.dump();
}

TEST(PhaseCli, Se3JsonHasRotationAndTranslationPerCycleAndWritesCsvAndSvg) {
  const fs::path out = scratch("se3");
  const Outcome r =
      hamel("phase " + source("models/satellite_se3.yaml") + " --path " + kSatellitePath +
            " --period 0.5 --cycles 3 --steps-per-cycle 200 --momentum rest --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["model"], "satellite_se3");
  EXPECT_EQ(j["group"], "SE3");
  EXPECT_EQ(j["momentum"], "rest");
  for (const char* list : {"cycles", "dynamic"}) {
    ASSERT_TRUE(j.contains(list));
    ASSERT_EQ(j[list].size(), 3u) << list;
    for (int k = 0; k < 3; ++k) {
      const json& c = j[list][static_cast<std::size_t>(k)];
      expect_keys(c, {"cycle", "t", "R", "p"}, {"theta", "x", "y"});
      EXPECT_EQ(c["cycle"], k + 1);
      EXPECT_DOUBLE_EQ(c["t"].get<double>(), 0.5 * (k + 1));
      ASSERT_EQ(c["R"].size(), 3u);
      double orthogonality = 0;  // |R Rᵀ − I|
      for (int a = 0; a < 3; ++a) {
        ASSERT_EQ(c["R"][static_cast<std::size_t>(a)].size(), 3u);
        for (int b = 0; b < 3; ++b) {
          double s = 0;
          for (std::size_t i = 0; i < 3; ++i)
            s += c["R"][static_cast<std::size_t>(a)][i].get<double>() *
                 c["R"][static_cast<std::size_t>(b)][i].get<double>();
          orthogonality = std::fmax(orthogonality, std::fabs(s - (a == b ? 1.0 : 0.0)));
        }
      }
      EXPECT_LT(orthogonality, 1e-13);
      EXPECT_EQ(c["p"].size(), 3u);
    }
  }
  const fs::path csv = out / "satellite_se3_phase.csv", svg = out / "satellite_se3_phase.svg";
  ASSERT_TRUE(fs::exists(csv));
  ASSERT_TRUE(fs::exists(svg));
  EXPECT_EQ(j["trajectory"], csv.string());
  EXPECT_EQ(j["plot"], svg.string());
  std::istringstream lines(slurp(csv));
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "t,R00,R01,R02,R10,R11,R12,R20,R21,R22,px,py,pz");
  int rows = 0;
  for (std::string line; std::getline(lines, line);) ++rows;
  EXPECT_EQ(rows, 1 + 3 * 100);  // t = 0 and --samples-per-cycle (100) per cycle
  EXPECT_NE(slurp(svg).find("<svg"), std::string::npos);
}

TEST(PhaseCli, So3xR3JsonHasRotationAndTranslation) {
  const Outcome r = hamel("phase " + source("models/satellite_so3xr3.yaml") + " --path " + kSatellitePath +
                          " --cycles 2 --steps-per-cycle 200 --json --no-files");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["cycles"].size(), 2u);
  for (const json& c : j["cycles"]) expect_keys(c, {"cycle", "t", "R", "p"}, {"theta", "x", "y"});
  EXPECT_FALSE(j.contains("dynamic"));  // zero momentum by default
}

TEST(PhaseCli, So3JsonHasOnlyTheRotationWithTheClosedFormValue) {
  const fs::path model = write_model("body_with_rotor", kBodyWithRotor);
  const fs::path out = scratch("so3");
  const Outcome r = hamel("phase " + model.string() + " --path \"2*pi*t\" --cycles 4 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["group"], "SO3");
  ASSERT_EQ(j["cycles"].size(), 4u);
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    const json& c = j["cycles"][static_cast<std::size_t>(k)];
    expect_keys(c, {"cycle", "t", "R"}, {"p", "theta", "x", "y"});
    const double th = -2 * kPi * (k + 1) / 3.0;
    const double Rz[3][3] = {{std::cos(th), -std::sin(th), 0}, {std::sin(th), std::cos(th), 0}, {0, 0, 1}};
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t b = 0; b < 3; ++b) worst = std::fmax(worst, std::fabs(c["R"][a][b].get<double>() - Rz[a][b]));
  }
  std::printf("SO3 body with rotor: max |R - Rz(-2 pi k J/I3)| = %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);  // a constant velocity: exact up to rounding
  // The trajectory is written, and a plot of the rotation vector over time (no translation to plot).
  EXPECT_TRUE(fs::exists(out / "body_with_rotor_phase.csv"));
  ASSERT_TRUE(fs::exists(out / "body_with_rotor_phase.svg"));
  EXPECT_EQ(j["plot"], (out / "body_with_rotor_phase.svg").string());
  const std::string svg = slurp(out / "body_with_rotor_phase.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  for (const char* label : {"rotation vector", ">wx<", ">wy<", ">wz<", "after each cycle"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  std::istringstream lines(slurp(out / "body_with_rotor_phase.csv"));
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "t,R00,R01,R02,R10,R11,R12,R20,R21,R22");
}

TEST(PhaseCli, Se2JsonHasThetaXYWithTheClosedFormValue) {
  const fs::path model = write_model("planar_body_with_rotor", kPlanarBodyWithRotor);
  const fs::path out = scratch("se2");
  const Outcome r = hamel("phase " + model.string() + " --path \"2*pi*t\" --cycles 3 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["group"], "SE2");
  ASSERT_EQ(j["cycles"].size(), 3u);
  const double a = 0.3;
  double worst = 0;
  for (int k = 0; k < 3; ++k) {
    const json& c = j["cycles"][static_cast<std::size_t>(k)];
    expect_keys(c, {"cycle", "t", "theta", "x", "y"}, {"R", "p"});
    const double th = -kPi * (k + 1) / 2.0;
    worst = std::fmax(worst, std::fabs(c["theta"].get<double>() - th));
    worst = std::fmax(worst, std::fabs(c["x"].get<double>() - (a - a * std::cos(th))));
    worst = std::fmax(worst, std::fabs(c["y"].get<double>() - (-a * std::sin(th))));
  }
  std::printf("SE2 planar body with rotor: max |(theta, x, y) - closed form| = %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
  EXPECT_TRUE(fs::exists(out / "planar_body_with_rotor_phase.csv"));
  EXPECT_TRUE(fs::exists(out / "planar_body_with_rotor_phase.svg"));
  std::istringstream lines(slurp(out / "planar_body_with_rotor_phase.csv"));
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "t,theta,x,y");
}

TEST(PhaseCli, WrongNumberOfPathEntriesExitsWithStatus2AndNamesPath) {
  const fs::path out = scratch("bad");
  for (const std::string path : {"\"t;t\"", "\"t;t;t;t\""}) {
    const Outcome r =
        hamel("phase " + source("models/satellite_se3.yaml") + " --path " + path + " --json --out " + out.string());
    EXPECT_EQ(r.status, 2) << path;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_NE(r.err.find("--path"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(PhaseCli, NoFilesWritesNothing) {
  const fs::path out = scratch("none");
  const Outcome r = hamel("phase " + source("models/satellite_se3.yaml") + " --path " + kSatellitePath +
                          " --steps-per-cycle 100 --json --no-files --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["cycles"].size(), 1u);
  EXPECT_FALSE(j.contains("trajectory"));
  EXPECT_FALSE(j.contains("plot"));
  EXPECT_TRUE(fs::is_empty(out));
}

}  // namespace
