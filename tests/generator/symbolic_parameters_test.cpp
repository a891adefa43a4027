// Derivations through intermediate symbols with the parameters left symbolic (the default):
// (a) the modular identity test decides known identities and non-identities exactly, with parameters in
//     numerators and denominators and sin² + cos² = 1 across sums of angles;
// (b) the falling cat's mechanical connection makes the total angular momentum about the centre of mass
//     vanish — momentum written in this test from rotation matrices with Eigen, not from the generator;
// (c) Routh's rolling disk written with `bodies:` gives the accelerations of the Euler–Lagrange equations
//     with multipliers of a Lagrangian written by hand in this test (O'Reilly's closed form, not built from
//     the pose), solved as a KKT system;
// (d) a model with `definitions:` derives the same equations as the same model written out;
// (e) regression guard: every shipped model derived with symbolic parameters, evaluated at the defaults
//     through its intermediates in 50 digits, equals the derivation with the parameters folded.
#include "algebra/identity_test.hpp"
#include "derive/derivation.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;

using hamel::test::source_dir;

hamel::Model fold_all(const hamel::Model& model) {
  std::map<std::string, double> values;
  for (const auto& p : model.parameters) values[p.symbol.get_name()] = p.default_value;
  return hamel::fold_parameters(model, values);
}

double number(const ex& e, const GiNaC::exmap& values) {
  const ex v = e.subs(values).evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(v)) {
    std::ostringstream text;
    text << "not a number: " << v;
    throw std::runtime_error(text.str());
  }
  return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
}

// The state and parameter values of a derivation at a random point, extended by its intermediates.
GiNaC::exmap evaluate_at(const hamel::Model& model, const hamel::Derivation& d, std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  GiNaC::exmap values;
  for (const auto& p : model.parameters) values[p.symbol] = GiNaC::numeric(p.default_value);
  for (const auto& q : d.system.coordinates) values[q] = GiNaC::numeric(uniform(rng));
  for (const auto& u : d.system.velocities) values[u] = GiNaC::numeric(uniform(rng));
  for (const auto& in : model.inputs) values[in] = GiNaC::numeric(uniform(rng));
  values[model.time] = GiNaC::numeric(uniform(rng));
  return d.equations.intermediates.evaluate(values);
}

TEST(SymbolicParameters, ModularIdentityTestDecidesKnownIdentities) {
  const GiNaC::realsymbol a("a"), b("b"), x("x"), y("y");
  const hamel::Intermediates none;
  const auto zero = [&](const ex& e) { return hamel::identically_zero(e, none); };
  EXPECT_EQ(zero((a + b) / (a * b) - 1 / a - 1 / b), hamel::Identity::zero);
  EXPECT_EQ(zero(pow(sin(x + y), 2) + pow(cos(x + y), 2) - 1), hamel::Identity::zero);
  EXPECT_EQ(zero(sin(2 * x - y) - 2 * sin(x) * cos(x) * cos(y) + cos(2 * x) * sin(y)), hamel::Identity::zero);
  EXPECT_EQ(zero(a / (a + 3 * b) * sin(x) * sin(x) + a / (a + 3 * b) * cos(x) * cos(x) - a / (a + 3 * b)),
            hamel::Identity::zero);
  EXPECT_EQ(zero((a + b) / (a * b) - 1 / a), hamel::Identity::nonzero);
  EXPECT_EQ(zero(sin(2 * x) - 2 * sin(x)), hamel::Identity::nonzero);
  EXPECT_EQ(zero(exp(a) - 1), hamel::Identity::undecided);
  // Square roots are algebraic elements: one root r of x, so x^(j/2) = r^j and derivatives agree.
  EXPECT_EQ(zero(sqrt(a) - 1), hamel::Identity::nonzero);
  EXPECT_EQ(zero(sqrt(a) * sqrt(a) - a), hamel::Identity::zero);
  EXPECT_EQ(zero(pow(a + b, GiNaC::numeric(3, 2)) - (a + b) * sqrt(a + b)), hamel::Identity::zero);
  EXPECT_EQ(zero(sqrt(1 - a * a).diff(a) + a / sqrt(1 - a * a)), hamel::Identity::zero);
  // Through intermediates: s := sin(x)^2, c := cos(x)^2 (definitions), s + c − 1 is zero.
  hamel::Intermediates program;
  const ex s = program.define(pow(sin(x), 2) * a / (a + b)), c = program.define(pow(cos(x), 2) * a / (a + b));
  EXPECT_EQ(hamel::identically_zero(s + c - a / (a + b), program), hamel::Identity::zero);
  EXPECT_EQ(hamel::identically_zero(s + c - a / (a + 2 * b), program), hamel::Identity::nonzero);
  GiNaC::matrix singular(2, 2);
  singular(0, 0) = s, singular(0, 1) = c, singular(1, 0) = 2 * s, singular(1, 1) = 2 * c;
  EXPECT_EQ(hamel::identically_singular(singular, program), hamel::Identity::zero);
  singular(1, 1) = 3 * c;
  EXPECT_EQ(hamel::identically_singular(singular, program), hamel::Identity::nonzero);
}

