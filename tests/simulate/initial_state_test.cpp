// Where `simulate` and `report` start: the model's key `initial` (the variables it does not name 0), overridden by
// a scene's `initial`, overridden by --init. Checked on the Chaplygin sleigh, whose straight run at speed v from
// the origin (theta = 0, omega = 0) is x(t) = v t, y = 0: the value of v each source gives shows in x(1).
#include "run_hamel.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace hamel_test;

const char* sleigh = R"yaml(name: sleigh
parameters: {m: 1, a: 0.2}
coordinates: [x, y, theta]
quasi_velocities:
  names: [u_lat, v, omega]
  A:
    - ["-sin(theta)", "cos(theta)", 0]
    - ["cos(theta)", "sin(theta)", 0]
    - [0, 0, 1]
constraints: [u_lat]
lagrangian: "m/2*(x_dot^2 + y_dot^2) + m*a^2/2*theta_dot^2"
initial: {v: 1}
)yaml";

// The last row of simulate's CSV as column → value.
std::vector<std::pair<std::string, double>> last_row(const std::string& csv) {
  std::istringstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<std::pair<std::string, double>> row;
  std::stringstream h(header), v(last);
  std::string name, value;
  while (std::getline(h, name, ',') && std::getline(v, value, ',')) row.emplace_back(name, std::stod(value));
  return row;
}

double column(const std::vector<std::pair<std::string, double>>& row, const std::string& name) {
  for (const auto& [n, v] : row)
    if (n == name) return v;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

TEST(InitialState, ModelSceneAndCommandLineOverrideInTurn) {
  const fs::path dir = scratch_dir("initial_state");
  spit(dir / "sleigh.yaml", sleigh);
  spit(dir / "scene.yaml", "scene: run\nmodel: sleigh.yaml\ninitial: {v: 2}\n");
  const std::string run = " --t-end 1 --tol 1e-12";
  const std::string model = shell_quote((dir / "sleigh.yaml").string()),
                    scene = shell_quote((dir / "scene.yaml").string());
  struct Case {
    std::string args;
    double v;
  };
  for (const Case& c : {Case{"simulate " + model + run, 1}, Case{"simulate " + scene + run, 2},
                        Case{"simulate " + scene + run + " --init v=3", 3}}) {
    const Outcome r = hamel(c.args, dir);
    ASSERT_EQ(r.status, 0) << c.args << "\n" << r.err;
    const auto row = last_row(r.out);
    EXPECT_NEAR(column(row, "t"), 1.0, 1e-15) << c.args;
    EXPECT_NEAR(column(row, "x"), c.v, 1e-10) << c.args;  // x(1) = v: the sleigh runs straight
    EXPECT_NEAR(column(row, "y"), 0.0, 1e-12) << c.args;
    EXPECT_NEAR(column(row, "v"), c.v, 1e-12) << c.args;
  }
}

TEST(InitialState, AnUnknownNameInASceneIsReportedAtItsLine) {
  const fs::path dir = scratch_dir("initial_state_scene_error");
  spit(dir / "sleigh.yaml", sleigh);
  spit(dir / "scene.yaml", "scene: run\nmodel: sleigh.yaml\ninitial:\n  v: 2\n  u_lat: 1\n");
  const Outcome r = hamel("simulate " + shell_quote((dir / "scene.yaml").string()) + " --t-end 1", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("scene.yaml:5:3: error: 'initial.u_lat': 'u_lat' is not a state variable"), std::string::npos)
      << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(InitialState, ReportStartsFromTheModelsStateWithTheRestZero) {
  const fs::path dir = scratch_dir("initial_state_report");
  spit(dir / "sleigh.yaml", sleigh);
  // Without the key the report starts away from equilibria (coordinates 0.1 k, velocities 0.5); with it, from the
  // model's state, the variables it does not name at 0.
  const Outcome r = hamel("report " + shell_quote((dir / "sleigh.yaml").string()) +
                              " --t-end 0.5 --integrators dop853 --out " + shell_quote(dir.string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string md = slurp(dir / "sleigh_work_precision.md");
  EXPECT_NE(md.find("initial state x = 0, y = 0, theta = 0, v = 1, omega = 0."), std::string::npos) << md;
}

}  // namespace
