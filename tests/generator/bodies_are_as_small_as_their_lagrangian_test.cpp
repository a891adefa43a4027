// A model written with `bodies:` (rigid bodies and their poses or twists, docs/model-format.md) must derive and emit as
// small as the same model with its Lagrangian written out (issue 48): what is exact prints exactly, and rhs takes at
// most 1.2 times the operations. Each pair of files describes one system twice; the two derivations share nothing
// but the generator, so their mass matrices and forcings agreeing at random states is an independent check of both.
//   - the torque-free rigid body in ZYX angles (models/rigid_body_euler_zyx.yaml and a `bodies:` copy): M is
//     diag(I1, I2, I3) entry by entry;
//   - a snakeboard with its two wheel constraints (bodies_models/snakeboard_*.yaml): the steering equation is
//     exactly 2 J1 w_phi' = tau_phi;
//   - a quadrotor with a slung load in ZYX angles (bodies_models/quadrotor_*.yaml): M[wy][wy] prints as the
//     hand-written Lagrangian's, M[vx][vx] = m + mL;
//   - the quadrotor with its load on SE(3), bodies given by their twists (bodies_models/quadrotor_se3_*.yaml), in
//     the Euler-Poincare form (the Lagrange-Poincare form: 8 220 against 7 726 operations, in seconds: not here).
#include "algebra/simplify.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <string>

namespace {

std::string with_bodies(std::string text) {
  const std::size_t at = text.find("lagrangian:");
  text.replace(at, std::string::npos,
               "bodies:\n"
               "  - name: body\n"
               "    mass: m\n"
               "    com: [0, 0, 0]\n"
               "    inertia: [[I1, 0, 0], [0, I2, 0], [0, 0, I3]]\n"
               "    rotation: [[z, psi], [y, theta], [x, phi]]\n"
               "    position: [0, 0, 0]\n");
  text.replace(text.find("parameters:\n"), 12, "parameters:\n  m: 1.0\n");
  return text;
}

hamel::Model load(const std::string& file) {
  const std::string path = hamel::test::source("tests/generator/bodies_models/" + file);
  return hamel::load_model_from_text(hamel::test::slurp(path), path);
}

int rhs_operations(const hamel::Model& model, const hamel::Derivation& d) {
  const hamel::KernelSet k = hamel::build_kernels(model, d, {"rhs"});
  return k.graph.count(k.graph.schedule(k.get("rhs").outputs)).total();
}

std::string printed(const GiNaC::ex& e) {
  std::ostringstream out;
  out << e;
  return out.str();
}

// The same system twice: M and f agree at random states (every symbol of the model drawn in [0.2, 1.2], the
// parameters too, so no default value hides a term), and the bodies' rhs is no larger than 1.2 times the other's.
void expect_same_and_as_small(const hamel::Model& by_hand, const hamel::Model& bodies,
                              const hamel::DeriveSettings& settings = {}) {
  const hamel::Derivation a = hamel::derive(by_hand, settings), b = hamel::derive(bodies, settings);
  ASSERT_EQ(a.equations.independent.size(), b.equations.independent.size());
  std::mt19937 random(48);
  std::uniform_real_distribution<double> draw(0.2, 1.2);
  // Values by name: the system's velocities (the Lagrange-Poincare form's locked ones are not the model's symbols)
  // and the model's symbols.
  const auto symbols_of = [](const hamel::Model& model, const hamel::Derivation& d) {
    std::map<std::string, GiNaC::ex> out;
    for (const auto& [name, symbol] : model.symbols()) out[name] = symbol;
    for (const auto& u : d.system.velocities) out[u.get_name()] = u;
    return out;
  };
  const std::map<std::string, GiNaC::ex> symbols_a = symbols_of(by_hand, a), symbols_b = symbols_of(bodies, b);
  for (int point = 0; point < 5; ++point) {
    GiNaC::exmap values, values_b;
    for (const auto& [name, symbol] : symbols_a) {
      const double v = draw(random);
      values[symbol] = v;
      if (symbols_b.count(name)) values_b[symbols_b.at(name)] = v;
    }
    hamel::Intermediates::ValueMemo memo_a, memo_b;
    const auto value = [](const hamel::Derivation& d, const GiNaC::ex& e, const GiNaC::exmap& at,
                          hamel::Intermediates::ValueMemo& memo) {
      const GiNaC::ex v = d.equations.intermediates.value_at(e, at, memo);
      EXPECT_TRUE(GiNaC::is_a<GiNaC::numeric>(v)) << e;
      return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
    };
    const unsigned n = static_cast<unsigned>(a.equations.independent.size());
    for (unsigned i = 0; i < n; ++i) {
      const double fa = value(a, a.equations.forcing[i], values, memo_a);
      const double fb = value(b, b.equations.forcing[i], values_b, memo_b);
      EXPECT_NEAR(fa, fb, 1e-11 * (1 + std::abs(fa))) << "f[" << i << "] at point " << point;
      for (unsigned j = 0; j < n; ++j) {
        const double Ma = value(a, a.equations.mass_matrix(i, j), values, memo_a);
        const double Mb = value(b, b.equations.mass_matrix(i, j), values_b, memo_b);
        EXPECT_NEAR(Ma, Mb, 1e-11 * (1 + std::abs(Ma))) << "M[" << i << "][" << j << "] at point " << point;
      }
    }
  }
  const int operations_by_hand = rhs_operations(by_hand, a), operations_bodies = rhs_operations(bodies, b);
  std::printf("%s: rhs operations, Lagrangian written out %d, bodies %d\n", bodies.name.c_str(), operations_by_hand,
              operations_bodies);
  EXPECT_LE(operations_bodies, 1.2 * operations_by_hand);
}

TEST(BodiesAreAsSmallAsTheirLagrangian, RigidBodyInEulerAngles) {
  const std::string text = hamel::test::slurp(hamel::test::source("models/rigid_body_euler_zyx.yaml"));
  const hamel::Model lagrangian = hamel::load_model_from_text(text, "lagrangian.yaml");
  const hamel::Model bodies = hamel::load_model_from_text(with_bodies(text), "bodies.yaml");
  const hamel::Derivation d = hamel::derive(bodies);
  const GiNaC::matrix& M = d.equations.mass_matrix;
  const char* const inertia[3] = {"I1", "I2", "I3"};
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) {
      if (i != j) {
        EXPECT_TRUE(M(i, j).is_zero()) << "M[" << i << "][" << j << "] = " << M(i, j);
        continue;
      }
      EXPECT_EQ(printed(M(i, i)), inertia[i]);
    }
  const hamel::Derivation by_hand = hamel::derive(lagrangian);
  const int operations_by_hand = rhs_operations(lagrangian, by_hand), operations_bodies = rhs_operations(bodies, d);
  std::printf("rhs operations: Lagrangian written out %d, bodies %d\n", operations_by_hand, operations_bodies);
  EXPECT_LE(operations_bodies, 1.2 * operations_by_hand);
}

