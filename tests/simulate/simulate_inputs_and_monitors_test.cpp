// `hamel simulate` inputs and monitors against closed-form solutions of a forced linear oscillator
// m x'' + k x = F (m = 1, k = 4, ω = 2), and of the free rigid body:
//  - --input-file: F a ramp 2t up to t = 1, then held at 2 (linear interpolation between the rows; held
//    after the last): x = t/2 − sin(2t)/4 for t ≤ 1, and after it the homogeneous solution about 1/2
//    continued from x(1), x'(1);
//  - --input with a feedback law F = −2 v − 2 (x − 1/2) (a PD controller towards 1/2): x'' + 2x' + 6x = 1,
//    x = 1/6 + e^{−t}(c1 cos √5 t + c2 sin √5 t);
//  - --monitors energy,momentum: the energy column is ½ m v² + ½ k x², p_v = m v; on the free rigid body
//    p = Θ ω (Θ from the model's defaults) and the energy ½ ω·Θω, constant;
//  - --monitors constraint_residual on the rolling ball: one column per constraint, at rounding level;
//  - errors: an unknown input, a law with an unknown name, a table with decreasing times (file:line);
//  - and `hamel phase`'s warning for a shape path that does not close.
#include "run_hamel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace hamel_test;

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  double at(std::size_t row, const std::string& column) const {
    for (std::size_t c = 0; c < header.size(); ++c)
      if (header[c] == column) return rows.at(row)[c];
    throw std::runtime_error("no column " + column);
  }
};

Csv parse_csv(const std::string& text) {
  Csv csv;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (csv.header.empty()) {
      csv.header = cells;
      continue;
    }
    std::vector<double> r;
    for (const auto& c : cells) r.push_back(std::stod(c));
    csv.rows.push_back(r);
  }
  return csv;
}

const char* oscillator = R"(name: oscillator
parameters: {m: 1, k: 4}
coordinates: [x]
quasi_velocities: {names: [v], A: [[1]]}
lagrangian: m*x_dot^2/2 - k*x^2/2
forces: [F]
inputs: [F]
)";

std::string source_dir() {
  const char* d = std::getenv("HAMEL_SOURCE_DIR");
  return d ? d : ".";
}

