// A power of a sum must not reach emitted code multiplied out. With
// L = ½ẋ² − (x+1)^200/200 the forcing is −(x+1)^199; its 200 monomials, summed in doubles at x = −0.9,
// gave −3.4e38 where the value is −1e−199. The kernels (evaluated by GraphEvaluator, the double interpreter
// behind `hamel simulate`, which runs the same graph the emitter prints) must match the exact value at the
// double x to 1e-12 relative, and so must a power of a multivariate sum and one in a denominator. Cancellations
// the normal form finds must survive: a power of a sum minus its expansion is still exactly zero. The same holds
// on the bundle path (a potential) and the kinematic tree's (body data it multiplies out).
#include "algebra/simplify.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/expression_parser.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

GiNaC::numeric power(const GiNaC::numeric& base, int exponent) { return base.power(exponent); }

// The double d as an exact rational.
GiNaC::numeric exact(double d) {
  int e = 0;
  const double m = std::frexp(d, &e);
  return GiNaC::numeric(static_cast<long>(std::ldexp(m, 53))) * power(GiNaC::numeric(2), e - 53);
}

double relative_error(double value, const GiNaC::numeric& reference) {
  const double r = reference.to_double();
  return std::fabs(value - r) / std::fabs(r);
}

struct Kernels {
  hamel::Model model;
  hamel::Derivation derivation;
  hamel::KernelSet kernels;
};

Kernels build(const std::string& text) {
  Kernels k{hamel::load_model_from_text(text, "powers.yaml"), {}, {}};
  k.derivation = hamel::derive(k.model);
  k.kernels = hamel::build_kernels(k.model, k.derivation, {"forcing", "rhs", "energy"});
  return k;
}

double evaluate(const Kernels& k, const std::string& kernel, const std::vector<double>& x, std::size_t output = 0,
                const std::vector<double>& p = {}) {
  hamel::GraphEvaluator f(k.kernels.graph, k.kernels.get(kernel).outputs);
  std::vector<double> out(k.kernels.get(kernel).outputs.size());
  f.evaluate(0, x.data(), p.empty() ? nullptr : p.data(), nullptr, out.data());
  return out[output];
}

TEST(PowersOfSums, ForcingOfAHighPowerIsAccurateNearTheRoot) {
  const Kernels k = build(
      "name: p\ncoordinates: [x]\nquasi_velocities:\n  names: [v]\n  A: [[1]]\n"
      "lagrangian: \"1/2*x_dot^2 - (x+1)^200/200\"\n");
  for (double x : {-0.9, -1.3, -0.95, 0.5}) {
    const GiNaC::numeric xr = exact(x);
    const GiNaC::numeric forcing = -power(xr + 1, 199);
    const GiNaC::numeric energy = power(xr + 1, 200) / 200;
    EXPECT_LT(relative_error(evaluate(k, "forcing", {x, 0.0}), forcing), 1e-12) << "x = " << x;
    EXPECT_LT(relative_error(evaluate(k, "rhs", {x, 0.0}, 1), forcing), 1e-12) << "x = " << x;
    EXPECT_LT(relative_error(evaluate(k, "energy", {x, 0.0}), energy), 1e-12) << "x = " << x;
  }
}

TEST(PowersOfSums, MultivariateAndDenominatorPowersAreAccurate) {
  // Forcing dL/dq for L = ½(ẋ² + ẏ²) − (x+y−1)^20 − (x−1)^(−10), near the roots of both bases.
  const Kernels k = build(
      "name: p\ncoordinates: [x, y]\nquasi_velocities:\n  names: [u, w]\n  A: [[1, 0], [0, 1]]\n"
      "lagrangian: \"1/2*(x_dot^2 + y_dot^2) - (x+y-1)^20 - (x-1)^(-10)\"\n");
  const double x = 0.95, y = 0.1;
  const GiNaC::numeric xr = exact(x), yr = exact(y);
  const GiNaC::numeric fx = -20 * power(xr + yr - 1, 19) + 10 * power(xr - 1, -11);
  const GiNaC::numeric fy = -20 * power(xr + yr - 1, 19);
  EXPECT_LT(relative_error(evaluate(k, "forcing", {x, y, 0.0, 0.0}, 0), fx), 1e-12);
  EXPECT_LT(relative_error(evaluate(k, "forcing", {x, y, 0.0, 0.0}, 1), fy), 1e-12);
}

