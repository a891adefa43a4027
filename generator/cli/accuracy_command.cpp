// `hamel accuracy MODEL [--points N] [--param n=v ...] [--sweep n=lo:hi:count ...] [--fold all|none] [--json]`:
// the forward error of every kernel in ulps, double evaluation of the kernel graph against the derivation's
// expressions in 50 digits (numeric/kernel_accuracy.hpp has the definition), at random points and over
// parameter sweeps. A table kernel -> worst ulps, mean ulps, points; --json for scripts.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "numeric/kernel_accuracy.hpp"
#include "report/progress.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace hamel::cli {

namespace {

struct AccuracyOptions {
  PipelineOptions in;
  int points = 200;
  std::uint64_t seed = 1;
  double range = 1.0, velocity_range = 1.0, floor = 1e-3;
  std::vector<std::string> sweeps, at;
  bool json = false, markdown = false, no_condition = false;
};

struct Sweep {
  std::string name;
  std::vector<double> values;
};

// "name=lo:hi:count": count values from lo to hi, geometric when both are positive, else evenly spaced.
Sweep parse_sweep(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--sweep: expected name=lo:hi:count, got '" + text + "'");
  Sweep s{text.substr(0, eq), {}};
  std::vector<double> parts;
  std::stringstream rest(text.substr(eq + 1));
  std::string item;
  while (std::getline(rest, item, ':')) {
    try {
      std::size_t used = 0;
      parts.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError("--sweep: '" + item + "' in '" + text + "' is not a number");
    }
  }
  if (parts.size() != 3 || !(parts[2] >= 1) || parts[2] != std::floor(parts[2]) || parts[2] > 1000 ||
      !std::isfinite(parts[0]) || !std::isfinite(parts[1]))
    throw InputError("--sweep: expected name=lo:hi:count with finite lo, hi and 1 <= count <= 1000, got '" + text +
                     "'");
  const int count = static_cast<int>(parts[2]);
  const bool geometric = parts[0] > 0 && parts[1] > 0;
  for (int k = 0; k < count; ++k) {
    const double f = count == 1 ? 0.0 : static_cast<double>(k) / (count - 1);
    s.values.push_back(geometric ? parts[0] * std::pow(parts[1] / parts[0], f) : parts[0] + f * (parts[1] - parts[0]));
  }
  return s;
}

std::string number(double v, int precision = 3) {
  if (std::isinf(v)) return "inf";
  std::ostringstream os;
  os << std::setprecision(precision) << v;
  return os.str();
}

void run(const AccuracyOptions& opt) {
  // Each point is a 50-digit evaluation of every kernel (milliseconds): 10^8 points ran for days, without bound
  // like --sample's rows and --dt's steps before their limits.
  constexpr int kMaxPoints = 1000000;
  if (opt.points < 1) throw InputError("--points: expected a positive number of points");
  if (opt.points > kMaxPoints)
    throw InputError("--points: " + std::to_string(opt.points) + " points, more than the limit of " +
                     std::to_string(kMaxPoints) + "; expected fewer points");
  if (!(opt.range > 0) || !std::isfinite(opt.range)) throw InputError("--range: expected a positive half-width");
  if (!(opt.velocity_range > 0) || !std::isfinite(opt.velocity_range))
    throw InputError("--velocity-range: expected a positive half-width");
  if (!(opt.floor > 0) || !(opt.floor <= 1)) throw InputError("--floor: expected a fraction in (0, 1]");
  Pipeline pipeline(opt.in);
  const Model& model = pipeline.loaded();
  const std::vector<double> base = pipeline.parameters();

  AccuracySettings settings;
  settings.points = opt.points;
  settings.seed = opt.seed;
  settings.coordinate_range = opt.range;
  settings.velocity_range = opt.velocity_range;
  settings.floor_fraction = opt.floor;
  settings.fixed = parse_assignments(opt.at, "--at");
  settings.condition = !opt.no_condition;

  // The settings: the base values, then each sweep with the other parameters at their base values.
  std::vector<std::pair<std::string, std::vector<double>>> cases{{"base", base}};
  for (const std::string& text : opt.sweeps) {
    const Sweep s = parse_sweep(text);
    std::size_t k = 0;
    while (k < model.parameters.size() && model.parameters[k].symbol.get_name() != s.name) ++k;
    if (k == model.parameters.size())
      throw InputError("--sweep: '" + s.name + "' is not a parameter of model '" + model.name + "'");
    for (double v : s.values) {
      std::vector<double> p = base;
      p[k] = v;
      cases.emplace_back(s.name + "=" + number(v, 6), p);
    }
  }

  std::vector<KernelAccuracy> total;
  nlohmann::json per_setting = nlohmann::json::array();
  for (const auto& [label, p] : cases) {
    pipeline.refold(p);
    const Derivation& derivation = pipeline.derivation();
    const KernelSet kernels = pipeline.kernels();
    std::vector<KernelAccuracy> r;
    try {
      r = measure_kernel_accuracy(model, derivation, kernels, p, settings, label);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--at: ") + e.what());
    }
    nlohmann::json js;
    js["setting"] = label;
    for (const KernelAccuracy& a : r) js["worst_ulps"][a.kernel] = a.worst_ulps;
    per_setting.push_back(js);
    merge_accuracy(total, r);
  }

  if (opt.json) {
    nlohmann::json j;
    j["model"] = model.name;
    j["fold"] = pipeline.fold();
    j["points_per_setting"] = opt.points;
    j["seed"] = opt.seed;
    j["floor_fraction"] = opt.floor;
    j["digits"] = settings.digits;
    j["settings"] = per_setting;
    j["kernels"] = nlohmann::json::array();
    for (const KernelAccuracy& a : total) {
      nlohmann::json k;
      k["kernel"] = a.kernel;
      k["outputs"] = a.outputs;
      k["points"] = a.points;
      k["skipped"] = a.skipped;
      k["measured"] = a.has_reference;
      k["worst_ulps"] = std::isinf(a.worst_ulps) ? nlohmann::json("inf") : nlohmann::json(a.worst_ulps);
      k["mean_ulps"] = a.mean_ulps();
      k["worst_evaluation_ulps"] = a.worst_evaluation_ulps;
      k["condition_at_worst"] = a.condition_at_worst;
      k["worst_ulps_over_condition"] = a.worst_excess;
      k["worst_ulps_over_condition_output"] = a.worst_excess_output;
      k["worst_output"] = a.worst_output;
      k["worst_setting"] = a.worst_setting;
      k["worst_t"] = a.worst_time;
      k["worst_state"] = a.worst_state;
      k["worst_double"] = a.worst_double;
      k["worst_reference"] = a.worst_reference;
      j["kernels"].push_back(k);
    }
    std::cout << j.dump(2) << "\n";
    return;
  }

  const auto worst_at = [&](const KernelAccuracy& a) {
    std::string at;
    if (!a.has_reference) return std::string("not measured: no reference for this kernel");
    if (a.worst_ulps > 0) at = a.worst_output + (cases.size() > 1 ? " [" + a.worst_setting + "]" : "");
    if (a.skipped) at += " (" + std::to_string(a.skipped) + " points at poles skipped)";
    return at;
  };
  if (opt.markdown) {
    std::cout << "| kernel | outputs | points | worst ulps | mean ulps | eval-only | cond | eval/cond | worst at |\n"
              << "|---|---|---|---|---|---|---|---|---|\n";
    for (const KernelAccuracy& a : total)
      std::cout << "| " << a.kernel << " | " << a.outputs << " | " << a.points << " | " << number(a.worst_ulps) << " | "
                << number(a.mean_ulps()) << " | " << number(a.worst_evaluation_ulps) << " | "
                << number(a.condition_at_worst) << " | " << number(a.worst_excess) << " | " << worst_at(a) << " |\n";
    return;
  }
  std::cout << "kernel forward error of " << model.name << " (" << opt.in.file << "), fold " << pipeline.fold() << ": "
            << opt.points << " random points x " << cases.size() << " setting" << (cases.size() > 1 ? "s" : "")
            << ", seed " << opt.seed << "\n"
            << "  worst/mean ulps: |double - ref| / ulp(max(|ref|, " << number(opt.floor)
            << " * the kernel's largest |ref|)), ref = the derivation's expressions in " << settings.digits
            << " digits\n"
            << "  eval-only: the same against the kernel graph in " << settings.digits
            << " digits (rounding of the operations alone)\n"
            << "  cond: condition number of the worst output w.r.t. state, inputs and t; eval/cond: the largest "
               "eval-only / max(1, cond) (what the form adds)\n\n";
  std::cout << std::left << std::setw(20) << "kernel" << std::right << std::setw(8) << "outputs" << std::setw(8)
            << "points" << std::setw(12) << "worst ulps" << std::setw(11) << "mean ulps" << std::setw(11) << "eval-only"
            << std::setw(10) << "cond" << std::setw(11) << "eval/cond"
            << "  worst at\n";
  for (const KernelAccuracy& a : total)
    std::cout << std::left << std::setw(20) << a.kernel << std::right << std::setw(8) << a.outputs << std::setw(8)
              << a.points << std::setw(12) << number(a.worst_ulps) << std::setw(11) << number(a.mean_ulps())
              << std::setw(11) << number(a.worst_evaluation_ulps) << std::setw(10) << number(a.condition_at_worst)
              << std::setw(11) << number(a.worst_excess) << "  " << worst_at(a) << "\n";
}

}  // namespace

