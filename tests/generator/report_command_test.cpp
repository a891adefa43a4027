// `hamel report`: the three files of a work-precision study on a small scene, the CSV contract, and that
// the numbers mean something: RK4's error falls at order 4 against the reference, the adaptive methods'
// errors follow their tolerance, and only the implicit method evaluates Jacobians; on a stiff model RK4's
// steps start at its stability bound.
#include <gtest/gtest.h>
#include "support/command.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using hamel::test::source_dir;

std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path, std::vector<std::string>& header) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::map<std::string, std::string> row;
    std::size_t k = 0;
    for (std::string cell; std::getline(ls, cell, ',');) row[header.at(k++)] = cell;
    rows.push_back(row);
  }
  return rows;
}

TEST(ReportCommand, WritesCsvMarkdownAndPlotWithMeaningfulNumbers) {
  const fs::path out = fs::temp_directory_path() / ("hamel_report_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string cmd = std::string(HAMEL_BINARY) + " report " + source_dir() +
                          "/models/double_pendulum.yaml --t-end 2 --out " + out.string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const char* ext : {".csv", ".md", ".svg"})
    EXPECT_TRUE(fs::exists(out / (std::string("double_pendulum_work_precision") + ext))) << ext;

  std::vector<std::string> header;
  const auto rows = read_csv(out / "double_pendulum_work_precision.csv", header);
  for (const char* column : {"integrator", "setting", "error", "cpu_s", "steps", "rhs_evals", "jac_evals", "drift"})
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  ASSERT_GE(rows.size(), 20u);

  std::vector<double> log_h, log_e;
  for (const auto& r : rows) {
    EXPECT_EQ(r.at("status"), "ok");
    const double error = std::stod(r.at("error")), setting = std::stod(r.at("setting"));
    EXPECT_TRUE(std::isfinite(error));
    EXPECT_GT(std::stod(r.at("cpu_s")), 0.0);
    if (r.at("integrator") == "radau5") {
      EXPECT_GT(std::stol(r.at("jac_evals")), 0);
    } else {
      EXPECT_EQ(std::stol(r.at("jac_evals")), 0);
    }
    // Errors above the reference's noise and in the asymptotic range of RK4 give the order.
    if (r.at("integrator") == "rk4" && error > 1e-12 && setting <= 0.02) {
      log_h.push_back(std::log(setting));
      log_e.push_back(std::log(error));
    }
    if ((r.at("integrator") == "dopri5" || r.at("integrator") == "dop853") && setting >= 1e-9) {
      EXPECT_LT(error, 1000 * setting) << r.at("integrator") << " at tol " << setting;
    }
  }
  ASSERT_GE(log_h.size(), 3u);
  const double n = static_cast<double>(log_h.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < log_h.size(); ++i)
    sx += log_h[i], sy += log_e[i], sxx += log_h[i] * log_h[i], sxy += log_h[i] * log_e[i];
  const double order = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  EXPECT_NEAR(order, 4.0, 0.3);

  std::ifstream svg(out / "double_pendulum_work_precision.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("radau5"), std::string::npos);
  fs::remove_all(out);
}

// A reference run that stalls (more than --reference-steps steps within a hundredth of the horizon: here the
// double pendulum released near the top, slow at first, then whipping round) shortens the horizon to the start of
// that hundredth, says so in the Markdown, and the study runs over the shorter horizon: RK4's finest step agrees
// with that reference (an integrator the reference does not share) to 1e-9, which it would not if the reference
// ended elsewhere. A reference that stalls in the first hundredth is a clear error (exit status 2).
TEST(ReportCommand, AStalledReferenceShortensTheHorizon) {
  const fs::path out = fs::temp_directory_path() / ("hamel_report_budget_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string base = std::string(HAMEL_BINARY) + " report " + source_dir() +
                           "/models/double_pendulum.yaml --t-end 10 --init theta1=3.1,theta2=0,omega1=0,omega2=0 "
                           "--integrators rk4 dop853 --out " +
                           out.string();
  const std::string cmd = base + " --reference-steps 8 > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream md(out / "double_pendulum_work_precision.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Horizon shortened from 10 to "), std::string::npos) << text;

  std::vector<std::string> header;
  const auto rows = read_csv(out / "double_pendulum_work_precision.csv", header);
  ASSERT_FALSE(rows.empty());
  double coarsest = 0, finest_error = 1;
  for (const auto& r : rows) {
    if (r.at("integrator") != "rk4") continue;
    coarsest = std::max(coarsest, std::stod(r.at("setting")));
    finest_error = std::min(finest_error, std::stod(r.at("error")));
  }
  const double horizon = 25 * coarsest;  // the sweep's steps are horizon / (25 · 2^k)
  EXPECT_GT(horizon, 0.1);
  EXPECT_LT(horizon, 10.0);
  EXPECT_NEAR(horizon / 0.1, std::round(horizon / 0.1), 1e-9);  // a hundredth's start
  EXPECT_LT(finest_error, 1e-9);
  fs::remove_all(out);

  const std::string none = base + " --reference-steps 1 > /dev/null 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(none.c_str())), 2) << none;
  EXPECT_FALSE(fs::exists(out / "double_pendulum_work_precision.csv"));
  fs::remove_all(out);
}

// On a stiff model the fixed-step sweep starts at RK4's stability bound. A spring of stiffness k = 10⁶ on a unit
// mass oscillates at ω = √(k/m) = 1000 rad/s, so the Jacobian's eigenvalues are ±1000 i (an analytic value the
// report does not share): the steps start at 2.5/ω = 2.5e-3 instead of the horizon / 25 = 0.04, where every RK4
// run would blow up (|h λ| = 40 against a stability bound of about 2.8), and halve from there. Every RK4 run is
// then stable, and its error falls at order 4 once the step resolves the oscillation.
TEST(ReportCommand, FixedStepsStartAtTheStabilityBoundOfAStiffModel) {
  const fs::path out = fs::temp_directory_path() / ("hamel_report_stiff_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  const fs::path model = out / "stiff_spring.yaml";
  std::ofstream(model) << "schema: 1\n"
                          "name: stiff_spring\n"
                          "parameters:\n  m: 1.0\n  k: 1.0e6\n"
                          "coordinates: [x]\n"
                          "quasi_velocities:\n  names: [v]\n  A:\n    - [1]\n"
                          "lagrangian: \"1/2*m*x_dot^2 - 1/2*k*x^2\"\n";
  const std::string cmd = std::string(HAMEL_BINARY) + " report " + model.string() +
                          " --t-end 1 --init x=0.001,v=0 --integrators rk4 --out " + out.string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream md(out / "stiff_spring_work_precision.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Fixed steps from 2.5/ρ = 0.0025"), std::string::npos) << text;
  EXPECT_NE(text.find("ρ = 1000,"), std::string::npos) << text;

  std::vector<std::string> header;
  const auto rows = read_csv(out / "stiff_spring_work_precision.csv", header);
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_NEAR(std::stod(rows.front().at("setting")), 2.5e-3, 1e-12);
  std::vector<double> errors;
  double previous = 0;
  for (const auto& r : rows) {
    const double setting = std::stod(r.at("setting")), error = std::stod(r.at("error"));
    EXPECT_EQ(r.at("status"), "ok") << setting;
    EXPECT_TRUE(std::isfinite(error)) << setting;
    if (previous > 0) {
      EXPECT_NEAR(setting, previous / 2, 1e-15);
    }
    previous = setting;
    errors.push_back(error);
  }
  // Stable but too coarse at first (the fast oscillation damped away: an error of order one), then fourth order:
  // each halving divides the error by about 16.
  for (std::size_t i = errors.size() - 4; i < errors.size(); ++i) EXPECT_LT(errors[i], errors[i - 1] / 10) << i;
  const double last_error = errors.back();
  EXPECT_LT(last_error, 1e-6);
  fs::remove_all(out);
}

// The report states how far dop853 at 1e-13 ends from its reference (dop853 at 1e-14), as an indication of the
// reference's own error. The number must be that distance: here recomputed from two `hamel simulate` runs (the final
// rows of their CSVs, 17 digits), in the report's norm (max-norm relative to max(1, |x_ref|)).
TEST(ReportCommand, StatesHowFarTheSameMethodAtTenTimesTheToleranceEndsFromTheReference) {
  const fs::path out = fs::temp_directory_path() / ("hamel_report_check_test_" + std::to_string(::getpid()));
  fs::create_directories(out);
  const std::string model = source_dir() + "/models/double_pendulum.yaml";
  const std::string init = " --t-end 2 --init theta1=0.1,theta2=0.2,omega1=0.5,omega2=0.5";
  const std::string report = std::string(HAMEL_BINARY) + " report " + model + init + " --integrators dop853 --out " +
                             out.string() + " > /dev/null 2>&1";
  ASSERT_EQ(std::system(report.c_str()), 0) << report;
  const auto final_state = [&](const std::string& tol) {
    const fs::path csv = out / ("simulate_" + tol + ".csv");
    const std::string cmd = std::string(HAMEL_BINARY) + " simulate " + model + init + " --integrator dop853 --tol " +
                            tol + " --out " + csv.string() + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::vector<std::string> header;
    const auto rows = read_csv(csv, header);
    std::vector<double> x;
    for (std::size_t k = 1; k < header.size(); ++k) x.push_back(std::stod(rows.back().at(header[k])));
    EXPECT_EQ(std::stod(rows.back().at("t")), 2.0);
    return x;
  };
  const std::vector<double> check = final_state("1e-13"), reference = final_state("1e-14");
  ASSERT_EQ(check.size(), 4u);
  double distance = 0, scale = 1;
  for (std::size_t k = 0; k < check.size(); ++k) {
    distance = std::max(distance, std::fabs(check[k] - reference[k]));
    scale = std::max(scale, std::fabs(reference[k]));
  }
  distance /= scale;
  ASSERT_GT(distance, 0.0);  // the two runs differ, so the comparison below means something
  std::ifstream md(out / "double_pendulum_work_precision.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  const std::string lead = "dop853 at rtol = atol = 1e-13 ends ";
  const std::size_t at = text.find(lead);
  ASSERT_NE(at, std::string::npos) << text;
  const double stated = std::stod(text.substr(at + lead.size()));
  EXPECT_NEAR(stated, distance, 1e-5 * distance) << text.substr(at, 120);
  std::ifstream svg(out / "double_pendulum_work_precision.svg");
  const std::string plot((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(plot.find("dop853 1e-13 vs reference"), std::string::npos);
  fs::remove_all(out);
}

}  // namespace

// The default initial state is the one the report prints (coordinates 0.1, 0.2, 0.3, ..., velocities 0.5): a study
// from the defaults and one from those printed values given with --init run the same motions, step for step. Written
// as 0.1 · 3 the third coordinate was 0.30000000000000004, one ulp off the printed 0.3, and a sensitive motion (the
// rolling disk passing near its flat position) ended 3e-10 apart. The shipped disk names its own initial state (key
// `initial`), so the study runs on a copy without it.
TEST(ReportCommand, TheDefaultInitialStateIsTheOnePrinted) {
  const fs::path out = fs::temp_directory_path() / ("hamel_report_init_test_" + std::to_string(::getpid()));
  fs::create_directories(out);
  {
    std::ifstream in(source_dir() + "/models/rolling_disk_routh.yaml");
    std::ofstream copy(out / "disk.yaml");
    bool dropped = false;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("initial:", 0) == 0) {
        dropped = true;
        continue;
      }
      copy << line << "\n";
    }
    ASSERT_TRUE(dropped) << "models/rolling_disk_routh.yaml has no line 'initial: ...' any more; update this test";
  }
  const auto study = [&](const std::string& init, const std::string& folder) {
    const std::string cmd = std::string(HAMEL_BINARY) + " report " + (out / "disk.yaml").string() +
                            " --t-end 6 --integrators dop853 " + init + " --out " + (out / folder).string() +
                            " > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::vector<std::string> header;
    return read_csv(out / folder / "rolling_disk_routh_work_precision.csv", header);
  };
  const auto defaults = study("", "defaults");
  const auto printed = study("--init x=0.1,y=0.2,psi=0.3,theta=0.4,phi=0.5,w_psi=0.5,w_theta=0.5,w_phi=0.5", "printed");
  ASSERT_EQ(defaults.size(), printed.size());
  ASSERT_FALSE(defaults.empty());
  for (std::size_t k = 0; k < defaults.size(); ++k)
    for (const char* column : {"setting", "error", "steps", "rhs_evals", "drift"})
      EXPECT_EQ(defaults[k].at(column), printed[k].at(column)) << column << " of run " << k;
  std::ifstream md(out / "defaults" / "rolling_disk_routh_work_precision.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("psi = 0.3, theta = 0.4"), std::string::npos) << text;
  fs::remove_all(out);
}
