// The emitted kernels of the shipped models, compiled into the test build, behind one table so that
// tests can loop over models. Each entry points at the model file it was generated from.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace hamel::test {

using KernelFn = void (*)(double t, const double* x, const double* p, const double* in, double* out);

struct CompiledModel {
  std::string name;
  std::string model_file;  ///< relative to the source tree, e.g. "models/rolling_ball.yaml"
  int n_coordinates, n_independent, n_parameters, n_inputs, n_constraints, n_hamel;
  const double* default_parameters;
  KernelFn kinematics, mass_matrix, forcing, hamel_coefficients, rhs, energy;
  KernelFn constraint_residual;  ///< null when the model has no constraints
  // Bundle models (Sec. 3-6) only; zero / null for models in general coordinates.
  std::string fold;         ///< the `hamel emit --fold` it was emitted with ("" or "all")
  int n_group;              ///< dim G
  KernelFn group_velocity;  ///< xi^alpha(r, u_I) for the reconstruction
  KernelFn connection;      ///< A^alpha_I(r), row-major; null without shape
  KernelFn locked_inertia;  ///< L_alpha_beta(r), row-major
  /// The packages' name tables, read generically: every package has them, null where there is nothing.
  const char* const* input_names;
  const char* const* constraint_names;
};

/// Test names print the model's name, not the struct's bytes.
inline void PrintTo(const CompiledModel& m, std::ostream* os) { *os << m.name; }

const std::vector<CompiledModel>& compiled_models();
const CompiledModel& compiled_model(const std::string& name);

/// Absolute path of a file in the source tree (tests run with HAMEL_SOURCE_DIR set by ctest).
std::string source_path(const std::string& relative);

}  // namespace hamel::test
