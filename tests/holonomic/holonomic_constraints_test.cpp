// The model key `holonomic` (derive/holonomic_constraints.hpp) as loaded and derived:
//  - the four-bar's constraints become the quasi-velocities loop_x, loop_y = G q_dot held at zero, the crank rate the
//    independent one (the partition q = (s, r) with s = theta2, theta3), and all Hamel coefficients vanish;
//  - the derived M u' = f and kinematics agree with the Euler-Lagrange equations with Lagrange multipliers written out
//    by hand (four_bar_reference.hpp), for hamel's partition, for quasi-velocities the model gives itself (the
//    rocker's rate), and with the parameters folded;
//  - the partition pivots on G at the model's `initial` configuration (a point on a circle keeps the coordinate
//    that moves there independent), and the pivoting rule in numbers: largest column first, ties to the later one,
//    nothing when G is rank-deficient;
//  - file constraints among given quasi-velocities are numbered after the holonomic ones.
#include "derive/holonomic_constraints.hpp"
#include "derive/derivation.hpp"
#include "four_bar_reference.hpp"
#include "model/fold_parameters.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace hamel {
namespace {

namespace ref = four_bar_reference;

std::string source(const std::string& relative) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : HAMEL_SOURCE_DIR_DEFAULT) + "/" + relative;
}

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> names(const std::vector<GiNaC::realsymbol>& symbols) {
  std::vector<std::string> out;
  for (const auto& s : symbols) out.push_back(s.get_name());
  return out;
}

TEST(Holonomic, FourBarConstraintsAreConstrainedQuasiVelocities) {
  const Model model = load_model(source("models/four_bar.yaml"));
  ASSERT_EQ(model.holonomic.size(), 2u);
  EXPECT_EQ(names(model.quasi_velocities), (std::vector<std::string>{"loop_x", "loop_y", "theta1_dot"}));
  EXPECT_EQ(model.constrained, (std::vector<int>{0, 1}));
  EXPECT_EQ(model.dependent_coordinates, (std::vector<int>{1, 2}));
  // A = [G; the crank's rate], (sys1).
  for (unsigned a = 0; a < 3; ++a) {
    EXPECT_TRUE((model.A(0, a) - model.holonomic[0].gradient[a]).is_zero());
    EXPECT_TRUE((model.A(2, a) - (a == 0 ? 1 : 0)).is_zero());
  }
  const Derivation d = derive(model);
  EXPECT_TRUE(d.system.gamma.empty()) << "holonomic: every gamma vanishes (gammaHolo)";
  ASSERT_EQ(d.system.position_constraints.size(), 2u);
  EXPECT_EQ(d.system.position_constraints[1].name, "loop_y");
  EXPECT_EQ(d.equations.independent, (std::vector<int>{2}));
}

// u_I' and q_dot of a derivation at (q, u_I), in doubles, through its program.
struct Evaluated {
  std::vector<double> q_dot;
  double u_dot;
};

Evaluated evaluate(const Model& model, const Derivation& d, const ref::Parameters& p, const ref::Vector3& q, double u) {
  GiNaC::exmap values;
  values[model.time] = 0;
  for (int a = 0; a < 3; ++a) values[model.coordinates[static_cast<std::size_t>(a)]] = q[a];
  values[d.system.velocities[static_cast<std::size_t>(d.equations.independent[0])]] = u;
  for (int alpha : d.system.constrained) values[d.system.velocities[static_cast<std::size_t>(alpha)]] = 0;
  const auto P = p.array();
  for (std::size_t k = 0; k < model.parameters.size(); ++k) values[model.parameters[k].symbol] = P[static_cast<int>(k)];
  const GiNaC::exmap all = d.equations.intermediates.evaluate(values);
  const auto number = [&](const GiNaC::ex& e) { return GiNaC::ex_to<GiNaC::numeric>(e.subs(all).evalf()).to_double(); };
  Evaluated out;
  for (const GiNaC::ex& e : d.equations.kinematics) out.q_dot.push_back(number(e));
  out.u_dot = number(d.equations.forcing[0]) / number(d.equations.mass_matrix(0, 0));
  return out;
}

void expect_matches_reference(const Model& model, int independent_coordinate, const ref::Parameters& p) {
  const Derivation d = derive(model);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20.0, 20.0);
  for (int trial = 0; trial < 20; ++trial) {
    const ref::Vector3 q = ref::closed(p, angle(rng));
    const ref::Vector3 v = ref::velocities(p, q, rate(rng));
    const ref::Vector3 a = ref::accelerations(p, q, v);
    const double u = v[independent_coordinate];
    const Evaluated e = evaluate(model, d, p, q, u);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(e.q_dot[static_cast<std::size_t>(i)], v[i], 1e-12 * (1 + v.norm()));
    EXPECT_NEAR(e.u_dot, a[independent_coordinate], 1e-10 * (1 + a.norm()));
  }
}

