// The snakeboard (models/snakeboard.yaml), a bundle on SE(2) whose two wheel constraints leave one group direction
// free, against references that share no code with hamel's nonholonomic derivation
// (derive/nonholonomic_connection, derive/nonholonomic_momentum):
//  - the Euler–Lagrange equations in general coordinates q = (x, y, θ, ψ, φ) with the two wheel constraints and
//    their Lagrange multipliers, written out here: M q̈ = Q + aᵀλ, a q̈ + ȧ q̇ = 0 (a constant M);
//  - the published nonholonomic momentum and momentum equation of Bloch, Krishnaprasad, Marsden & Murray,
//    "Nonholonomic mechanical systems with symmetry", Arch. Rational Mech. Anal. 136 (1996) 21–99, the snakeboard
//    example (after Lewis, Ostrowski, Murray & Burdick 1994 and Ostrowski's thesis, 1996): with J + J0 + 2 J1 = m l²,
//        p = −2 m l cos²φ (cos θ ẋ + sin θ ẏ) + (m l² θ̇ + J0 ψ̇) sin 2φ,
//        ṗ = 2 J0 cos²φ ψ̇ φ̇ − tan φ p φ̇,
//    p = ⟨∂L/∂q̇, ξ_Q⟩ along the section ξ_Q = −2l cos²φ (cos θ ∂x + sin θ ∂y) + sin 2φ ∂θ of D ∩ V.
// The reduced state (ψ, φ, Ω_S, ψ̇, φ̇) is integrated with the emitted rhs (the interpreter `simulate` runs), the
// pose (θ, x, y) from the group_velocity kernel; along the trajectory the accelerations, the multiplier reference's
// q̈ and the momentum's rate are compared, with parameters off BKMM's simplification for the general check.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/phase.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <map>
#include <random>

