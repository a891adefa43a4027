#include "numeric/integrators.hpp"

#include "model/input_error.hpp"

#include <hamel/runtime/dop853.hpp>
#include <hamel/runtime/dopri5.hpp>
#include <hamel/runtime/radau5.hpp>
#include <hamel/runtime/rk4.hpp>

namespace hamel {

const std::vector<IntegratorInfo>& integrators() {
  static const std::vector<IntegratorInfo> list = {
      {"rk4", false, false, "classic Runge-Kutta, fixed step (setting: step)"},
      {"rkmk4", false, false, "Munthe-Kaas RK4: RK4 on the state, RKMK4 on G for bundle models (setting: step)"},
      {"dopri5", true, false, "Dormand-Prince 5(4), adaptive (setting: tolerance)"},
      {"dop853", true, false, "Hairer's DOP853, 8th order, adaptive (setting: tolerance)"},
      {"radau5", true, true, "Radau IIA order 5, implicit, emitted Jacobian (alias: implicit; setting: tolerance)"},
  };
  return list;
}

const IntegratorInfo& find_integrator(const std::string& name) {
  const std::string key = name == "implicit" ? "radau5" : name;
  for (const IntegratorInfo& i : integrators())
    if (i.name == key) return i;
  std::string names;
  for (const IntegratorInfo& i : integrators()) names += (names.empty() ? "" : ", ") + i.name;
  throw InputError("--integrator: unknown integrator '" + name + "'; expected one of " + names + ", implicit");
}

namespace {

// The run with `project` as the projector: NoProjector (the integrators as before projectors) or a function.
template <class Projector>
runtime::IntegrationResult run(const IntegratorInfo& info, double setting, const RhsFunction& rhs,
                               const JacobianFunction& jacobian, std::vector<double> x0, double t0, double t_end,
                               double sample_dt, const ObserveFunction& observe, long max_steps,
                               const std::vector<double>& stops, Projector&& project) {
  const auto with = [&](auto& o) {
    o.rtol = o.atol = setting;
    if (max_steps > 0) o.max_steps = max_steps;
    o.stops = stops.empty() ? nullptr : stops.data();
    o.n_stops = stops.size();
  };
  if (info.name == "rk4" || info.name == "rkmk4")
    return runtime::integrate_rk4(rhs, std::move(x0), t0, t_end, setting, sample_dt, observe, project);
  if (info.name == "dopri5") {
    runtime::Dopri5Options o;
    with(o);
    return runtime::integrate_dopri5(rhs, std::move(x0), t0, t_end, o, sample_dt, observe, project);
  }
  if (info.name == "dop853") {
    runtime::Dop853Options o;
    with(o);
    return runtime::integrate_dop853(rhs, std::move(x0), t0, t_end, o, sample_dt, observe, project);
  }
  runtime::Radau5Options o;
  with(o);
  return runtime::integrate_radau5(rhs, jacobian, std::move(x0), t0, t_end, o, sample_dt, observe, project);
}

}  // namespace

runtime::IntegrationResult integrate(const std::string& name, double setting, const RhsFunction& rhs,
                                     const JacobianFunction& jacobian, std::vector<double> x0, double t0, double t_end,
                                     double sample_dt, const ObserveFunction& observe, long max_steps,
                                     const ProjectFunction& project, const std::vector<double>& stops) {
  const IntegratorInfo& info = find_integrator(name);
  if (!(setting > 0) || !std::isfinite(setting))
    throw InputError(std::string(info.adaptive ? "--tol" : "--dt") + ": expected a positive finite number");
  if (!project)
    return run(info, setting, rhs, jacobian, std::move(x0), t0, t_end, sample_dt, observe, max_steps, stops,
               runtime::NoProjector{});
  return run(info, setting, rhs, jacobian, std::move(x0), t0, t_end, sample_dt, observe, max_steps, stops, project);
}

}  // namespace hamel
