#include "derive/derivation.hpp"

#include "derive/kinematic_tree.hpp"
#include "model/input_error.hpp"
#include "report/progress.hpp"

namespace hamel {

HamelSystem general_coordinate_system(const Model& model, const QuasiVelocities& qv,
                                      std::vector<HamelCoefficient> gamma, Intermediates program) {
  const unsigned n = static_cast<unsigned>(model.n());
  HamelSystem sys;
  sys.form = model.constrained.empty() ? "Boltzmann-Hamel (BHEqu2)" : "constrained Hamel (BHconstr)";
  sys.coordinates = model.coordinates;
  sys.velocities = model.quasi_velocities;
  sys.constrained = model.constrained;
  sys.B = qv.B;
  sys.program = std::move(program);
  // q̇ = B u substituted into L and the forces as intermediates: ℒ(q, u, t) keeps the shape L has in q̇,
  // and its derivatives follow by the chain rule through q̇(q, u).
  GiNaC::exmap to_quasi;
  for (unsigned a = 0; a < n; ++a) {
    GiNaC::ex rate = 0;
    for (unsigned b = 0; b < n; ++b) rate += qv.B(a, b) * model.quasi_velocities[b];
    to_quasi[model.rates[a]] = sys.program.define(rate);
  }
  Intermediates::SubstitutionMemo memo;
  sys.lagrangian = sys.program.substitute(model.lagrangian, to_quasi, memo);
  for (const GiNaC::ex& q : model.forces) sys.forces.push_back(sys.program.substitute(q, to_quasi, memo));
  sys.gamma = std::move(gamma);
  for (int alpha : model.constrained) {
    std::vector<GiNaC::ex> row;
    for (unsigned a = 0; a < n; ++a) row.push_back(qv.A(static_cast<unsigned>(alpha), a));
    sys.constraint_form.push_back(row);
  }
  for (const HolonomicConstraint& h : model.holonomic)
    sys.position_constraints.push_back({h.velocity.get_name(), h.g, h.gradient});
  sys.where_key = model.locations.count("bodies") ? "bodies" : "lagrangian";
  sys.where = model.locations.count(sys.where_key) ? model.locations.at(sys.where_key)
                                                   : SourceLocation{model.source_path, 0, 0};
  return sys;
}

Derivation derive(const Model& model, const DeriveSettings& settings) {
  Derivation d;
  if (model.tree) {  // fixed base: the recursive derivation in u = q̇
    if (!settings.form.empty())
      throw InputError("--form applies to bundle models (with 'group'); '" + model.source_path +
                       "' is a tree on a fixed base");
    progress::Step step("deriving the equations of motion of " + model.name + " (recursive over the tree)");
    TreeDerivation tree = derive_tree(model);
    const GiNaC::matrix identity = GiNaC::ex_to<GiNaC::matrix>(GiNaC::unit_matrix(model.n()));  // u = q̇
    d.quasi_velocities = {identity, identity};
    d.system = std::move(tree.system);
    d.equations = std::move(tree.equations);
    step.detail(std::to_string(d.equations.intermediates.size()) + " intermediates");
    return d;
  }
  if (model.bundle && model.bundle->tree) {
    d.form = settings.form.empty() ? default_form(*model.bundle) : parse_form(settings.form);
    if (*d.form == BundleForm::euler_poincare) {
      TreeDerivation tree = derive_tree(model);
      d.bundle = std::move(tree.geometry);
      d.system = std::move(tree.system);
      d.equations = std::move(tree.equations);
      d.group_velocity.assign(model.bundle->group_velocity.begin(), model.bundle->group_velocity.end());
      return d;
    }
    // The other forms differentiate T as a whole: the tree's kinetic energy as one expression. They rest on the
    // group symmetry (the connection, the conserved momentum), which gravity and applied wrenches break.
    if (model.bundle->tree->has_gravity() || !model.wrenches.empty())
      throw InputError(model.locations.count(model.wrenches.empty() ? "tree.gravity" : "wrenches")
                           ? model.locations.at(model.wrenches.empty() ? "tree.gravity" : "wrenches")
                           : SourceLocation{model.source_path, 0, 0},
                       model.wrenches.empty() ? "tree.gravity" : "wrenches",
                       std::string(model.wrenches.empty() ? "gravity" : "applied wrenches") +
                           " break the symmetry of the floating base, on which the form '" + settings.form +
                           "' rests (the momentum is no longer conserved); expected --form ep, the "
                           "Euler-Poincare equations with gravity resolved in the base's frame");
    return derive(with_inlined_tree(model), settings);
  }
  if (model.bundle) {
    {
      progress::Step step("deriving the bundle geometry of " + model.name + " (Hessian of T, connection, curvature)");
      d.bundle = derive_bundle_geometry(model);
      step.detail(std::to_string(d.bundle->program.size()) + " intermediates");
    }
    d.form = settings.form.empty() ? default_form(*model.bundle) : parse_form(settings.form);
    BundleSystem bs = bundle_system(model, *d.bundle, *d.form);
    d.system = std::move(bs.system);
    d.group_velocity = std::move(bs.group_velocity);
  } else {
    if (!settings.form.empty())
      throw InputError("--form applies to bundle models (with 'group'); '" + model.source_path +
                       "' is in general coordinates");
    progress::Step step("deriving B = A^-1 and the Hamel coefficients of " + model.name);
    Intermediates program = model.definitions;
    d.quasi_velocities = derive_quasi_velocities(model, program);
    std::vector<HamelCoefficient> gamma = hamel_coefficients(model, d.quasi_velocities, program);
    step.detail(std::to_string(gamma.size()) + " non-zero coefficients");
    d.system = general_coordinate_system(model, d.quasi_velocities, std::move(gamma), std::move(program));
  }
  progress::Step step("deriving the equations of motion of " + model.name + " (mass matrix, forcing)");
  d.equations = hamel_equations(d.system, model.time);
  step.detail(std::to_string(d.equations.intermediates.size()) + " intermediates");
  if (d.form == BundleForm::nonholonomic)
    d.momentum_equation = nonholonomic_momentum(model, *d.bundle, d.system, d.equations.intermediates);
  return d;
}

}  // namespace hamel
