// `hamel report MODEL [--t-end T] [--init n=v,...] [--param n=v ...] [--out DIR]`: work–precision study of
// every applicable integrator (numeric/work_precision.hpp); writes <model>_work_precision.{csv,md,svg}.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "numeric/integrators.hpp"
#include "numeric/work_precision.hpp"
#include "report/atomic_file.hpp"
#include "report/progress.hpp"

#include <filesystem>
#include <iostream>

namespace hamel::cli {

namespace {

struct ReportOptions {
  PipelineOptions in;
  std::string out = ".";
  double t_end = 0;  // 0: the scene's t_end, else 10
  std::vector<std::string> init, inputs, integrators;
  long max_steps = WorkPrecisionRequest{}.max_steps, reference_steps = WorkPrecisionRequest{}.reference_steps;
};

void run(const ReportOptions& opt) {
  Pipeline pipeline(opt.in);
  const Target& target = pipeline.target();
  const Model& model = target.model;
  const std::vector<double>& p = target.parameters;
  std::map<std::string, double> input_values;
  double t_end = opt.t_end;
  if (target.scene) {
    input_values = target.scene->inputs;
    if (t_end == 0 && target.scene->t_end) t_end = *target.scene->t_end;
  }
  if (t_end == 0) t_end = 10;
  const Constants constants = parameter_constants(target);
  const std::map<std::string, double> init = parse_assignments(opt.init, "--init", constants);
  for (const auto& [k, v] : parse_assignments(opt.inputs, "--input", constants)) input_values[k] = v;
  const Derivation& d = pipeline.derivation();
  const KernelSet kernels = pipeline.kernels();

  WorkPrecisionRequest req;
  req.t_end = t_end;
  req.parameters = p;
  req.integrators = opt.integrators;
  if (opt.max_steps < 0) throw InputError("--max-steps: expected a number of steps (0: no limit of the study's own)");
  req.max_steps = opt.max_steps;
  if (opt.reference_steps < 1) throw InputError("--reference-steps: expected a positive number of steps");
  req.reference_steps = opt.reference_steps;
  std::vector<std::string> names;
  for (const auto& q : d.system.coordinates) names.push_back(q.get_name());
  for (int I : d.equations.independent) names.push_back(d.system.velocities[static_cast<std::size_t>(I)].get_name());
  // Default initial state: away from equilibria (coordinates 0.1 k, velocities 0.5), stated in the report; k / 10
  // is the double the report prints (0.1 * 3 is not 0.3). The model's `initial`, the scene's and --init override it.
  std::vector<double> defaults;
  for (std::size_t k = 0; k < names.size(); ++k)
    defaults.push_back(k < d.system.coordinates.size() ? static_cast<double>(k + 1) / 10 : 0.5);
  req.x0 = initial_state(target, names, defaults, init);
  req.inputs.assign(model.inputs.size(), 0.0);
  for (const auto& [name, v] : input_values) {
    std::size_t k = 0;
    while (k < model.inputs.size() && model.inputs[k].get_name() != name) ++k;
    if (k == model.inputs.size()) throw InputError("--input: '" + name + "' is not an input of " + model.name);
    req.inputs[k] = v;
  }
  for (const std::string& i : opt.integrators) (void)find_integrator(i);

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(opt.out, ec);
  if (ec) throw InputError("--out: cannot create '" + opt.out + "': " + ec.message());
  std::ostream* stream = progress::enabled() ? &std::cerr : nullptr;
  if (stream) *stream << "hamel: work-precision study of " << model.name << " over t = 0 .. " << t_end << "\n";
  const WorkPrecisionStudy study = work_precision(model, d, kernels, req, stream);
  const fs::path base = fs::path(opt.out) / (model.name + "_work_precision");
  OutputTransaction outputs;  // all three files or none
  outputs.open(base.string() + ".csv", "--out") << work_precision_csv(study);
  outputs.open(base.string() + ".md", "--out") << work_precision_markdown(model, study);
  outputs.open(base.string() + ".svg", "--out") << work_precision_svg(model, study);
  outputs.commit();
  std::cout << "wrote " << base.string() << ".csv, .md and .svg (" << study.runs.size() << " runs; " << study.reference
            << ")\n";
}

}  // namespace

Run add_report_command(CLI::App& app) {
  auto opt = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Work-precision study: error against CPU time for every integrator over a sweep of settings");
  add_pipeline_options(cmd, opt->in);
  cmd->add_option("--t-end", opt->t_end, "Horizon (start is 0; default: the scene's t_end, else 10)");
  cmd->add_option(
      "--init", opt->init,
      "Initial values name=value,... (default: the model's key initial, then the scene's; else coordinates 0.1, "
      "0.2, ..., velocities 0.5)");
  cmd->add_option("--input", opt->inputs,
                  "Constant input values name=value,... (default 0); a value may be an expression in the parameters");
  cmd->add_option("--integrators", opt->integrators, "Integrators to compare (default rk4 dopri5 dop853 radau5)");
  cmd->add_option("--out", opt->out, "Folder for <model>_work_precision.csv, .md and .svg")->capture_default_str();
  cmd->add_option("--max-steps", opt->max_steps,
                  "Step attempts per adaptive run of the sweep; a run beyond it reports too many steps (0: the "
                  "integrators' own limits)")
      ->capture_default_str();
  cmd->add_option("--reference-steps", opt->reference_steps,
                  "The reference run's budget: more than this many steps within a hundredth of the horizon shortens "
                  "the horizon to there (stated in the report); for motions that pass near a singular configuration")
      ->capture_default_str();
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
