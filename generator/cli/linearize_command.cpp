// `hamel linearize MODEL --at n=v,...`: the linearized reduced state equations x' ≈ A (x − x₀) + B (in − in₀) + c
// about a point (or a steady motion found from it), their eigenvalues, and sweeps of one quantity with the
// points where an eigenvalue crosses the imaginary axis (docs/linearization.md).
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "numeric/linearization.hpp"
#include "report/atomic_file.hpp"
#include "report/progress.hpp"
#include "report/svg_plot.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace hamel::cli {

namespace {

struct LinearizeOptions {
  std::string model;
  std::vector<std::string> at, params, inputs;
  std::string steady, hold, sweep, out = "-", plot, form, fold, dynamics;
  bool json = false;
};

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

std::string eigenvalue_text(const Eigenvalue& e) {
  if (e.im == 0) return number(e.re);
  return number(e.re) + (e.im < 0 ? " - " : " + ") + number(std::fabs(e.im)) + "i";
}

// "v=0:10:0.01" → name, from, to, step.
struct SweepSpec {
  std::string name;
  double from = 0, to = 0, step = 0;
};

SweepSpec parse_sweep(const std::string& text) {
  const std::string usage = "expected name=from:to:step, e.g. v=0:10:0.01";
  SweepSpec s;
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--sweep: " + quote(text) + ": " + usage);
  s.name = text.substr(0, eq);
  std::vector<double> parts;
  std::stringstream rest(text.substr(eq + 1));
  for (std::string item; std::getline(rest, item, ':');) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v)) throw InputError("--sweep: " + quote(text) + ": " + usage);
    parts.push_back(v);
  }
  if (parts.size() != 3) throw InputError("--sweep: " + quote(text) + ": " + usage);
  s.from = parts[0], s.to = parts[1], s.step = parts[2];
  if (!(s.step > 0) || !(s.to > s.from))
    throw InputError("--sweep: " + quote(text) + ": expected from < to and a positive step");
  if ((s.to - s.from) / s.step > 1e6)
    throw InputError("--sweep: " + quote(text) + ": more than 10^6 points; expected a larger step");
  return s;
}

std::vector<std::string> split_names(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream s(list);
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

nlohmann::json matrix_json(const std::vector<double>& m, int rows, int cols) {
  nlohmann::json j = nlohmann::json::array();
  for (int i = 0; i < rows; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int k = 0; k < cols; ++k) row.push_back(m[static_cast<std::size_t>(i * cols + k)]);
    j.push_back(row);
  }
  return j;
}

nlohmann::json eigenvalues_json(const Spectrum& s) {
  nlohmann::json j = nlohmann::json::array();
  for (const Eigenvalue& e : s.values) j.push_back({e.re, e.im});
  return j;
}

