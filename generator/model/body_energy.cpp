#include "model/body_energy.hpp"

#include <array>
#include <string>

namespace hamel {

namespace {

// ½ m |v_c|² + ½ ωᵀΘω.
GiNaC::ex kinetic_energy(const RigidBody& body, const GiNaC::ex (&omega)[3], const GiNaC::ex (&centre_velocity)[3]) {
  GiNaC::ex T = 0;
  for (unsigned i = 0; i < 3; ++i) {
    T += body.mass * centre_velocity[i] * centre_velocity[i] / 2;
    for (unsigned j = 0; j < 3; ++j) T += omega[i] * body.inertia[i][j] * omega[j] / 2;
  }
  return T;
}

}  // namespace

GiNaC::matrix rotation_about(unsigned axis, const GiNaC::ex& angle) {
  const GiNaC::ex c = GiNaC::cos(angle), s = GiNaC::sin(angle);
  GiNaC::matrix E = GiNaC::ex_to<GiNaC::matrix>(GiNaC::unit_matrix(3));
  const unsigned i = (axis + 1) % 3, j = (axis + 2) % 3;
  E(i, i) = c, E(i, j) = -s, E(j, i) = s, E(j, j) = c;
  return E;
}

GiNaC::ex posed_body_kinetic_energy(Model& model, const RigidBody& body, const GiNaC::matrix& R,
                                    const std::vector<GiNaC::ex>& position) {
  Intermediates& program = model.definitions;
  const auto rate = [&](const GiNaC::ex& e) {  // d/dt along q̇, by the chain rule through the program
    GiNaC::ex out = program.diff(e, model.time);
    for (std::size_t a = 0; a < model.coordinates.size(); ++a)
      out += program.diff(e, model.coordinates[a]) * model.rates[a];
    return out;
  };
  const std::string prefix = "_" + body.name + "_";
  GiNaC::matrix Rs(3, 3);
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j)
      Rs(i, j) = GiNaC::is_a<GiNaC::numeric>(R(i, j))
                     ? R(i, j)
                     : GiNaC::ex(program.define_named(prefix + "R" + std::to_string(i) + std::to_string(j), R(i, j)));
  // ω̂ = RᵀṘ: ω = ((RᵀṘ)_21, (RᵀṘ)_02, (RᵀṘ)_10), ω = Σ_a Ω_a q̇_a + Ω_t with Ω_a = (Rᵀ ∂R/∂q_a)^∨. Where R is written
  // out in the coordinates (no definitions in it), each Ω_a is formed from R itself and brought to its normal form:
  // RᵀR = I holds there through sin² + cos² = 1, so a product of elementary rotations gives the short rows of the
  // kinematic equations (ZYX angles: Ω_psi = (−sin θ, cos θ sin φ, cos θ cos φ)) instead of the products of nine
  // named entries whose cancellation no later step sees (issue 48: M of a rigid body in its own angular velocity
  // printed as 1 149 characters where it is exactly its inertia); an Ω_a entry that stays large after that is named
  // (Intermediates::keep), so its derivatives go through the program. Otherwise Ṙ by the chain rule through R's names.
  const auto vee = [](const GiNaC::matrix& M) { return std::array<GiNaC::ex, 3>{M(2, 1), M(0, 2), M(1, 0)}; };
  bool explicit_R = true;
  for (unsigned i = 0; i < 9; ++i) explicit_R = explicit_R && program.used_by(R.op(i)).empty();
  std::array<GiNaC::ex, 3> omega_entries{0, 0, 0};
  if (explicit_R) {
    for (std::size_t a = 0; a <= model.coordinates.size(); ++a) {
      const bool time = a == model.coordinates.size();
      const GiNaC::symbol& by = time ? model.time : model.coordinates[a];
      GiNaC::matrix dR(3, 3);
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned j = 0; j < 3; ++j) dR(i, j) = R(i, j).diff(by);
      const std::array<GiNaC::ex, 3> column = vee(R.transpose().mul(dR));
      const GiNaC::ex rate = time ? GiNaC::ex(1) : GiNaC::ex(model.rates[a]);
      // Small entries inline (where the equations' simplification sees them), larger ones as intermediates.
      for (unsigned i = 0; i < 3; ++i) omega_entries[i] += program.keep(column[i]) * rate;
    }
  } else {
    GiNaC::matrix Rdot(3, 3);
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = 0; j < 3; ++j) Rdot(i, j) = rate(Rs(i, j));
    omega_entries = vee(Rs.transpose().mul(Rdot));
  }
  GiNaC::ex omega[3], velocity[3];
  for (unsigned i = 0; i < 3; ++i) {
    omega[i] = program.define_named(prefix + "w" + std::to_string(i), omega_entries[i]);
    GiNaC::ex centre = position[i];
    for (unsigned j = 0; j < 3; ++j) centre += Rs(i, j) * body.com[j];
    velocity[i] = program.define_named(prefix + "v" + std::to_string(i), rate(centre));
  }
  return kinetic_energy(body, omega, velocity);
}

GiNaC::ex twist_body_kinetic_energy(Model& model, const RigidBody& body, const std::vector<GiNaC::ex>& twist) {
  const auto named = [&](const std::string& what, const GiNaC::ex& e) -> GiNaC::ex {
    if (GiNaC::is_a<GiNaC::symbol>(e) || GiNaC::is_a<GiNaC::numeric>(e)) return e;
    return model.definitions.define_named("_" + body.name + "_" + what, e);
  };
  const GiNaC::ex w[3] = {named("w0", twist[0]), named("w1", twist[1]), named("w2", twist[2])};
  const GiNaC::ex* com = body.com;
  const GiNaC::ex vc[3] = {named("v0", twist[3] + w[1] * com[2] - w[2] * com[1]),
                           named("v1", twist[4] + w[2] * com[0] - w[0] * com[2]),
                           named("v2", twist[5] + w[0] * com[1] - w[1] * com[0])};
  return kinetic_energy(body, w, vc);
}

}  // namespace hamel