TEST(SymbolicParameters, QuadraticFormTestAcceptsParametersInDenominators) {
  // satellite_so3xr3 writes (m0 + 3 mr) in denominators: T is still a quadratic form, decided exactly.
  const hamel::Model model = hamel::load_model(source_dir() + "/models/satellite_so3xr3.yaml");
  const hamel::Derivation d = hamel::derive(model);
  ASSERT_TRUE(d.bundle->quadratic);
  // A cubic term makes it not one.
  const std::string text =
      "name: cubic\nparameters: {m: 1}\ngroup: SO3\ngroup_velocity: [a, b, c]\nshape: [r]\n"
      "connection: mechanical\nkinetic: \"1/2*(a^2 + b^2 + c^2 + r_dot^2)/m + a*b*c\"\n";
  EXPECT_THROW(hamel::derive(hamel::load_model_from_text(text, "cubic.yaml")), hamel::InputError);
}

// Angular momentum of the two bodies about the system's centre of mass, in the front body's frame, from
// rotation matrices: Θ1 ω + R Θ2 ω2 + μ d × ḋ with ω2 = Rᵀω + (relative angular velocity), d and ḋ from R.
Eigen::Vector3d cat_momentum(const std::map<std::string, double>& p, double psi, double theta, double psi_dot,
                             double theta_dot, const Eigen::Vector3d& w) {
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  // Ṙ = R ω̂_rel with ω_rel (rear frame) from Ṙ = Rz' Ry + Rz Ry': numerically by a central difference of R.
  const double h = 1e-6;
  const auto rot = [](double a, double b) {
    return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()))
        .toRotationMatrix();
  };
  const Eigen::Matrix3d Rdot =
      (rot(psi + h * psi_dot, theta + h * theta_dot) - rot(psi - h * psi_dot, theta - h * theta_dot)) / (2 * h);
  const Eigen::Matrix3d W = R.transpose() * Rdot;
  const Eigen::Vector3d w_rel(W(2, 1), W(0, 2), W(1, 0));
  const Eigen::Vector3d w2 = R.transpose() * w + w_rel;
  const Eigen::Vector3d d = Eigen::Vector3d(0, 0, p.at("l1")) + R * Eigen::Vector3d(0, 0, p.at("l2"));
  const Eigen::Vector3d d_rel = Rdot * Eigen::Vector3d(0, 0, p.at("l2"));
  const Eigen::Vector3d d_dot = w.cross(d) + d_rel;
  const double mu = p.at("m1") * p.at("m2") / (p.at("m1") + p.at("m2"));
  const Eigen::Matrix3d T1 = Eigen::Vector3d(p.at("A1"), p.at("A1"), p.at("C1")).asDiagonal();
  const Eigen::Matrix3d T2 = Eigen::Vector3d(p.at("A2"), p.at("B2"), p.at("C2")).asDiagonal();
  return T1 * w + R * (T2 * w2) + mu * d.cross(d_dot);
}

TEST(SymbolicParameters, FallingCatConnectionZeroesAngularMomentum) {
  const hamel::Model model = hamel::load_model(source_dir() + "/models/falling_cat.yaml");
  const hamel::Derivation d = hamel::derive(model);  // parameters symbolic
  std::map<std::string, double> p;
  for (const auto& param : model.parameters) p[param.symbol.get_name()] = param.default_value;
  std::mt19937 rng(7);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const GiNaC::exmap values = evaluate_at(model, d, rng);
    const double psi = number(model.coordinates[0], values), theta = number(model.coordinates[1], values);
    const double rates[2] = {number(model.rates[0], values), number(model.rates[1], values)};
    Eigen::Vector3d w = Eigen::Vector3d::Zero();  // ξ = −𝒜 ṙ: zero momentum
    for (unsigned a = 0; a < 3; ++a)
      for (unsigned I = 0; I < 2; ++I) w(a) -= number(d.bundle->connection(a, I), values) * rates[I];
    const Eigen::Vector3d H = cat_momentum(p, psi, theta, rates[0], rates[1], w);
    const Eigen::Vector3d H_spin = cat_momentum(p, psi, theta, 0, 0, Eigen::Vector3d(1, 0, 0));
    worst = std::max(worst, H.norm() / H_spin.norm());
  }
  std::printf("falling cat: worst |momentum| at xi = -A r_dot, relative: %.2e\n", worst);
  EXPECT_LT(worst, 1e-9);  // the central difference of R limits this reference to about 1e-10
}

