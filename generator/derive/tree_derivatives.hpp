// Analytical derivatives of the inverse dynamics of a kinematic tree (after Carpentier & Mansard, RSS 2018,
// "Analytical derivatives of rigid body dynamics algorithms"), for the `jacobian` kernel:
// ∂u̇/∂x = −M⁻¹ ∂ID/∂x with ID(r, u, u̇) = M(r) u̇ − f(r, u) evaluated at the solved u̇.
//
// The recursion runs in one frame for all bodies: the base's frame at the current instant (on a floating
// base; the equations are invariant under the base's pose) or the world (fixed base). There, turning joint k
// moves the whole subtree of k rigidly about its axis s_k, so every derivative with respect to r_k is a
// Lie bracket with s_k and a few per-body composite quantities; nothing is propagated per pair of bodies but
// dot products of 6-vectors. Per column and row pair (I, K), with I in the subtree of K:
//   ∂τ_I/∂r_K = ⟨𝕀ᶜ_I s_I, c_K⟩ + ⟨Bᶜ_Iᵀ s_I, ψ_K⟩,   ∂τ_I/∂ṙ_K = 2⟨𝕀ᶜ_I s_I, ψ_K⟩ + ⟨Bᶜ_Iᵀ s_I, s_K⟩,
// with I an ancestor of K: ⟨s_I, Δ_K⟩ and ⟨s_I, Δ'_K⟩. ψ_K = v_λ × s_K, c_K = a_λ × s_K + v_λ × ψ_K
// (λ the parent of K), B_j x = 𝕀_j (x × v_j) + x ×* 𝕀_j v_j + v_j ×* 𝕀_j x summed over the subtree as
// Bᶜ = Qᶜ + Qᶜᵀ + (x ↦ x ×* hᶜ) with Qᶜ = Σ v_j ×* 𝕀_j, Δ_K = s_K ×* Fᶜ_K + 𝕀ᶜ_K c_K + Bᶜ_K ψ_K and
// Δ'_K = 2 𝕀ᶜ_K ψ_K + Bᶜ_K s_K (derivation: docs/tree-derivatives.md). O(n) per-body work and O(n·depth)
// dot products, against O(n·depth) tangent steps through whole bodies for the chain rule through the
// body-frame program.
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/spatial_algebra.hpp"
#include "model/model.hpp"

#include <vector>

