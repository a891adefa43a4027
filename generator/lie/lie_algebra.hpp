// Matrix Lie algebras of the symmetry groups a bundle model may name (docs/model-format.md, "group").
// Each group is defined once, by a basis of matrices E_α of its Lie algebra in the documented order
// (angular before linear); everything else — the structure constants c^α_βλ with
// [E_β, E_λ] = c^α_βλ E_α, the adjoint — is computed from that basis, never typed in.
#pragma once

#include "algebra/indexed_coefficient.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace hamel {

struct LieAlgebra {
  std::string group;                     ///< as named in the model: "SE3", "SO3xR3", ...
  std::vector<GiNaC::matrix> basis;      ///< E_α, exact, all of the same square size
  std::vector<std::string> basis_names;  ///< "omega_x", ..., documentation only
  unsigned dim() const { return static_cast<unsigned>(basis.size()); }
};

/// The names accepted by lie_algebra(), for messages: SE3, SO3, SE2, R1…R6 and products such as SO3xR3.
std::vector<std::string> known_groups();

/// The groups a kinematic tree's floating base may have, and the directions of a body's twist (ω, v) in which
/// each moves the base, as indices 0…5 into (ω_x, ω_y, ω_z, v_x, v_y, v_z), in the order of the group's
/// velocity: SE3 all six, SO3 ω, SE2 (ω_z, v_x, v_y), R1…R3 v_x…. Empty for any other group.
std::vector<int> tree_base_directions(const std::string& group);

/// The groups tree_base_directions() accepts, for messages: "SE3, SO3, SE2, R1, R2 or R3".
std::string tree_base_groups();

/// The algebra of `group`: SO3 (ω), SE3 (ω, v), SE2 (ω, vx, vy), Rk (k translations, 1 ≤ k ≤ 6) and direct
/// products written with 'x' (SO3xR3: (ω, v)), represented block-diagonally. Throws std::invalid_argument
/// naming the accepted groups when `group` is none of them.
LieAlgebra lie_algebra(const std::string& group);

/// One non-zero structure constant c^upper_{lower_a lower_b}.
using StructureConstant = IndexedCoefficient;

/// All non-zero c^α_βλ with [E_β, E_λ] = c^α_βλ E_α, ordered by (α, β, λ). The bracket is expanded in the
/// basis exactly (Gram system of the Frobenius inner product); a basis whose span is not closed under the
/// bracket is a programming error and throws std::logic_error.
std::vector<StructureConstant> structure_constants(const LieAlgebra& algebra);

/// Dense c[α][β][λ] from the sparse list.
std::vector<std::vector<std::vector<GiNaC::ex>>> dense(const std::vector<StructureConstant>& c, unsigned dim);

}  // namespace hamel