namespace {

using hamel::test::source;

struct Parameters {
  double m, l, J, J0, J1;
};

// The multiplier reference: q = (x, y, θ, ψ, φ), L = ½ m (ẋ² + ẏ²) + ½ J θ̇² + ½ J0 (θ̇ + ψ̇)²
// + ½ J1 ((θ̇ + φ̇)² + (θ̇ − φ̇)²); the back wheel (at −l, turned by φ) and the front wheel (at +l, turned by −φ)
// do not slip sideways: −sin(θ ± φ) ẋ + cos(θ ± φ) ẏ ∓ l cos φ θ̇ = 0.
Eigen::Matrix<double, 5, 1> reference_acceleration(const Parameters& P, const Eigen::Matrix<double, 5, 1>& q,
                                                   const Eigen::Matrix<double, 5, 1>& qd, double tau_psi,
                                                   double tau_phi) {
  const double th = q[2], ph = q[4], thd = qd[2], phd = qd[4];
  Eigen::Matrix<double, 5, 5> M = Eigen::Matrix<double, 5, 5>::Zero();
  M(0, 0) = M(1, 1) = P.m;
  M(2, 2) = P.J + P.J0 + 2 * P.J1;
  M(2, 3) = M(3, 2) = M(3, 3) = P.J0;
  M(4, 4) = 2 * P.J1;
  Eigen::Matrix<double, 2, 5> a = Eigen::Matrix<double, 2, 5>::Zero();
  a << -std::sin(th + ph), std::cos(th + ph), -P.l * std::cos(ph), 0, 0,  //
      -std::sin(th - ph), std::cos(th - ph), P.l * std::cos(ph), 0, 0;
  Eigen::Matrix<double, 2, 5> a_dot = Eigen::Matrix<double, 2, 5>::Zero();
  a_dot << -std::cos(th + ph) * (thd + phd), -std::sin(th + ph) * (thd + phd), P.l * std::sin(ph) * phd, 0, 0,  //
      -std::cos(th - ph) * (thd - phd), -std::sin(th - ph) * (thd - phd), -P.l * std::sin(ph) * phd, 0, 0;
  Eigen::Matrix<double, 7, 7> K = Eigen::Matrix<double, 7, 7>::Zero();
  K.topLeftCorner<5, 5>() = M;
  K.topRightCorner<5, 2>() = -a.transpose();
  K.bottomLeftCorner<2, 5>() = a;
  Eigen::Matrix<double, 7, 1> rhs = Eigen::Matrix<double, 7, 1>::Zero();
  rhs[3] = tau_psi;
  rhs[4] = tau_phi;
  rhs.tail<2>() = -a_dot * qd;
  return K.fullPivLu().solve(rhs).head<5>();
}

// BKMM's section ξ_Q(q) of D ∩ V and its rate along q̇.
Eigen::Matrix<double, 5, 1> section(const Parameters& P, const Eigen::Matrix<double, 5, 1>& q) {
  const double th = q[2], ph = q[4], c2 = std::cos(ph) * std::cos(ph);
  Eigen::Matrix<double, 5, 1> z;
  z << -2 * P.l * c2 * std::cos(th), -2 * P.l * c2 * std::sin(th), std::sin(2 * ph), 0, 0;
  return z;
}
Eigen::Matrix<double, 5, 1> section_rate(const Parameters& P, const Eigen::Matrix<double, 5, 1>& q,
                                         const Eigen::Matrix<double, 5, 1>& qd) {
  const double th = q[2], ph = q[4], thd = qd[2], phd = qd[4];
  const double c2 = std::cos(ph) * std::cos(ph), s2 = std::sin(2 * ph);
  Eigen::Matrix<double, 5, 1> z;
  z << 2 * P.l * (s2 * phd * std::cos(th) + c2 * std::sin(th) * thd),
      2 * P.l * (s2 * phd * std::sin(th) - c2 * std::cos(th) * thd), 2 * std::cos(2 * ph) * phd, 0, 0;
  return z;
}

Eigen::Matrix<double, 5, 5> mass_matrix(const Parameters& P) {
  Eigen::Matrix<double, 5, 5> M = Eigen::Matrix<double, 5, 5>::Zero();
  M(0, 0) = M(1, 1) = P.m;
  M(2, 2) = P.J + P.J0 + 2 * P.J1;
  M(2, 3) = M(3, 2) = M(3, 3) = P.J0;
  M(4, 4) = 2 * P.J1;
  return M;
}

// The model's kernels and symbolic results at the parameters P (left symbolic in the derivation, passed as p[]).
struct Snakeboard {
  hamel::Model model = hamel::load_model(source("models/snakeboard.yaml"));
  hamel::Derivation d = hamel::derive(model);
  hamel::KernelSet k = hamel::build_kernels(model, d);
  std::vector<double> p;
  explicit Snakeboard(const Parameters& P) {
    const std::map<std::string, double> values{{"m", P.m}, {"l", P.l}, {"J", P.J}, {"J0", P.J0}, {"J1", P.J1}};
    for (const auto& par : model.parameters) p.push_back(values.at(par.symbol.get_name()));
  }
  // A derived expression of the reduced state (and the momentum p_S) at numbers.
  double value(const GiNaC::ex& e, const hamel::Intermediates& program, const std::array<double, 5>& x,
               double p_S = 0) const {
    GiNaC::exmap at;
    for (std::size_t i = 0; i < model.parameters.size(); ++i) at[model.parameters[i].symbol] = p[i];
    const char* names[] = {"psi", "phi", "Omega_S", "psi_dot", "phi_dot"};
    const GiNaC::symtab all = model.symbols();
    for (int i = 0; i < 5; ++i) at[all.at(names[i])] = x[static_cast<std::size_t>(i)];
    at[d.momentum_equation->momenta[0]] = p_S;
    const GiNaC::exmap values = program.evaluate(at);
    return GiNaC::ex_to<GiNaC::numeric>(e.subs(values).evalf()).to_double();
  }
};

TEST(Snakeboard, StateIsShapeMomentumVelocityAndShapeRates) {
  Snakeboard s({3.0, 0.3, 0.15, 0.1, 0.01});
  ASSERT_TRUE(s.d.momentum_equation);
  std::vector<std::string> state;
  for (const auto& c : s.d.system.coordinates) state.push_back(c.get_name());
  for (int I : s.d.equations.independent)
    state.push_back(s.d.system.velocities[static_cast<std::size_t>(I)].get_name());
  EXPECT_EQ(state, (std::vector<std::string>{"psi", "phi", "Omega_S", "psi_dot", "phi_dot"}));
}

// Along a trajectory with time-varying rotor and steering torques, at parameters off BKMM's simplification.
TEST(Snakeboard, ReducedEquationsMatchLagrangeMultipliersAlongATrajectory) {
  const Parameters P{2.5, 0.35, 0.21, 0.08, 0.015};
  Snakeboard s(P);
  hamel::GraphEvaluator rhs(s.k.graph, s.k.get("rhs").outputs);
  hamel::GraphEvaluator xi(s.k.graph, s.k.get("group_velocity").outputs);
  ASSERT_EQ(s.k.get("rhs").outputs.size(), 5u);
  const auto inputs = [](double t) { return std::array<double, 2>{0.05 * std::cos(3 * t), -0.02 * std::sin(2 * t)}; };
  // Extended state: the reduced (ψ, φ, Ω_S, ψ̇, φ̇), then the pose (θ, x, y).
  using State = std::array<double, 8>;
  const auto velocity = [&](const State& z, std::array<double, 3>& g) {
    xi.evaluate(0, z.data(), s.p.data(), nullptr, g.data());
  };
  const auto f = [&](double t, const State& z) {
    State dz{};
    const std::array<double, 2> in = inputs(t);
    rhs.evaluate(t, z.data(), s.p.data(), in.data(), dz.data());
    std::array<double, 3> g;
    velocity(z, g);  // (ω, vx, vy), body frame
    dz[5] = g[0];
    dz[6] = std::cos(z[5]) * g[1] - std::sin(z[5]) * g[2];
    dz[7] = std::sin(z[5]) * g[1] + std::cos(z[5]) * g[2];
    return dz;
  };
  // ξ as the derivation gives it, for its rate along the reduced motion (by GiNaC's differentiation).
  std::vector<GiNaC::ex> xi_closed;
  for (const GiNaC::ex& e : s.d.group_velocity) xi_closed.push_back(s.d.system.program.inline_all(e));
  const GiNaC::symtab syms = s.model.symbols();
  const char* names[] = {"psi", "phi", "Omega_S", "psi_dot", "phi_dot"};

  State z{0.2, 0.4, -1.1, 1.5, -0.7, 0.3, 0.1, -0.2};
  const double h = 1e-3;
  double worst_acceleration = 0, worst_constraint = 0, worst_momentum = 0;
  int compared = 0;
  for (int step = 0; step <= 1500; ++step) {
    const double t = step * h;
    if (step % 100 == 0) {
      const State dz = f(t, z);
      std::array<double, 3> g;
      velocity(z, g);
      Eigen::Matrix<double, 5, 1> q, qd, qdd;
      q << z[6], z[7], z[5], z[0], z[1];
      qd << dz[6], dz[7], dz[5], dz[0], dz[1];
      // ξ̇ = ∂ξ/∂x ẋ of the reduced motion; q̈ from it in the inertial frame.
      GiNaC::exmap at;
      for (std::size_t i = 0; i < s.model.parameters.size(); ++i) at[s.model.parameters[i].symbol] = s.p[i];
      for (int i = 0; i < 5; ++i) at[syms.at(names[i])] = z[static_cast<std::size_t>(i)];
      std::array<double, 3> g_dot{};
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 5; ++i) {
          const GiNaC::ex de =
              xi_closed[static_cast<std::size_t>(a)].diff(GiNaC::ex_to<GiNaC::symbol>(syms.at(names[i])));
          g_dot[static_cast<std::size_t>(a)] +=
              GiNaC::ex_to<GiNaC::numeric>(de.subs(at).evalf()).to_double() * dz[static_cast<std::size_t>(i)];
        }
      const double th = z[5], thd = g[0];
      // vx = cos θ ẋ + sin θ ẏ, vy = −sin θ ẋ + cos θ ẏ: ẍ, ÿ from v̇ and θ̇.
      const double ax = g_dot[1] - thd * g[2], ay = g_dot[2] + thd * g[1];
      qdd << std::cos(th) * ax - std::sin(th) * ay, std::sin(th) * ax + std::cos(th) * ay, g_dot[0], dz[3], dz[4];
      const std::array<double, 2> in = inputs(t);
      const Eigen::Matrix<double, 5, 1> want = reference_acceleration(P, q, qd, in[0], in[1]);
      worst_acceleration =
          std::max(worst_acceleration, (qdd - want).cwiseAbs().maxCoeff() / want.cwiseAbs().maxCoeff());
      // The reconstructed velocity meets both wheel constraints.
      const double c1 = -std::sin(th + q[4]) * qd[0] + std::cos(th + q[4]) * qd[1] - P.l * std::cos(q[4]) * qd[2];
      const double c2 = -std::sin(th - q[4]) * qd[0] + std::cos(th - q[4]) * qd[1] + P.l * std::cos(q[4]) * qd[2];
      worst_constraint = std::max({worst_constraint, std::fabs(c1), std::fabs(c2)});
      // The nonholonomic momentum p = ⟨∂L/∂q̇, ξ_Q⟩ and its rate along the multiplier reference's motion.
      const Eigen::Matrix<double, 5, 5> M = mass_matrix(P);
      const double p_ref = (M * qd).dot(section(P, q));
      const double p_rate_ref = (M * want).dot(section(P, q)) + (M * qd).dot(section_rate(P, q, qd));
      const std::array<double, 5> x{z[0], z[1], z[2], z[3], z[4]};
      const hamel::NonholonomicMomentum& nm = *s.d.momentum_equation;
      const double p_hamel = s.value(nm.momentum[0], s.d.equations.intermediates, x);
      const double p_rate = s.value(nm.rate[0], s.d.equations.intermediates, x, p_hamel);
      worst_momentum = std::max({worst_momentum, std::fabs(p_hamel - p_ref) / std::fabs(p_ref),
                                 std::fabs(p_rate - p_rate_ref) / std::max(1e-3, std::fabs(p_rate_ref))});
      ++compared;
    }
    // Classical RK4 on the extended state.
    const State k1 = f(t, z);
    State y;
    for (int i = 0; i < 8; ++i) y[i] = z[i] + h / 2 * k1[i];
    const State k2 = f(t + h / 2, y);
    for (int i = 0; i < 8; ++i) y[i] = z[i] + h / 2 * k2[i];
    const State k3 = f(t + h / 2, y);
    for (int i = 0; i < 8; ++i) y[i] = z[i] + h * k3[i];
    const State k4 = f(t + h, y);
    for (int i = 0; i < 8; ++i) z[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }
  EXPECT_EQ(compared, 16);
  EXPECT_LT(worst_acceleration, 1e-10);
  EXPECT_LT(worst_constraint, 1e-13);
  EXPECT_LT(worst_momentum, 1e-10);
}

// BKMM's momentum equation at random states, with the defaults (J + J0 + 2 J1 = m l²).
TEST(Snakeboard, MomentumEquationIsBKMMsPublishedForm) {
  const Parameters P{3.0, 0.3, 0.15, 0.1, 0.01};
  ASSERT_NEAR(P.J + P.J0 + 2 * P.J1, P.m * P.l * P.l, 1e-15);
  Snakeboard s(P);
  const hamel::NonholonomicMomentum& nm = *s.d.momentum_equation;
  ASSERT_EQ(nm.momenta.size(), 1u);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  double worst = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const std::array<double, 5> x{u(rng), u(rng), u(rng), 2 * u(rng), 2 * u(rng)};  // ψ, φ, (Ω_S unused), ψ̇, φ̇
    const double p = 3 * u(rng), phi = x[1];
    const double published = 2 * P.J0 * std::cos(phi) * std::cos(phi) * x[3] * x[4] - std::tan(phi) * p * x[4];
    worst = std::max(worst, std::fabs(s.value(nm.rate[0], s.d.equations.intermediates, x, p) - published));
  }
  EXPECT_LT(worst, 1e-12);
}

