// The runtime's integrators by command-line name, behind one call, for `simulate` and `report`:
//   rk4 (fixed step), dopri5 and dop853 (adaptive explicit), radau5 alias implicit (Radau IIA order 5,
//   Newton with the emitted Jacobian kernel), rkmk4 (Munthe-Kaas RK4: on the reduced state it is RK4;
//   bundle models also reconstruct the group element with it, see simulate_command.cpp).
#pragma once

#include <hamel/runtime/integration.hpp>

#include <functional>
#include <string>
#include <vector>

namespace hamel {

struct IntegratorInfo {
  std::string name;
  bool adaptive = false;  ///< the setting is a tolerance (else a step)
  bool uses_jacobian = false;
  std::string description;
};

/// All integrators, in the order reports list them.
const std::vector<IntegratorInfo>& integrators();
/// The integrator called `name` ("implicit" is radau5); throws InputError listing the names.
const IntegratorInfo& find_integrator(const std::string& name);

using RhsFunction = std::function<void(double, const double*, double*)>;
using JacobianFunction = std::function<void(double, const double*, double*)>;  ///< row-major n x n
using ObserveFunction = std::function<void(double, const double*)>;
/// A projector onto position constraints (runtime/projection.hpp): moves an accepted state in place.
using ProjectFunction = std::function<runtime::Status(double, double*)>;

/// Integrates x' = rhs(t, x) from t0 to t_end with `name` at `setting` (tolerance, used as rtol and atol,
/// or step). sample_dt > 0 observes at t0 + k sample_dt, else every step. max_steps > 0 limits the step attempts of
/// the adaptive integrators (status too_many_steps beyond; 0: their own limits); fixed-step runs take t_end / step.
/// `project`, when set, is called on every accepted state and every sample (the runtime's projector argument); when
/// empty the integrators run without one (bit-identical to before projectors). `stops` (ascending): times the
/// adaptive integrators' steps end on exactly, the knots of an --input-file table (rk4 steps on its own grid).
runtime::IntegrationResult integrate(const std::string& name, double setting, const RhsFunction& rhs,
                                     const JacobianFunction& jacobian, std::vector<double> x0, double t0, double t_end,
                                     double sample_dt, const ObserveFunction& observe, long max_steps = 0,
                                     const ProjectFunction& project = {}, const std::vector<double>& stops = {});

}  // namespace hamel
