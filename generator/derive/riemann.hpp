// The Riemannian view (paper, section "Remark on Classical Riemannian Geometry Formulations"): for a
// holonomic system in general coordinates whose Lagrangian is L = ½ g_ab(q) q̇ᵃq̇ᵇ − V(q, t), the mass
// matrix is a Riemannian metric g on the configuration space, the equations of motion are
// D q̇ᵃ/dt = Qᵃ = g^ab Q_b with the Levi-Civita connection Γᵃ_bc, and the linearization about a nominal
// trajectory q(t) is, in covariant form with the Riemann–Christoffel tensor,
//
//   g_ab D²xᵇ/dt² + (R_cbda q̇ᶜq̇ᵈ − ∇_b Q_a) xᵇ = Φ_a,   ∇_b Q_a = ∂Q_a/∂qᵇ − Γᶜ_ba Q_c,
//
// where D xᵃ/dt = ẋᵃ + Γᵃ_bc q̇ᵇ xᶜ. Conventions: those under which the paper's formula is the Jacobi
// (geodesic-deviation) equation D²J/dt² + R(J, q̇)q̇ = ∇_J Q♯ with R(X, Y)Z = ∇_X∇_Y Z − ∇_Y∇_X Z − ∇_[X,Y] Z
// (Lee, Introduction to Riemannian Manifolds, 2nd ed., ch. 10; Misner–Thorne–Wheeler's index placement):
//   Γ_a,bc = ½ (∂_b g_ac + ∂_c g_ab − ∂_a g_bc),   Γᵃ_bc = g^ad Γ_d,bc,
//   R(∂_c, ∂_d)∂_b = Rᵃ_bcd ∂_a,  Rᵃ_bcd = ∂_c Γᵃ_db − ∂_d Γᵃ_cb + Γᵃ_ce Γᵉ_db − Γᵃ_de Γᵉ_cb,  R_abcd = g_ae Rᵉ_bcd;
// R_abcd q̇ᵇ Jᶜ q̇ᵈ = R_cbda q̇ᶜ Jᵇ q̇ᵈ by the pair symmetries, which is the paper's term.
// With these the round sphere of radius r has R_θφθφ = r² sin²θ > 0 and K_ab = R_cbda q̇ᶜq̇ᵈ is positive
// semi-definite there: positive curvature makes nearby geodesics converge ("a measure of stability").
#pragma once

#include "algebra/intermediates.hpp"
#include "model/model.hpp"

#include <vector>

namespace hamel {

/// A Christoffel symbol Γᵃ_bc (second kind) or Γ_a,bc (first kind): `index` is a, lower pair (b, c), b ≤ c.
struct ChristoffelSymbol {
  int index;
  int b;
  int c;
  GiNaC::ex value;
};

/// A component R_abcd of the Riemann–Christoffel tensor with a < b, c < d and (a, b) ≤ (c, d): the others
/// follow from R_abcd = −R_bacd = −R_abdc = R_cdab (and, for n ≥ 4, the first Bianchi identity relates some
/// of these).
struct CurvatureComponent {
  int a, b, c, d;
  GiNaC::ex value;
};

struct RiemannGeometry {
  std::vector<GiNaC::realsymbol> coordinates;  ///< qᵃ
  std::vector<GiNaC::realsymbol> rates;        ///< q̇ᵃ (the model's <coordinate>_dot)
  GiNaC::matrix metric;                        ///< g_ab(q) = ∂²L/∂q̇ᵃ∂q̇ᵇ
  GiNaC::ex potential;                         ///< V(q, t) = −L(q, 0, t)
  std::vector<GiNaC::ex> forces;               ///< Q_a = (model forces)_a − ∂V/∂qᵃ, functions of (q, t, inputs)
  std::vector<ChristoffelSymbol> first_kind;   ///< non-zero Γ_a,bc, b ≤ c
  std::vector<ChristoffelSymbol> second_kind;  ///< non-zero Γᵃ_bc, b ≤ c
  std::vector<CurvatureComponent> curvature;   ///< non-zero independent R_abcd (see CurvatureComponent)
  GiNaC::matrix connection_rate;               ///< Gᵃ_c = Γᵃ_bc q̇ᵇ: D xᵃ/dt = ẋᵃ + Gᵃ_c xᶜ
  GiNaC::matrix force_gradient;                ///< ∇_b Q_a, row a, column b
  GiNaC::matrix stiffness;                     ///< K_ab = R_cbda q̇ᶜq̇ᵈ − ∇_b Q_a, row a, column b
};

/// Derives the Riemannian quantities of `model` through intermediate symbols appended to `program`, which
/// must hold the model's definitions (as the derivation's programs do). Throws InputError, naming the key,
/// for models with a group or constraints, a Lagrangian that is not ½ g_ab(q) q̇ᵃq̇ᵇ − V(q, t) (checked
/// exactly: third derivatives in the rates, no linear term, g independent of t), a singular metric, or
/// forces that depend on the velocities.
RiemannGeometry derive_riemann(const Model& model, Intermediates& program);

/// R_abcd for any indices, from the independent components of `geometry` by the symmetries (0 if absent).
GiNaC::ex curvature_component(const RiemannGeometry& geometry, int a, int b, int c, int d);

}  // namespace hamel
