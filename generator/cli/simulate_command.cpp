// `hamel simulate MODEL --t-end T ...`: integrates the model's right-hand side kernel (evaluated from
// the same expression graph that `emit` prints) with the runtime's integrators; CSV out, summary and
// invariant monitors on stderr.
#include "algebra/expression_text.hpp"
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "cli/simulation.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/group_pose.hpp"
#include "numeric/input_sources.hpp"
#include "numeric/integrators.hpp"
#include "report/atomic_file.hpp"

#include <hamel/runtime/csv.hpp>
#include <hamel/runtime/lie/rkmk_coupled.hpp>
#include <hamel/runtime/monitor.hpp>
#include <hamel/runtime/projection.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

namespace hamel::cli {

namespace {

// Work refused up front (docs/errors.md, "Limits"): a typo such as --dt 1e-12 must not fill a disk.
constexpr double kMaxFixedSteps = 1e8;
constexpr double kMaxOutputRows = 1e7;

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The run's options: the command line's values over the scene's over the defaults, checked before any work.
struct Settled {
  SimulateOptions opt;
  std::map<std::string, double> init, scene_inputs;
  const IntegratorInfo* info = nullptr;
};

Settled settle(const SimulateOptions& given, const Target& target) {
  Settled s;
  SimulateOptions& opt = s.opt;
  opt = given;
  if (target.scene) {
    const Scene& scene = *target.scene;
    if (opt.integrator.empty()) opt.integrator = scene.integrator;
    if (opt.t_end == 0 && scene.t_end) opt.t_end = *scene.t_end;
    if (opt.dt == 0 && scene.dt) opt.dt = *scene.dt;
    if (opt.tol == 0 && scene.tol) opt.tol = *scene.tol;
    if (opt.sample == 0 && scene.sample) opt.sample = *scene.sample;
    s.scene_inputs = scene.inputs;
  }
  if (opt.integrator.empty()) opt.integrator = "dopri5";
  // A value given as 0 or below is an error, not "use the default"; a value the chosen integrator does not
  // use is an error, not ignored.
  if (given.dt_given && !(given.dt > 0 && std::isfinite(given.dt)))
    throw InputError("--dt: expected a positive finite step, got " + number_text(given.dt));
  if (given.tol_given && !(given.tol >= 1e-15 && given.tol < 1))
    throw InputError("--tol: expected a tolerance in [1e-15, 1), got " + number_text(given.tol) +
                     (given.tol > 0 ? "" : " (a value below the smallest double reads as 0)"));
  if (given.sample_given && !(given.sample > 0 && std::isfinite(given.sample)))
    throw InputError("--sample: expected a positive finite output interval, got " + number_text(given.sample));
  if (opt.dt == 0) opt.dt = 1e-3;
  if (opt.tol == 0) opt.tol = 1e-8;
  for (const auto& [k, v] : parse_assignments(opt.init, "--init")) s.init[k] = v;
  if (!(opt.t_end > 0) || !std::isfinite(opt.t_end))
    throw InputError("--t-end: expected a positive finite time (required unless the scene gives t_end)");
  // A subnormal end time (1e-320) has too few digits for any step to reach it: the integrators would fail on
  // "step size underflow" (exit 1) at t = 0.
  if (opt.t_end < std::numeric_limits<double>::min())
    throw InputError("--t-end: " + number_text(opt.t_end) +
                     " is below the smallest normal double (2.2e-308), too small for a step to resolve; expected a "
                     "positive time of at least 2.2e-308");
  const IntegratorInfo& info = *(s.info = &find_integrator(opt.integrator));
  if (!info.adaptive && !(opt.dt > 0)) throw InputError("--dt: expected a positive step");
  if (info.adaptive && !(opt.tol > 0)) throw InputError("--tol: expected a positive tolerance");
  if (info.adaptive && given.dt_given)
    throw InputError("--dt: " + opt.integrator +
                     " chooses its own steps; give --tol instead, or a fixed-step "
                     "integrator (--integrator rk4)");
  if (!info.adaptive && given.tol_given)
    throw InputError("--tol: " + opt.integrator +
                     " takes fixed steps; give --dt instead, or an adaptive integrator "
                     "(--integrator dopri5)");
  if (!info.adaptive && opt.t_end / opt.dt > kMaxFixedSteps)
    throw InputError("--dt: " + number_text(opt.t_end) + " / " + number_text(opt.dt) + " = " +
                     number_text(opt.t_end / opt.dt) + " steps, more than the limit of " + number_text(kMaxFixedSteps) +
                     "; expected a larger --dt or a shorter --t-end");
  const double rows = opt.sample > 0 ? opt.t_end / opt.sample : info.adaptive ? 0 : opt.t_end / opt.dt;
  if (rows > kMaxOutputRows)
    throw InputError(std::string(opt.sample > 0 ? "--sample" : "--dt") + ": " +
                     (std::isfinite(rows) ? number_text(rows) : std::string("more than 1e308")) +
                     " output rows, more than the limit of " + number_text(kMaxOutputRows) +
                     "; expected a larger --sample (output interval)");
  return s;
}

// --monitors: extra CSV columns evaluated at every output row.
struct Monitors {
  bool energy = false, residual = false, momentum = false;
};

Monitors parse_monitors(const std::string& list) {
  Monitors m;
  for (const std::string& name : list.empty() ? std::vector<std::string>{} : split_list(list)) {
    if (name == "energy")
      m.energy = true;
    else if (name == "constraint_residual")
      m.residual = true;
    else if (name == "momentum")
      m.momentum = true;
    else
      throw InputError("--monitors: unknown monitor " + quote(name) +
                       "; expected a comma-separated list of: energy, constraint_residual, momentum");
  }
  return m;
}

// The reconstruction starts the base at the identity, aligned with the world: gravity in its frame must then be the
// world's g (the state default), else the state and the pose would describe two different motions.
void check_gravity_at_identity(const Target& target, const std::vector<std::string>& columns,
                               const std::vector<double>& x0) {
  for (const auto& [name, g] : state_default_values(target)) {
    const auto it = std::find(columns.begin() + 1, columns.end(), name);
    if (it == columns.end()) continue;
    const double start = x0[static_cast<std::size_t>(it - columns.begin() - 1)];
    if (std::abs(start - g) > 1e-12 * (1 + std::abs(g)))
      throw InputError("--integrator rkmk4: the reconstruction starts the base aligned with the world, where " + name +
                       " is " + number_text(g) + ", but the initial state gives " + number_text(start) +
                       "; expected gravity in the base frame equal to the world's at t = 0 (the default), or an "
                       "integrator without reconstruction (dopri5)");
  }
}

// The CSV's columns after t and the state: the pose (when reconstructed), then the monitors'. The constraint residual
// monitor has the velocity residuals residual_<u> = A^alpha(q) q_dot of the constrained quasi-velocities, then the
// position residuals position_residual_<c> = g_c(q) of the position constraints (the outputs of the
// constraint_residual kernel, in order).
std::vector<std::string> monitor_columns(const Derivation& derivation, const Monitors& monitors) {
  const HamelSystem& sys = derivation.system;
  std::vector<std::string> header;
  if (monitors.energy) header.push_back("energy");
  if (monitors.residual) {
    const std::vector<int>& held = sys.constrained;
    const std::size_t n_res = derivation.equations.constraint_residual.size();
    for (std::size_t k = 0; k < n_res; ++k)
      header.push_back("residual_" + (held.size() == n_res
                                          ? sys.velocities[static_cast<std::size_t>(held[k])].get_name()
                                          : std::to_string(k)));
    for (const PositionConstraint& c : sys.position_constraints) header.push_back("position_residual_" + c.name);
  }
  if (monitors.momentum)
    for (int I : derivation.equations.independent)
      header.push_back("p_" + sys.velocities[static_cast<std::size_t>(I)].get_name());
  return header;
}

// Bundle models with rkmk4: the reduced state and g together (RKMK4 on G × ℝⁿ), g(0) = identity; `pose` holds
// g at every output row when `observe` is called.
template <class Rhs, class Xi, class Observe>
runtime::IntegrationResult integrate_with_pose(const Model& model, const SimulateOptions& opt,
                                               const std::vector<double>& x0, Rhs& rhs, Xi& xi, GroupPose& pose,
                                               Observe& observe) {
  return with_group(model.bundle->group, [&](auto tag) {
    using G = typename decltype(tag)::type;
    auto f = [&](double t, const double* x, double* xdot) { rhs(t, x, xdot); };
    auto observe_pose = [&](double t, const double* x, const typename G::Element& g) {
      pose = pose_of(t, g);
      observe(t, x);
    };
    const auto r = runtime::lie::integrate_rkmk4_coupled<G>(
        model.bundle->right ? runtime::lie::Trivialization::right : runtime::lie::Trivialization::left, f, xi,
        G::identity(), x0, 0.0, opt.t_end, opt.dt, opt.sample, observe_pose);
    runtime::IntegrationResult out;
    out.status = r.status;
    out.t = r.t;
    out.stats = r.stats;
    out.x = r.x;
    return out;
  });
}

// What the projection onto the position constraints did in a run (for the summary).
struct ProjectionSummary {
  double position_max = 0;  ///< max |g_c(q)| over the observed states
  runtime::ProjectionStats stats;
};

// The run's summary on stderr, or, when the integration failed, where it failed (then RunFailed).
void print_outcome(const Model& model, const SimulateOptions& opt, const Derivation& derivation,
                   const std::vector<std::string>& columns, const runtime::IntegrationResult& result,
                   const runtime::DriftMonitor& energy, const double* residual_max,
                   const std::optional<ProjectionSummary>& projection) {
  std::ostringstream state;
  for (std::size_t k = 0; k + 1 < columns.size(); ++k) state << (k ? ", " : "") << columns[k + 1] << "=" << result.x[k];
  if (result.status != runtime::Status::ok) {
    std::cerr << "hamel: simulation failed at t = " << result.t << ": " << runtime::describe(result.status)
              << "\n  state: " << state.str() << "\n";
    throw RunFailed(std::string("integration failed (") + runtime::describe(result.status) + ")" +
                    (opt.out == "-" ? "" : "; " + opt.out + " was not written"));
  }
  std::cerr << "hamel: simulated " << model.name << " with " << opt.integrator << " to t = " << result.t << ": "
            << result.stats.steps << " steps (" << result.stats.rejected << " rejected), " << result.stats.rhs_evals
            << " right-hand-side evaluations, " << result.stats.jac_evals << " Jacobians\n";
  // Relative to the initial energy only when it is not 0: from E = 0 (a system at rest) the relative drift is the
  // absolute one over the smallest double, and a forced spring printed "max relative drift 3.63e+307".
  if (energy.initial() != 0)
    std::cerr << "  energy: initial " << energy.initial() << ", max relative drift " << energy.max_relative_deviation();
  else
    std::cerr << "  energy: initial 0, max drift " << energy.max_abs_deviation()
              << " (absolute: the energy starts at 0)";
  std::cerr << (derivation.equations.conservative
                    ? ""
                    : " (an invariant only while the model's forces vanish and L has no explicit t)")
            << "\n";
  if (residual_max) std::cerr << "  constraint residual |A_alpha(q) q_dot|: max " << *residual_max << "\n";
  if (projection)
    std::cerr << "  position residual |g(q)|: max " << projection->position_max << " (projected onto g(q) = 0 "
              << projection->stats.projections << " times, " << projection->stats.iterations
              << " Gauss-Newton corrections; largest |g| before a projection " << projection->stats.largest_residual
              << ")\n";
  std::cerr << "  final state: " << state.str() << "\n";
}

// The kernels a run evaluates, each at the inputs of (t, x): a feedback law or a table is evaluated first.
class Evaluation {
 public:
  Evaluation(const KernelSet& kernels, const std::vector<double>& p, const InputSources& sources, std::size_t inputs)
      : kernels_(kernels), p_(p), sources_(sources), in_(inputs, 0.0), varying_(sources.varying()) {}
  /// The evaluator of kernel `name`, or of nothing when it is not wanted.
  GraphEvaluator kernel(const char* name, bool wanted) const {
    return GraphEvaluator(kernels_.graph, wanted ? kernels_.get(name).outputs : std::vector<int>{});
  }
  void inputs_at(double t, const double* x) { sources_.evaluate(t, x, in_.data()); }
  void operator()(GraphEvaluator& kernel, double t, const double* x, double* out) {
    if (varying_) inputs_at(t, x);
    again(kernel, t, x, out);
  }
  /// With the inputs of the last evaluation (a monitor evaluated right after another at the same (t, x)).
  void again(GraphEvaluator& kernel, double t, const double* x, double* out) {
    kernel.evaluate(t, x, p_.data(), in_.empty() ? nullptr : in_.data(), out);
  }

