#include "numeric/work_precision.hpp"

#include "model/input_error.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/integrators.hpp"
#include "report/progress.hpp"
#include "report/svg_plot.hpp"

#include <hamel/runtime/monitor.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>

namespace hamel {

namespace {

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The fixed-step sweep: 8 steps halving from the horizon / 25, or from 2.5 / ρ when that is smaller, where ρ is the
// largest |eigenvalue| of the Jacobian along the reference: explicit RK4 is stable for |h λ| up to about 2.8 (2.785
// on the negative real axis, 2.828 on the imaginary one), so on a stiff model steps from the horizon / 25 would all
// blow up and say nothing. Steps that would need more than fixed_step_limit steps over the horizon are left out.
constexpr double rk4_stability_margin = 2.5;
constexpr double fixed_step_limit = 1e5;
constexpr std::size_t fixed_step_count = 8;

std::vector<double> fixed_steps(double t_end, double stiffness) {
  double h = t_end / 25.0;
  if (stiffness > 0 && std::isfinite(stiffness)) h = std::min(h, rk4_stability_margin / stiffness);
  std::vector<double> s;
  while (s.size() < fixed_step_count && t_end / h <= fixed_step_limit) s.push_back(h), h /= 2;
  return s;
}

// Settings per integrator: `steps` (above) for fixed-step methods, tolerances otherwise.
std::vector<double> sweep(const IntegratorInfo& info, const std::vector<double>& steps) {
  if (!info.adaptive) return steps;
  std::vector<double> s;
  for (int k = 3; k <= 11; ++k) s.push_back(std::pow(10.0, -k));
  return s;
}

// The largest |eigenvalue| of the n × n Jacobian at (t, x); 0 when it is not finite.
double spectral_radius(const JacobianFunction& jac, double t, const double* x, std::size_t n) {
  const auto size = static_cast<Eigen::Index>(n);
  Eigen::MatrixXd a(size, size);
  jac(t, x, a.data());  // row- or column-major alike: a matrix and its transpose have the same eigenvalues
  if (!a.allFinite()) return 0;
  return Eigen::EigenSolver<Eigen::MatrixXd>(a, false).eigenvalues().cwiseAbs().maxCoeff();
}

std::string number(double v) {
  if (std::isnan(v)) return "nan";
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

// The reference run's tolerance (rtol = atol), and that of the run whose distance from it indicates the reference's
// own error: the same method at ten times the tolerance.
constexpr double reference_tolerance = 1e-14;
constexpr double check_tolerance = 1e-13;
const std::string reference_method = "dop853";

// The kernels a study runs, interpreted from the graph, as the integrators call them.
struct StudyKernels {
  StudyKernels(const Derivation& d, const KernelSet& kernels, const WorkPrecisionRequest& req)
      : rhs_kernel(kernels.graph, kernels.get("rhs").outputs),
        jac_kernel(kernels.graph, kernels.get("jacobian").outputs),
        energy_kernel(kernels.graph, kernels.get("energy").outputs),
        constrained(!d.equations.constraint_residual.empty()),
        residual_kernel(kernels.graph, constrained ? kernels.get("constraint_residual").outputs : std::vector<int>{}),
        p(req.parameters.data()),
        in(req.inputs.empty() ? nullptr : req.inputs.data()),
        rhs([this](double t, const double* x, double* xdot) { rhs_kernel.evaluate(t, x, p, in, xdot); }),
        jac([this](double t, const double* x, double* J) { jac_kernel.evaluate(t, x, p, in, J); }) {}
  StudyKernels(const StudyKernels&) = delete;
  StudyKernels& operator=(const StudyKernels&) = delete;

  GraphEvaluator rhs_kernel, jac_kernel, energy_kernel;
  const bool constrained;
  GraphEvaluator residual_kernel;
  const double* p;
  const double* in;
  const RhsFunction rhs;
  const JacobianFunction jac;
};

// The reference run: dop853 at reference_tolerance over the horizon, or over part of it. A motion that passes near a
// singular configuration can need ever smaller steps at 1e-14, and the interpreted rhs of a large model makes that
// minutes: when the reference spends more than req.reference_steps steps' worth of evaluations within one hundredth
// of the horizon, the study stops it and runs over the horizon up to the start of that hundredth instead (the same
// run, cut short there).
struct Reference {
  runtime::IntegrationResult run;
  double t_end = 0;  ///< where it ends
  std::string note;  ///< why the horizon was shortened; empty when it was not
  /// Its states every hundredth of the horizon, where the stiffness of the fixed-step sweep is measured.
  std::vector<std::pair<double, std::vector<double>>> visited;
};

Reference reference_run(const StudyKernels& k, const WorkPrecisionRequest& req) {
  Reference ref;
  ref.t_end = req.t_end;
  ref.visited = {{0.0, req.x0}};
  const std::size_t n = req.x0.size();
  struct Stalled {
    double t;
  };
  const double window = req.t_end / 100;
  const long evaluations_per_window = 12 * req.reference_steps;  // dop853: 12 evaluations per step
  // The hundredths are those of accepted steps (the observer's times), so the horizon never moves past where the
  // reference got.
  double window_start = 0;
  long evaluations = 0;
  const RhsFunction watched = [&](double t, const double* x, double* xdot) {
    if (++evaluations > evaluations_per_window) throw Stalled{window_start};
    k.rhs(t, x, xdot);
  };
  const ObserveFunction accepted = [&](double t, const double* x) {
    if (t >= window_start + window) window_start = std::floor(t / window) * window, evaluations = 0;
    if (t >= ref.visited.back().first + window) ref.visited.emplace_back(t, std::vector<double>(x, x + n));
  };
  const auto run = [&](double until, const RhsFunction& f, const ObserveFunction& observe) {
    progress::Step step("reference run of the study: " + reference_method +
                        " at rtol = atol = " + number(reference_tolerance) + " over t = 0 .. " + number(until));
    return integrate(reference_method, reference_tolerance, f, k.jac, req.x0, 0.0, until, 0.0, observe);
  };
  try {
    ref.run = run(ref.t_end, watched, accepted);
  } catch (const Stalled& stalled) {
    if (!(stalled.t > 0))
      throw InputError("report: the reference run (" + reference_method + ", tolerance " + number(reference_tolerance) +
                       ") took more than " + std::to_string(req.reference_steps) + " steps without getting past t = " +
                       number(window) + ", a hundredth of the horizon: the motion from this state is too hard to " +
                       "resolve there; choose --init or a shorter --t-end");
    ref.t_end = stalled.t;
    ref.note = "horizon shortened from " + number(req.t_end) + " to " + number(ref.t_end) +
               ": the reference run took more than " + std::to_string(req.reference_steps) +
               " steps within the next hundredth of it (the motion from this state is hard to resolve "
               "there; --t-end or --init change it)";
    ref.run = run(ref.t_end, k.rhs, [](double, const double*) {});
  }
  if (ref.run.status != runtime::Status::ok)
    throw InputError("report: the reference run (" + reference_method + ", tolerance " + number(reference_tolerance) +
                     ") failed at t = " + std::to_string(ref.run.t) + ": " + runtime::describe(ref.run.status));
  return ref;
}

// What the fixed-step sweep says of itself: steps from the stability bound instead of the horizon / 25, and steps
// left out because they would need too many; empty when neither.
std::string fixed_step_note(double t_end, double stiffness, const std::vector<double>& steps) {
  const std::string rho = "ρ = " + number(stiffness) +
                          ", the largest |eigenvalue| of the Jacobian at the reference's states every hundredth of "
                          "the horizon";
  const std::string limit = "more than " + number(fixed_step_limit) + " steps over the horizon";
  std::string note;
  if (steps.empty())
    note = "fixed-step methods left out: steps below their stability bound 2.5/ρ = " +
           number(rk4_stability_margin / stiffness) + " (" + rho + ") need " + limit;
  else if (steps.front() < t_end / 25.0)
    note = "fixed steps from 2.5/ρ = " + number(steps.front()) + " (the stability bound of RK4; " + rho +
           ") instead of the horizon / 25";
  if (!steps.empty() && steps.size() < fixed_step_count)
    note += "; " + std::to_string(fixed_step_count - steps.size()) + " finer steps would need " + limit +
            " and are left out";
  return note;
}

// One run of the sweep, timed. Invariants along it (observed at every step): the energy when it is conserved, the
// constraint residual when there are constraints; the observer's own time is measured (steady clock, about 30 ns a
// reading against about 600 ns for a CPU-time reading here) and taken off the run's. A run that took at least
// min_cpu_s is its own measurement; a shorter one is repeated without observer until min_cpu_s has passed, and the
// mean taken. `error_of`: its error against the reference.
WorkPrecisionRun timed_run(StudyKernels& k, const Derivation& d, const WorkPrecisionRequest& req,
                           const IntegratorInfo& info, double setting, double t_end,
                           const std::function<double(const runtime::IntegrationResult&)>& error_of) {
  WorkPrecisionRun run;
  run.integrator = info.name;
  run.setting = setting;
  double e0 = 0;
  k.energy_kernel.evaluate(0.0, req.x0.data(), k.p, k.in, &e0);
  runtime::DriftMonitor energy(e0);
  double residual = 0, observer_s = 0;
  std::vector<double> r(d.equations.constraint_residual.size() + d.system.position_constraints.size());
  const bool observed = d.equations.conservative || k.constrained;
  const ObserveFunction observe = [&](double t, const double* x) {
    if (!observed) return;
    const auto begin = std::chrono::steady_clock::now();
    if (d.equations.conservative) {
      double e = 0;
      k.energy_kernel.evaluate(t, x, k.p, k.in, &e);
      energy.update(e);
    }
    if (k.constrained) {
      k.residual_kernel.evaluate(t, x, k.p, k.in, r.data());
      for (double v : r) residual = std::max(residual, std::fabs(v));
    }
    observer_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  };
  const double start = cpu_seconds();
  runtime::IntegrationResult result =
      integrate(info.name, setting, k.rhs, k.jac, req.x0, 0.0, t_end, 0.0, observe, req.max_steps);
  double elapsed = cpu_seconds() - start - observer_s;
  int repeats = 1;
  if (elapsed < req.min_cpu_s) {
    repeats = 0;
    const double again = cpu_seconds();
    do {
      result = integrate(
          info.name, setting, k.rhs, k.jac, req.x0, 0.0, t_end, 0.0, [](double, const double*) {}, req.max_steps);
      ++repeats;
      elapsed = cpu_seconds() - again;
    } while (elapsed < req.min_cpu_s && repeats < 1000);
  }
  run.cpu_s = elapsed / repeats;
  run.status = result.status == runtime::Status::ok ? "ok" : runtime::describe(result.status);
  run.steps = result.stats.steps;
  run.rhs_evals = result.stats.rhs_evals;
  run.jac_evals = result.stats.jac_evals;
  run.error = error_of(result);
  run.drift = d.equations.conservative ? energy.max_relative_deviation() : std::numeric_limits<double>::quiet_NaN();
  run.constraint_residual = residual;
  return run;
}

}  // namespace

WorkPrecisionStudy work_precision(const Model& /*model*/, const Derivation& d, const KernelSet& kernels,
                                  const WorkPrecisionRequest& req, std::ostream* progress) {
  if (!(req.t_end > 0) || !std::isfinite(req.t_end)) throw InputError("--t-end: expected a positive finite time");
  StudyKernels k(d, kernels, req);
  const std::size_t n = req.x0.size();

  WorkPrecisionStudy study;
  study.x0 = req.x0;
  study.min_cpu_s = req.min_cpu_s;
  for (const auto& q : d.system.coordinates) study.state_names.push_back(q.get_name());
  for (int I : d.equations.independent)
    study.state_names.push_back(d.system.velocities[static_cast<std::size_t>(I)].get_name());

  const Reference ref = reference_run(k, req);
  const double t_end = ref.t_end;
  study.t_end = t_end;
  study.horizon_note = ref.note;
  if (progress && !study.horizon_note.empty()) *progress << "hamel: " << study.horizon_note << "\n";
  study.reference = "reference run: " + reference_method + " at rtol = atol = " + number(reference_tolerance) + " (" +
                    std::to_string(ref.run.stats.steps) + " steps); no analytic solution is used";
  double ref_scale = 1;
  for (double v : ref.run.x) ref_scale = std::max(ref_scale, std::fabs(v));
  // The error of run x(T) against the reference, relative (NaN when the run failed).
  const auto error_of = [&](const runtime::IntegrationResult& run) {
    if (run.status != runtime::Status::ok) return std::numeric_limits<double>::quiet_NaN();
    double e = 0;
    for (std::size_t i = 0; i < n; ++i) e = std::max(e, std::fabs(run.x[i] - ref.run.x[i]));
    return e / ref_scale;
  };
  {
    progress::Step step("check run of the reference: " + reference_method +
                        " at rtol = atol = " + number(check_tolerance) + " over t = 0 .. " + number(t_end));
    study.reference_check = error_of(integrate(reference_method, check_tolerance, k.rhs, k.jac, req.x0, 0.0, t_end, 0.0,
                                               [](double, const double*) {}));
  }
  if (progress)
    *progress << "hamel: " << reference_method << " at rtol = atol = " << number(check_tolerance) << " ends "
              << number(study.reference_check) << " from the reference (an indication of the reference's own error)\n";

  std::vector<std::string> names = req.integrators;
  if (names.empty()) names = {"rk4", "dopri5", "dop853", "radau5"};
  double stiffness = 0;
  for (const auto& [t, x] : ref.visited)
    if (t <= t_end) stiffness = std::max(stiffness, spectral_radius(k.jac, t, x.data(), n));
  const std::vector<double> steps = fixed_steps(t_end, stiffness);
  study.sweep_note = fixed_step_note(t_end, stiffness, steps);
  if (progress && !study.sweep_note.empty()) *progress << "hamel: " << study.sweep_note << "\n";
  for (const std::string& name : names) {
    const IntegratorInfo& info = find_integrator(name);
    for (double setting : sweep(info, steps)) {
      const WorkPrecisionRun run = timed_run(k, d, req, info, setting, t_end, error_of);
      if (progress)
        *progress << "  " << std::setw(7) << run.integrator << "  " << std::setw(9) << number(setting) << "  error "
                  << std::setw(12) << number(run.error) << "  cpu " << number(run.cpu_s) << " s  " << run.steps
                  << " steps  " << run.status << "\n";
      study.runs.push_back(run);
    }
  }
  return study;
}

std::string work_precision_csv(const WorkPrecisionStudy& study) {
  std::ostringstream s;
  s << std::setprecision(17);
  s << "integrator,setting,error,cpu_s,steps,rhs_evals,jac_evals,drift,constraint_residual,status\n";
  for (const WorkPrecisionRun& r : study.runs)
    s << r.integrator << "," << r.setting << "," << r.error << "," << r.cpu_s << "," << r.steps << "," << r.rhs_evals
      << "," << r.jac_evals << "," << r.drift << "," << r.constraint_residual << "," << r.status << "\n";
  return s.str();
}

std::string work_precision_markdown(const Model& model, const WorkPrecisionStudy& study) {
  std::ostringstream s;
  s << "# Work–precision: " << model.name << "\n\n"
    << "Horizon t = 0 … " << number(study.t_end) << "; initial state";
  for (std::size_t k = 0; k < study.x0.size(); ++k)
    s << (k ? ", " : " ") << study.state_names[k] << " = " << number(study.x0[k]);
  s << ".";
  for (const std::string& note : {study.horizon_note, study.sweep_note})
    if (!note.empty())
      s << " " << static_cast<char>(std::toupper(static_cast<unsigned char>(note[0]))) << note.substr(1) << ".";
  s << "\n\nError: max-norm of x(T) − x_ref(T) relative to max(1, |x_ref(T)|); " << study.reference
    << ". The reference's own error is not measured; as an indication, " << reference_method
    << " at rtol = atol = " << number(check_tolerance) << " ends " << number(study.reference_check)
    << " from it, so errors of about that size or below may be the reference's. CPU time: one run less the time spent "
       "observing it (energy and constraint residual at every step), or "
       "the mean of repeats without observer for runs shorter than "
    << number(study.min_cpu_s)
    << " s; right-hand side evaluated by the kernel "
       "interpreter (the graph `hamel emit` prints; compiled kernels are faster). Drift: max relative energy "
       "deviation along the run (nan when the model is not conservative).\n\n"
    << "| integrator | setting | error | CPU [s] | CPU per simulated s | steps | rhs | Jacobians | drift | constraint "
       "residual | status |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const WorkPrecisionRun& r : study.runs)
    s << "| " << r.integrator << " | " << number(r.setting) << " | " << number(r.error) << " | " << number(r.cpu_s)
      << " | " << number(r.cpu_s / study.t_end) << " | " << r.steps << " | " << r.rhs_evals << " | " << r.jac_evals
      << " | " << number(r.drift) << " | " << number(r.constraint_residual) << " | " << r.status << " |\n";
  return s.str();
}

std::string work_precision_svg(const Model& model, const WorkPrecisionStudy& study) {
  PlotSpec plot;
  plot.title = model.name + ": error against CPU time";
  plot.x_label = "CPU time per run [s]";
  plot.y_label = "relative error at t_end";
  plot.log_x = plot.log_y = true;
  for (const WorkPrecisionRun& r : study.runs) {
    if (plot.series.empty() || plot.series.back().label != r.integrator)
      plot.series.push_back({r.integrator, {}, {}, true, true, false});
    // Errors at or below the reference's own accuracy are drawn at 1e-16.
    plot.series.back().x.push_back(r.cpu_s);
    plot.series.back().y.push_back(std::max(r.error, 1e-16));
  }
  // The reference check (the reference's method at ten times its tolerance) as a dashed line across the plot.
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const WorkPrecisionRun& r : study.runs)
    if (r.cpu_s > 0) lo = std::min(lo, r.cpu_s), hi = std::max(hi, r.cpu_s);
  if (hi > 0 && std::isfinite(study.reference_check)) {
    const double y = std::max(study.reference_check, 1e-16);
    plot.series.push_back(
        {reference_method + " " + number(check_tolerance) + " vs reference", {lo, hi}, {y, y}, true, false, true});
  }
  return render_svg(plot);
}

}  // namespace hamel
