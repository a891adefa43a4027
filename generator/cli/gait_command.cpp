// `hamel gait MODEL --target "wz=pi" [--pseudo-holonomic] [--harmonics H] ...`: a closed shape path, a truncated
// Fourier series, whose geometric phase is a given group element, at a small cost ∫|ṙ|² dt (numeric/gait.hpp,
// docs/gait.md). Prints the achieved displacement, its error, the cost and the convergence; writes the path as the
// --path argument of `hamel phase` (to confirm it), the coefficients (JSON) and the path drawn over the curvature
// of the connection (SVG).
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "derive/derivation.hpp"
#include "model/input_error.hpp"
#include "numeric/gait.hpp"
#include "numeric/phase.hpp"
#include "report/atomic_file.hpp"
#include "report/heat_map.hpp"
#include "report/pose_json.hpp"
#include "report/progress.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace hamel::cli {

namespace {

struct GaitOptions {
  PipelineOptions in;
  std::vector<std::string> target, center;
  std::string out = ".", plot, component;
  double period = 1, amplitude = 0.5, max_amplitude = 0, max_rate = 0, tolerance = 1e-12;
  int harmonics = 2, steps = 2000, iterations = 60;
  bool pseudo_holonomic = false, free_center = false, no_cost = false, json = false, no_files = false;
};

int index_of(const std::vector<std::string>& names, const std::string& name, const std::string& option) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError(option + ": '" + name + "' is not a name of the model's; expected one of " + list);
  }
  return static_cast<int>(it - names.begin());
}

std::vector<std::string> names_of(const std::vector<GiNaC::realsymbol>& symbols) {
  std::vector<std::string> out;
  for (const auto& s : symbols) out.push_back(s.get_name());
  return out;
}

std::vector<double> values_by_name(const std::vector<std::string>& items, const std::vector<std::string>& names,
                                   const std::string& option) {
  std::vector<double> out(names.size(), 0.0);
  for (const auto& [name, value] : parse_assignments(items, option, Constants{}))
    out[static_cast<std::size_t>(index_of(names, name, option))] = value;
  return out;
}

// The two shape coordinates drawn: --plot, else the two the path moves most (the first two of one coordinate).
std::pair<unsigned, unsigned> plotted(const GaitOptions& opt, const std::vector<std::string>& shape,
                                      const FourierGait& gait) {
  if (!opt.plot.empty()) {
    const std::vector<std::string> items = split_list(opt.plot);
    if (items.size() != 2)
      throw InputError("--plot: expected two shape coordinates, e.g. --plot " + shape[0] + "," +
                       (shape.size() > 1 ? shape[1] : shape[0]));
    const int i = index_of(shape, items[0], "--plot"), j = index_of(shape, items[1], "--plot");
    if (i == j) throw InputError("--plot: expected two different shape coordinates");
    return {static_cast<unsigned>(i), static_cast<unsigned>(j)};
  }
  std::vector<std::pair<double, unsigned>> spread;
  for (unsigned I = 0; I < gait.n(); ++I) {
    double s = 0;
    for (int k = 0; k < gait.harmonics; ++k) {
      const std::size_t at = I * static_cast<std::size_t>(gait.harmonics) + static_cast<std::size_t>(k);
      s += gait.cosine[at] * gait.cosine[at] + gait.sine[at] * gait.sine[at];
    }
    spread.push_back({-s, I});
  }
  std::stable_sort(spread.begin(), spread.end());
  return {std::min(spread[0].second, spread[1].second), std::max(spread[0].second, spread[1].second)};
}