namespace hamel {

/// Every body's pose (R, p), joint axis s_i and inertia in the common frame (the base's frame, or the world
/// on a fixed base), and the composite inertias 𝕀ᶜ_i of the subtrees, named in a program.
struct CommonFrame {
  std::vector<spatial::Mat3> R;
  std::vector<spatial::Vec3> p;
  std::vector<spatial::Vec6> axis;  ///< s_i (i ≥ 1; zero for the base)
  std::vector<spatial::Inertia> inertia, composite;
};

/// The inverse dynamics of a kinematic tree as derive_tree built it, in the bodies' frames. Body 0 is the
/// base, body i ≥ 1 moves with joint i − 1 (shape coordinate r^{i−1}); parents come before children.
struct TreeRecursion {
  std::vector<int> parent;               ///< parent of body i; −1 for the base
  std::vector<spatial::Link> link;       ///< pose of body i in its parent's frame (i ≥ 1)
  std::vector<spatial::Vec6> axis;       ///< S_i: body i's joint axis in its own frame (i ≥ 1)
  std::vector<RigidBody> bodies;         ///< mass, centre of mass, inertia about it, body frame
  std::vector<spatial::Vec6> base;       ///< the m directions the group moves the base (empty: fixed base)
  spatial::Vec6 base_acceleration;       ///< the base's acceleration at u̇ = 0: (0, −g) on a fixed base
  std::vector<GiNaC::ex> base_velocity;  ///< ξ^α (m)
  std::vector<GiNaC::ex> coordinates;    ///< r^I (n)
  std::vector<GiNaC::ex> rates;          ///< ṙ^I (n)
  std::vector<GiNaC::ex> accelerations;  ///< the m + n symbols standing for u̇
  std::vector<GiNaC::ex> joint_force;    ///< τ_I(r, u, t, inputs): joint forces, springs, dampers (n)
  std::vector<GiNaC::ex> armature;       ///< a_I: added to M's diagonal (n)
  CommonFrame frame;                     ///< of the above, in the derivation's intermediates
};

/// The common-frame quantities of `tree` (everything above but `frame`), new definitions added to `tape`.
/// derive_tree forms the mass matrix from them: M_JI = ⟨s_J, 𝕀ᶜ_I s_I⟩ for J = I or an ancestor of I.
CommonFrame common_frame(const TreeRecursion& tree, Intermediates& tape);

/// The mass matrix derive_tree forms from `tree.frame`, factored by the articulated-body recursion in that one
/// frame (Featherstone, Rigid Body Dynamics Algorithms, Table 7.1, with every transform the identity), to
/// solve M y = b for many right-hand sides at O(n) each (emit/kernels.hpp: articulated_solve_columns). From the
/// leaves in: 𝕀ᴬ_i = 𝕀_i + Σ_children (𝕀ᴬ_c − U_c U_cᵀ / D_c), U_i = 𝕀ᴬ_i s_i, D_i = ⟨s_i, U_i⟩ + a_i, and the
/// base's block ⟨e_α, 𝕀ᴬ_0 e_β⟩ (no rows on a fixed base). Index 0 of U and inverse_pivot is unused.
struct ArticulatedFactor {
  std::vector<spatial::Vec6> U;
  std::vector<spatial::Vec6> W;                      ///< U_i / D_i
  std::vector<GiNaC::ex> inverse_pivot;              ///< 1 / D_i
  std::vector<std::vector<GiNaC::ex>> base_inertia;  ///< m × m
};

/// The factor of `tree`'s mass matrix, new definitions added to `tape`.
ArticulatedFactor articulated_factor(const TreeRecursion& tree, Intermediates& tape);

/// ∂ID/∂x for the state x = (r, ξ, ṙ), one column per x_k, in the intermediates of `tape` (new definitions are
/// added to it), at u̇ = tree.accelerations. Every column has one form: with per-body vectors u_i = 𝕀ᶜ_i s_i and
/// b_i = Bᶜ_iᵀ s_i and per-column vectors P, V and Δ,
///   row of joint i:  [i inside] (⟨u_i, P⟩ + ⟨b_i, V⟩) + [i an ancestor] ⟨s_i, Δ⟩ − ∂τ_i/∂x_k,
///   base row α:      ⟨e_α, Δ⟩,
/// where for the columns of joint K's angle and rate (Column::body = K) the bodies inside are K's subtree and the
/// ancestors K's strict ancestors, Δ being the force K's subtree passes inward (Δ_K or Δ'_K); for a base velocity
/// (body 0) every body is inside and none an ancestor. A recursive solve takes Δ as that force (emit/linear_solve.hpp:
/// rows() lists the rows without it, inward() gives it); dense() adds its rows.
struct InverseDynamicsJacobian {
  std::vector<spatial::Vec6> u, b;  ///< per body i ≥ 1 (index 0 unused)
  struct Column {
    std::size_t body = 0;  ///< K for the columns of joint K's angle and rate; 0 for a base velocity
    spatial::Vec6 P, V, Delta;
    std::vector<GiNaC::ex> force;  ///< ∂τ_I/∂x_k of the joint forces (n)
  };
  std::vector<Column> columns;

  /// Whether joint i's row (body i ≥ 1) of column k sees P and V.
  bool inside(const TreeRecursion& tree, std::size_t i, std::size_t k) const;
  /// Column k's rows (m + n: base directions, then joints) but those an inward force gives: an ancestor's ⟨s_i, Δ⟩
  /// and, for a joint's column, the base's ⟨e_α, Δ⟩.
  std::vector<GiNaC::ex> rows(const TreeRecursion& tree, std::size_t k) const;
  /// The force column k passes inward from its joint's body (Column::body; none for 0).
  const spatial::Vec6& inward(std::size_t k) const { return columns[k].Delta; }
  /// The full columns: rows() with the inward forces' rows added.
  std::vector<std::vector<GiNaC::ex>> dense(const TreeRecursion& tree) const;
  /// The columns of −∂ID/∂x, the right-hand sides M y = b takes, in the same form: P, V and Δ negated, each named
  /// once per column (18 negations), and the joint forces' derivatives with the opposite sign. Negating each row
  /// instead costs one negation per row and column.
  InverseDynamicsJacobian negated(Intermediates& tape) const;
};

InverseDynamicsJacobian inverse_dynamics_jacobian(const TreeRecursion& tree, Intermediates& tape);

/// f = −ID(r, u, 0) in the common frame (m + n rows: base directions, then joints): M u̇ = f. Per body the twist
/// v_i = v_λ + s_i ṙ_i, the acceleration at u̇ = 0 a_i = a_λ + (v_λ × s_i) ṙ_i (a_0 the base's: gravity on a fixed
/// base), the wrench 𝕀_i a_i + v_i ×* 𝕀_i v_i summed over the subtree as Fᶜ_i; rows −⟨e_α, Fᶜ_0⟩ and
/// τ_i − ⟨s_i, Fᶜ_i⟩. What the Jacobian solves with the factor its columns already use, to get u̇ without the
/// body-frame recursion of rhs.
std::vector<GiNaC::ex> bias_forcing(const TreeRecursion& tree, Intermediates& tape);

}  // namespace hamel