void run(const LinearizeOptions& opt) {
  Target target = resolve_target(opt.model, opt.params, opt.fold, opt.form, "none");
  target.settings.dynamics = opt.dynamics;
  const Model& model = target.model;
  std::vector<double> p = target.parameters;
  const Derivation derivation = derive(model, target.settings);
  const HamelSystem& sys = derivation.system;
  std::vector<std::string> state;
  for (const auto& q : sys.coordinates) state.push_back(q.get_name());
  for (int I : derivation.equations.independent) state.push_back(sys.velocities[static_cast<std::size_t>(I)].get_name());
  std::vector<std::string> inputs;
  for (const auto& u : model.inputs) inputs.push_back(u.get_name());
  const int nx = static_cast<int>(state.size()), ni = static_cast<int>(inputs.size());

  const auto state_index = [&](const std::string& name, const std::string& option) {
    for (int k = 0; k < nx; ++k)
      if (state[static_cast<std::size_t>(k)] == name) return k;
    throw InputError(option + ": " + quote(name) + " is not a state variable of model '" + model.name +
                     "' (coordinates and independent quasi-velocities: " + join(state) + ")");
  };
  std::vector<double> x(static_cast<std::size_t>(nx), 0.0), in(static_cast<std::size_t>(ni), 0.0);
  std::map<std::string, double> initial = target.scene ? target.scene->initial : std::map<std::string, double>{};
  for (const auto& [k, v] : parse_assignments(opt.at, "--at")) initial[k] = v;
  for (const auto& [name, v] : initial) x[static_cast<std::size_t>(state_index(name, "--at"))] = v;
  std::map<std::string, double> input_values = target.scene ? target.scene->inputs : std::map<std::string, double>{};
  for (const auto& [k, v] : parse_assignments(opt.inputs, "--input")) input_values[k] = v;
  for (const auto& [name, v] : input_values) {
    const auto it = std::find(inputs.begin(), inputs.end(), name);
    if (it == inputs.end())
      throw InputError("--input: " + quote(name) + " is not an input of model '" + model.name + "'" +
                       (inputs.empty() ? " (it has none)" : " (inputs: " + join(inputs) + ")"));
    in[static_cast<std::size_t>(it - inputs.begin())] = v;
  }
  std::optional<SweepSpec> sweep_spec;
  int swept_state = -1, swept_param = -1;
  if (!opt.sweep.empty()) {
    sweep_spec = parse_sweep(opt.sweep);
    for (int k = 0; k < nx; ++k)
      if (state[static_cast<std::size_t>(k)] == sweep_spec->name) swept_state = k;
    for (std::size_t k = 0; k < model.parameters.size(); ++k)
      if (model.parameters[k].symbol.get_name() == sweep_spec->name) swept_param = static_cast<int>(k);
    if (swept_state < 0 && swept_param < 0) {
      std::vector<std::string> names = state;
      for (const Parameter& par : model.parameters) names.push_back(par.symbol.get_name());
      throw InputError("--sweep: " + quote(sweep_spec->name) + " is neither a state variable nor a parameter of model '" +
                       model.name + "'" +
                       " (expected one of: " + join(names) + "; a parameter folded by --fold cannot be swept)");
    }
  }
  std::vector<int> moving, free;
  const bool steady = !opt.steady.empty();
  if (steady) {
    for (const std::string& name : split_names(opt.steady)) {
      const int k = state_index(name, "--steady");
      if (k >= static_cast<int>(sys.coordinates.size()))
        throw InputError("--steady: " + quote(name) + " is a quasi-velocity; expected the coordinates that advance at a "
                         "constant rate in the steady motion (cyclic coordinates, e.g. a wheel angle or the heading)");
      moving.push_back(k);
    }
    std::vector<int> held;
    for (const std::string& name : split_names(opt.hold)) held.push_back(state_index(name, "--hold"));
    if (swept_state >= 0) held.push_back(swept_state);
    for (int k = 0; k < nx; ++k)
      if (std::find(moving.begin(), moving.end(), k) == moving.end() &&
          std::find(held.begin(), held.end(), k) == held.end())
        free.push_back(k);
  } else if (!opt.hold.empty()) {
    throw InputError("--hold: goes with --steady (the components Newton's method keeps fixed)");
  }

  const KernelSet kernels = [&] {
    progress::Step step("building the rhs program and its forward-mode derivatives (A, B)");
    return build_kernels(model, derivation, {"rhs", "linearization"});
  }();
  const Linearizer linearizer(kernels, nx, ni);
  const auto linearize_at = [&](const std::vector<double>& point) { return linearizer.at(0.0, point, p, in); };
  SteadyResult found;
  const auto steady_point = [&](std::vector<double> start) {
    if (!steady) return start;
    try {
      found = find_steady_motion(linearize_at, start, free, moving);
    } catch (const std::runtime_error& e) {
      throw RunFailed(e.what());
    }
    return found.x;
  };

  if (sweep_spec) {
    std::vector<double> last = x;
    const auto spectrum_at = [&](double v) {
      std::vector<double> point = last;
      if (swept_state >= 0) point[static_cast<std::size_t>(swept_state)] = v;
      if (swept_param >= 0) p[static_cast<std::size_t>(swept_param)] = v;
      point = steady_point(point);
      if (steady) last = point;
      return spectrum(linearize_at(point));
    };
    Sweep result;
    {
      progress::Step step("sweeping " + sweep_spec->name + " from " + number(sweep_spec->from) + " to " +
                          number(sweep_spec->to));
      result = sweep(spectrum_at, sweep_spec->from, sweep_spec->to, sweep_spec->step);
    }
    OutputFile out(opt.out, "--out");
    if (opt.json) {
      nlohmann::json j;
      j["model"] = model.name;
      j["state"] = state;
      j["sweep"] = sweep_spec->name;
      j["values"] = result.values;
      nlohmann::json all = nlohmann::json::array();
      for (const Spectrum& s : result.spectra) all.push_back(eigenvalues_json(s));
      j["eigenvalues"] = all;
      nlohmann::json crossings = nlohmann::json::array();
      for (const Crossing& c : result.crossings)
        crossings.push_back({{"value", c.value},
                             {"kind", c.complex ? "complex pair" : "real"},
                             {"frequency", c.frequency},
                             {"direction", c.to_unstable ? "to unstable" : "to stable"}});
      j["crossings"] = crossings;
      out.stream() << j.dump(2) << "\n";
    } else {
      std::ostream& os = out.stream();
      os << sweep_spec->name;
      for (int k = 0; k < nx; ++k) os << ",re" << k + 1 << ",im" << k + 1;
      os << "\n";
      for (std::size_t i = 0; i < result.values.size(); ++i) {
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.17g", result.values[i]);
        os << buf;
        for (const Eigenvalue& e : result.spectra[i].values) {
          std::snprintf(buf, sizeof buf, ",%.17g", e.re);
          os << buf;
          std::snprintf(buf, sizeof buf, ",%.17g", e.im);
          os << buf;
        }
        os << "\n";
      }
    }
    out.commit();
    std::cerr << "hamel: swept " << sweep_spec->name << " over " << result.values.size() << " points"
              << (result.crossings.empty() ? "; no eigenvalue crosses the imaginary axis" : "; stability boundaries:")
              << "\n";
    for (const Crossing& c : result.crossings)
      std::cerr << "  " << sweep_spec->name << " = " << number(c.value) << ": "
                << (c.complex ? "a complex pair (frequency " + number(c.frequency) + " rad/s)" : std::string("a real eigenvalue"))
                << " crosses " << (c.to_unstable ? "into the right half-plane (loss of stability)"
                                                 : "into the left half-plane (gain of stability)")
                << "\n";
    if (!opt.plot.empty()) {
      PlotSpec spec;
      spec.title = model.name + ": eigenvalues against " + sweep_spec->name;
      spec.x_label = sweep_spec->name;
      spec.y_label = "eigenvalues [1/s]";
      // All real parts as one series of points, the positive imaginary parts as another (as in Meijaard et
      // al.'s Fig. 3); exact zeros of decoupled components are left out.
      PlotSeries re{"real parts", {}, {}, false, true, false}, im{"imaginary parts (> 0)", {}, {}, false, true, false};
      for (std::size_t i = 0; i < result.values.size(); ++i)
        for (const Eigenvalue& e : result.spectra[i].values) {
          if (e.re == 0 && e.im == 0) continue;
          re.x.push_back(result.values[i]);
          re.y.push_back(e.re);
          if (e.im > 0) im.x.push_back(result.values[i]), im.y.push_back(e.im);
        }
      spec.series = {re, im};
      write_file_atomically(opt.plot, render_svg(spec), "--plot");
      std::cerr << "hamel: wrote " << opt.plot << "\n";
    }
    return;
  }

  x = steady_point(x);
  const LinearSystem s = linearize_at(x);
  const Spectrum spec = spectrum(s);
  std::vector<std::string> decoupled;
  for (int k : spec.decoupled) decoupled.push_back(state[static_cast<std::size_t>(k)]);
  OutputFile out(opt.out, "--out");
  std::ostream& os = out.stream();
  if (opt.json) {
    nlohmann::json j;
    j["model"] = model.name;
    j["state"] = state;
    j["inputs"] = inputs;
    nlohmann::json point = nlohmann::json::object();
    for (int k = 0; k < nx; ++k) point[state[static_cast<std::size_t>(k)]] = x[static_cast<std::size_t>(k)];
    j["point"] = point;
    j["A"] = matrix_json(s.A, nx, nx);
    j["B"] = matrix_json(s.B, nx, ni);
    j["residual"] = s.residual;
    j["eigenvalues"] = eigenvalues_json(spec);
    j["decoupled"] = decoupled;
    if (steady) {
      std::vector<std::string> moving_names;
      for (int k : moving) moving_names.push_back(state[static_cast<std::size_t>(k)]);
      j["steady"] = {{"moving", moving_names}, {"iterations", found.iterations}, {"residual", found.residual}};
    }
    os << j.dump(2) << "\n";
  } else {
    os << "linearization of " << model.name << " (" << model.source_path << "): x' ~ A (x - x0) + B (in - in0) + c\n";
    os << (steady ? "steady motion (Newton, " + std::to_string(found.iterations) + " steps, max |x'| = " +
                        number(found.residual) + ") x0:\n"
                  : "point x0:\n");
    for (int k = 0; k < nx; ++k) os << "  " << state[static_cast<std::size_t>(k)] << " = " << number(x[static_cast<std::size_t>(k)]) << "\n";
    const auto print_matrix = [&](const std::string& title, const std::vector<double>& m, int cols,
                                  const std::vector<std::string>& col_names) {
      os << "\n" << title << " (rows: x' of " << join(state) << "; columns: " << join(col_names) << "):\n";
      for (int i = 0; i < nx; ++i) {
        os << "  " << state[static_cast<std::size_t>(i)] << "':";
        for (int k = 0; k < cols; ++k) os << " " << number(m[static_cast<std::size_t>(i * cols + k)]);
        os << "\n";
      }
    };
    print_matrix("A = d x'/d x", s.A, nx, state);
    if (ni > 0) print_matrix("B = d x'/d in", s.B, ni, inputs);
    os << "\nc = x' at x0:";
    for (double v : s.residual) os << " " << number(v);
    os << "\n\neigenvalues of A, by real part:\n";
    for (const Eigenvalue& e : spec.values) os << "  " << eigenvalue_text(e) << "\n";
    if (!decoupled.empty())
      os << "of which " << decoupled.size() << " exactly zero: at this point no other rate depends on "
         << join(decoupled) << " (cyclic coordinates of a symmetry, or quantities conserved to first order)\n";
  }
  out.commit();
}

}  // namespace