std::string curvature_svg(const Model& model, const Derivation& d, const std::vector<double>& params,
                          const GaitOptions& opt, const GaitRequest& req, const GaitResult& result) {
  const std::vector<std::string> shape = names_of(model.coordinates), group = names_of(model.bundle->group_velocity);
  const auto [i, j] = plotted(opt, shape, result.gait);
  // The component drawn: --curvature-component, else the target's largest (the first for a loop to the identity).
  std::size_t alpha = 0;
  if (!opt.component.empty()) {
    alpha = static_cast<std::size_t>(index_of(group, opt.component, "--curvature-component"));
  } else {
    for (std::size_t a = 1; a < req.target.size(); ++a)
      if (std::abs(req.target[a]) > std::abs(req.target[alpha])) alpha = a;
  }
  PlotSeries path{"gait (one period, from the dot)", {}, {}, true, false, false};
  PlotSeries start{"", {}, {}, false, true, false};
  std::vector<double> r(result.gait.n()), r_dot(result.gait.n());
  for (int k = 0; k <= 400; ++k) {
    result.gait.evaluate(result.gait.period * k / 400, r.data(), r_dot.data());
    path.x.push_back(r[i]);
    path.y.push_back(r[j]);
  }
  start.x = {path.x.front()};
  start.y = {path.y.front()};
  const auto range = [](const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    const double pad = std::max(0.25 * (*hi - *lo), 0.1);
    return std::pair<double, double>{*lo - pad, *hi + pad};
  };
  const auto [xa, xb] = range(path.x);
  const auto [ya, yb] = range(path.y);
  HeatMapSpec map;
  const int cells = 48;
  for (int k = 0; k < cells; ++k) {
    map.xs.push_back(xa + (xb - xa) * k / (cells - 1));
    map.ys.push_back(ya + (yb - ya) * k / (cells - 1));
  }
  map.values =
      curvature_height(model, d, params, result.gait.center, i, j, static_cast<unsigned>(alpha), map.xs, map.ys);
  std::string others;
  for (unsigned I = 0; I < shape.size(); ++I)
    if (I != i && I != j) {
      std::ostringstream s;
      s << std::setprecision(3) << (others.empty() ? "" : ", ") << shape[I] << " = " << result.gait.center[I];
      others += s.str();
    }
  map.title = model.name + ": gait over the curvature, component " + group[alpha] +
              (others.empty() ? "" : " (projected; curvature at " + others + ")");
  map.x_label = shape[i];
  map.y_label = shape[j];
  map.value_label = std::string("curvature height F^") + group[alpha] + "_(" + shape[i] + "," + shape[j] + ") = -dA" +
                    (model.bundle->right ? " - " : " + ") + "[A_i, A_j]";
  map.curves = {path, start};
  return render_heat_map_svg(map);
}

void print_text(const nlohmann::json& j) {
  std::cout << std::setprecision(10);
  std::cout << "gait of " << j["model"].get<std::string>() << " on " << j["group"].get<std::string>() << ", "
            << j["harmonics"] << " harmonic(s), period " << j["period"].get<double>() << " s, " << j["steps"]
            << " RKMK4 steps\n";
  std::cout << "  target exp(" << j["target"].dump() << ")"
            << (j["pseudo_holonomic"].get<bool>() ? " (pseudo-holonomic loop)" : "") << "\n";
  std::cout << "  achieved g(T) = " << j["achieved"].dump() << "\n";
  std::cout << "           log g(T) = " << j["achieved_log"].dump() << "\n";
  std::cout << "  error |e| = " << j["error"].get<double>() << "  (e = " << j["residual"].dump() << ")\n";
  std::cout << "  cost integral |r_dot|^2 dt = " << j["cost"].get<double>() << " (initial path "
            << j["initial_cost"].get<double>() << ")\n";
  std::cout << "  iterations: " << j["iterations"]["target"] << " reaching the target, " << j["iterations"]["cost"]
            << " lowering the cost; " << j["phase_evaluations"] << " phase evaluations; optimality "
            << j["optimality"].get<double>() << "\n";
  std::cout << "  " << j["status"].get<std::string>() << "\n";
  std::cout << "  path r(t) (hamel phase --path): " << j["path"].get<std::string>() << "\n";
  if (j.contains("files"))
    for (const auto& [what, file] : j["files"].items()) std::cout << what << ": " << file.get<std::string>() << "\n";
  if (j.contains("confirm")) std::cout << "confirm: " << j["confirm"].get<std::string>() << "\n";
}

