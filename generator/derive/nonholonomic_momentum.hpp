// The reduced equations of a bundle model with constraints that leave some group directions free (BKMM 1996, see
// derive/nonholonomic_connection.hpp): the Hamel equations (BHconstr) in the quasi-velocities ν of the frame
// P = [Y Z] of g and the shape rates,
//     ξ = Y ν_c + Z Ω_S − 𝒜ṙ,   ν_c = C_ξ ξ + C_r ṙ (the constraints, held at zero),   Ω_S,   ṙ,
// whose vector fields are e_c = Y^α_c E_α, e_j = Z^α_j E_α and e_I = ∂_I − 𝒜^α_I E_α (E_α the left-invariant
// fields, [E_β, E_λ] = ±c^α_βλ E_α). Their Hamel coefficients, [e_a, e_b] = γ^c_ab e_c with Q = P⁻¹, are
//     γ^c_ab = ±Q^c_α c^α_βλ P^β_a P^λ_b,
//     γ^c_aI = −Q^c_α (∂P^α_a/∂r^I ± c^α_βλ P^β_a 𝒜^λ_I) = −γ^c_Ia,
//     γ^c_IJ = Q^c_α ℬ^α_IJ (the curvature of 𝒜, gamma3 / gammaRight),
// which for P = I are (gamma41)–(gamma43). The state is (r, Ω_S, ṙ). The equation of Ω_S is BKMM's momentum
// equation: with the nonholonomic momentum p_j = ∂ℒ/∂Ω_S^j = Z^α_j ∂l/∂ξ^α = (I^S Ω_S)_j,
//     ṗ_j = −∂ℒ/∂ν^a γ^a_{j J} ν^J     (J over Ω_S and ṙ; no force acts along the group),
// the equations of ṙ are the reduced shape equations, and the reconstruction is ξ = Z (I^S)⁻¹ p − 𝒜ṙ.
#pragma once

#include "derive/bundle_connection.hpp"
#include "derive/bundle_forms.hpp"
#include "model/model.hpp"

#include <string>
#include <vector>

namespace hamel {

/// The Hamel system above (form `nonholonomic`); `geometry` must hold the nonholonomic connection.
BundleSystem nonholonomic_system(const Model& model, const BundleGeometry& geometry);

/// BKMM's momentum equation, one entry per section Z_j of S.
struct NonholonomicMomentum {
  std::vector<GiNaC::realsymbol> momenta;  ///< p_j, named p_S (one) or p_S1, p_S2, ...
  std::vector<GiNaC::ex> momentum;         ///< p_j(r, Ω_S, ṙ) = Z^α_j ∂l/∂ξ^α on D (= I^S Ω_S)
  std::vector<GiNaC::ex> rate;             ///< ṗ_j(r, p, ṙ) with Ω_S = (I^S)⁻¹ p
};

/// The momentum and the momentum equation of the nonholonomic system `system` (from nonholonomic_system);
/// `program` holds the system's intermediates (the equations' program, which this extends).
NonholonomicMomentum nonholonomic_momentum(const Model& model, const BundleGeometry& geometry,
                                           const HamelSystem& system, Intermediates& program);

}  // namespace hamel