TEST(Holonomic, FourBarEquationsAreTheLagrangeMultiplierEquations) {
  const Model model = load_model(source("models/four_bar.yaml"));
  expect_matches_reference(model, 0, ref::Parameters{});
  // Folded at other values: the same equations with numbers.
  ref::Parameters p;
  p.l2 = 0.65, p.m2 = 1.5, p.g = 3.7;
  expect_matches_reference(fold_parameters(model, {{"l2", p.l2}, {"m2", p.m2}, {"g", p.g}}), 0, p);
}

TEST(Holonomic, GivenQuasiVelocitiesCompleteTheConstraints) {
  // The four-bar with the rocker's rate w3 as the independent quasi-velocity, given in the file.
  std::string text = file_text(source("models/four_bar.yaml"));
  const std::string before = "bodies:";
  text.replace(text.find(before), before.size(), "quasi_velocities:\n  names: [w3]\n  A: [[0, 0, 1]]\nbodies:");
  const Model model = load_model_from_text(text, "four_bar_rocker.yaml");
  EXPECT_EQ(names(model.quasi_velocities), (std::vector<std::string>{"loop_x", "loop_y", "w3"}));
  EXPECT_TRUE(model.dependent_coordinates.empty());
  expect_matches_reference(model, 2, ref::Parameters{});
}

const char* circle = R"yaml(name: bead
parameters: {m: 1, R: 2}
coordinates: [x, y]
holonomic:
  ring: "x^2 + y^2 - R^2"
lagrangian: "m/2*(x_dot^2 + y_dot^2)"
)yaml";

TEST(Holonomic, PartitionPivotsAtTheInitialConfiguration) {
  // On the ring x^2 + y^2 = R^2: at (R, 0) the bead moves along y, so x is dependent; at (0, R) the other way round.
  const Model at_x = load_model_from_text(std::string(circle) + "initial: {x: 2, y: 0}\n", "bead.yaml");
  EXPECT_EQ(at_x.dependent_coordinates, (std::vector<int>{0}));
  EXPECT_EQ(names(at_x.quasi_velocities), (std::vector<std::string>{"ring", "y_dot"}));
  const Model at_y = load_model_from_text(std::string(circle) + "initial: {x: 0, y: 2}\n", "bead.yaml");
  EXPECT_EQ(at_y.dependent_coordinates, (std::vector<int>{1}));
  EXPECT_EQ(names(at_y.quasi_velocities), (std::vector<std::string>{"ring", "x_dot"}));
  // Without `initial` (q = 0, where G = 0) at a generic configuration.
  const Model generic = load_model_from_text(circle, "bead.yaml");
  EXPECT_EQ(generic.dependent_coordinates.size(), 1u);
}

TEST(Holonomic, PivotingRule) {
  EXPECT_EQ(dependent_coordinates_by_pivoting({{0.2, 0.6, 0.45}}), (std::vector<int>{1}));
  EXPECT_EQ(dependent_coordinates_by_pivoting({{1.0, -1.0, 0.5}}), (std::vector<int>{1}));  // tie: the later one
  EXPECT_EQ(dependent_coordinates_by_pivoting({{1.0, 0.0, 1.0}, {0.0, 1.0, 0.0}}), (std::vector<int>{1, 2}));
  EXPECT_TRUE(dependent_coordinates_by_pivoting({{1.0, 2.0}, {2.0, 4.0}}).empty());  // rank 1
  EXPECT_TRUE(dependent_coordinates_by_pivoting({{0.0, 0.0}}).empty());
}

TEST(Holonomic, FileConstraintsAreNumberedAfterTheHolonomicOnes) {
  // A point in space on the sphere |p| = 1 whose quasi-velocities are given: u1 held at zero by the file.
  const Model model = load_model_from_text(R"yaml(name: point
coordinates: [x, y, z]
holonomic: {sphere: "x^2 + y^2 + z^2 - 1"}
quasi_velocities:
  names: [u1, u2]
  A: [[1, 0, 0], [0, 1, 0]]
constraints: [u1]
lagrangian: "(x_dot^2 + y_dot^2 + z_dot^2)/2"
initial: {z: 1}
)yaml",
                                           "point.yaml");
  EXPECT_EQ(names(model.quasi_velocities), (std::vector<std::string>{"sphere", "u1", "u2"}));
  EXPECT_EQ(model.constrained, (std::vector<int>{0, 1}));
  const Derivation d = derive(model);
  EXPECT_EQ(d.equations.independent, (std::vector<int>{2}));
}

}  // namespace
}  // namespace hamel