 private:
  const KernelSet& kernels_;
  const std::vector<double>& p_;
  const InputSources& sources_;
  std::vector<double> in_;
  bool varying_;
};

// What the run writes at every output row: t, the state, the pose (when reconstructed) and the monitors; it also
// follows the energy and the constraint residual for the summary.
class Recorder {
 public:
  Recorder(const Derivation& derivation, const Monitors& monitors, Evaluation& evaluate, std::ostream& out,
           const std::vector<std::string>& columns, const std::optional<GroupPose>& pose, const std::vector<double>& x0)
      : monitors_(monitors),
        evaluate_(evaluate),
        energy_kernel_(evaluate.kernel("energy", true)),
        residual_kernel_(evaluate.kernel("constraint_residual", !derivation.equations.constraint_residual.empty() ||
                                                                    !derivation.system.position_constraints.empty())),
        mass_kernel_(evaluate.kernel("mass_matrix", monitors.momentum)),
        constrained_(!derivation.equations.constraint_residual.empty() ||
                     !derivation.system.position_constraints.empty()),
        n_x_(columns.size() - 1),
        n_q_(derivation.system.coordinates.size()),
        n_u_(derivation.equations.independent.size()),
        n_velocity_residuals_(derivation.equations.constraint_residual.size()),
        energy_(energy_at(0.0, x0.data())),
        residual_(derivation.equations.constraint_residual.size() + derivation.system.position_constraints.size()),
        mass_(monitors.momentum ? n_u_ * n_u_ : 0),
        header_(columns) {
    if (pose) {
      pose_ = *pose;
      for (const std::string& c : pose_columns(*pose_)) header_.push_back(c);
    }
    first_monitor_ = header_.size();
    for (const std::string& c : monitor_columns(derivation, monitors)) header_.push_back(c);
    row_.resize(header_.size());
    csv_.emplace(out, header_);
  }
  /// The pose written with the next row (bundle models integrated with rkmk4).
  GroupPose& pose() { return *pose_; }
  const runtime::DriftMonitor& energy() const { return energy_; }
  const double* residual_max() const { return n_velocity_residuals_ > 0 ? &residual_max_ : nullptr; }
  /// max |g_c(q)| over the observed states (0 without position constraints).
  double position_residual_max() const { return position_max_; }

