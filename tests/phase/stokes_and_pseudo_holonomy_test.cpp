// Geometric phase of the planar space robot (models/planar_space_robot.yaml, paper Sec. 6b) against
// the curvature of its mechanical connection.
//
// Stokes. G = SE(2) left-trivialized, ξ = (w, vx, vy). The rotation component is abelian: c^w_βλ = 0
// ([E_w, E_v] and [E_vx, E_vy] have no E_w part), so θ̇ = w and the reconstruction (KinRec) with zero
// momentum, ξ = −A(q) q̇, gives over a closed shape loop C
//     Δθ = −∮_C A^w_I dq^I.
// The paper's curvature (gamma43) has no structure-constant term in its w row:
//     B^w_12 = γ^w_12 = ∂A^w_1/∂q2 − ∂A^w_2/∂q1.
// Green's theorem for C traversed counter-clockwise in the (q1, q2) plane (q1 to the right, q2 up)
// around the region D: ∮_C (P dq1 + Q dq2) = ∬_D (∂Q/∂q1 − ∂P/∂q2) dq1 dq2. With P = A^w_1, Q = A^w_2
//     Δθ = −∬_D (∂A^w_2/∂q1 − ∂A^w_1/∂q2) = +∬_D B^w_12 dq1 dq2   (counter-clockwise C),
// and the opposite sign for a clockwise C. The test integrates the generator's B^w_12 (evaluated from
// BundleGeometry::curvature) over D by Gauss–Legendre quadrature and compares with compute_phase.
//
// Pseudo-holonomy. All centres of mass lie on the body x axes, so the mirror image of a motion is a
// motion: A^w(−q) = A^w(q) and B^w_12(−q) = −B^w_12(q) (the same about (π, 0), (0, π), (π, π)).
// At the default parameters the generator finds
//     B^w_12 = −12150 (57 sin q1 + 158 sin q2 + 26 sin(q1 + q2)) / D²,
//     D = 4973 + 3000 cos q1 + 1320 cos q2 + 720 cos(q1 + q2) = 675 I_c(q)
// (I_c: the system's inertia about its centre of mass [kg m²]), which changes sign across the curve
// 57 sin q1 + 158 sin q2 + 26 sin(q1 + q2) = 0 through q = 0 (q2 ≈ −0.45 q1 near 0; a curve, not a
// line). The symmetry that makes enclosed curvature cancel is the point reflection q → −q: a loop that
// is symmetric under it (the paper's necessary condition holds, B = 0 inside the loop) has zero
// orientation phase; the same loop shifted off the centre does not.
// The translation: with zero momentum the system centre of mass is fixed in space, p + R(θ) r_c(q) =
// const with r_c(q) the centre of mass in the base frame, so after a loop p = (I − R(Δθ)) r_c(q0): the
// full SE(2) phase vanishes with the orientation phase (on the way the base frame moves by up to
// 0.85 m and turns by up to 1.56 rad).
#include "algebra/simplify.hpp"
#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/phase.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;

using hamel::test::source_dir;

// Gauss–Legendre nodes and weights on [a, b] (Newton on the three-term recurrence).
struct Rule {
  std::vector<double> x, w;
};
Rule gauss_legendre(int n, double a, double b) {
  Rule r;
  for (int i = 0; i < n; ++i) {
    double z = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::fabs(dz) < 1e-16) break;
    }
    r.x.push_back(0.5 * (a + b) + 0.5 * (b - a) * z);
    r.w.push_back((b - a) / ((1 - z * z) * dp * dp));
  }
  return r;
}

// The robot with its parameters folded at their defaults; only the bundle geometry is derived (the
// equations of motion are not needed for the phase).
struct Robot {
  hamel::Model model;
  hamel::Derivation derivation;
  std::vector<double> parameters;
  std::map<std::string, double> value;
  hamel::ExpressionGraph graph;
  std::unique_ptr<hamel::GraphEvaluator> curvature, connection;  // B^w_12(q); (A^w_1, A^w_2)(q)