// Routh's disk: L = ½ m |v_c|² + ½ (A θ̇² + A ψ̇² cos²θ + C (φ̇ + ψ̇ sin θ)²) − m g r cos θ with
// v_c = d/dt (x + r sinψ sinθ, y − r cosψ sinθ, r cosθ), rolling: ẋ = r cosψ φ̇, ẏ = r sinψ φ̇.
TEST(SymbolicParameters, RouthDiskWithBodiesMatchesLagrangeMultipliers) {
  const hamel::Model model = hamel::load_model(source_dir() + "/models/rolling_disk_routh.yaml");
  const hamel::Derivation d = hamel::derive(model);
  const GiNaC::symtab s = model.symbols();
  // The model's own symbols (realsymbols: kept as ex, a copy as GiNaC::symbol would be another type).
  const ex x = s.at("x"), y = s.at("y"), psi = s.at("psi"), th = s.at("theta"), ph = s.at("phi");
  const ex m = s.at("m"), r = s.at("r"), A = s.at("A"), C = s.at("C"), g = s.at("g");
  const std::vector<ex> q = {x, y, psi, th, ph};
  std::vector<ex> qd;
  for (const ex& c : q) qd.push_back(s.at(GiNaC::ex_to<GiNaC::symbol>(c).get_name() + "_dot"));
  const auto D = [](const ex& e, const ex& v) { return e.diff(GiNaC::ex_to<GiNaC::symbol>(v)); };
  const ex t = model.time;
  const ex pos[3] = {x + r * sin(psi) * sin(th), y - r * cos(psi) * sin(th), r * cos(th)};
  ex L = -m * g * r * cos(th);
  for (const ex& p : pos) {
    ex v = 0;
    for (std::size_t a = 0; a < q.size(); ++a) v += D(p, q[a]) * qd[a];
    L += m * v * v / 2;
  }
  L += (A * qd[3] * qd[3] + A * qd[2] * qd[2] * cos(th) * cos(th) + C * pow(qd[4] + qd[2] * sin(th), 2)) / 2;
  // Constraints Φ q̇ = 0: rows (1, 0, 0, 0, −r cosψ), (0, 1, 0, 0, −r sinψ).
  const ex Phi[2][5] = {{1, 0, 0, 0, -r * cos(psi)}, {0, 1, 0, 0, -r * sin(psi)}};

  std::mt19937 rng(3);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    GiNaC::exmap values = evaluate_at(model, d, rng);
    // Consistent rates from the independent quasi-velocities w_psi, w_theta, w_phi (q̇ = B u).
    const GiNaC::symtab sv = [&] {
      GiNaC::symtab out;
      for (const auto& u : d.system.velocities) out[u.get_name()] = u;
      return out;
    }();
    const double u[3] = {number(sv.at("w_psi"), values), number(sv.at("w_theta"), values),
                         number(sv.at("w_phi"), values)};
    const double psi_v = number(psi, values);
    const double r_v = number(r, values);
    const double rates[5] = {r_v * std::cos(psi_v) * u[2], r_v * std::sin(psi_v) * u[2], u[0], u[1], u[2]};
    GiNaC::exmap at;
    for (const auto& [k, v] : values) at[k] = v;
    for (std::size_t a = 0; a < 5; ++a) at[qd[a]] = GiNaC::numeric(rates[a]);
    // KKT: M q̈ − Φᵀλ = −h, Φ q̈ = −Φ̇ q̇.
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(7, 7);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(7);
    for (std::size_t a = 0; a < 5; ++a) {
      const ex p_a = D(L, qd[a]);
      ex h = D(p_a, t) - D(L, q[a]);
      for (std::size_t b = 0; b < 5; ++b) {
        K(a, b) = number(D(p_a, qd[b]), at);
        h += D(p_a, q[b]) * qd[b];
      }
      rhs(a) = -number(h, at);
      for (int k = 0; k < 2; ++k) K(a, 5 + k) = -number(Phi[k][a], at);
    }
    for (int k = 0; k < 2; ++k) {
      ex Phidot_qd = 0;
      for (std::size_t a = 0; a < 5; ++a) {
        K(5 + k, a) = number(Phi[k][a], at);
        for (std::size_t b = 0; b < 5; ++b) Phidot_qd += D(Phi[k][a], q[b]) * qd[b] * qd[a];
      }
      rhs(5 + k) = -number(Phidot_qd, at);
    }
    const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
    // hamel: M u̇ = f.
    const unsigned n = d.equations.mass_matrix.rows();
    Eigen::MatrixXd M(n, n);
    Eigen::VectorXd f(n);
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j < n; ++j) M(i, j) = number(d.equations.mass_matrix(i, j), values);
      f(i) = number(d.equations.forcing[i], values);
    }
    const Eigen::VectorXd udot = M.ldlt().solve(f);
    for (unsigned i = 0; i < 3; ++i)
      worst = std::max(worst, std::fabs(udot(i) - sol(2 + i)) / (1 + std::fabs(sol(2 + i))));
  }
  std::printf("Routh's disk: worst difference of the accelerations to the KKT reference: %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(SymbolicParameters, DefinitionsDeriveTheSameEquationsAsTheWrittenOutModel) {
  const std::string head =
      "name: pendulum_on_cart\nparameters: {m: 1.5, M0: 3, l: 0.7, g: 9.81}\ncoordinates: [s, th]\n"
      "quasi_velocities: {names: [v, w], A: [[1, 0], [0, 1]]}\n";
  const std::string written = head +
                              "lagrangian: \"1/2*M0*s_dot^2 + 1/2*m*((s_dot + l*cos(th)*th_dot)^2 + "
                              "(l*sin(th)*th_dot)^2) + m*g*l*cos(th)\"\n";
  const std::string defined = head +
                              "definitions:\n  bx: s_dot + l*cos(th)*th_dot\n  by: l*sin(th)*th_dot\n"
                              "  T: 1/2*M0*s_dot^2 + 1/2*m*(bx^2 + by^2)\n"
                              "lagrangian: \"T + m*g*l*cos(th)\"\n";
  const hamel::Model a = hamel::load_model_from_text(written, "written.yaml");
  const hamel::Model b = hamel::load_model_from_text(defined, "defined.yaml");
  ASSERT_EQ(b.definitions.size(), 3u);
  const hamel::Derivation da = hamel::derive(a), db = hamel::derive(b);
  std::mt19937 rng(5), rng2(5);
  const GiNaC::exmap va = evaluate_at(a, da, rng), vb = evaluate_at(b, db, rng2);
  for (unsigned i = 0; i < 2; ++i) {
    EXPECT_NEAR(number(da.equations.forcing[i], va), number(db.equations.forcing[i], vb), 1e-13);
    for (unsigned j = 0; j < 2; ++j)
      EXPECT_NEAR(number(da.equations.mass_matrix(i, j), va), number(db.equations.mass_matrix(i, j), vb), 1e-13);
  }
  // A definition with velocities cannot stand in A(q).
  const std::string bad = head.substr(0, head.find("quasi_velocities")) + "definitions: {bx: s_dot}\n" +
                          "quasi_velocities: {names: [v, w], A: [[bx, 0], [0, 1]]}\nlagrangian: \"s_dot^2\"\n";
  EXPECT_THROW(hamel::load_model_from_text(bad, "bad.yaml"), hamel::InputError);
}

