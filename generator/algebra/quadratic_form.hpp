// Two steps shared by the derivations that start from a kinetic energy: the exact test that T is a
// quadratic form in the velocities (eq. T; the Riemannian view's L = ½ g_ab q̇ᵃq̇ᵇ − V), and the solve of a
// symmetric positive definite system by a symbolic LDLᵀ through intermediate symbols (A = L⁻¹K of eq.
// mechConn; Γᵃ_bc = g^ad Γ_d,bc of the Riemannian view), so that no inverse is ever expanded.
#pragma once

#include "algebra/intermediates.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace hamel {

/// True iff T is the quadratic form ½ vᵀ H v in `v` (H = ∂²T/∂v∂v, given): its third derivatives vanish and
/// nothing but ½ vᵀ H v remains (so no linear and no constant terms). Both by identically_zero()
/// (algebra/identity_test.hpp), exact for parameters in numerators and denominators alike.
bool is_quadratic_form(const GiNaC::ex& T, const std::vector<GiNaC::realsymbol>& v, const GiNaC::matrix& H,
                       Intermediates& program);

/// X with S X = K for S symmetric positive definite (no pivoting), by LDLᵀ and two triangular solves (rbd/ldlt.hpp);
/// every pivot, factor and entry kept through `program` (Intermediates::keep), entries of X with inline size
/// `inline_size`.
GiNaC::matrix solve_positive_definite(const GiNaC::matrix& S, const GiNaC::matrix& K, Intermediates& program,
                                      std::size_t inline_size = 400);

}  // namespace hamel
