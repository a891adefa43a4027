#include "derive/bundle_forms.hpp"

#include "algebra/simplify.hpp"
#include "derive/nonholonomic_momentum.hpp"
#include "model/input_error.hpp"

#include <algorithm>
#include <tuple>

namespace hamel {

using GiNaC::ex;

std::string form_name(BundleForm form) {
  switch (form) {
    case BundleForm::euler_poincare:
      return "ep";
    case BundleForm::lagrange_poincare:
      return "lp";
    case BundleForm::ldap:
      return "ldap";
    case BundleForm::momentum:
      return "momentum";
    case BundleForm::nonholonomic:
      return "nonholonomic";
  }
  return "?";
}

BundleForm parse_form(const std::string& name) {
  for (BundleForm f : {BundleForm::euler_poincare, BundleForm::lagrange_poincare, BundleForm::ldap,
                       BundleForm::momentum, BundleForm::nonholonomic})
    if (form_name(f) == name) return f;
  throw InputError(
      "--form: unknown form '" + name +
      "'; expected ep (Euler-Poincare + Euler-Lagrange), lp (Lagrange-Poincare in the locked velocity), "
      "ldap (Lagrange-d'Alembert-Poincare, kinematic connection), momentum (zero momentum) or nonholonomic "
      "(momentum equation and reduced shape equations, a bundle with constraints)");
}

BundleForm default_form(const Bundle& bundle) {
  if (bundle.tree) return BundleForm::euler_poincare;  // the recursive derivation (derive/kinematic_tree.hpp)
  if (bundle.nonholonomic) return BundleForm::nonholonomic;
  return bundle.mechanical ? BundleForm::lagrange_poincare : BundleForm::ldap;
}

namespace {

std::string form_title(BundleForm form) {
  switch (form) {
    case BundleForm::euler_poincare:
      return "Euler-Poincare + Euler-Lagrange (HEorig1, HEorig2)";
    case BundleForm::lagrange_poincare:
      return "Lagrange-Poincare in the locked velocity (BHESym1, BHESym2)";
    case BundleForm::ldap:
      return "Lagrange-d'Alembert-Poincare (HE-kinBundle)";
    case BundleForm::momentum:
      return "momentum-conserving reduced equations, zero momentum (HEMomCons)";
    case BundleForm::nonholonomic:
      return "nonholonomic momentum and reduced shape equations (BKMM 1996)";
  }
  return "?";
}

}  // namespace

BundleSystem bundle_system(const Model& model, const BundleGeometry& geometry, BundleForm form) {
  const Bundle& b = *model.bundle;
  if ((form == BundleForm::nonholonomic) != b.nonholonomic)
    throw InputError("--form " + form_name(form) + ": " +
                     (b.nonholonomic ? "the model has 'constraints' that leave group directions free; expected --form "
                                       "nonholonomic (the nonholonomic momentum and the reduced shape equations)"
                                     : "the form nonholonomic needs a bundle model with 'constraints'"));
  if (form == BundleForm::nonholonomic) return nonholonomic_system(model, geometry);
  const bool wants_mechanical = form != BundleForm::ldap;
  if (wants_mechanical != b.mechanical)
    throw InputError("--form " + form_name(form) + ": the model's connection is " +
                     (b.mechanical ? "mechanical" : "kinematic") + "; the form " + form_name(form) + " needs a " +
                     (wants_mechanical ? "mechanical" : "kinematic") + " connection" +
                     (b.mechanical ? " (use ep, lp or momentum)" : " (use ldap)"));
  const unsigned m = geometry.algebra.dim();
  const unsigned d = static_cast<unsigned>(model.coordinates.size());
  const int sign = geometry.trivialization_sign;
  // With no shape the shift is the identity: keep the names ξ^α.
  const bool shifted = form != BundleForm::euler_poincare && d > 0;
  const bool held = form == BundleForm::ldap || form == BundleForm::momentum;
  GiNaC::matrix A(m, d == 0 ? 1 : d);  // the connection the quasi-velocities use; zero for ep
  if (shifted)
    for (unsigned a = 0; a < m; ++a)
      for (unsigned I = 0; I < d; ++I) A(a, I) = geometry.connection(a, I);

  BundleSystem out;
  HamelSystem& sys = out.system;
  sys.form = form_title(form);
  sys.coordinates = model.coordinates;
  const std::string suffix = form == BundleForm::ldap ? "_constraint" : "_locked";
  for (unsigned a = 0; a < m; ++a)
    sys.velocities.push_back(shifted ? GiNaC::realsymbol(b.group_velocity[a].get_name() + suffix)
                                     : b.group_velocity[a]);
  for (const auto& r : model.rates) sys.velocities.push_back(r);
  if (held)
    for (unsigned a = 0; a < m; ++a) sys.constrained.push_back(static_cast<int>(a));
  sys.B = GiNaC::matrix(d == 0 ? 1 : d, m + d);
  for (unsigned I = 0; I < d; ++I) sys.B(I, m + I) = 1;

  // ξ^α = u^α − A^α_I ṙ^I, substituted into l and the forces as intermediates: l keeps the shape it has
  // in ξ, and its derivatives in u and ṙ follow by the chain rule through ξ(u, ṙ) (no expansion).
  sys.program = geometry.program;
  GiNaC::exmap to_shifted;
  for (unsigned a = 0; a < m; ++a) {
    ex xi = sys.velocities[a];
    for (unsigned I = 0; I < d; ++I) xi -= A(a, I) * model.rates[I];
    to_shifted[b.group_velocity[a]] = sys.program.define(xi);
    ex xi_held = xi;
    if (held) xi_held = xi.subs(GiNaC::exmap{{sys.velocities[a], 0}});
    out.group_velocity.push_back(xi_held);
  }
  Intermediates::SubstitutionMemo memo;
  sys.lagrangian = sys.program.substitute(model.lagrangian, to_shifted, memo);
  for (const ex& q : model.forces) sys.forces.push_back(sys.program.substitute(q, to_shifted, memo));
  sys.where_key = model.locations.count("bodies") ? "bodies" : model.bundle->tree ? "tree" : "kinetic";
  sys.where = model.locations.count(sys.where_key) ? model.locations.at(sys.where_key)
                                                   : SourceLocation{model.source_path, 0, 0};

  // Hamel coefficients, indices: α → α, I → m + I.
  auto add = [&](int upper, int la, int lb, const ex& v) {
    if (!v.is_zero()) sys.gamma.push_back({upper, la, lb, v});
  };
  for (const StructureConstant& s : geometry.structure_constants)
    add(s.upper, s.lower_a, s.lower_b, sign * s.value);  // gamma41
  if (shifted) {
    for (const BundleCoefficient& e : geometry.E) {  // gamma42: γ^α_Iβ = E^α_βI, γ^α_βI = −E^α_βI
      add(e.upper, static_cast<int>(m) + e.lower_b, e.lower_a, e.value);
      add(e.upper, e.lower_a, static_cast<int>(m) + e.lower_b, -e.value);
    }
    for (const BundleCoefficient& c : geometry.curvature)  // gamma3 / gamma43
      add(c.upper, static_cast<int>(m) + c.lower_a, static_cast<int>(m) + c.lower_b, c.value);
  }
  sort_by_indices(sys.gamma);
  return out;
}

}  // namespace hamel
