// The `hamel gait` command line on the real binary, and issue 50's gait targets confirmed by `hamel phase`
// (a reconstruction that shares no code with the designer's sensitivities, and reads the path as text):
//  - the falling cat (models/falling_cat.yaml) flips by 180° about its long (z) axis: the phase of the gait
//    `hamel gait` writes is Rz(π) to 1e-9;
//  - the satellite with three wheels (models/satellite_so3xr3.yaml) turns by 30° about a given axis;
//  - a pseudo-holonomic loop of the planar space robot about a centre where the initial loop has a clear phase:
//    `hamel phase` finds a net motion below 1e-10 along a loop of the prescribed size;
//  - --json keys, the three files (path, coefficients, SVG over the curvature) in --out; a model without a
//    connection, an unknown --target name and a trivial target exit with status 2, name the file or flag and
//    write nothing.
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using hamel::test::slurp;
using hamel::test::source;
using nlohmann::json;

fs::path scratch_root() { return fs::temp_directory_path() / ("hamel_gait_cli_test_" + std::to_string(::getpid())); }

fs::path scratch(const std::string& name) {
  const fs::path dir = scratch_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override { fs::remove_all(scratch_root()); }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

struct Outcome {
  int status;
  std::string out, err;
};

Outcome hamel(const std::string& args) {
  const fs::path err_file = scratch_root() / "err.txt";
  fs::create_directories(scratch_root());
  const hamel::test::Outcome r =
      hamel::test::run(std::string(HAMEL_BINARY) + " -q " + args + " 2>" + err_file.string());
  return {r.status, r.out, slurp(err_file)};
}

// The rotation of `hamel phase` on the path `hamel gait` wrote into `out`.
std::array<double, 9> confirmed_rotation(const std::string& model, const fs::path& out, const std::string& name) {
  const Outcome r = hamel("phase " + source(model) + " --steps-per-cycle 2000 --no-files --json --path \"$(cat " +
                          (out / (name + "_gait.txt")).string() + ")\"");
  EXPECT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  std::array<double, 9> R{};
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = 0; b < 3; ++b) R[3 * a + b] = j["cycles"][0]["R"][a][b].get<double>();
  return R;
}

// The rotation angle of Aᵀ B.
double angle_between(const std::array<double, 9>& A, const std::array<double, 9>& B) {
  double trace = 0;
  for (int k = 0; k < 9; ++k) trace += A[static_cast<std::size_t>(k)] * B[static_cast<std::size_t>(k)];
  double skew[3] = {0, 0, 0};  // vee(AᵀB − BᵀA) / 2 = sin(angle) n
  for (int i = 0; i < 3; ++i) {
    auto m = [&](int r, int c) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += A[static_cast<std::size_t>(3 * k + r)] * B[static_cast<std::size_t>(3 * k + c)];
      return s;
    };
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    skew[i] = 0.5 * (m(k, j) - m(j, k));
  }
  return std::atan2(std::sqrt(skew[0] * skew[0] + skew[1] * skew[1] + skew[2] * skew[2]), 0.5 * (trace - 1));
}

TEST(GaitCli, FallingCatFlipsByHalfATurnAboutItsLongAxis) {
  const fs::path out = scratch("cat");
  const Outcome r = hamel("gait " + source("models/falling_cat.yaml") +
                          " --target wz=pi --max-iterations 15 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"achieved", "achieved_log", "residual", "error", "cost", "cost_definition", "iterations",
                          "optimality", "reached", "status", "coefficients", "path", "files", "confirm"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["reached"].get<bool>());
  EXPECT_LT(j["error"].get<double>(), 1e-11);
  EXPECT_LE(j["cost"].get<double>(), j["initial_cost"].get<double>() * 1e3);
  EXPECT_EQ(slurp(out / "falling_cat_gait.svg").rfind("<svg", 0), 0u);
  EXPECT_EQ(json::parse(slurp(out / "falling_cat_gait.json"))["path"], j["path"]);
  const std::array<double, 9> Rz_pi = {-1, 0, 0, 0, -1, 0, 0, 0, 1};
  EXPECT_LT(angle_between(Rz_pi, confirmed_rotation("models/falling_cat.yaml", out, "falling_cat")), 1e-9);
}

