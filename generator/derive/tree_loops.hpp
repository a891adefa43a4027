// Closed kinematic loops of a tree fixed to the world (model key `loops`, docs/model-format.md "### Closed loops").
//
// A loop closes the tree at the position level: a `connect` holds a point a of body A on a point b of body B (or of
// the world), g = p_A(q) + R_A(q) a − p_B(q) − R_B(q) b = 0 in the world frame (3 equations); a `weld` also holds a
// frame R_a of A on a frame R_b of B, with the orientation error g_rot = vee(skew(E)), E = (R_A R_a)ᵀ (R_B R_b) (the
// sine of the relative rotation's angle times its axis, zero at E = I, 3 more equations). The poses are the tree's
// forward kinematics (rbd/forward_kinematics.hpp); where the file gives no b (R_b) it is the one that coincides with
// A's at the reference configuration q = 0, as MJCF's `connect` and `weld` define their second anchor.
//
// On a fixed base the tree's velocities are the joint rates, u = q̇, so the closure's velocity form is ġ = G q̇ with
// G = ∂g/∂q, and the loops are holonomic constraints in general coordinates: this step turns the tree with loops into
// that model (L = T − V with T, the weight and the joint springs from the tree's recursion, the joint forces, dampers
// and the generalized forces Jᵀw of the applied wrenches as forces Q), and the holonomic path does the rest
// (derive/holonomic_constraints.hpp: the partition q = (s, r) by pivoting at the initial configuration, A = [G; 0 I],
// the constrained Hamel equations (HE-holo) in ṙ, the position constraints for the emitted constraint_position
// kernels, the runtime projector and `simulate`'s projection of the initial state).
//
// The equations a loop gives need not be independent: a planar loop written as a spatial connect has a z equation
// that vanishes identically, and a loop between two revolute joints on parallel axes repeats one equation. Rows whose
// gradient vanishes identically are dropped when g vanishes with them (a row that is a non-zero constant is a loop
// that cannot close: an error); of the others a maximal independent subset at the initial configuration is kept (the
// rows a QR factorization with row pivoting picks, 1e-9 of the largest row norm), or at the first of three generic
// configurations where the rank is larger (an initial configuration that is singular for the loops, as a four-bar
// stretched straight, would otherwise drop an equation that holds everywhere else). A note on stderr names the
// dropped rows.
#pragma once

#include "model/model.hpp"

#include <optional>
#include <string>
#include <vector>

namespace hamel {

/// A closed kinematic loop of a fixed-base tree (model key `loops`): a point of `body` held at a point of `to`
/// (connect, 3 equations), or a frame of `body` held on a frame of `to` (weld, 3 + 3 equations); points and rotations
/// in the bodies' frames, parameters only. Where `to_point` (`to_rotation`) is not given it is the one that coincides
/// with the body's at the reference configuration q = 0 (MJCF's convention).
struct TreeLoop {
  std::string name;
  bool weld = false;
  std::string body, to;  ///< body names of the tree; `to` may be the base ("world")
  GiNaC::ex point[3] = {0, 0, 0};
  GiNaC::ex rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::optional<std::vector<GiNaC::ex>> to_point;     ///< 3 entries
  std::optional<std::vector<GiNaC::ex>> to_rotation;  ///< 9 entries, row by row
  SourceLocation where;
};

/// Turns a fixed-base tree model (model.tree set) with `loops` into a general-coordinate model with the loops'
/// independent closure equations as holonomic constraints (model.tree and model.wrenches cleared; lagrangian, forces,
/// holonomic, A, quasi_velocities, constrained and dependent_coordinates set). Throws InputError naming file:line and
/// the loop's key for a loop that cannot close or closes nothing.
void close_tree_loops(Model& model, const std::vector<TreeLoop>& loops);

}  // namespace hamel
