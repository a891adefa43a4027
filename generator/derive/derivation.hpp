// The whole derivation of a model, in the order of the paper's Sec. 2: quasi-velocities (u2), Hamel
// coefficients (gamma, gammaNH), equations of motion (BHEqu2/BHconstr) with kinematics (qadot).
#pragma once

#include "derive/hamel_coefficients.hpp"
#include "derive/hamel_equations.hpp"
#include "derive/quasi_velocities.hpp"
#include "model/model.hpp"

namespace hamel {

struct Derivation {
  QuasiVelocities quasi_velocities;
  std::vector<HamelCoefficient> hamel;
  HamelEquations equations;
};

/// Runs every derivation step on `model`. Throws InputError for models that are inconsistent.
inline Derivation derive(const Model& model) {
  Derivation d;
  d.quasi_velocities = derive_quasi_velocities(model);
  d.hamel = hamel_coefficients(model, d.quasi_velocities);
  d.equations = hamel_equations(model, d.quasi_velocities, d.hamel);
  return d;
}

}  // namespace hamel