  void operator()(double t, const double* x) {
    row_[0] = t;
    std::copy(x, x + n_x_, row_.begin() + 1);
    if (pose_) {
      const std::vector<double> v = pose_values(*pose_);
      std::copy(v.begin(), v.end(), row_.begin() + 1 + static_cast<std::ptrdiff_t>(n_x_));
    }
    const double e = energy_at(t, x);
    energy_.update(e);
    if (constrained_) {
      evaluate_.again(residual_kernel_, t, x, residual_.data());
      for (std::size_t k = 0; k < residual_.size(); ++k) {
        double& worst = k < n_velocity_residuals_ ? residual_max_ : position_max_;
        worst = std::max(worst, std::fabs(residual_[k]));
      }
    }
    std::size_t col = first_monitor_;
    if (monitors_.energy) row_[col++] = e;
    if (monitors_.residual)
      for (double r : residual_) row_[col++] = r;
    if (monitors_.momentum) {
      // p = M u: the momenta conjugate to the independent quasi-velocities (∂T/∂u for T quadratic in u).
      evaluate_.again(mass_kernel_, t, x, mass_.data());
      for (std::size_t I = 0; I < n_u_; ++I) {
        double s = 0;
        for (std::size_t J = 0; J < n_u_; ++J) s += mass_[I * n_u_ + J] * x[n_q_ + J];
        row_[col++] = s;
      }
    }
    csv_->row(row_.data(), row_.size());
  }