  Robot() {
    const hamel::Model loaded = hamel::load_model(source_dir() + "/models/planar_space_robot.yaml");
    std::map<std::string, double> defaults;
    for (const auto& p : loaded.parameters) {
      defaults[p.symbol.get_name()] = p.default_value;
      parameters.push_back(p.default_value);
    }
    value = defaults;
    model = hamel::fold_parameters(loaded, defaults);
    derivation.bundle = hamel::inlined(hamel::derive_bundle_geometry(model));  // closed forms, no intermediates
    const hamel::BundleGeometry& geo = *derivation.bundle;

    std::map<ex, int, GiNaC::ex_is_less> leaves;
    for (int I = 0; I < 2; ++I)
      leaves[model.coordinates[static_cast<std::size_t>(I)]] = graph.input(hamel::Argument::state, I);
    ex b12;
    for (const auto& b : geo.curvature)
      if (b.upper == 0 && b.lower_a == 0 && b.lower_b == 1) b12 = hamel::simplify(b.value);  // one fraction
    curvature = std::make_unique<hamel::GraphEvaluator>(graph, std::vector<int>{graph.from_expression(b12, leaves)});
    connection = std::make_unique<hamel::GraphEvaluator>(
        graph, std::vector<int>{graph.from_expression(geo.connection(0, 0), leaves),
                                graph.from_expression(geo.connection(0, 1), leaves)});
  }

  double B(double q1, double q2) const {
    const double q[2] = {q1, q2};
    double out = 0;
    curvature->evaluate(0, q, nullptr, nullptr, &out);
    return out;
  }
  std::array<double, 2> A(double q1, double q2) const {
    const double q[2] = {q1, q2};
    std::array<double, 2> out{};
    connection->evaluate(0, q, nullptr, nullptr, out.data());
    return out;
  }

  // The system centre of mass in the base frame, written here from the model's description.
  std::array<double, 2> centre_of_mass(double q1, double q2) const {
    const auto& v = value;
    const double M = v.at("m0") + v.at("m1") + v.at("m2");
    const double x = v.at("m0") * v.at("c0") + v.at("m1") * v.at("c1") * std::cos(q1) +
                     v.at("m2") * (v.at("l1") * std::cos(q1) + v.at("c2") * std::cos(q1 + q2));
    const double y = v.at("m1") * v.at("c1") * std::sin(q1) +
                     v.at("m2") * (v.at("l1") * std::sin(q1) + v.at("c2") * std::sin(q1 + q2));
    return {x / M, y / M};
  }

  // The rotational connection from the angular momentum about the system centre of mass, written here
  // from the model's description: with d_i = s_i − s_c (body centres of mass minus the system's, in the
  // base frame), H = w (Σ J_i + Σ m_i |d_i|²) + J1 q̇1 + J2 (q̇1 + q̇2) + Σ m_i d_i × ḋ_i = 0, so
  // w = −A^w_I q̇^I with A^w_I = (∂/∂q̇^I of the q̇ terms) / (Σ J_i + Σ m_i |d_i|²).
  struct AngularMomentum {
    double inertia;           // Σ J_i + Σ m_i |d_i|², about the system centre of mass
    std::array<double, 2> N;  // the coefficients of q̇1, q̇2 in H
  };
  AngularMomentum angular_momentum(double q1, double q2) const {
    const auto& v = value;
    const double m[3] = {v.at("m0"), v.at("m1"), v.at("m2")};
    const double M = m[0] + m[1] + m[2];
    const double c1 = v.at("c1"), l1 = v.at("l1"), c2 = v.at("c2");
    const double s1 = std::sin(q1), k1 = std::cos(q1), s12 = std::sin(q1 + q2), k12 = std::cos(q1 + q2);
    // s[i] and ∂s[i]/∂q^I.
    const double s[3][2] = {{v.at("c0"), 0}, {c1 * k1, c1 * s1}, {l1 * k1 + c2 * k12, l1 * s1 + c2 * s12}};
    const double ds[3][2][2] = {{{0, 0}, {0, 0}},
                                {{-c1 * s1, c1 * k1}, {0, 0}},
                                {{-l1 * s1 - c2 * s12, l1 * k1 + c2 * k12}, {-c2 * s12, c2 * k12}}};
    double sc[2] = {0, 0}, dsc[2][2] = {{0, 0}, {0, 0}};
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 2; ++k) {
        sc[k] += m[i] * s[i][k] / M;
        for (int I = 0; I < 2; ++I) dsc[I][k] += m[i] * ds[i][I][k] / M;
      }
    double inertia = v.at("J0") + v.at("J1") + v.at("J2");
    std::array<double, 2> N = {v.at("J1") + v.at("J2"), v.at("J2")};
    for (int i = 0; i < 3; ++i) {
      const double d[2] = {s[i][0] - sc[0], s[i][1] - sc[1]};
      inertia += m[i] * (d[0] * d[0] + d[1] * d[1]);
      for (int I = 0; I < 2; ++I)
        N[static_cast<std::size_t>(I)] += m[i] * (d[0] * (ds[i][I][1] - dsc[I][1]) - d[1] * (ds[i][I][0] - dsc[I][0]));
    }
    return {inertia, N};
  }
  std::array<double, 2> angular_momentum_connection(double q1, double q2) const {
    const AngularMomentum h = angular_momentum(q1, q2);
    return {h.N[0] / h.inertia, h.N[1] / h.inertia};
  }
  double inertia_about_centre_of_mass(double q1, double q2) const { return angular_momentum(q1, q2).inertia; }

  hamel::PhaseResult phase(const std::vector<ex>& path, int steps = 2000) const {
    hamel::PhaseRequest req;
    req.path = path;
    req.period = 1;
    req.steps_per_cycle = steps;
    req.samples_per_cycle = 50;
    return hamel::compute_phase(model, derivation, parameters, req);
  }
  ex t() const { return model.time; }
};

