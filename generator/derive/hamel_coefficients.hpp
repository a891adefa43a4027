// Hamel coefficients γ^c_ab, paper eq. (gamma); the constrained ones γ^a_IJ of eq. (gammaNH) are
// the entries whose lower indices are both independent.
#pragma once

#include "algebra/indexed_coefficient.hpp"
#include "derive/quasi_velocities.hpp"
#include "model/model.hpp"

#include <vector>

namespace hamel {

/// One non-zero coefficient γ^upper_{lower_a lower_b} (indices into the quasi-velocities).
using HamelCoefficient = IndexedCoefficient;

/// All non-zero γ^c_ab = (∂A^c_r/∂q^s − ∂A^c_s/∂q^r) B^r_a B^s_b, ordered by (c, a, b); zero is decided
/// exactly (see simplify.hpp). Antisymmetry in (a, b) is used: each pair is computed once.
/// Derivatives go through the intermediates of `program` (the model's definitions and any the derivation
/// added); coefficients too large to print are kept there as new intermediates.
std::vector<HamelCoefficient> hamel_coefficients(const Model& model, const QuasiVelocities& qv, Intermediates& program);

/// The same with a program of the model's own definitions (for expressions without derived intermediates).
std::vector<HamelCoefficient> hamel_coefficients(const Model& model, const QuasiVelocities& qv);

}  // namespace hamel