 private:
  double energy_at(double t, const double* x) {
    double e = 0;
    evaluate_(energy_kernel_, t, x, &e);
    return e;
  }

  const Monitors& monitors_;
  Evaluation& evaluate_;
  GraphEvaluator energy_kernel_, residual_kernel_, mass_kernel_;
  bool constrained_;
  std::size_t n_x_, n_q_, n_u_, n_velocity_residuals_;
  runtime::DriftMonitor energy_;
  double residual_max_ = 0, position_max_ = 0;
  std::vector<double> residual_, mass_;
  std::optional<GroupPose> pose_;
  std::vector<std::string> header_;
  std::size_t first_monitor_ = 0;
  std::vector<double> row_;
  std::optional<runtime::CsvWriter> csv_;
};

// The position constraints g(q) = 0 of a run, evaluated by the constraint_position kernels, for the projection of the
// initial state and the projector after every step (runtime/projection.hpp). Needs nothing but the two kernels.
class PositionConstraints {
 public:
  PositionConstraints(const HamelSystem& sys, Evaluation& evaluate)
      : sys_(sys),
        evaluate_(evaluate),
        n_q_(sys.coordinates.size()),
        k_(sys.position_constraints.size()),
        g_(evaluate.kernel("constraint_position", k_ > 0)),
        G_(evaluate.kernel("constraint_position_jacobian", k_ > 0)),
        work_(runtime::ProjectionWorkspace::doubles(n_q_, k_)),
        projector_(Position{this}, Jacobian{this}, n_q_, k_, runtime::ProjectionWorkspace{work_.data(), work_.size()}) {
  }

