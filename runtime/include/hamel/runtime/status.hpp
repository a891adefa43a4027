// SPDX-License-Identifier: MIT
// Outcome codes shared by the solvers and integrators of the hamel runtime.
#pragma once

namespace hamel::runtime {

// Solvers report failure through a value rather than an exception so that the
// runtime stays usable in code built with -fno-exceptions.
enum class Status {
  ok,
  step_size_underflow,
  non_finite_state,
  newton_failure,
  singular_mass_matrix,
  too_many_steps,
  invalid_argument,              // a caller's mistake, not a property of the problem: a step h <= 0 or NaN, a setting
                                 // that makes no sense (negative or non-finite tolerance, ...), too small a work space
  projection_failure,            // projection.hpp: Gauss-Newton onto g(q) = 0 did not converge in max_iterations
  singular_constraint_jacobian,  // projection.hpp: G G^T not positive definite, the constraints dependent there
};

/// Human-readable description of a status, suitable for log and error messages.
inline const char* describe(Status status) {
  switch (status) {
    case Status::ok:
      return "ok";
    case Status::step_size_underflow:
      return "step size underflow";
    case Status::non_finite_state:
      return "non-finite state";
    case Status::newton_failure:
      return "Newton iteration failed to converge";
    case Status::singular_mass_matrix:
      return "singular or indefinite mass matrix";
    case Status::too_many_steps:
      return "too many steps";
    case Status::invalid_argument:
      return "invalid argument (a step, setting or work space that makes no sense)";
    case Status::projection_failure:
      return "projection onto the position constraints did not converge";
    case Status::singular_constraint_jacobian:
      return "singular constraint Jacobian (the position constraints are dependent at this configuration)";
  }
  // Reachable only through a value cast from outside the enumeration.
  return "unknown status";
}

}  // namespace hamel::runtime
