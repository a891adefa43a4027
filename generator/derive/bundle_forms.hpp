// The equations of a bundle model in the paper's forms, each as a HamelSystem for the one equation
// builder (hamel_equations): with the shifted group velocity u^α = ξ^α + A^α_I ṙ^I and u^I = ṙ^I, the
// Hamel coefficients are γ^α_βλ = ±c^α_βλ (gamma41), γ^α_Jβ = −γ^α_βJ = ±c^α_βδ A^δ_J (gamma42) and
// γ^α_IJ = B^α_IJ (gamma3/gammaRight/gamma43); the forms differ only in A and in which u are held at 0:
//   euler_poincare     A = 0, nothing held          (HEorig1, HEorig2), state (r, ξ, ṙ)
//   lagrange_poincare  A mechanical, nothing held   (BHESym1, BHESym2), state (r, Ω, ṙ), Ω = locked velocity
//   ldap               A kinematic, u^α held at 0   (HE-kinBundle), state (r, ṙ)
//   momentum           A mechanical, Ω held at 0    (HEMomCons, zero momentum), state (r, ṙ)
//   nonholonomic       A nonholonomic, the constraints held at 0 (BKMM 1996), state (r, Ω_S, ṙ):
//                      derive/nonholonomic_momentum.hpp
// Non-zero momentum is the lagrange_poincare form started at Ω = L⁻¹Π⁰.
#pragma once

#include "derive/bundle_connection.hpp"
#include "derive/hamel_system.hpp"
#include "model/model.hpp"

#include <string>
#include <vector>

namespace hamel {

enum class BundleForm { euler_poincare, lagrange_poincare, ldap, momentum, nonholonomic };

/// Command-line names: "ep", "lp", "ldap", "momentum", "nonholonomic".
std::string form_name(BundleForm form);
/// Parses a command-line name; throws InputError listing the names.
BundleForm parse_form(const std::string& name);
/// ldap for a kinematic connection, lagrange_poincare for a mechanical one, nonholonomic with `constraints`.
BundleForm default_form(const Bundle& bundle);

struct BundleSystem {
  HamelSystem system;
  std::vector<GiNaC::ex> group_velocity;  ///< ξ^α(r, u_I) for the reconstruction ġ = gξ̂ / ξ̂g (KinRec)
};

/// The system of `form`; throws InputError when the form does not fit the connection (ldap needs a
/// kinematic one; ep, lp and momentum a mechanical one).
BundleSystem bundle_system(const Model& model, const BundleGeometry& geometry, BundleForm form);

}  // namespace hamel