  PositionConstraints(const PositionConstraints&) = delete;  // its callables point to it
  PositionConstraints& operator=(const PositionConstraints&) = delete;

  std::size_t size() const { return k_; }
  /// g(q) at x.
  std::vector<double> residuals(const double* x) {
    std::vector<double> r(k_);
    evaluate_.again(g_, 0.0, x, r.data());
    return r;
  }

  /// Moves the coordinates of x0 onto g(q) = 0 (Newton on q from the given q, minimum-norm corrections; the
  /// velocities u_I are the state and need nothing), saying on stderr what it changed; an InputError naming the
  /// violated constraint and its residual where Newton does not get there.
  void project_initial_state(const Model& model, std::vector<double>& x0) {
    if (k_ == 0) return;
    const std::vector<double> given = x0;
    runtime::ProjectionOptions options;
    options.max_iterations = 50;
    const runtime::ProjectionOutcome o =
        runtime::project_positions(Position{this}, Jacobian{this}, 0.0, x0.data(), n_q_, k_,
                                   runtime::ProjectionWorkspace{work_.data(), work_.size()}, options);
    const std::vector<double> before = residuals(given.data());
    std::size_t worst = 0;
    for (std::size_t c = 0; c < k_; ++c)
      if (std::fabs(before[c]) > std::fabs(before[worst])) worst = c;
    const std::string& name = sys_.position_constraints[worst].name;
    if (o.status != runtime::Status::ok) {
      const std::vector<double> after = residuals(x0.data());
      double left = 0;
      for (double r : after) left = std::max(left, std::fabs(r));
      std::string why = o.status == runtime::Status::singular_constraint_jacobian
                            ? "the constraint gradients dg/dq became dependent on the way (G G^T singular)"
                        : o.status == runtime::Status::projection_failure
                            ? "it did not converge in " + std::to_string(options.max_iterations) + " corrections"
                            : "it met a non-finite value";
      // A tree's closed loop (key loops) is named as the file names it, its equations <loop>_x, ...
      const std::string key = (model.locations.count("loops." + name) ? "loops." : "holonomic.") + name;
      const auto it = model.locations.find(key);
      const SourceLocation where = it != model.locations.end() ? it->second : SourceLocation{model.source_path, 0, 0};
      throw InputError(where, key,
                       "the initial state (" + state_text(given) +
                           ") violates this constraint by g = " + shortest_decimal(before[worst]) +
                           ", and Newton's method on the coordinates cannot close it (" + why +
                           "; max |g| = " + shortest_decimal(left) + " after " + std::to_string(o.iterations) +
                           " corrections): the constraints have no solution near it; expected an initial state "
                           "near one that meets every position constraint (key initial, --init, or the "
                           "parameters)");
    }
    if (o.iterations < 2) {  // the first correction was already at rounding level: the state stays as given
      x0 = given;
      return;
    }
    std::cerr << "hamel: note: the initial state violates the position constraints (max |g| = "
              << shortest_decimal(o.residual) << ", at " << name
              << "); projected it onto g(q) = 0 by Newton's method on the "
              << "coordinates (" << o.iterations << " corrections, minimum-norm), the velocities unchanged:\n";
    for (std::size_t a = 0; a < n_q_; ++a)
      if (x0[a] != given[a])
        std::cerr << "  " << sys_.coordinates[a].get_name() << ": " << shortest_decimal(given[a]) << " -> "
                  << shortest_decimal(x0[a]) << "\n";
  }

  /// The projector the integrators call after every accepted step (and on every sample).
  runtime::Status project(double t, double* x) { return projector_(t, x); }
  const runtime::ProjectionStats& stats() const { return projector_.stats(); }

