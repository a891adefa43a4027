// `hamel linearize MODEL --at n=v,...`: the linearized reduced state equations x' ≈ A (x − x₀) + B (in − in₀) + c
// about a point (or a steady motion found from it), their eigenvalues, and sweeps of one quantity with the
// points where an eigenvalue crosses the imaginary axis (docs/linearization.md).
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
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
#include <set>
#include <sstream>

namespace hamel::cli {

namespace {

struct LinearizeOptions {
  PipelineOptions in;
  std::vector<std::string> at, inputs;
  std::string steady, hold, sweep, out = "-", plot;
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
  for (const std::string& item : split_list(list))
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

// The names of the state (coordinates, then independent quasi-velocities) and of the inputs, in kernel order.
struct Names {
  std::vector<std::string> state, inputs;
  std::string model;
  int nx() const { return static_cast<int>(state.size()); }
  int ni() const { return static_cast<int>(inputs.size()); }
  int state_index(const std::string& name, const std::string& option) const {
    for (int k = 0; k < nx(); ++k)
      if (state[static_cast<std::size_t>(k)] == name) return k;
    throw InputError(option + ": " + quote(name) + " is not a state variable of model '" + model +
                     "' (coordinates and independent quasi-velocities: " + join(state) + ")");
  }
};

// What the command line says of the point, read before the derivation (a wrong value fails at once): --at values and
// the --input values, numbers or expressions in the parameters (as simulate's --input takes them), kept as
// expressions so that a --sweep of a parameter moves them with it.
struct PointOptions {
  std::map<std::string, double> at;
  std::map<std::string, GiNaC::ex> inputs;
};

PointOptions point_options(const LinearizeOptions& opt, const Target& target) {
  const Constants constants = parameter_constants(target);
  PointOptions out{parse_assignments(opt.at, "--at", constants),
                   parse_expression_assignments(opt.inputs, "--input", constants)};
  for (const auto& [name, e] : out.inputs) {
    target.model.input_index(name, "--input");
    constant_value(e, constants.values, "--input", name);  // finite, real
  }
  return out;
}

// in₀ at the parameter values `p`: zero but for the scene's inputs and --input over them.
std::vector<double> point_inputs(const PointOptions& point, const Target& target, const std::vector<double>& p) {
  const Model& model = target.model;
  std::vector<double> in(model.inputs.size(), 0.0);
  if (target.scene)
    for (const auto& [name, v] : target.scene->inputs) in[model.input_index(name, "--input")] = v;
  GiNaC::exmap values;
  for (std::size_t k = 0; k < model.parameters.size() && k < p.size(); ++k) values[model.parameters[k].symbol] = p[k];
  for (const auto& [name, e] : point.inputs)
    in[model.input_index(name, "--input")] = constant_value(e, values, "--input", name);
  return in;
}

// The point x₀: zero but for the model's state defaults (Γ = g of a floating base under gravity), the scene's values
// and --at over them. A model with position constraints g(q) = 0 (holonomic, closed loops) starts from its `initial`
// instead of zero, which is in general not on the constraints (where G_s, and with it the equations, may even be
// singular).
std::vector<double> point_state(const PointOptions& point, const Target& target, const Names& names) {
  std::vector<double> x(names.state.size(), 0.0);
  std::map<std::string, double> initial = state_default_values(target);
  if (!target.model.holonomic.empty())
    for (const auto& [k, v] : target.model.initial) initial[k] = v;
  if (target.scene)
    for (const auto& [k, v] : target.scene->initial) initial[k] = v;
  for (const auto& [k, v] : point.at) initial[k] = v;
  for (const auto& [name, v] : initial) x[static_cast<std::size_t>(names.state_index(name, "--at"))] = v;
  return x;
}

// --sweep's quantity: a state component or a parameter (index ≥ 0 in one of them).
struct SweepTarget {
  SweepSpec spec;
  int state = -1, parameter = -1;
};

SweepTarget sweep_target(const std::string& text, const Names& names, const Model& model,
                         const std::set<std::string>& folded) {
  SweepTarget s{parse_sweep(text)};
  if (folded.count(s.spec.name))
    throw InputError("--sweep: " + quote(s.spec.name) +
                     " is folded into the equations as a number (--fold, or the scene's fixed), so every point of "
                     "the sweep would have the same eigenvalues; expected a parameter that is not folded (leave it "
                     "out of --fold, e.g. --fold none)");
  for (int k = 0; k < names.nx(); ++k)
    if (names.state[static_cast<std::size_t>(k)] == s.spec.name) s.state = k;
  for (std::size_t k = 0; k < model.parameters.size(); ++k)
    if (model.parameters[k].symbol.get_name() == s.spec.name) s.parameter = static_cast<int>(k);
  if (s.state < 0 && s.parameter < 0) {
    std::vector<std::string> all = names.state;
    for (const Parameter& par : model.parameters) all.push_back(par.symbol.get_name());
    throw InputError("--sweep: " + quote(s.spec.name) + " is neither a state variable nor a parameter of model '" +
                     model.name + "'" + " (expected one of: " + join(all) +
                     "; a parameter folded by --fold cannot be swept)");
  }
  return s;
}

// --steady and --hold: the coordinates that advance at a constant rate, and the components Newton's method may
// change (all but those and the held ones, the swept state among them).
struct SteadyComponents {
  std::vector<int> moving, free;
};

SteadyComponents steady_components(const LinearizeOptions& opt, const Names& names, std::size_t n_coordinates,
                                   int swept_state) {
  SteadyComponents c;
  if (opt.steady.empty()) {
    if (!opt.hold.empty()) throw InputError("--hold: goes with --steady (the components Newton's method keeps fixed)");
    return c;
  }
  for (const std::string& name : split_names(opt.steady)) {
    const int k = names.state_index(name, "--steady");
    if (k >= static_cast<int>(n_coordinates))
      throw InputError("--steady: " + quote(name) +
                       " is a quasi-velocity; expected the coordinates that advance at a "
                       "constant rate in the steady motion (cyclic coordinates, e.g. a wheel angle or the heading)");
    c.moving.push_back(k);
  }
  std::vector<int> held;
  for (const std::string& name : split_names(opt.hold)) held.push_back(names.state_index(name, "--hold"));
  if (swept_state >= 0) held.push_back(swept_state);
  for (int k = 0; k < names.nx(); ++k)
    if (std::find(c.moving.begin(), c.moving.end(), k) == c.moving.end() &&
        std::find(held.begin(), held.end(), k) == held.end())
      c.free.push_back(k);
  if (c.free.empty())
    throw InputError("--hold: with --steady " + quote(opt.steady) +
                     " it holds every other state component, so Newton's method has nothing to solve for; expected "
                     "at least one component that is neither advancing (--steady) nor held (--hold" +
                     (swept_state >= 0 ? std::string(", or swept") : std::string()) + ")");
  return c;
}

// A sweep's spectra as JSON or CSV (one row per value: re1,im1,re2,im2,...).
void write_sweep(std::ostream& os, bool json, const Names& names, const std::string& swept, const Sweep& result) {
  if (json) {
    nlohmann::json j;
    j["model"] = names.model;
    j["state"] = names.state;
    j["sweep"] = swept;
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
    os << j.dump(2) << "\n";
    return;
  }
  os << swept;
  for (int k = 0; k < names.nx(); ++k) os << ",re" << k + 1 << ",im" << k + 1;
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

// The sweep's stability boundaries on stderr.
void print_crossings(const std::string& swept, const Sweep& result) {
  std::cerr << "hamel: swept " << swept << " over " << result.values.size() << " points"
            << (result.crossings.empty() ? "; no eigenvalue crosses the imaginary axis" : "; stability boundaries:")
            << "\n";
  for (const Crossing& c : result.crossings)
    std::cerr << "  " << swept << " = " << number(c.value) << ": "
              << (c.complex ? "a complex pair (frequency " + number(c.frequency) + " rad/s)"
                            : std::string("a real eigenvalue"))
              << " crosses "
              << (c.to_unstable ? "into the right half-plane (loss of stability)"
                                : "into the left half-plane (gain of stability)")
              << "\n";
}

// --plot: the eigenvalues against the swept quantity as SVG.
void plot_sweep(std::ostream& os, const std::string& model_name, const std::string& swept, const Sweep& result) {
  PlotSpec spec;
  spec.title = model_name + ": eigenvalues against " + swept;
  spec.x_label = swept;
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
  os << render_svg(spec);
}

// One linearization as JSON or text: the point, A, B, c and A's eigenvalues.
void write_linearization(std::ostream& os, bool json, const Model& model, const Names& names,
                         const std::vector<double>& x, const std::vector<double>& in, const LinearSystem& s,
                         const std::vector<int>* moving, const SteadyResult& found) {
  const int nx = names.nx(), ni = names.ni();
  const std::vector<std::string>& state = names.state;
  const Spectrum spec = spectrum(s);
  std::vector<std::string> decoupled;
  for (int k : spec.decoupled) decoupled.push_back(state[static_cast<std::size_t>(k)]);
  if (json) {
    nlohmann::json j;
    j["model"] = model.name;
    j["state"] = state;
    j["inputs"] = names.inputs;
    nlohmann::json point = nlohmann::json::object();
    for (int k = 0; k < nx; ++k) point[state[static_cast<std::size_t>(k)]] = x[static_cast<std::size_t>(k)];
    j["point"] = point;
    nlohmann::json inputs = nlohmann::json::object();  // in₀, the inputs B is taken at
    for (int k = 0; k < ni; ++k) inputs[names.inputs[static_cast<std::size_t>(k)]] = in[static_cast<std::size_t>(k)];
    j["input_values"] = inputs;
    j["A"] = matrix_json(s.A, nx, nx);
    j["B"] = matrix_json(s.B, nx, ni);
    j["residual"] = s.residual;
    j["eigenvalues"] = eigenvalues_json(spec);
    j["decoupled"] = decoupled;
    if (moving) {
      std::vector<std::string> moving_names;
      for (int k : *moving) moving_names.push_back(state[static_cast<std::size_t>(k)]);
      j["steady"] = {{"moving", moving_names}, {"iterations", found.iterations}, {"residual", found.residual}};
    }
    os << j.dump(2) << "\n";
    return;
  }
  os << "linearization of " << model.name << " (" << model.source_path << "): x' ~ A (x - x0) + B (in - in0) + c\n";
  os << (moving ? "steady motion (Newton, " + std::to_string(found.iterations) +
                      " steps, max |x'| = " + number(found.residual) + ") x0:\n"
                : "point x0:\n");
  for (int k = 0; k < nx; ++k)
    os << "  " << state[static_cast<std::size_t>(k)] << " = " << number(x[static_cast<std::size_t>(k)]) << "\n";
  if (ni > 0) os << "inputs in0:\n";
  for (int k = 0; k < ni; ++k)
    os << "  " << names.inputs[static_cast<std::size_t>(k)] << " = " << number(in[static_cast<std::size_t>(k)]) << "\n";
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
  if (ni > 0) print_matrix("B = d x'/d in", s.B, ni, names.inputs);
  os << "\nc = x' at x0:";
  for (double v : s.residual) os << " " << number(v);
  os << "\n\neigenvalues of A, by real part:\n";
  for (const Eigenvalue& e : spec.values) os << "  " << eigenvalue_text(e) << "\n";
  if (!decoupled.empty())
    os << "of which " << decoupled.size() << " exactly zero: at this point no other rate depends on " << join(decoupled)
       << " (cyclic coordinates of a symmetry, or quantities conserved to first order)\n";
}

void run(const LinearizeOptions& opt) {
  Pipeline pipeline(opt.in);
  const Target& target = pipeline.target();
  const Model& model = target.model;
  std::vector<double> p = target.parameters;
  const PointOptions point_spec = point_options(opt, target);
  const Derivation& derivation = pipeline.derivation();
  const HamelSystem& sys = derivation.system;
  Names names;
  names.model = model.name;
  for (const auto& q : sys.coordinates) names.state.push_back(q.get_name());
  for (int I : derivation.equations.independent)
    names.state.push_back(sys.velocities[static_cast<std::size_t>(I)].get_name());
  for (const auto& u : model.inputs) names.inputs.push_back(u.get_name());
  const int nx = names.nx(), ni = names.ni();

  std::vector<double> x = point_state(point_spec, target, names), in = point_inputs(point_spec, target, p);
  const std::optional<SweepTarget> swept =
      opt.sweep.empty() ? std::nullopt
                        : std::optional<SweepTarget>(sweep_target(opt.sweep, names, model, target.folded));
  const bool steady = !opt.steady.empty();
  const SteadyComponents components = steady_components(opt, names, sys.coordinates.size(), swept ? swept->state : -1);

  const KernelSet kernels = pipeline.kernels({"rhs", "linearization"});
  const Linearizer linearizer(kernels, nx, ni);
  const auto linearize_at = [&](const std::vector<double>& point) { return linearizer.at(0.0, point, p, in); };
  SteadyResult found;
  const auto steady_point = [&](std::vector<double> start) {
    if (!steady) return start;
    try {
      found = find_steady_motion(linearize_at, start, components.free, components.moving);
    } catch (const std::runtime_error& e) {
      throw RunFailed(e.what());
    }
    return found.x;
  };

  if (swept) {
    const SweepSpec& spec = swept->spec;
    std::vector<double> last = x;
    const auto spectrum_at = [&](double v) {
      std::vector<double> point = last;
      if (swept->state >= 0) point[static_cast<std::size_t>(swept->state)] = v;
      if (swept->parameter >= 0) {
        p[static_cast<std::size_t>(swept->parameter)] = v;
        in = point_inputs(point_spec, target, p);  // --input "f=m*g" follows a swept m
      }
      point = steady_point(point);
      if (steady) last = point;
      return spectrum(linearize_at(point));
    };
    Sweep result;
    {
      progress::Step step("sweeping " + spec.name + " from " + number(spec.from) + " to " + number(spec.to));
      result = sweep(spectrum_at, spec.from, spec.to, spec.step);
    }
    // The table and the plot are committed together: a plot that cannot be written keeps the old table too.
    OutputTransaction outputs;
    write_sweep(outputs.open(opt.out, "--out"), opt.json, names, spec.name, result);
    if (!opt.plot.empty()) plot_sweep(outputs.open(opt.plot, "--plot"), model.name, spec.name, result);
    outputs.commit();
    print_crossings(spec.name, result);
    if (!opt.plot.empty()) std::cerr << "hamel: wrote " << printable(opt.plot) << "\n";
    return;
  }

  x = steady_point(x);
  const LinearSystem s = linearize_at(x);
  OutputTransaction outputs;
  write_linearization(outputs.open(opt.out, "--out"), opt.json, model, names, x, in, s,
                      steady ? &components.moving : nullptr, found);
  outputs.commit();
}

}  // namespace

Run add_linearize_command(CLI::App& app) {
  auto opt = std::make_shared<LinearizeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "linearize", "Linearize the state equations about a point or a steady motion: A, B, eigenvalues, sweeps");
  add_pipeline_options(cmd, opt->in);
  cmd->add_option("--at", opt->at,
                  "The point: values name=value,... of coordinates and independent quasi-velocities (default 0)");
  cmd->add_option("--input", opt->inputs,
                  "Input values name=value,... at the point (default 0); a value may be an expression in the "
                  "parameters, e.g. f=(mq+mL)*g");
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
  return [opt] {
    if (!opt->plot.empty() && opt->sweep.empty()) throw InputError("--plot: goes with --sweep");
    try {
      run(*opt);
    } catch (const EigenvalueFailure& e) {
      throw RunFailed(e.what());  // a failed run (exit 1) that says why, not an internal error
    }
  };
}

}  // namespace hamel::cli