const Robot& robot() {
  static const Robot r;
  return r;
}

// ∬ B over the disc of radius rho about (c1, c2), polar coordinates.
double curvature_in_disc(double c1, double c2, double rho) {
  const Rule radial = gauss_legendre(30, 0, rho), angular = gauss_legendre(60, 0, 2 * M_PI);
  double sum = 0;
  for (std::size_t i = 0; i < radial.x.size(); ++i)
    for (std::size_t j = 0; j < angular.x.size(); ++j)
      sum += radial.w[i] * angular.w[j] * radial.x[i] *
             robot().B(c1 + radial.x[i] * std::cos(angular.x[j]), c2 + radial.x[i] * std::sin(angular.x[j]));
  return sum;
}

double curvature_in_rectangle(double a1, double b1, double a2, double b2) {
  const Rule r1 = gauss_legendre(40, a1, b1), r2 = gauss_legendre(40, a2, b2);
  double sum = 0;
  for (std::size_t i = 0; i < r1.x.size(); ++i)
    for (std::size_t j = 0; j < r2.x.size(); ++j) sum += r1.w[i] * r2.w[j] * robot().B(r1.x[i], r2.x[j]);
  return sum;
}

// A circle of radius rho about (c1, c2), once per unit time; direction +1 counter-clockwise, −1 clockwise.
std::vector<ex> circle(double c1, double c2, double rho, int direction = 1) {
  const ex t = robot().t();
  return {ex(c1) + ex(rho) * GiNaC::cos(2 * GiNaC::Pi * t),
          ex(c2) + ex(rho) * direction * GiNaC::sin(2 * GiNaC::Pi * t)};
}

TEST(Stokes, CurvatureOfTheRotationIsTheCurlOfTheConnection) {
  // B^w_12 = ∂A^w_1/∂q2 − ∂A^w_2/∂q1 (no structure-constant term), by central differences.
  const double h = 1e-5;
  for (const auto& q : std::vector<std::array<double, 2>>{{0.3, -0.7}, {1.1, 0.4}, {-2.0, 2.5}, {2.9, 1.3}}) {
    const double dA1_dq2 = (robot().A(q[0], q[1] + h)[0] - robot().A(q[0], q[1] - h)[0]) / (2 * h);
    const double dA2_dq1 = (robot().A(q[0] + h, q[1])[1] - robot().A(q[0] - h, q[1])[1]) / (2 * h);
    EXPECT_NEAR(robot().B(q[0], q[1]), dA1_dq2 - dA2_dq1, 1e-8) << q[0] << ", " << q[1];
  }
}

TEST(Stokes, RotationalConnectionIsTheAngularMomentumBalance) {
  for (const auto& q : std::vector<std::array<double, 2>>{{0, 0}, {0.3, -0.7}, {1.1, 0.4}, {-2.0, 2.5}, {2.9, 1.3}}) {
    const auto got = robot().A(q[0], q[1]), want = robot().angular_momentum_connection(q[0], q[1]);
    EXPECT_NEAR(got[0], want[0], 1e-14) << q[0] << ", " << q[1];
    EXPECT_NEAR(got[1], want[1], 1e-14) << q[0] << ", " << q[1];
  }
}

