// Work–precision study (error against run time): every applicable integrator over a sweep of
// tolerances or steps on one model and initial state; error against a reference run far below the sweep
// (DOP853 at rtol = atol = 1e-14), CPU time, work counters and invariant drift per run. The right-hand side
// is the interpreter of the kernels' expression graph (GraphEvaluator), the same graph `emit` prints.
#pragma once

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <string>
#include <vector>

namespace hamel {

struct WorkPrecisionRun {
  std::string integrator;
  double setting = 0;  ///< tolerance (adaptive) or step
  std::string status;  ///< "ok" or the runtime's failure
  double error = 0;    ///< max-norm of x(T) − x_ref(T), relative to max(1, |x_ref(T)|)
  double cpu_s = 0;    ///< CPU seconds of one run
  long steps = 0, rhs_evals = 0, jac_evals = 0;
  double drift = 0;                ///< max relative energy drift (NaN when the model is not conservative)
  double constraint_residual = 0;  ///< max |A_alpha(q) q_dot| along the run (0 without Pfaffian constraints)
};

struct WorkPrecisionStudy {
  std::string reference;  ///< how the error was measured
  /// The reference's own error is not measured; as an indication, the max-norm distance of dop853 at rtol = atol =
  /// 1e-13 (ten times the reference's tolerance) from the reference at t_end, relative as the runs' errors. NaN when
  /// that run failed.
  double reference_check = 0;
  double t_end = 0;          ///< the horizon studied (below the requested one when the reference could not reach it)
  std::string horizon_note;  ///< why the horizon is shorter than requested; empty when it is not
  std::string sweep_note;    ///< how the fixed steps follow from ρ when they start below the horizon / 25; else empty
  std::vector<std::string> state_names;
  std::vector<double> x0;
  double min_cpu_s = 0;  ///< runs shorter than this were repeated for their CPU time (WorkPrecisionRequest)
  std::vector<WorkPrecisionRun> runs;
};

struct WorkPrecisionRequest {
  double t_end = 10;
  std::vector<double> x0;  ///< initial state (coordinates, independent velocities)
  std::vector<double> parameters;
  std::vector<double> inputs;
  std::vector<std::string> integrators;  ///< empty: all of rk4, dopri5, dop853, radau5
  /// A run shorter than this (CPU seconds, less the time its observer took) is repeated without observer until this
  /// much CPU time has passed, and the mean reported; a longer one is its own measurement.
  double min_cpu_s = 0.02;
  /// Step attempts per adaptive run of the sweep (beyond: status "too many steps"); 0: the integrators' own limits.
  long max_steps = 0;
  /// The reference run's budget: more than this many steps' worth of rhs evaluations within one hundredth of the
  /// horizon shortens the horizon to the start of that hundredth (WorkPrecisionStudy::horizon_note says so).
  long reference_steps = 10000;
};

/// Runs the study; progress goes to `progress` (one line per run) when non-null. Throws InputError when the
/// reference run fails, or stalls (above) in the first hundredth of the horizon.
WorkPrecisionStudy work_precision(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                                  const WorkPrecisionRequest& request, std::ostream* progress);

/// CSV with the columns integrator,setting,error,cpu_s,steps,rhs_evals,jac_evals,drift,constraint_residual,status.
std::string work_precision_csv(const WorkPrecisionStudy& study);
/// Markdown: the setup and one table row per run.
std::string work_precision_markdown(const Model& model, const WorkPrecisionStudy& study);
/// Log–log SVG: error against CPU time, one line per integrator.
std::string work_precision_svg(const Model& model, const WorkPrecisionStudy& study);

}  // namespace hamel
