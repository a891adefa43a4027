// Holonomic constraints g(q) = 0 of a model in general coordinates (model key `holonomic`) as quasi-velocities held at
// zero, after A. Müller, Proc. R. Soc. A 479 (2023) 20220732, Sec. 2, "partitioned coordinates".
//
// Each constraint g^α(q) = 0, α = 1..k, is imposed in its velocity form ġ^α = G^α_a(q) q̇^a = 0 with G = ∂g/∂q
// (taken through the model's definitions, Intermediates::diff): the quasi-velocity u^α := ġ^α, named after the
// constraint, is held at zero. That is a Pfaffian constraint (PfaffianConstr2) whose rows are exact differentials, so
// its Hamel coefficients γ^α_IJ vanish (gammaHolo: they vanish if and only if the constraints are holonomic), and the
// constrained Hamel equations (BHconstr) of the general path are the equations of the constrained system. The other
// n − k quasi-velocities are
//  - the model's `quasi_velocities` when it gives them (n − k rows; A = [G; A_other] must be regular), or else
//  - the rates of independent coordinates r of a partition q = (s, r), u^I := ṙ^I, so that
//      A = [[G_s, G_r], [0, I]]   (sys1)   and   B = A⁻¹ = [[G_s⁻¹, −G_s⁻¹ G_r], [0, I]]   (salpha, sys2),
//    and the equations are (HE-holo) in ṙ with the kinematics ṡ = B^α_I ṙ^I (solConstr).
// B, γ and the equations then follow by the general path (derive/quasi_velocities, hamel_coefficients,
// hamel_equations); this step only builds the quasi-velocities. The state stays (q, u_I): the velocity constraint
// G q̇ = G B_I u_I = 0 holds by construction (A B = I), only the positions drift numerically from g(q) = 0, which the
// runtime's projector corrects (runtime/include/hamel/runtime/projection.hpp, fed by the constraint_position kernels).
//
// The partition. The dependent coordinates s are the k columns of G that a QR factorization with column pivoting
// picks (each time the column with the largest norm orthogonal to those already picked; ties go to the later
// coordinate), with G evaluated at the configuration of the model's `initial` (coordinates it does not name at 0,
// parameters at their defaults): G_s is then regular, and as well conditioned as greedy pivoting makes it, where the
// model is meant to start. Where G has rank below k there, at fixed generic configurations instead. A model that
// wants another partition (or other quasi-velocities altogether) gives `quasi_velocities` with the n − k others.
#pragma once

#include "model/model.hpp"

namespace hamel {

/// Completes the quasi-velocities of a model with holonomic constraints. On entry model.holonomic holds the
/// constraints (their velocity symbols and g; gradients empty), and model.quasi_velocities, model.A (its rows × n) and
/// model.constrained the other quasi-velocities as the file gives them (`others_given`; n − k of them), or nothing. On
/// return the gradients are formed, quasi_velocities = (ġ^1..ġ^k, then the others), A = [G; the others' rows] (n × n),
/// constrained = (0..k−1, then the file's constraints shifted by k), and, when hamel chose the partition,
/// dependent_coordinates holds s. Throws InputError naming file:line and the key for a constraint that does not
/// depend on the coordinates, constraints that are dependent everywhere, and quasi-velocities that do not complete
/// the gradients to a regular A.
void add_holonomic_quasi_velocities(Model& model, bool others_given);

/// The dependent coordinates of a partition q = (s, r) with G_s regular (as above) for gradients `G` (k rows of n
/// values): indices into the coordinates, ascending; empty when G has rank below k (pivots at most 1e-9 of the largest
/// column norm).
std::vector<int> dependent_coordinates_by_pivoting(const std::vector<std::vector<double>>& G);

}  // namespace hamel