// The closed form quoted at the top of this file (default parameters).
TEST(Stokes, CurvatureHasTheQuotedClosedForm) {
  for (const auto& q : std::vector<std::array<double, 2>>{{0.3, -0.7}, {1.1, 0.4}, {-2.0, 2.5}, {2.9, 1.3}}) {
    const double D = 4973 + 3000 * std::cos(q[0]) + 1320 * std::cos(q[1]) + 720 * std::cos(q[0] + q[1]);
    const double B = -12150 * (57 * std::sin(q[0]) + 158 * std::sin(q[1]) + 26 * std::sin(q[0] + q[1])) / (D * D);
    EXPECT_NEAR(robot().B(q[0], q[1]), B, 1e-14 * std::fabs(B) + 1e-17) << q[0] << ", " << q[1];
    EXPECT_NEAR(D, 675 * robot().inertia_about_centre_of_mass(q[0], q[1]), 1e-10 * D);
  }
}

TEST(Stokes, OrientationPhaseOfACircleIsTheEnclosedCurvature) {
  struct Disc {
    double c1, c2, rho;
  };
  for (const Disc& d : {Disc{0.4, -0.3, 0.5}, Disc{1.0, 1.2, 0.8}, Disc{-2.0, 0.5, 1.2}, Disc{2.5, -2.8, 0.3}}) {
    const double flux = curvature_in_disc(d.c1, d.c2, d.rho);
    const hamel::PhaseResult ccw = robot().phase(circle(d.c1, d.c2, d.rho, 1));
    const hamel::PhaseResult cw = robot().phase(circle(d.c1, d.c2, d.rho, -1));
    const double theta_ccw = *ccw.cycles.back().theta, theta_cw = *cw.cycles.back().theta;
    std::printf("circle (%g, %g) r %g: flux %.15e, phase ccw %.15e, cw %.15e, rel %.2e\n", d.c1, d.c2, d.rho, flux,
                theta_ccw, theta_cw, std::fabs(theta_ccw - flux) / std::fabs(flux));
    EXPECT_GT(std::fabs(flux), 1e-3);
    EXPECT_LE(std::fabs(theta_ccw - flux), 1e-8 * std::fabs(flux));
    EXPECT_LE(std::fabs(theta_cw + flux), 1e-8 * std::fabs(flux));
  }
}

// A rectangle [a1, b1] × [a2, b2] counter-clockwise, one side per call of compute_phase (each side a
// straight segment at constant speed, so the path is smooth within every call). In SE(2) the pieces
// compose as g = g1 g2 g3 g4 and the angles add.
TEST(Stokes, OrientationPhaseOfARectangleIsTheEnclosedCurvature) {
  const double a1 = 0.2, b1 = 1.4, a2 = -0.5, b2 = 0.7;
  const ex t = robot().t();
  const std::vector<std::vector<ex>> sides = {{a1 + (b1 - a1) * t, ex(a2)},
                                              {ex(b1), a2 + (b2 - a2) * t},
                                              {b1 - (b1 - a1) * t, ex(b2)},
                                              {ex(a1), b2 - (b2 - a2) * t}};
  double theta = 0;
  for (const auto& side : sides) theta += *robot().phase(side).cycles.back().theta;
  const double flux = curvature_in_rectangle(a1, b1, a2, b2);
  std::printf("rectangle: flux %.15e, phase %.15e, rel %.2e\n", flux, theta, std::fabs(theta - flux) / std::fabs(flux));
  EXPECT_GT(std::fabs(flux), 1e-3);
  EXPECT_LE(std::fabs(theta - flux), 1e-8 * std::fabs(flux));
}

TEST(PseudoHolonomy, CurvatureIsOddAboutTheHalfPeriodPoints) {
  for (const auto& c : std::vector<std::array<double, 2>>{{0, 0}, {M_PI, 0}, {0, M_PI}, {M_PI, M_PI}}) {
    EXPECT_NEAR(robot().B(c[0], c[1]), 0, 1e-15);
    for (const auto& q : std::vector<std::array<double, 2>>{{0.3, -0.7}, {1.1, 0.4}, {-0.2, 2.5}}) {
      const double plus = robot().B(c[0] + q[0], c[1] + q[1]), minus = robot().B(c[0] - q[0], c[1] - q[1]);
      EXPECT_GT(std::fabs(plus), 1e-4);
      EXPECT_NEAR(plus, -minus, 1e-14 * std::fabs(plus));
    }
  }
}