Run add_linearize_command(CLI::App& app) {
  auto opt = std::make_shared<LinearizeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "linearize", "Linearize the state equations about a point or a steady motion: A, B, eigenvalues, sweeps");
  cmd->add_option("model", opt->model, "Model or scene file (YAML, schema 1)")->required();
  cmd->add_option("--at", opt->at,
                  "The point: values name=value,... of coordinates and independent quasi-velocities (default 0)");
  cmd->add_option("--param", opt->params, "Parameter value name=value (repeatable)");
  cmd->add_option("--input", opt->inputs, "Input values name=value,... at the point (default 0)");
  cmd->add_flag("--json", opt->json, "JSON instead of text");
  cmd->add_option("--steady", opt->steady,
                  "Find a steady motion near the point first: the coordinates (comma-separated) that advance at a "
                  "constant rate; every other component of x' is driven to zero by Newton's method");
  cmd->add_option("--hold", opt->hold, "With --steady: state components Newton's method keeps at their --at values");
  cmd->add_option("--sweep", opt->sweep,
                  "name=from:to:step: eigenvalues against a parameter or state variable (CSV, or JSON with --json), "
                  "with the values where an eigenvalue crosses the imaginary axis on stderr");
  cmd->add_option("--out", opt->out, "Output file, or - for standard output")->capture_default_str();
  cmd->add_option("--plot", opt->plot, "With --sweep: an SVG plot of the eigenvalues against the swept quantity");
  cmd->add_option("--form", opt->form, "Bundle models: ep, lp, ldap or momentum (see hamel derive --help)");
  cmd->add_option("--dynamics", opt->dynamics, dynamics_help());
  cmd->add_option("--fold", opt->fold, std::string(fold_help()) + " (default: none)");
  return [opt] {
    if (!opt->plot.empty() && opt->sweep.empty()) throw InputError("--plot: goes with --sweep");
    run(*opt);
  };
}

}  // namespace hamel::cli
