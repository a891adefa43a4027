// `hamel simulate models/four_bar_tree.yaml` through the binary, the closure of the loop checked with the loop written
// out by hand (tests/holonomic/four_bar_reference.hpp, absolute angles theta1 = crank, theta2 = crank + coupler,
// theta3 = rocker), from the CSV's joint coordinates:
//  - 100 s with every integrator at its default setting (rk4, dopri5, dop853, radau5), every accepted step observed:
//    the loop stays closed to 1e-10 at every row, the position_residual_* columns say so too, and the energy is
//    conserved to the integrator's accuracy;
//  - a start with the loop opened by 0.1 m (the rocker turned) is projected onto the loop with a note, and the run
//    starts from there, on the loop;
//  - loading says on stderr that the planar loop's z equation was dropped.
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
  return std::string(source ? source : HAMEL_SOURCE_DIR_DEFAULT) + "/models/four_bar_tree.yaml";
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

ref::Vector3 absolute(const Csv& csv, const std::vector<double>& r) {
  const double crank = r[csv.column("crank")], coupler = r[csv.column("coupler")], rocker = r[csv.column("rocker")];
  return {crank, crank + coupler, rocker};
}

double worst_closure(const Csv& csv) {
  double worst = 0;
  for (const auto& r : csv.rows) worst = std::max(worst, ref::loop(ref::Parameters{}, absolute(csv, r)).norm());
  return worst;
}

TEST(FourBarTreeSimulate, LoopStaysClosedFor100SecondsWithEveryIntegrator) {
  const fs::path scratch = scratch_dir("four_bar_tree_100s");
  for (const char* integrator : {"rk4", "dopri5", "dop853", "radau5"}) {
    SCOPED_TRACE(integrator);
    const Outcome o = hamel("simulate " + shell_quote(model()) + " --t-end 100 --integrator " + integrator +
                                " --monitors energy,constraint_residual --out -",
                            scratch);
    ASSERT_EQ(o.status, 0) << o.err;
    const Csv csv = parse_csv(o.out);
    ASSERT_GT(csv.rows.size(), 1000u);
    EXPECT_EQ(csv.rows.back()[0], 100.0);
    const double closure = worst_closure(csv);
    double reported = 0, energy_drift = 0;
    const std::size_t gx = csv.column("position_residual_tip_x"), gy = csv.column("position_residual_tip_y");
    const std::size_t e = csv.column("energy");
    for (const auto& r : csv.rows) {
      reported = std::max({reported, std::fabs(r[gx]), std::fabs(r[gy])});
      energy_drift = std::max(energy_drift, std::fabs(r[e] - csv.rows[0][e]) / std::fabs(csv.rows[0][e]));
    }
    std::printf("%s: %zu rows, loop closed to %.2e (columns: %.2e), energy drift %.2e\n", integrator, csv.rows.size(),
                closure, reported, energy_drift);
    EXPECT_LE(closure, 1e-10);
    EXPECT_LE(reported, 1e-10);
    EXPECT_LT(energy_drift, 1e-4);
    EXPECT_NE(o.err.find("loops: kept 2 of 3 closure equations; dropped tip_z (identically zero)"), std::string::npos)
        << o.err;
    EXPECT_GT(csv.rows.back()[csv.column("crank")], 100.0);  // the crank keeps turning
  }
  fs::remove_all(scratch);
}

TEST(FourBarTreeSimulate, OpenedStartIsProjectedWithAMessage) {
  const fs::path scratch = scratch_dir("four_bar_tree_opened");
  const ref::Parameters p;
  const double rocker = 1.141737657845791 + 0.2225;  // the rocker's tip moves by 2 l3 sin(0.2225 / 2) = 0.1 m
  ASSERT_NEAR(ref::loop(p, ref::Vector3(0.5, 0.54944008690290802, rocker)).norm(), 0.1, 1e-4);
  std::ostringstream init;
  init.precision(17);
  init << "rocker=" << rocker;
  const Outcome o =
      hamel("simulate " + shell_quote(model()) + " --t-end 1 --sample 0.5 --init " + init.str() + " --out -", scratch);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("the initial state violates the position constraints"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("  rocker: "), std::string::npos) << o.err;
  const Csv csv = parse_csv(o.out);
  ASSERT_EQ(csv.rows.size(), 3u);
  EXPECT_LT(ref::loop(p, absolute(csv, csv.rows[0])).norm(), 1e-15);
  EXPECT_LE(worst_closure(csv), 1e-14);
  fs::remove_all(scratch);
}

}  // namespace