Run add_accuracy_command(CLI::App& app) {
  auto opt = std::make_shared<AccuracyOptions>();
  CLI::App* cmd = app.add_subcommand(
      "accuracy", "Forward error of every emitted kernel in ulps against a 50-digit evaluation of its expressions");
  add_pipeline_options(cmd, opt->in);
  cmd->add_option("--points", opt->points, "Random points per parameter setting")->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the random points")->capture_default_str();
  cmd->add_option("--sweep", opt->sweeps,
                  "Parameter sweep name=lo:hi:count (geometric for positive lo, hi; repeatable, one parameter at a "
                  "time, the others at their --param values)");
  cmd->add_option("--range", opt->range, "Coordinates uniform in [-range, range]")->capture_default_str();
  cmd->add_option("--velocity-range", opt->velocity_range, "Independent velocities and inputs uniform in [-v, v]")
      ->capture_default_str();
  cmd->add_option("--at", opt->at, "Pinned values name=value,... of state variables, inputs or t");
  cmd->add_option("--floor", opt->floor,
                  "Floor fraction: outputs smaller than this fraction of the kernel's largest output count errors "
                  "in ulps of that size")
      ->capture_default_str();
  cmd->add_flag("--no-condition", opt->no_condition,
                "Skip the condition numbers (one more 50-digit evaluation per argument and point)");
  auto* json = cmd->add_flag("--json", opt->json, "Print JSON instead of text");
  cmd->add_flag("--markdown", opt->markdown, "Print the table as Markdown")->excludes(json);
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