TEST(PseudoHolonomy, ALoopSymmetricAboutTheOriginReturnsTheBase) {
  // q(t + 1/2) = −q(t): a tilted ellipse about q = 0, the joints moving with a phase shift.
  const ex t = robot().t();
  const ex w = 2 * GiNaC::Pi * t;
  auto ellipse = [&](double c1, double c2) {
    return std::vector<ex>{ex(c1) + ex(1.2) * GiNaC::cos(w), ex(c2) + ex(0.9) * GiNaC::sin(w + ex(0.6))};
  };
  // B takes both signs inside the loop (the necessary condition for a zero phase).
  double b_min = 0, b_max = 0;
  for (int k = 0; k < 64; ++k)
    for (double s : {0.3, 0.6, 0.9}) {
      const double phi = 2 * M_PI * k / 64;
      const double b = robot().B(s * 1.2 * std::cos(phi), s * 0.9 * std::sin(phi + 0.6));
      b_min = std::min(b_min, b);
      b_max = std::max(b_max, b);
    }
  EXPECT_LT(b_min, -1e-3);
  EXPECT_GT(b_max, 1e-3);

  const hamel::PhaseResult symmetric = robot().phase(ellipse(0, 0));
  const hamel::GroupPose& g = symmetric.cycles.back();
  // Over the loop the base turns and moves, then comes back.
  double theta_range = 0, p_range = 0;
  for (const auto& pose : symmetric.trajectory) {
    theta_range = std::max(theta_range, std::fabs(*pose.theta));
    p_range = std::max(p_range, std::hypot(pose.p[0], pose.p[1]));
  }
  std::printf("symmetric loop: theta %.3e, p (%.3e, %.3e); max |theta| on the way %.3f, max |p| %.3f\n", *g.theta,
              g.p[0], g.p[1], theta_range, p_range);
  EXPECT_GT(theta_range, 0.05);
  EXPECT_GT(p_range, 0.01);
  EXPECT_LE(std::fabs(*g.theta), 1e-9);
  EXPECT_LE(std::hypot(g.p[0], g.p[1]), 1e-9);

  const hamel::PhaseResult shifted = robot().phase(ellipse(0.6, 0));
  const hamel::GroupPose& h = shifted.cycles.back();
  std::printf("shifted loop: theta %.6e, p (%.6e, %.6e)\n", *h.theta, h.p[0], h.p[1]);
  EXPECT_GT(std::fabs(*h.theta), 1e-2);
}

// With zero momentum the system centre of mass stays where it was: p + R(θ) r_c(q) = r_c(q(0)) along
// the whole motion, and after a loop p = (I − R(Δθ)) r_c(q(0)).
TEST(PseudoHolonomy, TheCentreOfMassStaysFixedSoTheTranslationFollowsTheOrientation) {
  const double c1 = 1.0, c2 = 1.2, rho = 0.8;
  const hamel::PhaseResult r = robot().phase(circle(c1, c2, rho));
  const auto rc0 = robot().centre_of_mass(c1 + rho, c2);
  double worst = 0;
  for (const auto& pose : r.trajectory) {
    const double q1 = c1 + rho * std::cos(2 * M_PI * pose.t), q2 = c2 + rho * std::sin(2 * M_PI * pose.t);
    const auto rc = robot().centre_of_mass(q1, q2);
    const double c = std::cos(*pose.theta), s = std::sin(*pose.theta);
    worst = std::max(
        worst, std::hypot(pose.p[0] + c * rc[0] - s * rc[1] - rc0[0], pose.p[1] + s * rc[0] + c * rc[1] - rc0[1]));
  }
  const hamel::GroupPose& g = r.cycles.back();
  const double c = std::cos(*g.theta), s = std::sin(*g.theta);
  const double px = rc0[0] - (c * rc0[0] - s * rc0[1]), py = rc0[1] - (s * rc0[0] + c * rc0[1]);
  std::printf("centre of mass drift %.2e; after the loop theta %.6e, p (%.6e, %.6e), expected (%.6e, %.6e)\n", worst,
              *g.theta, g.p[0], g.p[1], px, py);
  EXPECT_GT(std::fabs(*g.theta), 1e-2);
  EXPECT_LE(worst, 1e-9);
  EXPECT_LE(std::hypot(g.p[0] - px, g.p[1] - py), 1e-9);
}

}  // namespace