// Bad `constraints` on a bundle: errors name file:line, the key and what was expected.
std::string board(const std::string& constraints, const std::string& connection = "") {
  return "name: board\nparameters: {m: 1, l: 0.3}\ngroup: SE2\ngroup_velocity: [omega, vx, vy]\nshape: [phi]\n" +
         constraints + connection + "kinetic: \"1/2*m*(vx^2 + vy^2 + omega^2 + phi_dot^2)\"\n";
}

std::string error_of(const std::string& text) {
  try {
    (void)hamel::derive(hamel::load_model_from_text(text, "bad.yaml"));
  } catch (const hamel::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SnakeboardModelErrors, NameTheConstraintAndWhatWasExpected) {
  const struct {
    std::string text, location, fragment;
  } cases[] = {
      {board("constraints: {a: \"vx*vy\"}\n"), "bad.yaml:6:", "is not linear in the velocities"},
      {board("constraints: {a: \"vx + l\"}\n"), "bad.yaml:6:", "part without a velocity"},
      {board("constraints: {a: \"phi_dot\"}\n"), "bad.yaml:6:", "does not involve the group velocity"},
      {board("constraints: {a: vx, b: vy, c: omega}\n"), "bad.yaml:6:", "leave none free"},
      {board("constraints: [vx]\n"), "bad.yaml:6:", "expected an ordered map"},
      {board("constraints: {a: vy, b: \"2*vy\"}\n"), "bad.yaml:6:", "rank below 2"},
      {board("constraints: {a: vy}\n", "connection: mechanical\n"), "bad.yaml:7:", "expected 'nonholonomic'"},
      {board("", "connection: nonholonomic\n"), "bad.yaml:6:", "needs the constraints"},
      {board("constraints: {vx: vy}\n"), "bad.yaml:6:", "already declared"},
  };
  for (const auto& c : cases) {
    const std::string message = error_of(c.text);
    EXPECT_NE(message.find(c.location), std::string::npos) << message;
    EXPECT_NE(message.find(c.fragment), std::string::npos) << message;
    EXPECT_TRUE(message.find("'constraints") != std::string::npos || message.find("'connection'") != std::string::npos)
        << message;
  }
}

TEST(SnakeboardModelErrors, PhaseRefusesANonholonomicModel) {
  const hamel::Model model = hamel::load_model(source("models/snakeboard.yaml"));
  hamel::PhaseRequest req;
  req.path = {GiNaC::sin(GiNaC::realsymbol("t")), 0};
  try {
    hamel::check_phase_request(model, req);
    FAIL() << "no error";
  } catch (const hamel::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("snakeboard.yaml:"), std::string::npos) << message;
    EXPECT_NE(message.find("momentum equation"), std::string::npos) << message;
  }
}

}  // namespace