// The bundle path: a potential V(r) = (x+1)^200 on a shape coordinate (rolling_ball_bundle's geometry) gives
// the forcing −200 (x+1)^199, kept whole like the Lagrangian's.
TEST(PowersOfSums, BundlePotentialIsAccurateNearTheRoot) {
  const Kernels k = build(
      "name: p\nparameters: {m: 1.0, R: 0.1}\ngroup: SO3\ntrivialization: right\n"
      "group_velocity: [omega_x, omega_y, omega_z]\nshape: [x, y]\n"
      "connection:\n  kinematic: [[0, \"1/R\"], [\"-1/R\", 0], [0, 0]]\n"
      "kinetic: \"1/2*m*(x_dot^2 + y_dot^2) + 1/2*(2/5*m*R^2)*(omega_x^2 + omega_y^2 + omega_z^2)\"\n"
      "potential: \"(x+1)^200\"\n");
  const double x = -0.9;
  const GiNaC::numeric forcing = -200 * power(exact(x) + 1, 199);
  // State (x, y, then the independent quasi-velocities x_dot, y_dot); forcing f[x_dot] first.
  EXPECT_LT(relative_error(evaluate(k, "forcing", {x, 0.0, 0.0, 0.0}, 0, {1.0, 0.1}), forcing), 1e-12);
}

// The kinematic tree multiplies the bodies' data out (spatial inertias, joint poses): a body mass and inertia
// (m+1)^20 became 21 monomials in m each, whose sum at m = −0.9 (mass 1e−20) was wrong by about 1e−12, 1e8
// times the value. M of one revolute joint about z with the centre of mass at (1/4, 0, 0) and Izz = mass/100
// is mass · (1/100 + 1/16).
TEST(PowersOfSums, KinematicTreeBodyDataAreAccurateNearTheRoot) {
  const Kernels k = build(
      "name: p\nparameters: {m: 1.0}\ntree:\n  base: world\n  gravity: [0, 0, 0]\n  bodies:\n"
      "    - {name: link, parent: world, joint: {name: q, type: revolute, axis: [0, 0, 1], offset: [0, 0, 0]},\n"
      "       mass: \"(m+1)^20\", com: [0.25, 0, 0],\n"
      "       inertia: [[\"(m+1)^20/100\", 0, 0], [0, \"(m+1)^20/100\", 0], [0, 0, \"(m+1)^20/100\"]]}\n");
  hamel::KernelSet mass = hamel::build_kernels(k.model, k.derivation, {"mass_matrix"});
  hamel::GraphEvaluator f(mass.graph, mass.get("mass_matrix").outputs);
  for (double m : {-0.9, -1.1, 0.5}) {
    const std::vector<double> x{0.3, 0.0}, p{m};
    double M = 0;
    f.evaluate(0, x.data(), p.data(), nullptr, &M);
    const GiNaC::numeric reference = power(exact(m) + 1, 20) * (GiNaC::numeric(1, 100) + GiNaC::numeric(1, 16));
    EXPECT_LT(relative_error(M, reference), 1e-12) << "m = " << m << ": " << M;
  }
}

TEST(PowersOfSums, ExpansionKeepsPowersOfSumsWholeUnlessTheyCancel) {
  GiNaC::symtab table;
  const GiNaC::realsymbol x("x"), c("c");
  table["x"] = x;
  table["c"] = c;
  const auto parse = [&](const std::string& s) { return hamel::parse_expression(s, table); };
  EXPECT_EQ(hamel::expand_keeping_powers_of_sums(parse("c*(x+1)^20")), parse("c*(x+1)^20"));
  EXPECT_EQ(hamel::expand_keeping_powers_of_sums(parse("(x+1)^2 - x^2 - 2*x")), GiNaC::ex(1));
  EXPECT_EQ(hamel::expand_keeping_powers_of_sums(parse("c*(x+c)")), parse("c*x + c^2"));
}

TEST(PowersOfSums, ZeroDetectionStaysExact) {
  GiNaC::symtab table;
  const GiNaC::realsymbol x("x"), y("y"), a("a");
  table["x"] = x;
  table["y"] = y;
  table["a"] = a;
  const auto parse = [&](const std::string& s) { return hamel::parse_expression(s, table); };
  EXPECT_EQ(hamel::simplify(parse("(x+1)^30 - (x+1)^29*x - (x+1)^29")), GiNaC::ex(0));
  EXPECT_EQ(hamel::simplify(parse("(x+y)^2 - x^2 - 2*x*y - y^2")), GiNaC::ex(0));
  // A cancellation through sin² + cos² = 1 inside squares still gives the short normal form.
  EXPECT_EQ(hamel::simplify(parse("(y*sin(a) + x*cos(a))^2 + (x*sin(a) - y*cos(a))^2")), parse("x^2 + y^2"));
  // Kept whole where the expansion only grows it.
  EXPECT_EQ(hamel::simplify(parse("-(x+1)^199")), parse("-(x+1)^199"));
}

}  // namespace