void run(const GaitOptions& opt) {
  Pipeline pipeline(opt.in);
  const Model& model = pipeline.model();
  if (!model.bundle)
    throw InputError(opt.in.file + ": 'hamel gait' needs a bundle model (with 'group', 'shape' and a connection)");
  const std::vector<double>& params = pipeline.parameters();
  const std::vector<std::string> shape = names_of(model.coordinates), group = names_of(model.bundle->group_velocity);
  if (shape.size() < 2)
    throw InputError(opt.in.file +
                     ": 'hamel gait' needs at least two shape coordinates (a closed path in one "
                     "dimension encloses nothing, so its phase is the identity)");

  GaitRequest req;
  req.target = values_by_name(opt.target, group, "--target");
  req.pseudo_holonomic = opt.pseudo_holonomic;
  const bool trivial = std::all_of(req.target.begin(), req.target.end(), [](double v) { return v == 0; });
  if (opt.pseudo_holonomic && !trivial)
    throw InputError("--pseudo-holonomic: the target is the identity; expected no --target with it");
  if (!opt.pseudo_holonomic && trivial)
    throw InputError("--target: expected a non-identity displacement, e.g. --target " + group[0] +
                     "=0.5 (exponential coordinates), or --pseudo-holonomic for a loop whose phase vanishes");
  FourierGait& g = req.initial;
  g.period = opt.period;
  g.harmonics = opt.harmonics;
  g.center = values_by_name(opt.center, shape, "--center");
  if (!(opt.amplitude > 0) || !std::isfinite(opt.amplitude)) throw InputError("--amplitude: expected a positive size");
  g.cosine.assign(shape.size() * static_cast<std::size_t>(std::max(opt.harmonics, 0)), 0.0);
  g.sine = g.cosine;
  // The first harmonic of coordinate I with phase πI/n: a loop that encloses area in every pair of coordinates.
  for (std::size_t I = 0; I < shape.size() && opt.harmonics > 0; ++I) {
    const double phi = M_PI * static_cast<double>(I) / static_cast<double>(shape.size());
    g.cosine[I * static_cast<std::size_t>(opt.harmonics)] = opt.amplitude * std::cos(phi);
    g.sine[I * static_cast<std::size_t>(opt.harmonics)] = -opt.amplitude * std::sin(phi);
  }
  req.free_center = opt.free_center;
  if (opt.max_amplitude != 0) req.max_amplitude = opt.max_amplitude;
  if (opt.max_rate != 0) req.max_rate = opt.max_rate;
  req.steps_per_cycle = opt.steps;
  req.max_iterations = opt.iterations;
  req.tolerance = opt.tolerance;
  req.minimise_cost = !opt.no_cost;
  check_gait_request(model, req);
  if (!opt.plot.empty()) plotted(opt, shape, g);
  if (!opt.component.empty()) index_of(group, opt.component, "--curvature-component");

  pipeline.settings().form = phase_form(model);
  const Derivation& d = pipeline.derivation();
  progress::say("designing the gait (" + std::to_string(opt.steps) + " RKMK4 steps per phase evaluation)");
  const GaitResult result = design_gait(model, d, params, req);

  nlohmann::json j;
  j["model"] = model.name;
  j["group"] = model.bundle->group;
  j["trivialization"] = model.bundle->right ? "right" : "left";
  j["pseudo_holonomic"] = opt.pseudo_holonomic;
  for (std::size_t a = 0; a < group.size(); ++a) j["target"][group[a]] = req.target[a];
  j["period"] = g.period;
  j["harmonics"] = g.harmonics;
  j["steps"] = opt.steps;
  j["achieved"] = pose_json(result.phase.end);
  for (std::size_t a = 0; a < group.size(); ++a) {
    j["achieved_log"][group[a]] = result.phase.log_end[a];
    j["residual"][group[a]] = result.phase.residual[a];
  }
  j["error"] = result.error;
  j["cost"] = result.cost;
  j["cost_definition"] = "integral over one period of |r_dot|^2 (identity metric on the shape coordinates)";
  j["initial_cost"] = result.initial_cost;
  j["iterations"] = {{"target", result.target_iterations}, {"cost", result.cost_iterations}};
  j["phase_evaluations"] = result.phase_evaluations;
  j["optimality"] = result.optimality;
  j["reached"] = result.reached;
  j["stationary"] = result.stationary;
  j["status"] = result.stop_reason;
  for (std::size_t I = 0; I < shape.size(); ++I) {
    nlohmann::json c;
    c["center"] = result.gait.center[I];
    for (int k = 0; k < g.harmonics; ++k) {
      const std::size_t at = I * static_cast<std::size_t>(g.harmonics) + static_cast<std::size_t>(k);
      c["cos"].push_back(result.gait.cosine[at]);
      c["sin"].push_back(result.gait.sine[at]);
    }
    j["coefficients"][shape[I]] = c;
  }
  j["path"] = result.gait.path_argument();
  if (!opt.no_files) {
    namespace fs = std::filesystem;
    OutputTransaction outputs;  // all files or none
    const std::string path_file = (fs::path(opt.out) / (model.name + "_gait.txt")).string();
    const std::string svg = (fs::path(opt.out) / (model.name + "_gait.svg")).string();
    const std::string json_file = (fs::path(opt.out) / (model.name + "_gait.json")).string();
    outputs.open(path_file, "--out") << result.gait.path_argument() << "\n";
    progress::say("sampling the curvature for the plot");
    outputs.open(svg, "--out") << curvature_svg(model, d, params, opt, req, result);
    j["files"] = {{"path", path_file}, {"plot", svg}, {"coefficients", json_file}};
    std::ostringstream confirm;
    confirm << "hamel phase " << opt.in.file << " --period " << std::setprecision(17) << g.period
            << " --steps-per-cycle " << opt.steps << " --path \"$(cat " << path_file << ")\"";
    j["confirm"] = confirm.str();
    outputs.open(json_file, "--out") << j.dump(2) << "\n";
    outputs.commit();
  }
  if (opt.json)
    std::cout << j.dump(2) << "\n";
  else
    print_text(j);
  if (!result.reached) {
    std::ostringstream why;
    why << "gait: the target was not reached (|e| = " << result.error << " > --tolerance " << opt.tolerance
        << "): " << result.stop_reason
        << "; try another --amplitude, more --harmonics, --free-center or a longer --max-iterations";
    throw RunFailed(why.str());
  }
}

}  // namespace