TEST(GaitCli, SatelliteWithThreeWheelsTurnsBy30Degrees) {
  const fs::path out = scratch("satellite");
  // 30° about the axis (1, 2, 2)/3.
  const Outcome r = hamel("gait " + source("models/satellite_so3xr3.yaml") +
                          " --target wx=pi/18,wy=pi/9,wz=pi/9 --max-iterations 15 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(json::parse(r.out)["reached"].get<bool>());
  const Outcome p = hamel("phase " + source("models/satellite_so3xr3.yaml") +
                          " --steps-per-cycle 2000 --no-files --json --path \"$(cat " +
                          (out / "satellite_so3xr3_gait.txt").string() + ")\"");
  ASSERT_EQ(p.status, 0) << p.err;
  const json c = json::parse(p.out)["cycles"][0];
  std::array<double, 9> R{};
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = 0; b < 3; ++b) R[3 * a + b] = c["R"][a][b].get<double>();
  // Rodrigues for 30° about n = (1, 2, 2)/3, written here.
  const double n[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, th = M_PI / 6, s = std::sin(th), k = 1 - std::cos(th);
  std::array<double, 9> want{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double v = (a == b ? 1.0 : 0.0) + k * (n[a] * n[b] - (a == b ? 1.0 : 0.0));
      const int third = 3 - a - b;
      if (a != b) v += s * ((b == (a + 1) % 3) ? -n[third] : n[third]);
      want[static_cast<std::size_t>(3 * a + b)] = v;
    }
  EXPECT_LT(angle_between(want, R), 1e-9);
  EXPECT_NEAR(angle_between({1, 0, 0, 0, 1, 0, 0, 0, 1}, R), M_PI / 6, 1e-9);
  // The centre of mass stays (the reference point is the total centre of mass).
  for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(c["p"][a].get<double>(), 0.0, 1e-12);
}

TEST(GaitCli, PlanarSpaceRobotPseudoHolonomicLoop) {
  const fs::path out = scratch("robot");
  const std::string centre = " --center q1=0.6,q2=0.9";
  // The initial loop (a circle of radius 0.5 about the centre) turns the base clearly.
  const Outcome initial = hamel("phase " + source("models/planar_space_robot.yaml") +
                                " --no-files --json --path \"0.6 + 0.5*cos(2*pi*t);0.9 - 0.5*sin(2*pi*t)\"");
  ASSERT_EQ(initial.status, 0) << initial.err;
  EXPECT_GT(std::abs(json::parse(initial.out)["cycles"][0]["theta"].get<double>()), 1e-2);

  const Outcome r = hamel("gait " + source("models/planar_space_robot.yaml") + " --pseudo-holonomic" + centre +
                          " --harmonics 2 --json --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["reached"].get<bool>());
  EXPECT_NEAR(j["cost"].get<double>(), j["initial_cost"].get<double>(), 1e-9 * j["cost"].get<double>());
  const Outcome p = hamel("phase " + source("models/planar_space_robot.yaml") +
                          " --steps-per-cycle 2000 --no-files --json --path \"$(cat " +
                          (out / "planar_space_robot_gait.txt").string() + ")\"");
  ASSERT_EQ(p.status, 0) << p.err;
  const json c = json::parse(p.out)["cycles"][0];
  EXPECT_LT(std::abs(c["theta"].get<double>()), 1e-10);
  EXPECT_LT(std::hypot(c["x"].get<double>(), c["y"].get<double>()), 1e-10);
}

TEST(GaitCli, BadInputExitsWithStatus2AndWritesNothing) {
  const fs::path out = scratch("bad");
  struct Bad {
    std::string args, names;
  };
  for (const Bad& b : {Bad{"gait " + source("models/double_pendulum.yaml") + " --target w=1", "bundle model"},
                       Bad{"gait " + source("models/falling_cat.yaml") + " --target spin=1", "--target"},
                       Bad{"gait " + source("models/satellite_thrusters.yaml") + " --pseudo-holonomic", "wrenches"},
                       Bad{"gait " + source("models/falling_cat.yaml"), "--target"},
                       Bad{"gait " + source("models/falling_cat.yaml") + " --target wz=1 --harmonics 0", "--harmonics"},
                       Bad{"gait " + source("models/falling_cat.yaml") + " --target wz=1 --plot psi,psi", "--plot"}}) {
    const Outcome r = hamel(b.args + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << b.args << "\n" << r.err;
    EXPECT_NE(r.err.find(b.names), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_TRUE(fs::is_empty(out)) << b.args;
  }
  const Outcome help = hamel("gait --help");
  EXPECT_EQ(help.status, 0);
  for (const char* flag : {"--target", "--pseudo-holonomic", "--harmonics", "--max-amplitude", "--max-rate"})
    EXPECT_NE(help.out.find(flag), std::string::npos) << flag;
}

}  // namespace
