#include "derive/derivation.hpp"

#include "derive/kinematic_tree.hpp"
#include "model/input_error.hpp"

namespace hamel {

HamelSystem general_coordinate_system(const Model& model, const QuasiVelocities& qv,
                                      std::vector<HamelCoefficient> gamma) {
  const unsigned n = static_cast<unsigned>(model.n());
  HamelSystem sys;
  sys.form = model.constrained.empty() ? "Boltzmann-Hamel (BHEqu2)" : "constrained Hamel (BHconstr)";
  sys.coordinates = model.coordinates;
  sys.velocities = model.quasi_velocities;
  sys.constrained = model.constrained;
  sys.B = qv.B;
  // q̇ = B u substituted into L and the forces: ℒ(q, u, t).
  GiNaC::exmap to_quasi;
  for (unsigned a = 0; a < n; ++a) {
    GiNaC::ex rate = 0;
    for (unsigned b = 0; b < n; ++b) rate += qv.B(a, b) * model.quasi_velocities[b];
    to_quasi[model.rates[a]] = rate;
  }
  sys.lagrangian = model.lagrangian.subs(to_quasi);
  for (const GiNaC::ex& q : model.forces) sys.forces.push_back(q.subs(to_quasi));
  sys.gamma = std::move(gamma);
  for (int alpha : model.constrained) {
    std::vector<GiNaC::ex> row;
    for (unsigned a = 0; a < n; ++a) row.push_back(qv.A(static_cast<unsigned>(alpha), a));
    sys.constraint_form.push_back(row);
  }
  sys.where =
      model.locations.count("lagrangian") ? model.locations.at("lagrangian") : SourceLocation{model.source_path, 0, 0};
  return sys;
}

Derivation derive(const Model& model, const DeriveSettings& settings) {
  Derivation d;
  if (model.tree) {  // fixed base: the recursive derivation in u = q̇
    if (!settings.form.empty())
      throw InputError("--form applies to bundle models (with 'group'); '" + model.source_path +
                       "' is a tree on a fixed base");
    TreeDerivation tree = derive_tree(model);
    d.quasi_velocities = {model.A, model.B};
    d.system = std::move(tree.system);
    d.equations = std::move(tree.equations);
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
    // The other forms differentiate T as a whole: the tree's kinetic energy as one expression.
    return derive(with_inlined_tree(model), settings);
  }
  if (model.bundle) {
    d.bundle = derive_bundle_geometry(model);
    d.form = settings.form.empty() ? default_form(*model.bundle) : parse_form(settings.form);
    BundleSystem bs = bundle_system(model, *d.bundle, *d.form);
    d.system = std::move(bs.system);
    d.group_velocity = std::move(bs.group_velocity);
  } else {
    if (!settings.form.empty())
      throw InputError("--form applies to bundle models (with 'group'); '" + model.source_path +
                       "' is in general coordinates");
    d.quasi_velocities = derive_quasi_velocities(model);
    d.system = general_coordinate_system(model, d.quasi_velocities, hamel_coefficients(model, d.quasi_velocities));
  }
  d.equations = hamel_equations(d.system, model.time);
  return d;
}

}  // namespace hamel