Run add_gait_command(CLI::App& app) {
  auto opt = std::make_shared<GaitOptions>();
  CLI::App* cmd = app.add_subcommand(
      "gait",
      "Gait design: a closed shape path (Fourier series) whose geometric phase is a given group motion, at a small "
      "cost; or a loop whose phase vanishes (--pseudo-holonomic). See docs/gait.md");
  add_pipeline_options(cmd, opt->in, PipelineFlags{"Bundle model or scene file (YAML, schema 1)", false, true});
  cmd->add_option("--target", opt->target,
                  "Net motion per cycle g* = exp(v), v in exponential coordinates named by the model's group velocity "
                  "(e.g. wz=pi; unnamed ones 0; values may use pi)");
  cmd->add_flag("--pseudo-holonomic", opt->pseudo_holonomic,
                "Find a loop whose phase is the identity, of the cost of the initial path");
  cmd->add_option("--harmonics", opt->harmonics, "Harmonics H of the Fourier series")->capture_default_str();
  cmd->add_option("--period", opt->period, "Period T of the path [s]")->capture_default_str();
  cmd->add_option("--center", opt->center, "Centre of the path per shape coordinate (name=value; default 0)");
  cmd->add_flag("--free-center", opt->free_center, "Optimise the centre too");
  cmd->add_option("--amplitude", opt->amplitude,
                  "Radius of the initial path (first harmonic in every shape coordinate)")
      ->capture_default_str();
  cmd->add_option("--max-amplitude", opt->max_amplitude, "Bound on |r^I(t) - centre^I| for every coordinate (0: none)");
  cmd->add_option("--max-rate", opt->max_rate, "Bound on |r_dot^I(t)| for every coordinate (0: none)");
  cmd->add_option("--steps-per-cycle", opt->steps, "RKMK4 steps per phase evaluation")->capture_default_str();
  cmd->add_option("--max-iterations", opt->iterations, "Iterations per stage (reaching the target; lowering the cost)")
      ->capture_default_str();
  cmd->add_option("--tolerance", opt->tolerance, "On |log(g*^-1 g(T))|")->capture_default_str();
  cmd->add_flag("--no-cost", opt->no_cost, "Stop when the target is reached (do not lower the cost)");
  cmd->add_option("--plot", opt->plot, "Two shape coordinates to draw (default: the two the path moves most)");
  cmd->add_option("--curvature-component", opt->component,
                  "Group velocity component of the curvature drawn (default: the target's largest)");
  cmd->add_option("--out", opt->out, "Folder for <model>_gait.txt (--path of phase), .json and .svg")
      ->capture_default_str();
  cmd->add_flag("--no-files", opt->no_files, "Write no files");
  cmd->add_flag("--json", opt->json, "Print JSON instead of text");
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
