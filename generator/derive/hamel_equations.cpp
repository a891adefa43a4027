// Eq. (BHconstr): d/dt ∂ℒ/∂u^I − ∂ℒ/∂q^a B^a_I + ∂ℒ/∂u^a γ^a_IJ u^J = Q_I, u^α = 0 after the
// derivatives, Q_I = B^a_I Q_a. With no constraints this is eq. (BHEqu2). The total time derivative
// is expanded by the chain rule along q̇ = B_J u^J (qadot): d/dt p_I = M_IJ u̇^J + ∂p_I/∂q^a q̇^a + ∂p_I/∂t.
#include "derive/hamel_equations.hpp"

#include "algebra/simplify.hpp"
#include "model/input_error.hpp"

#include <algorithm>

namespace hamel {

using GiNaC::ex;

HamelEquations hamel_equations(const Model& model, const QuasiVelocities& qv,
                               const std::vector<HamelCoefficient>& gamma) {
  const unsigned n = static_cast<unsigned>(model.n());
  HamelEquations eq;
  eq.independent = model.independent();
  const unsigned d = static_cast<unsigned>(eq.independent.size());

  // q̇ = B u substituted into L (and into the forces): ℒ(q, u, t).
  GiNaC::exmap to_quasi;
  for (unsigned a = 0; a < n; ++a) {
    ex rate = 0;
    for (unsigned b = 0; b < n; ++b) rate += qv.B(a, b) * model.quasi_velocities[b];
    to_quasi[model.rates[a]] = rate;
  }
  GiNaC::exmap constrained_zero;
  for (int alpha : model.constrained) constrained_zero[model.quasi_velocities[alpha]] = 0;

  const ex lagrangian = model.lagrangian.subs(to_quasi);
  const auto at_constraint = [&](const ex& e) { return e.subs(constrained_zero); };

  eq.kinematics.resize(n);
  for (unsigned a = 0; a < n; ++a) {
    ex rate = 0;
    for (int I : eq.independent) rate += qv.B(a, I) * model.quasi_velocities[I];
    eq.kinematics[a] = simplify(rate);
  }

  // ∂ℒ/∂u^a at u^α = 0: the momenta conjugate to all quasi-velocities, needed for the γ^α_IJ terms.
  std::vector<ex> momentum(n);
  for (unsigned a = 0; a < n; ++a) momentum[a] = at_constraint(lagrangian.diff(model.quasi_velocities[a]));

  eq.reduced_lagrangian = simplify(at_constraint(lagrangian));
  eq.mass_matrix = GiNaC::matrix(d, d);
  eq.forcing.resize(d);
  // Q_a and ∂ℒ/∂q^a at u^α = 0 do not depend on I: form them once.
  std::vector<ex> force(n), gradient(n);
  for (unsigned a = 0; a < n; ++a) {
    force[a] = at_constraint(model.forces[a].subs(to_quasi));
    gradient[a] = at_constraint(lagrangian.diff(model.coordinates[a]));
  }

  for (unsigned i = 0; i < d; ++i) {
    const int I = eq.independent[i];
    const ex& p_I = momentum[I];
    for (unsigned j = 0; j < d; ++j)
      eq.mass_matrix(i, j) = simplify(p_I.diff(model.quasi_velocities[eq.independent[j]]));

    ex f = 0;
    // Generalized force Q_I = B^a_I Q_a and the configuration gradient ∂ℒ/∂q^a B^a_I.
    for (unsigned a = 0; a < n; ++a) {
      f += qv.B(a, I) * (force[a] + gradient[a]);
      // Convective part of d/dt p_I.
      f -= p_I.diff(model.coordinates[a]) * eq.kinematics[a];
    }
    f -= p_I.diff(model.time);
    // Non-holonomic part: ∂ℒ/∂u^a γ^a_IJ u^J.
    for (const HamelCoefficient& g : gamma) {
      if (g.lower_a != I) continue;
      if (std::find(model.constrained.begin(), model.constrained.end(), g.lower_b) != model.constrained.end()) continue;
      f -= momentum[g.upper] * g.value * model.quasi_velocities[g.lower_b];
    }
    eq.forcing[i] = simplify(f);
  }

  if (is_zero_exactly(eq.mass_matrix.determinant()))
    throw InputError(model.locations.count("lagrangian") ? model.locations.at("lagrangian")
                                                         : SourceLocation{model.source_path, 0, 0},
                     "lagrangian",
                     "the mass matrix ∂²L/∂u^I∂u^J of the independent quasi-velocities is identically singular; "
                     "every independent quasi-velocity must carry kinetic energy");

  ex energy = -eq.reduced_lagrangian;
  for (int I : eq.independent) energy += momentum[I] * model.quasi_velocities[I];
  eq.energy_terms = {simplify(energy)};
  bool forced = false;
  for (const ex& q : model.forces) forced = forced || !q.is_zero();
  eq.conservative = !forced && !model.lagrangian.has(model.time);

  for (int alpha : model.constrained) {
    ex r = 0;
    for (unsigned a = 0; a < n; ++a) r += qv.A(alpha, a) * eq.kinematics[a];
    eq.constraint_residual.push_back(r);  // deliberately not simplified: evaluated numerically it shows A·B_I = 0
  }
  return eq;
}

}  // namespace hamel
