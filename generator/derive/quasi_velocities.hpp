// Quasi-velocities u = A(q) q̇ and their inverse q̇ = B(q) u, paper eq. (qdu)/(u2).
#pragma once

#include "algebra/intermediates.hpp"
#include "model/model.hpp"

namespace hamel {

struct QuasiVelocities {
  GiNaC::matrix A;  ///< simplified A(q)
  GiNaC::matrix B;  ///< B = A⁻¹, simplified
};

/// Returns A and B = A⁻¹. When the model gives B, checks A·B = I exactly; otherwise inverts A
/// symbolically. Throws InputError when A is singular or the given B is not A⁻¹.
/// A and B may use the intermediates of `program` (the model's definitions, extended here when A is
/// inverted through intermediates).
QuasiVelocities derive_quasi_velocities(const Model& model, Intermediates& program);
/// The same with B inlined into one expression per entry (tests, small models).
QuasiVelocities derive_quasi_velocities(const Model& model);

}  // namespace hamel
