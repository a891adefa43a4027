// The recursive Newton–Euler algorithm (Featherstone, Rigid Body Dynamics Algorithms, 2008, §5.3): the inverse
// dynamics ID(r, u, u̇) of a kinematic tree in u = (ξ, ṙ), in either frame convention (rbd/tree.hpp). Every body is
// a rigid body with its own twist v_i as quasi-velocity and the Euler–Poincaré equation
// d/dt(𝕀_i v_i) − ad*_{v_i} 𝕀_i v_i = W_i (BHEqu2 with γ = c of se(3)); the joints are the constraints
// v_i = X_i v_λ + S_i ṙ_i that leave u independent (BHconstr). Outward: twists v_i, the rates of the joint axes
// ψ_i = v_i × S_i = (X_i v_λ) × S_i, accelerations a_i = X_i a_λ + S_i r̈_i + ψ_i ṙ_i from the base's a_0 (gravity as
// its upward acceleration, rbd/tree.hpp), momenta h_i = 𝕀_i v_i and wrenches f_i = 𝕀_i a_i + v_i ×* h_i − f_ext,i;
// inward: the wrenches summed over each subtree, F_λ += X_iᵀ F_i. Then ID_α = ⟨e_α, F_0⟩ and ID_i = ⟨S_i, F_i⟩ + a_i
// r̈_i.
#pragma once

#include "rbd/tree.hpp"

#include <vector>

namespace hamel::rbd {

/// The outward pass's data, per body (index 0 the base).
struct Motion {
  std::vector<Vec6<Ex>> v;    ///< twists
  std::vector<Vec6<Ex>> psi;  ///< ψ_i, the rate of body i's joint axis (zero for the base)
  std::vector<Vec6<Ex>> a;    ///< accelerations
  std::vector<Vec6<Ex>> h;    ///< momenta 𝕀_i v_i
  std::vector<Vec6<Ex>> f;    ///< 𝕀_i a_i + v_i ×* h_i (not named; applied wrenches: with_applied)
};

/// The outward pass at base velocity ξ and rates ṙ, with base accelerations ξ̇ and joint accelerations r̈ (empty:
/// zero, the velocity-product and gravity terms alone). v_i, a_i and h_i are named; ψ_i in Frame::world, where s_i
/// is a general vector and ψ_i is read again by the derivatives (in the bodies' frames ψ_i = v_i × S_i, products of
/// named entries).
Motion rnea_motion(const FrameView& view, const std::vector<Ex>& base_velocity, const std::vector<Ex>& rates,
                   const std::vector<Ex>& base_acceleration, const std::vector<Ex>& joint_acceleration,
                   const Namer<Ex>& name);

/// f_i − f_ext,i for every body: the wrenches the joints and the base must supply, applied wrenches taken off.
std::vector<Vec6<Ex>> with_applied(const FrameView& view, std::vector<Vec6<Ex>> f);

/// The inward pass: F_i = f_i + Σ over i's children X_cᵀ F_c, each body's named (a fixed base's F_0 is not formed).
std::vector<Vec6<Ex>> rnea_forces(const FrameView& view, std::vector<Vec6<Ex>> f, const Namer<Ex>& name);

/// Jᵀ f_ext: the generalized forces (m + n rows: ⟨e_α, F_0⟩, then ⟨S_i, F_i⟩) of the applied wrenches alone, summed
/// inward without the bodies' inertia (F_i = Σ over i's subtree of f_ext). Empty wrenches give zeros.
std::vector<Ex> applied_generalized_forces(const FrameView& view, const Namer<Ex>& name);

/// −ID(r, u, 0) + τ: the forcing f of M u̇ = f (m + n rows: −⟨e_α, F_0⟩, then τ_i − ⟨S_i, F_i⟩), F from rnea_forces
/// at zero accelerations and `joint_force` τ (n: applied joint forces, springs, dampers).
std::vector<Ex> forcing(const FrameView& view, const std::vector<Vec6<Ex>>& F, const std::vector<Ex>& joint_force);

/// f = −ID(r, u, 0) + τ in the common frame (Frame::world), the forcing of M u̇ = f from `tree`'s state: what the
/// Jacobian solves with the articulated factor its columns use, to get u̇ without the body-frame recursion of rhs.
std::vector<Ex> bias_forcing(const TreeDynamics& tree, const Namer<Ex>& name);

/// f − M u̇ = −ID(r, u, u̇) + τ (with the armatures' a_i r̈_i) at u̇ = tree.accelerations, in the common frame: what
/// the kernels by inputs and parameters differentiate (M du̇/dw = −∂ID/∂w at fixed u̇), one O(n) program.
std::vector<Ex> residual_forcing(const TreeDynamics& tree, const Namer<Ex>& name);

}  // namespace hamel::rbd
