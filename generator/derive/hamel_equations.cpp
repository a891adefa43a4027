// Eq. (BHconstr): d/dt ∂ℒ/∂u^I − ∂ℒ/∂q^a B^a_I + ∂ℒ/∂u^a γ^a_IJ u^J = Q_I, u^α = 0 after the
// derivatives, Q_I = B^a_I Q_a. With no constraints this is eq. (BHEqu2). The total time derivative
// is expanded by the chain rule along q̇ = B_J u^J (qadot): d/dt p_I = M_IJ u̇^J + ∂p_I/∂q^a q̇^a + ∂p_I/∂t.
// The same equations in bundle coordinates are (HEorig1/2), (BHESym1/2), (HE-kinBundle) and (HEMomCons):
// only the system (velocities, γ, constraints) differs, see derive/bundle_forms.cpp.
#include "derive/hamel_equations.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"
#include "model/input_error.hpp"
#include "model/model.hpp"

#include <algorithm>
#include <optional>

namespace hamel {

using GiNaC::ex;

std::vector<int> HamelSystem::independent() const { return unconstrained_indices(velocities.size(), constrained); }

namespace {

// ℒ = c + Σ_a g_a u^a + ½ Σ_ab H_ab u^a u^b with its coefficients c, g_a, H_ab (functions of q and t) in small
// closed forms, simplified, when ℒ is such a polynomial in the velocities (ℒ minus it shown zero) and every
// coefficient has one; nothing otherwise (then `program` is left as it was). As derived, ℒ is a program whose
// coefficients cancel only when multiplied out: the kinetic energy of bodies posed by products of rotations holds
// RᵀR = I and sin² + cos² = 1 unapplied, so the mass matrix of a quadrotor in its body angular velocity printed as
// 1 409 characters where it is exactly its inertia, and the convective terms d/dt ∂ℒ/∂u carried the same swell into
// f (issue 48). Written in its simplified coefficients, ℒ's derivatives are the small closed forms a Lagrangian
// written out by hand gives. A coefficient with no small closed form (the satellites' locked inertia and
// connection, the bicycle's potential) keeps the program, whose derivatives share its subexpressions. Terms of
// second degree in the constrained velocities are left out: the equations use ℒ and its first derivatives only
// at u^α = 0, where those terms vanish.
std::optional<ex> simplified_quadratic_lagrangian(const HamelSystem& sys, Intermediates& program) {
  Intermediates trial = program;  // the substitutions and derivatives below define intermediates
  const ex& L = sys.lagrangian;
  const std::size_t nu = sys.velocities.size();
  GiNaC::exmap at_rest;
  for (const auto& u : sys.velocities) at_rest[u] = 0;
  Intermediates::SubstitutionMemo memo;
  const auto at = [&](const ex& e) { return trial.substitute(e, at_rest, memo); };
  const auto is_constrained = [&](std::size_t a) {
    return std::find(sys.constrained.begin(), sys.constrained.end(), static_cast<int>(a)) != sys.constrained.end();
  };
  const std::optional<ex> c = trial.closed_form(at(L));
  if (!c) return std::nullopt;
  ex form = *c, held = 0;  // held: ½ Σ H_αβ u^α u^β, only for the test below
  const std::vector<GiNaC::symbol> velocities(sys.velocities.begin(), sys.velocities.end());
  const std::vector<ex> first = trial.diff(L, velocities);
  for (std::size_t a = 0; a < nu; ++a) {
    const std::optional<ex> g = trial.closed_form(at(first[a]));
    if (!g) return std::nullopt;
    form += *g * sys.velocities[a];
    for (std::size_t b = a; b < nu; ++b) {
      const ex weight = (a == b ? ex(1) / 2 : ex(1)) * sys.velocities[a] * sys.velocities[b];
      const ex second = at(trial.diff(first[a], velocities[b]));
      if (is_constrained(a) && is_constrained(b)) {
        held += second * weight;
        continue;
      }
      const std::optional<ex> H = trial.closed_form(second);
      if (!H) return std::nullopt;
      form += *H * weight;
    }
  }
  if (identically_zero(L - form - held, trial) != Identity::zero) return std::nullopt;  // ℒ is not quadratic
  program = std::move(trial);
  return form;
}

}  // namespace

HamelEquations hamel_equations(const HamelSystem& sys, const GiNaC::realsymbol& time) {
  const unsigned n = static_cast<unsigned>(sys.coordinates.size());
  const unsigned nu = static_cast<unsigned>(sys.velocities.size());
  HamelEquations eq;
  eq.intermediates = sys.program;
  Intermediates& program = eq.intermediates;
  eq.independent = sys.independent();
  const unsigned d = static_cast<unsigned>(eq.independent.size());

  GiNaC::exmap constrained_zero;
  for (int alpha : sys.constrained) constrained_zero[sys.velocities[static_cast<std::size_t>(alpha)]] = 0;
  Intermediates::SubstitutionMemo held_memo;
  const auto at_constraint = [&](const ex& e) { return program.substitute(e, constrained_zero, held_memo); };
  const auto is_constrained = [&](int a) {
    return std::find(sys.constrained.begin(), sys.constrained.end(), a) != sys.constrained.end();
  };
  const std::optional<ex> quadratic = simplified_quadratic_lagrangian(sys, program);
  const ex lagrangian = quadratic ? *quadratic : sys.lagrangian;
  // Results as closed forms where those are small (readable; f's monomials then collect exactly, see
  // below), otherwise as expressions in the program's intermediates.
  const auto closed = [&](const ex& e) {
    const std::optional<ex> inlined = program.inline_bounded(e, 2000);
    return inlined ? *inlined : e;
  };

  eq.kinematics.resize(n);
  for (unsigned a = 0; a < n; ++a) {
    ex rate = 0;
    for (int I : eq.independent)
      rate += sys.B(a, static_cast<unsigned>(I)) * sys.velocities[static_cast<std::size_t>(I)];
    eq.kinematics[a] = simplify(rate);
  }

  // ∂ℒ/∂u^a at u^α = 0: the momenta conjugate to all quasi-velocities, needed for the γ terms.
  std::vector<ex> momentum(nu);
  for (unsigned a = 0; a < nu; ++a) momentum[a] = at_constraint(program.diff(lagrangian, sys.velocities[a]));

  eq.reduced_lagrangian = simplify_bounded(closed(at_constraint(lagrangian)));
  eq.mass_matrix = GiNaC::matrix(d, d);
  eq.forcing.resize(d);
  // Q_a and ∂ℒ/∂q^a at u^α = 0 do not depend on I: form them once.
  std::vector<ex> force(n), gradient(n);
  for (unsigned a = 0; a < n; ++a) {
    force[a] = at_constraint(sys.forces[a]);
    gradient[a] = at_constraint(program.diff(lagrangian, sys.coordinates[a]));
  }

  std::vector<ex> velocities;
  for (int I : eq.independent) velocities.push_back(sys.velocities[static_cast<std::size_t>(I)]);
  for (unsigned i = 0; i < d; ++i) {
    const int I = eq.independent[i];
    const ex& p_I = momentum[static_cast<std::size_t>(I)];
    for (unsigned j = 0; j < d; ++j)
      eq.mass_matrix(i, j) =
          simplify_bounded(closed(program.diff(p_I, sys.velocities[static_cast<std::size_t>(eq.independent[j])])));

    ex f = 0;
    // Generalized force Q_I = B^a_I Q_a and the configuration gradient ∂ℒ/∂q^a B^a_I.
    for (unsigned a = 0; a < n; ++a) {
      f += sys.B(a, static_cast<unsigned>(I)) * (force[a] + gradient[a]);
      // Convective part of d/dt p_I.
      f -= program.diff(p_I, sys.coordinates[a]) * eq.kinematics[a];
    }
    f -= program.diff(p_I, time);
    // Non-holonomic part: ∂ℒ/∂u^a γ^a_IJ u^J.
    for (const HamelCoefficient& g : sys.gamma) {
      if (g.lower_a != I || is_constrained(g.lower_b)) continue;
      f -= momentum[static_cast<std::size_t>(g.upper)] * g.value * sys.velocities[static_cast<std::size_t>(g.lower_b)];
    }
    // Monomials in the velocities collected exactly: as derived, f is a sum of products whose expansion
    // cancels, which costs the double evaluation up to 1e4 ulps (docs/accuracy.md, kernel forward error).
    eq.forcing[i] = simplify_quadratic_form(closed(f), velocities);
  }

  // A "singular" answer with intermediates read as free symbols is still a proof.
  if (shown_singular(eq.mass_matrix, program))
    throw InputError(sys.where, sys.where_key,
                     "the mass matrix ∂²L/∂u^I∂u^J of the independent quasi-velocities is identically singular; "
                     "every independent quasi-velocity must carry kinetic energy");

  ex energy = -eq.reduced_lagrangian;
  for (int I : eq.independent)
    energy += momentum[static_cast<std::size_t>(I)] * sys.velocities[static_cast<std::size_t>(I)];
  eq.energy_terms = {simplify_bounded(closed(energy))};
  bool forced = false;
  for (const ex& q : sys.forces) forced = forced || !q.is_zero();
  eq.conservative = !forced && shown_zero(program.diff(lagrangian, time), program);

  for (const std::vector<ex>& row : sys.constraint_form) {
    ex r = 0;
    for (unsigned a = 0; a < n; ++a) r += row[a] * eq.kinematics[a];
    eq.constraint_residual.push_back(r);  // deliberately not simplified: evaluated numerically it shows A·B_I = 0
  }
  return eq;
}

}  // namespace hamel
