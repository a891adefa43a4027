// Analytical derivatives of the inverse dynamics of a kinematic tree (after Carpentier & Mansard, RSS 2018,
// "Analytical derivatives of rigid body dynamics algorithms"), for the `jacobian` kernel:
// ∂u̇/∂x = −M⁻¹ ∂ID/∂x with ID(r, u, u̇) = M(r) u̇ − f(r, u) evaluated at the solved u̇.
//
// The recursion runs in the common frame (Frame::world, rbd/tree.hpp): turning joint k moves the whole subtree of k
// rigidly about its axis s_k, so every derivative with respect to r_k is a Lie bracket with s_k and a few per-body
// composite quantities; nothing is propagated per pair of bodies but dot products of 6-vectors. Per column and row
// pair (I, K), with I in the subtree of K:
//   ∂τ_I/∂r_K = ⟨𝕀ᶜ_I s_I, c_K⟩ + ⟨Bᶜ_Iᵀ s_I, ψ_K⟩,   ∂τ_I/∂ṙ_K = 2⟨𝕀ᶜ_I s_I, ψ_K⟩ + ⟨Bᶜ_Iᵀ s_I, s_K⟩,
// with I an ancestor of K: ⟨s_I, Δ_K⟩ and ⟨s_I, Δ'_K⟩. ψ_K = v_λ × s_K, c_K = a_λ × s_K + v_λ × ψ_K
// (λ the parent of K), B_j x = 𝕀_j (x × v_j) + x ×* 𝕀_j v_j + v_j ×* 𝕀_j x summed over the subtree as
// Bᶜ = Qᶜ + Qᶜᵀ + (x ↦ x ×* hᶜ) with Qᶜ = Σ v_j ×* 𝕀_j, Δ_K = s_K ×* Fᶜ_K + 𝕀ᶜ_K c_K + Bᶜ_K ψ_K and
// Δ'_K = 2 𝕀ᶜ_K ψ_K + Bᶜ_K s_K (derivation: docs/tree-derivatives.md). The generalized forces Q (applied wrenches,
// joint forces, springs, dampers: TreeDynamics::generalized_force) are differentiated symbolically through the
// program (Intermediates::diff). O(n) per-body work and O(n·depth) dot products.
#pragma once

#include "algebra/intermediates.hpp"
#include "rbd/tree.hpp"

#include <vector>

namespace hamel::rbd {

/// ∂ID/∂x for the state x = (r, Γ, ξ, ṙ) (Γ when the tree carries gravity in its state), one column per x_k, at u̇ =
/// tree.accelerations. Every column has one form: with per-body vectors u_i = 𝕀ᶜ_i s_i and b_i = Bᶜ_iᵀ s_i and
/// per-column vectors P, V and Δ,
///   row of joint i:  [i inside] (⟨u_i, P⟩ + ⟨b_i, V⟩) + [i an ancestor] ⟨s_i, Δ⟩ − ∂Q_i/∂x_k,
///   base row α:      ⟨e_α, Δ⟩ − ∂Q_α/∂x_k,
/// where for the columns of joint K's angle and rate (Column::body = K) the bodies inside are K's subtree and the
/// ancestors K's strict ancestors, Δ being the force K's subtree passes inward (Δ_K or Δ'_K); for a base velocity
/// (body 0) and for Γ every body is inside and none an ancestor. A recursive solve takes Δ as that force (rbd/aba.hpp:
/// rows() lists the rows without it, inward() gives it); dense() adds its rows.
struct InverseDynamicsJacobian {
  std::vector<Vec6<Ex>> u, b;  ///< per body i ≥ 1 (index 0 unused)
  struct Column {
    std::size_t body = 0;  ///< K for the columns of joint K's angle and rate; 0 for a base velocity
    Vec6<Ex> P, V, Delta;
    std::vector<Ex> force;  ///< ∂Q/∂x_k (m + n)
  };
  std::vector<Column> columns;

  /// Whether joint i's row (body i ≥ 1) of column k sees P and V.
  bool inside(const TreeModel& tree, std::size_t i, std::size_t k) const;
  /// Column k's rows (m + n: base directions, then joints) but those an inward force gives: an ancestor's ⟨s_i, Δ⟩
  /// and, for a joint's column, the base's ⟨e_α, Δ⟩.
  std::vector<Ex> rows(const TreeDynamics& tree, std::size_t k) const;
  /// The force column k passes inward from its joint's body (Column::body; none for 0).
  const Vec6<Ex>& inward(std::size_t k) const { return columns[k].Delta; }
  /// The full columns: rows() with the inward forces' rows added.
  std::vector<std::vector<Ex>> dense(const TreeDynamics& tree) const;
  /// The columns of −∂ID/∂x, the right-hand sides M y = b takes, in the same form: P, V and Δ negated, each named
  /// once per column (18 negations), and the forces' derivatives with the opposite sign. Negating each row instead
  /// costs one negation per row and column.
  InverseDynamicsJacobian negated(Intermediates& tape) const;
};

InverseDynamicsJacobian rnea_derivatives(const TreeDynamics& tree, Intermediates& tape);

}  // namespace hamel::rbd
