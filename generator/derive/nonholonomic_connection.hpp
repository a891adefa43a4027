// The nonholonomic connection of a bundle model whose constraints leave some group directions free (model key
// `constraints` on a bundle): Bloch, Krishnaprasad, Marsden & Murray, "Nonholonomic mechanical systems with
// symmetry", Arch. Rational Mech. Anal. 136 (1996) 21–99 (BKMM), in the body frame of a left (or right)
// trivialization G × M.
//
// The constraints C_ξ(r) ξ + C_r(r) ṙ = 0 (k rows, k < m = dim G) define the distribution D; the vertical space is
// V = {(ξ, 0)}, and S = D ∩ V = {(ξ, 0) : C_ξ ξ = 0}, of dimension m − k where C_ξ has rank k.
//  - Sections of S (BKMM's ξ^q, here body-fixed functions of r): C_ξ's k columns π picked by column pivoting at the
//    model's initial shape (as holonomic constraints pick their dependent coordinates), and for each other column f
//    the kernel vector Z_f = det(C_π) e_f − adj(C_π) C_f, polynomial in C's entries (no division).
//  - A complement: Y with C_ξ Y = I (Y_π = C_π⁻¹, zero elsewhere), so P = [Y Z] is a frame of g and
//    P⁻¹ = [C_ξ; W] with W = e_fᵀ / det(C_π).
//  - The kinematic part of the connection, 𝒜_kin = Y C_r (ξ = −𝒜_kin ṙ meets the constraints), and its mechanical
//    part from the locked inertia restricted to S, I^S = Zᵀ L Z: the horizontal space is {v ∈ D : v ⊥ S} in the
//    kinetic-energy metric, so
//        𝒜 = 𝒜_kin + Z (I^S)⁻¹ Zᵀ (K − L 𝒜_kin),
//    and every velocity in D is ξ = Z Ω_S − 𝒜ṙ with the nonholonomic momentum p = Zᵀ ∂l/∂ξ = I^S Ω_S.
// Without constraints (k = 0) this is the mechanical connection L⁻¹K (mechConn); with k = m it would be the
// kinematic one C_ξ⁻¹ C_r (KinConnect), which the model states as `connection: {kinematic: ...}` instead.
#pragma once

#include "algebra/intermediates.hpp"
#include "model/model.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace hamel {

struct NonholonomicConnection {
  std::vector<int> solved;       ///< π: the k group directions the constraints are solved for (column pivoting)
  std::vector<int> free;         ///< the m − k others; section j of S has the entry det(C_π) at free[j]
  GiNaC::matrix sections;        ///< Z, m × (m − k): a basis of S = ker C_ξ, BKMM's ξ^q in the body frame
  GiNaC::matrix frame;           ///< P = [Y Z], m × m: ξ = P ν − 𝒜ṙ with ν = (constraint velocities, Ω_S)
  GiNaC::matrix coframe;         ///< P⁻¹ = [C_ξ; W], m × m
  GiNaC::matrix kinematic;       ///< 𝒜_kin = Y C_r, m × d
  GiNaC::matrix locked_inertia;  ///< I^S = Zᵀ L Z, (m − k) × (m − k)
  GiNaC::matrix connection;      ///< 𝒜, m × d
};

/// The nonholonomic connection of `model` (a bundle with constraints) from the locked inertia L and the coupling K of
/// its kinetic energy (eq. M); every entry kept through `program`. Throws InputError naming the key `constraints`
/// when C_ξ has rank below k at the initial shape and at generic ones, and at `kinetic` when I^S is singular.
NonholonomicConnection derive_nonholonomic_connection(const Model& model, const GiNaC::matrix& L,
                                                      const GiNaC::matrix& K, Intermediates& program);

}  // namespace hamel