// Regression guard (two generator paths): symbolic parameters evaluated at their defaults equal folding.
TEST(SymbolicParameters, EveryShippedModelEqualsItsFoldedDerivation) {
  GiNaC::Digits = 50;
  for (const auto& entry : std::filesystem::directory_iterator(source_dir() + "/models")) {
    if (entry.path().extension() != ".yaml") continue;
    const hamel::Model model = hamel::load_model(entry.path().string());
    const hamel::Derivation symbolic = hamel::derive(model);
    const hamel::Derivation folded = hamel::derive(fold_all(model));
    std::mt19937 rng(11), rng2(11);
    const GiNaC::exmap vs = evaluate_at(model, symbolic, rng), vf = evaluate_at(model, folded, rng2);
    const unsigned n = symbolic.equations.mass_matrix.rows();
    double worst = 0;
    for (unsigned i = 0; i < n; ++i) {
      const double fs = number(symbolic.equations.forcing[i], vs), ff = number(folded.equations.forcing[i], vf);
      worst = std::max(worst, std::fabs(fs - ff) / (1 + std::fabs(ff)));
      for (unsigned j = 0; j < n; ++j) {
        const double ms = number(symbolic.equations.mass_matrix(i, j), vs);
        const double mf = number(folded.equations.mass_matrix(i, j), vf);
        worst = std::max(worst, std::fabs(ms - mf) / (1 + std::fabs(mf)));
      }
    }
    EXPECT_LT(worst, 1e-12) << entry.path();
  }
}

}  // namespace
