// `hamel simulate models/four_bar.yaml` through the binary, the closure of the loop checked with the loop written out
// by hand (four_bar_reference.hpp), from the CSV's coordinates:
//  - 100 s with every integrator at its default setting (rk4 at --dt 1e-3, dopri5, dop853 and radau5 at --tol 1e-8),
//    every accepted step observed, and dopri5 sampled every 0.01 s: the loop stays closed to 1e-10 (in fact to
//    rounding level) at every row, the position_residual_* columns of --monitors constraint_residual say so too, and
//    the energy is conserved to the integrator's accuracy;
//  - a start with the loop opened by 0.1 m (the rocker turned) is projected onto the loop, the note on stderr lists
//    each coordinate old -> new, and the run starts from those values, on the loop;
//  - a linkage that cannot close (ground link d = 2 m, longer than the other three links together) is refused with
//    exit 2, file:line, the constraint and its residual, and nothing is written.
#include "four_bar_reference.hpp"
#include "run_hamel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace hamel_test;
namespace ref = four_bar_reference;

std::string model() {
  const char* source = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(source ? source : HAMEL_SOURCE_DIR_DEFAULT) + "/models/four_bar.yaml";
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t c = 0; c < header.size(); ++c)
      if (header[c] == name) return c;
    throw std::runtime_error("no column " + name);
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

// max |g(q)| over the rows, from theta1..theta3 with the hand-written loop.
double worst_closure(const Csv& csv) {
  const std::size_t t1 = csv.column("theta1"), t2 = csv.column("theta2"), t3 = csv.column("theta3");
  double worst = 0;
  for (const auto& r : csv.rows) {
    const ref::Vector2 g = ref::loop(ref::Parameters{}, ref::Vector3(r[t1], r[t2], r[t3]));
    worst = std::max({worst, std::fabs(g[0]), std::fabs(g[1])});
  }
  return worst;
}

TEST(FourBarSimulate, LoopStaysClosedFor100SecondsWithEveryIntegrator) {
  const fs::path scratch = scratch_dir("four_bar_100s");
  struct Run {
    const char* integrator;
    const char* extra;
  };
  for (const Run& run :
       {Run{"rk4", ""}, Run{"dopri5", ""}, Run{"dop853", ""}, Run{"radau5", ""}, Run{"dopri5", " --sample 0.01"}}) {
    SCOPED_TRACE(std::string(run.integrator) + run.extra);
    const Outcome o = hamel("simulate " + shell_quote(model()) + " --t-end 100 --integrator " + run.integrator +
                                run.extra + " --monitors energy,constraint_residual --out -",
                            scratch);
    ASSERT_EQ(o.status, 0) << o.err;
    const Csv csv = parse_csv(o.out);
    ASSERT_GT(csv.rows.size(), 1000u);
    EXPECT_EQ(csv.rows.back()[0], 100.0);
    const double closure = worst_closure(csv);
    // The position residual columns: g itself, as the CSV gives it.
    double reported = 0, energy_drift = 0;
    const std::size_t gx = csv.column("position_residual_loop_x"), gy = csv.column("position_residual_loop_y");
    const std::size_t e = csv.column("energy");
    for (const auto& r : csv.rows) {
      reported = std::max({reported, std::fabs(r[gx]), std::fabs(r[gy])});
      energy_drift = std::max(energy_drift, std::fabs(r[e] - csv.rows[0][e]) / std::fabs(csv.rows[0][e]));
    }
    std::printf("%s%s: %zu rows, loop closed to %.2e (columns: %.2e), energy drift %.2e\n", run.integrator, run.extra,
                csv.rows.size(), closure, reported, energy_drift);
    EXPECT_LE(closure, 1e-10);
    EXPECT_LE(reported, 1e-10);
    EXPECT_LT(energy_drift, 1e-4);
    EXPECT_NE(o.err.find("position residual |g(q)|: max"), std::string::npos);
    // The crank keeps turning (the initial state's 15 rad/s is above the energy of the upright crank).
    EXPECT_GT(csv.rows.back()[csv.column("theta1")], 100.0);
  }
  fs::remove_all(scratch);
}

TEST(FourBarSimulate, OpenedStartIsProjectedWithAMessage) {
  const fs::path scratch = scratch_dir("four_bar_opened");
  // The model's initial state with the rocker turned by 0.2225 rad: its tip moves by 2 l3 sin(0.2225 / 2) = 0.1 m.
  const ref::Parameters p;
  const double theta3 = 1.141737657845791 + 0.2225;
  {
    const ref::Vector2 gap = ref::loop(p, ref::Vector3(0.5, 0.54944008690290802, theta3));
    ASSERT_NEAR(gap.norm(), 0.1, 1e-4);
  }
  std::ostringstream init;
  init.precision(17);
  init << "theta3=" << theta3;
  const Outcome o =
      hamel("simulate " + shell_quote(model()) + " --t-end 1 --sample 0.5 --init " + init.str() + " --out -", scratch);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("hamel: note: the initial state violates the position constraints"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("projected it onto g(q) = 0"), std::string::npos) << o.err;
  const Csv csv = parse_csv(o.out);
  ASSERT_EQ(csv.rows.size(), 3u);
  const std::vector<double>& first = csv.rows[0];
  // Each coordinate's line "  name: old -> new", new being the run's first row.
  const double given[3] = {0.5, 0.54944008690290802, theta3};
  const char* names[3] = {"theta1", "theta2", "theta3"};
  for (int a = 0; a < 3; ++a) {
    const std::string line = std::string("  ") + names[a] + ": ";
    const std::size_t at = o.err.find(line);
    ASSERT_NE(at, std::string::npos) << names[a] << "\n" << o.err;
    std::istringstream text(o.err.substr(at + line.size()));
    double old_value = 0, new_value = 0;
    std::string arrow;
    text >> old_value >> arrow >> new_value;
    EXPECT_EQ(arrow, "->");
    EXPECT_EQ(old_value, given[a]) << names[a];
    EXPECT_EQ(new_value, first[csv.column(names[a])]) << names[a];
  }
  // On the loop, and near where it started (the minimum-norm correction moves q by about the gap's size).
  const ref::Vector3 q(first[1], first[2], first[3]);
  EXPECT_LT(ref::loop(p, q).norm(), 1e-15);
  EXPECT_LT((q - ref::Vector3(given[0], given[1], given[2])).norm(), 0.5);
  EXPECT_EQ(first[4], 15.0);  // the velocity is the state's: unchanged
  EXPECT_LE(worst_closure(csv), 1e-15);
  // A consistent start says nothing.
  const Outcome quiet = hamel("simulate " + shell_quote(model()) + " --t-end 0.1 --out -", scratch);
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("hamel: note"), std::string::npos) << quiet.err;
  EXPECT_EQ(parse_csv(quiet.out).rows[0][2], 0.54944008690290802);  // as given
  fs::remove_all(scratch);
}

TEST(FourBarSimulate, LinkageThatCannotCloseIsRefused) {
  const fs::path scratch = scratch_dir("four_bar_apart");
  const fs::path out = scratch / "run.csv";
  const Outcome o =
      hamel("simulate " + shell_quote(model()) + " --t-end 1 --param d=2 --out " + shell_quote(out.string()), scratch);
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(o.err.rfind(model() + ":", 0), 0u) << o.err;  // file:line first
  EXPECT_NE(o.err.find("'holonomic.loop_x'"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("violates this constraint by g = -1.5"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("cannot close it"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(scratch);
}

}  // namespace
