// The equations of motion in quasi-velocities: Boltzmann–Hamel (BHEqu2) when nothing is constrained,
// constrained Hamel (BHconstr) otherwise, brought to M(q, u) u̇_I = f(t, q, u_I, inputs) together with
// the kinematics q̇ = B_I(q) u_I (qadot).
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/hamel_system.hpp"

#include <memory>
#include <vector>

namespace hamel {

namespace rbd {
struct TreeDynamics;  // rbd/tree.hpp
}

struct HamelEquations {
  std::vector<int> independent;                ///< indices I of the independent quasi-velocities
  GiNaC::ex reduced_lagrangian;                ///< ℒ(q, u) = L(q, B u), with u^α = 0
  std::vector<GiNaC::ex> kinematics;           ///< q̇^a = B^a_I u^I, eq. (qadot)
  GiNaC::matrix mass_matrix;                   ///< M_IJ = ∂²ℒ/∂u^I∂u^J at u^α = 0
  std::vector<GiNaC::ex> forcing;              ///< f_I: everything in (BHconstr) but M u̇, moved to the right
  std::vector<GiNaC::ex> energy_terms;         ///< {E}: E = ∂ℒ/∂u^I u^I − ℒ (Jacobi integral)
  bool conservative = false;                   ///< no forces and no explicit time: E is an invariant
  std::vector<GiNaC::ex> constraint_residual;  ///< A^α_a q̇^a with q̇ from the kinematics (≡ 0), if Pfaffian
  std::vector<GiNaC::realsymbol> acceleration_symbols;  ///< trees: symbols for u̇ in TreeDynamics (the Jacobian
                                                        ///< maps them to the solved accelerations)
  std::shared_ptr<const rbd::TreeDynamics> tree;        ///< trees: the rigid-body model and its state, for the
                                                  ///< kernels' recursive algorithms (emit/equations_of_motion.hpp)
  bool factor_last_first = false;  ///< solve M u̇ = f eliminating from the last index (trees: no fill-in)
  Intermediates intermediates;     ///< definitions of the intermediate symbols the expressions above may use
                                   ///< (recursive derivations, derive/kinematic_tree.hpp); empty otherwise
};

/// Derives the equations of motion of `system` (with time symbol `t`); throws InputError if the mass matrix
/// is identically singular.
HamelEquations hamel_equations(const HamelSystem& system, const GiNaC::realsymbol& t);

}  // namespace hamel