 private:
  struct Position {
    PositionConstraints* self;
    void operator()(double t, const double* x, double* out) const { self->evaluate_.again(self->g_, t, x, out); }
  };
  struct Jacobian {
    PositionConstraints* self;
    void operator()(double t, const double* x, double* out) const { self->evaluate_.again(self->G_, t, x, out); }
  };
  std::string state_text(const std::vector<double>& x) const {
    std::string text;
    for (std::size_t a = 0; a < n_q_; ++a)
      text += (a ? ", " : "") + sys_.coordinates[a].get_name() + " = " + shortest_decimal(x[a]);
    return text;
  }

  const HamelSystem& sys_;
  Evaluation& evaluate_;
  std::size_t n_q_, k_;
  GraphEvaluator g_, G_;
  std::vector<double> work_;
  runtime::ConstraintProjector<Position, Jacobian> projector_;
};

}  // namespace

void simulate(const SimulateOptions& given, Pipeline& pipeline, const std::function<std::ostream&()>& open,
              const std::function<void()>& check, const std::function<void()>& on_success) {
  const Target& target = pipeline.target();
  const Model& model = target.model;
  const std::vector<double>& p = target.parameters;
  const Settled settled = settle(given, target);
  const SimulateOptions& opt = settled.opt;
  const IntegratorInfo& info = *settled.info;

  const Derivation& derivation = pipeline.derivation();
  const Monitors monitors = parse_monitors(opt.monitors);
  std::set<std::string> needed = {
      "kinematics",    "rhs", "energy", "constraint_residual", "constraint_position", "constraint_position_jacobian",
      "group_velocity"};
  if (monitors.momentum) needed.insert("mass_matrix");
  if (info.uses_jacobian) needed.insert("jacobian");
  KernelSet kernels = pipeline.kernels(needed);
  drop_unrepresentable(kernels, true, printable(given.in.file));  // it evaluates every kernel it asked for
  const HamelSystem& sys = derivation.system;

  std::vector<std::string> columns{"t"};
  for (const auto& q : sys.coordinates) columns.push_back(q.get_name());
  for (int I : derivation.equations.independent)
    columns.push_back(sys.velocities[static_cast<std::size_t>(I)].get_name());
  std::vector<double> x0 = initial_state(target, std::vector<std::string>(columns.begin() + 1, columns.end()),
                                         std::vector<double>(columns.size() - 1, 0.0), settled.init);

  // Inputs: the scene's constants, then --input-file (tables) and --input (constants or laws in t and the
  // state), each input set once on the command line.
  InputSources sources(model, std::vector<std::string>(columns.begin() + 1, columns.end()), p);
  for (const auto& [name, v] : settled.scene_inputs) sources.set_constant(name, v, "scene");
  if (!opt.input_file.empty()) sources.load_csv(opt.input_file);
  sources.add_assignments(opt.inputs, "--input");
  Evaluation evaluate(kernels, p, sources, model.inputs.size());
  evaluate.inputs_at(0.0, x0.data());
  // Position constraints g(q) = 0: the initial state is projected onto them (before anything reads it), and so is
  // every accepted state of the run.
  PositionConstraints positions(sys, evaluate);
  positions.project_initial_state(model, x0);
  evaluate.inputs_at(0.0, x0.data());
  GraphEvaluator rhs_kernel = evaluate.kernel("rhs", true),
                 jacobian_kernel = evaluate.kernel("jacobian", info.uses_jacobian);
  auto rhs = [&](double t, const double* x, double* xdot) { evaluate(rhs_kernel, t, x, xdot); };

  std::ostream& csv = open();  // after the inputs are read: an output may not replace one of them
  const bool reconstruct = model.bundle && info.name == "rkmk4";
  if (reconstruct) check_gravity_at_identity(target, columns, x0);
  std::optional<GroupPose> pose;
  if (reconstruct)
    pose = with_group(model.bundle->group, [](auto tag) {
      using G = typename decltype(tag)::type;
      return pose_of(0.0, G::identity());
    });
  Recorder record(derivation, monitors, evaluate, csv, columns, pose, x0);
  auto observe = [&](double t, const double* x) {
    record(t, x);
    check();  // a full disk or closed pipe stops the run instead of integrating on into nothing
  };

  // With a feedback law the Jacobian leaves out d(in)/dx: implicit integrators then iterate Newton with an
  // approximate Jacobian (their result is unaffected, only their convergence).
  auto jacobian = [&](double t, const double* x, double* J) { evaluate(jacobian_kernel, t, x, J); };
  runtime::IntegrationResult result;
  if (reconstruct) {
    if (positions.size() > 0)
      throw InputError(
          "--integrator rkmk4: the group reconstruction does not project onto position constraints; "
          "expected another integrator for a model with position constraints");
    GraphEvaluator xi_kernel = evaluate.kernel("group_velocity", true);
    auto xi = [&](double t, const double* x, double* out) { evaluate(xi_kernel, t, x, out); };
    result = integrate_with_pose(model, opt, x0, rhs, xi, record.pose(), observe);
  } else {
    ProjectFunction project;
    if (positions.size() > 0) project = [&](double t, double* x) { return positions.project(t, x); };
    result = integrate(opt.integrator, info.adaptive ? opt.tol : opt.dt, rhs, jacobian, x0, 0.0, opt.t_end, opt.sample,
                       observe, 0, project, sources.knots());
  }
  if (result.status == runtime::Status::ok) on_success();
  std::optional<ProjectionSummary> projection;
  if (positions.size() > 0) projection = ProjectionSummary{record.position_residual_max(), positions.stats()};
  print_outcome(model, opt, derivation, columns, result, record.energy(), record.residual_max(), projection);
}

namespace {

void run(const SimulateOptions& given) {
  PipelineOptions in = given.in;
  in.announce = false;  // the trajectory may go to standard output
  Pipeline pipeline(in);
  // Output goes to a temporary file beside the target, renamed over it on success only: a failed run
  // (or one that throws or is interrupted) leaves neither a partial CSV nor the temporary file, and keeps an
  // old CSV. Devices and pipes are written through (report/atomic_file.hpp).
  OutputTransaction output;
  simulate(
      given, pipeline, [&]() -> std::ostream& { return output.open(given.out, "--out"); }, [&] { output.check(); },
      [&] { output.commit(); });
}

}  // namespace

std::function<void()> add_simulate_options(CLI::App* cmd, SimulateOptions& opt) {
  cmd->add_option("--t-end", opt.t_end, "End time (start is 0); required unless the scene gives t_end");
  cmd->add_option("--integrator", opt.integrator,
                  "rk4, rkmk4 (fixed step), dopri5 (default), dop853 (adaptive explicit) or radau5 = implicit (stiff)");
  CLI::Option* dt = cmd->add_option("--dt", opt.dt, "Step of rk4 and rkmk4 (default 1e-3)");
  CLI::Option* tol =
      cmd->add_option("--tol", opt.tol, "Relative and absolute tolerance of the adaptive integrators (default 1e-8)");
  dt->excludes(tol);
  cmd->add_option(
      "--init", opt.init,
      "Initial values name=value,... of coordinates and independent quasi-velocities (default: the model's key "
      "initial, then the scene's; else 0)");
  cmd->add_option("--input", opt.inputs,
                  "Inputs name=value or name=expression in t, the state's names and parameters (a feedback law, "
                  "e.g. tau=\"-4*(q-1)-2*q_dot\"), comma-separated (default 0)");
  cmd->add_option("--input-file", opt.input_file,
                  "CSV with a header t,<input names> and rows of values, interpolated linearly in t (held at "
                  "the ends)");
  CLI::Option* sample = cmd->add_option("--sample", opt.sample, "Output interval (default: every step)");
  return [&opt, dt, tol, sample] {
    opt.dt_given = dt->count() > 0;
    opt.tol_given = tol->count() > 0;
    opt.sample_given = sample->count() > 0;
  };
}

Run add_simulate_command(CLI::App& app) {
  auto opt = std::make_shared<SimulateOptions>();
  CLI::App* cmd = app.add_subcommand("simulate", "Integrate a model's equations of motion and write a CSV trajectory");
  add_pipeline_options(cmd, opt->in);
  const std::function<void()> given = add_simulate_options(cmd, *opt);
  cmd->add_option("--monitors", opt->monitors,
                  "Extra CSV columns, comma-separated: energy, constraint_residual (residual_<u> per constraint), "
                  "momentum (p_<u> = M u per independent quasi-velocity)");
  cmd->add_option("--out", opt->out, "CSV file, or - for standard output")->capture_default_str();
  return [opt, given] {
    given();
    run(*opt);
  };
}

}  // namespace hamel::cli
