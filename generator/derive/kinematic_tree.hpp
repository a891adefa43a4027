// Kinematic trees with a floating base (model key `tree`, docs/model-format.md): the base body rides on
// the group frame (left trivialization, body twist ξ), every other body hangs on its parent by a
// revolute or prismatic joint whose coordinate is a shape coordinate r^I.
//
// The equations are the paper's Euler–Poincaré + Euler–Lagrange form (HEorig1, HEorig2) in u = (ξ, ṙ),
// derived as Hamel's equations of the bodies (rbd/rnea.hpp) and projected onto u: M(r) u̇ = f(r, u), M by
// composite inertias (rbd/crba.hpp), f by the recursive Newton–Euler algorithm; the tree itself (rbd::TreeDynamics)
// for the kernels' recursive algorithms (emit/equations_of_motion.hpp: u̇ by the articulated-body algorithm, the
// Jacobian by the derivatives of the inverse dynamics). Every quantity is an intermediate symbol
// (algebra/intermediates.hpp), so the program has O(n) definitions for f and O(n·depth) for M instead of the
// expanded formula's exponential size. This file builds the rigid-body model (rbd/tree.hpp) from the model file's
// tree and assembles the equations; the algorithms are in rbd/.
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/bundle_connection.hpp"
#include "derive/hamel_equations.hpp"
#include "derive/hamel_system.hpp"
#include "model/model.hpp"

namespace hamel {

struct TreeDerivation {
  BundleGeometry geometry;   ///< algebra, structure constants, L, K, S (blocks of M); the connection is
                             ///< not formed symbolically (connection_derived = false)
  HamelSystem system;        ///< the Euler–Poincaré form's system: u = (ξ, ṙ), γ = c
  HamelEquations equations;  ///< M, f, kinematics, energy; their intermediates in equations.intermediates
};

/// The recursive derivation of a tree model (model.tree, or model.bundle->tree): M, f and the tree
/// (equations.tree) from which the kernels may form u̇ recursively instead (rbd::forward_dynamics).
TreeDerivation derive_tree(const Model& model);

/// T(ξ, r, ṙ) = Σ ½ V_iᵀ 𝕀_i V_i of a tree model as one expanded-free expression in the model's symbols
/// (intermediates inlined). Exponential in the depth of the tree: for small trees and cross-checks, and
/// for the forms other than ep, which differentiate T as a whole.
GiNaC::ex tree_kinetic_energy(const Model& model);

/// A copy of a tree model as a plain bundle model: `kinetic` = tree_kinetic_energy, no tree. What the
/// forms other than ep and the symbolic bundle geometry work on.
Model with_inlined_tree(const Model& model);

}  // namespace hamel
