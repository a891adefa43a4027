// The geometry of a bundle model (paper Sec. 3–5): structure constants of G, the partition (M) of the
// kinetic energy into locked inertia L, coupling K and shape inertia S, the connection A^α_I (kinematic,
// eq. KinConnect, as given; mechanical, eq. mechConn, A = L⁻¹K), its curvature (gamma3 / gammaRight /
// gamma43), the coefficients E^α_βI (gamma42) and the block-diagonal mass matrix M^Ω (MOmega).
#pragma once

#include "algebra/indexed_coefficient.hpp"
#include "algebra/intermediates.hpp"
#include "derive/nonholonomic_connection.hpp"
#include "lie/lie_algebra.hpp"
#include "model/model.hpp"

#include <optional>
#include <vector>

namespace hamel {

/// One non-zero coefficient with one upper group index and two lower indices (curvature B^α_IJ: both
/// shape; E^α_βI: a group and a shape index). Indices count within their own range (α, β from 0 in
/// the group, I, J from 0 in the shape).
using BundleCoefficient = IndexedCoefficient;

/// Rem. remSign: the paper's B^α_IJ = γ^α_IJ (default) or the gauge-theory convention B = −γ.
enum class CurvatureSign { paper, gauge };

struct BundleGeometry {
  LieAlgebra algebra;
  std::vector<StructureConstant> structure_constants;  ///< c^α_βλ, [E_β, E_λ] = c^α_βλ E_α
  int trivialization_sign = 1;                         ///< +1 left (γ^α_βλ = c), −1 right (γ = −c)
  bool quadratic = false;    ///< T is a quadratic form in (ξ, ṙ): L, K, S and M^Ω are defined
  GiNaC::matrix L, K, S;     ///< eq. (M): T = ½ (ξ, ṙ)ᵀ [[L, K], [Kᵀ, S]] (ξ, ṙ)
  GiNaC::matrix connection;  ///< A^α_I(r), m̄ × δ̄, when connection_derived
  std::optional<NonholonomicConnection> nonholonomic;  ///< with `constraints`: its parts; `connection` is its 𝒜
  bool connection_derived = true;                      ///< false for kinematic trees: A = L⁻¹K, the curvature, E and
                                   ///< S − AᵀLA are not formed symbolically (kernels solve L A = K)
  std::vector<BundleCoefficient> curvature;  ///< γ^α_IJ ≠ 0 (paper sign), both orders of (I, J)
  std::vector<BundleCoefficient> E;          ///< E^α_βI = γ^α_Iβ = ±c^α_βλ A^λ_I ≠ 0 (gamma42)
  GiNaC::matrix shape_inertia;  ///< S − AᵀLA, the lower block of M^Ω (eq. MOmega); its upper block is L
  Intermediates program;        ///< definitions of the intermediate symbols the expressions above may use

  /// The curvature in the requested sign convention.
  std::vector<BundleCoefficient> curvature_in(CurvatureSign sign) const;
};

/// Derives everything above for a bundle model that is not a kinematic tree (a tree is derived recursively by
/// derive/kinematic_tree, or inlined first by with_inlined_tree). Throws InputError (at the kinetic energy)
/// when the connection is mechanical and T is not a quadratic form in the velocities, or L is singular.
BundleGeometry derive_bundle_geometry(const Model& model);

/// The geometry with every intermediate symbol expanded (and an empty program): one expression per entry, in
/// the model's symbols. Can be far larger than the program; for small models and cross-checks.
BundleGeometry inlined(const BundleGeometry& geometry);

/// γ^α_IJ = ∂A^α_I/∂r^J − ∂A^α_J/∂r^I ± c^α_λμ A^λ_I A^μ_J (eqs. gamma3, gammaRight, gamma43) for any
/// connection matrix A (rows α, columns I) whose entries may use intermediates of `program` (derivatives
/// by the chain rule through them); the identically zero ones left out; both orders of (I, J).
std::vector<BundleCoefficient> curvature_of(const GiNaC::matrix& A, const std::vector<GiNaC::realsymbol>& shape,
                                            const std::vector<StructureConstant>& c, int trivialization_sign,
                                            Intermediates& program);

}  // namespace hamel