TEST(SimulateInputs, TableIsInterpolatedLinearlyAndHeld) {
  const fs::path dir = scratch_dir("inputs_table");
  spit(dir / "osc.yaml", oscillator);
  spit(dir / "in.csv", "t,F\n0,0\n1,2\n3,2\n");
  const Outcome r = hamel("simulate " + shell_quote((dir / "osc.yaml").string()) +
                              " --t-end 4 --sample 0.25 --tol 1e-12 "
                              "--input-file " +
                              shell_quote((dir / "in.csv").string()) + " --monitors energy,momentum",
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = parse_csv(r.out);
  ASSERT_EQ(csv.header, (std::vector<std::string>{"t", "x", "v", "energy", "p_v"}));
  const double x1 = 0.5 - std::sin(2.0) / 4, v1 = 0.5 - std::cos(2.0) / 2;
  for (std::size_t k = 0; k < csv.rows.size(); ++k) {
    const double t = csv.at(k, "t");
    double x, v;
    if (t <= 1) {
      x = t / 2 - std::sin(2 * t) / 4;
      v = 0.5 - std::cos(2 * t) / 2;
    } else {  // F = 2 beyond t = 1 (the table holds its last value after t = 3): equilibrium 1/2
      const double s = t - 1;
      x = 0.5 + (x1 - 0.5) * std::cos(2 * s) + v1 / 2 * std::sin(2 * s);
      v = -2 * (x1 - 0.5) * std::sin(2 * s) + v1 * std::cos(2 * s);
    }
    EXPECT_NEAR(csv.at(k, "x"), x, 1e-9) << "t = " << t;
    EXPECT_NEAR(csv.at(k, "v"), v, 1e-9) << "t = " << t;
    EXPECT_NEAR(csv.at(k, "energy"), v * v / 2 + 2 * x * x, 1e-9) << "t = " << t;
    EXPECT_NEAR(csv.at(k, "p_v"), v, 1e-9) << "t = " << t;
  }
}

TEST(SimulateInputs, FeedbackLawInStateAndTime) {
  const fs::path dir = scratch_dir("inputs_law");
  spit(dir / "osc.yaml", oscillator);
  // Written with t so that the law is also a function of time (t*0 adds nothing).
  const Outcome r = hamel("simulate " + shell_quote((dir / "osc.yaml").string()) +
                              " --t-end 3 --sample 0.5 --tol 1e-12 --init x=1 --input 'F=-2*v - 2*(x - 1/2) + 0*t'",
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = parse_csv(r.out);
  const double w = std::sqrt(5.0), c1 = 1 - 1.0 / 6, c2 = c1 / w;  // x(0) = 1, x'(0) = 0
  for (std::size_t k = 0; k < csv.rows.size(); ++k) {
    const double t = csv.at(k, "t");
    EXPECT_NEAR(csv.at(k, "x"), 1.0 / 6 + std::exp(-t) * (c1 * std::cos(w * t) + c2 * std::sin(w * t)), 1e-9);
  }
}

TEST(SimulateMonitors, FreeRigidBodyMomentumAndEnergy) {
  const fs::path dir = scratch_dir("monitors_body");
  const Outcome r = hamel("simulate " + shell_quote(source_dir() + "/models/free_rigid_body.yaml") +
                              " --t-end 1 --sample 0.5 --init wx=0.3,wy=-1,wz=0.7 --monitors momentum,energy",
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = parse_csv(r.out);
  std::vector<std::string> p;
  for (const auto& h : csv.header)
    if (h.rfind("p_", 0) == 0) p.push_back(h);
  ASSERT_EQ(p.size(), 3u) << r.out;
  // The body's principal inertias from the monitors at t = 0 (p = Θ ω, ω known), then p = Θ ω and E = ½ ω·Θω
  // at every later row.
  const double w0[3] = {0.3, -1, 0.7};
  double theta[3];
  for (int i = 0; i < 3; ++i) theta[i] = csv.at(0, p[static_cast<std::size_t>(i)]) / w0[i];
  for (std::size_t k = 0; k < csv.rows.size(); ++k) {
    double e = 0;
    for (int i = 0; i < 3; ++i) {
      const std::string w = p[static_cast<std::size_t>(i)].substr(2);
      EXPECT_NEAR(csv.at(k, p[static_cast<std::size_t>(i)]), theta[i] * csv.at(k, w), 1e-12);
      e += theta[i] * csv.at(k, w) * csv.at(k, w) / 2;
    }
    EXPECT_NEAR(csv.at(k, "energy"), e, 1e-12);
    EXPECT_NEAR(csv.at(k, "energy"), csv.at(0, "energy"), 1e-7);
  }
}

TEST(SimulateMonitors, ConstraintResidualColumns) {
  const fs::path dir = scratch_dir("monitors_residual");
  const Outcome r = hamel("simulate " + shell_quote(source_dir() + "/models/rolling_ball.yaml") +
                              " --t-end 1 --sample 0.5 --init vx=1,vy=0.5 --monitors constraint_residual",
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Csv csv = parse_csv(r.out);
  int columns = 0;
  for (const auto& h : csv.header)
    if (h.rfind("residual_", 0) == 0) {
      ++columns;
      for (std::size_t k = 0; k < csv.rows.size(); ++k) EXPECT_NEAR(csv.at(k, h), 0, 1e-12);
    }
  EXPECT_EQ(columns, 3) << r.out;  // u1, u2, u3: rolling without slipping
}

TEST(SimulateInputs, BadInputsAreInputErrors) {
  const fs::path dir = scratch_dir("inputs_errors");
  spit(dir / "osc.yaml", oscillator);
  const std::string model = shell_quote((dir / "osc.yaml").string()) + " --t-end 1 ";
  Outcome r = hamel("simulate " + model + "--input G=1", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'G' is not an input"), std::string::npos) << r.err;
  r = hamel("simulate " + model + "--input 'F=-y'", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("the state (x, v)"), std::string::npos) << r.err;
  spit(dir / "bad.csv", "t,F\n0,1\n0,2\n");
  r = hamel("simulate " + model + "--input-file " + shell_quote((dir / "bad.csv").string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.csv:3:1:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("times must increase"), std::string::npos) << r.err;
  r = hamel("simulate " + model + "--monitors power", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--monitors"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace

namespace {

// `hamel phase` warns when the shape path does not close (r(T) ≠ r(0)), and only then.
TEST(PhasePath, OpenPathWarnsClosedPathDoesNot) {
  const fs::path dir = hamel_test::scratch_dir("phase_open_path");
  const std::string model = hamel_test::shell_quote(source_dir() + "/models/planar_swimmer.yaml");
  hamel_test::Outcome r =
      hamel_test::hamel("phase " + model + " --path 't; sin(2*pi*t); 0' --period 1 --cycles 1 --no-files", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the path does not close: q1(0) = 0 but q1(1) = 1"), std::string::npos) << r.err;
  r = hamel_test::hamel("phase " + model + " --path 'cos(2*pi*t); sin(2*pi*t); 0' --period 1 --cycles 1 --no-files",
                        dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace

namespace {

// The adaptive integrators end their steps on an --input-file table's knots, where the interpolated input has a kink:
// a free mass pushed by a piecewise-linear force follows the exact piecewise-cubic motion at tolerance 1e-12 with
// dopri5, dop853 and radau5, and rejects few steps. Straddling the kinks, dop853 rejected most of its steps and ended
// 5.6e-8 off a reference restarted at each knot (issue 49).
TEST(SimulateInputs, AdaptiveStepsEndOnTheTablesKnots) {
  const fs::path dir = scratch_dir("inputs_knots");
  spit(dir / "mass.yaml", R"(name: mass
parameters: {m: 1}
coordinates: [x]
quasi_velocities: {names: [v], A: [[1]]}
lagrangian: m*x_dot^2/2
forces: [F]
inputs: [F]
)");
  const std::vector<double> t = {0, 0.3, 0.7, 1.0, 1.6, 2.0}, f = {0, 2, -1, 3, 0, 1};
  std::string table = "t,F\n";
  for (std::size_t k = 0; k < t.size(); ++k) table += std::to_string(t[k]) + "," + std::to_string(f[k]) + "\n";
  spit(dir / "force.csv", table);
  // Exact at t = 2: per segment of length h, Δv = h (f_a + f_b) / 2, Δx = v_a h + h² (2 f_a + f_b) / 6.
  double x = 0, v = 0;
  for (std::size_t k = 0; k + 1 < t.size(); ++k) {
    const double h = t[k + 1] - t[k];
    x += v * h + h * h * (2 * f[k] + f[k + 1]) / 6;
    v += h * (f[k] + f[k + 1]) / 2;
  }
  for (const char* integrator : {"dopri5", "dop853", "radau5"}) {
    const Outcome r =
        hamel("simulate " + shell_quote((dir / "mass.yaml").string()) + " --integrator " + integrator +
                  " --t-end 2 --sample 1 --tol 1e-12 --input-file " + shell_quote((dir / "force.csv").string()),
              dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const Csv csv = parse_csv(r.out);
    const std::size_t last = csv.rows.size() - 1;
    ASSERT_DOUBLE_EQ(csv.at(last, "t"), 2.0);
    EXPECT_NEAR(csv.at(last, "x"), x, 1e-11) << integrator;
    EXPECT_NEAR(csv.at(last, "v"), v, 1e-11) << integrator;
    // "<n> steps (<r> rejected)" on stderr: a handful per kink at most.
    const std::size_t at = r.err.find(" rejected)");
    ASSERT_NE(at, std::string::npos) << r.err;
    const std::size_t open = r.err.rfind('(', at);
    EXPECT_LE(std::stoi(r.err.substr(open + 1, at - open - 1)), 20) << integrator << ": " << r.err;
  }
}

}  // namespace