TEST(BodiesAreAsSmallAsTheirLagrangian, Snakeboard) {
  const hamel::Model by_hand = load("snakeboard_lagrangian.yaml"), bodies = load("snakeboard_bodies.yaml");
  expect_same_and_as_small(by_hand, bodies);
  // Independent: v, w_psi, w_phi. The steering takes no constraint force (the wheels turn about their contact
  // points), so its equation is 2 J1 w_phi' = tau_phi, decoupled from the others.
  const hamel::Derivation d = hamel::derive(bodies);
  EXPECT_EQ(printed(d.equations.forcing[2]), "tau_phi");
  EXPECT_EQ(printed(d.equations.mass_matrix(2, 2)), "2*J1");
  for (unsigned j = 0; j < 2; ++j) {
    EXPECT_TRUE(d.equations.mass_matrix(2, j).is_zero()) << d.equations.mass_matrix(2, j);
    EXPECT_TRUE(d.equations.mass_matrix(j, 2).is_zero()) << d.equations.mass_matrix(j, 2);
  }
}

TEST(BodiesAreAsSmallAsTheirLagrangian, QuadrotorWithSlungLoad) {
  const hamel::Model by_hand = load("quadrotor_lagrangian.yaml"), bodies = load("quadrotor_bodies.yaml");
  expect_same_and_as_small(by_hand, bodies);
  const hamel::Derivation a = hamel::derive(by_hand), b = hamel::derive(bodies);
  // Independent: vx, vy, vz, wx, wy, wz, a_rate, b_rate. Exact entries print as the hand-written Lagrangian's: the
  // same normal form (terms in GiNaC's order, which may differ between the two programs).
  const std::string mass = printed(b.equations.mass_matrix(0, 0));
  EXPECT_TRUE(mass == "m+mL" || mass == "mL+m") << mass;
  EXPECT_TRUE(b.equations.mass_matrix(0, 1).is_zero()) << b.equations.mass_matrix(0, 1);
  const GiNaC::ex& wy_b = b.equations.mass_matrix(4, 4);
  const GiNaC::ex& wy_a = a.equations.mass_matrix(4, 4);
  GiNaC::exmap by_name;  // the two models' symbols are different objects of the same names
  const GiNaC::symtab symbols_a = by_hand.symbols();
  for (const auto& [name, symbol] : bodies.symbols())
    if (symbols_a.count(name)) by_name[symbol] = symbols_a.at(name);
  EXPECT_TRUE(hamel::simplify(wy_b.subs(by_name) - wy_a).is_zero()) << wy_b << " against " << wy_a;
  EXPECT_EQ(printed(wy_b).size(), printed(wy_a).size()) << wy_b << " against " << wy_a;
}

TEST(BodiesAreAsSmallAsTheirLagrangian, QuadrotorOnSe3ByTwists) {
  const hamel::Model by_hand = load("quadrotor_se3_kinetic.yaml"), bodies = load("quadrotor_se3_bodies.yaml");
  for (const char* form : {"ep"}) {
    SCOPED_TRACE(form);
    hamel::DeriveSettings settings;
    settings.form = form;
    expect_same_and_as_small(by_hand, bodies, settings);
  }
}

}  // namespace
