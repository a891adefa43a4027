#include "cli/pipeline.hpp"

#include "cli/options.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"
#include "report/progress.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <utility>

namespace hamel::cli {

Pipeline::Pipeline(PipelineOptions options) : options_(std::move(options)) {
  fold_ = options_.fold.empty() ? "none" : options_.fold;
  std::map<std::string, double> overrides;
  if (is_scene_file(options_.file)) {
    target_.scene = load_scene(options_.file);
    const Scene& scene = *target_.scene;
    loaded_ = load_model(scene.model_path);
    overrides = scene.parameters;
    if (options_.fold.empty()) fold_ = scene.fixed;
    target_.settings.form = scene.form;
    target_.kernels = scene_kernels(scene);
    // The emitted code is the scene's: its namespace and its stamp (scene file, hash of scene + model).
    loaded_.name = scene.name;
    loaded_.source_path = scene.path;
    std::ifstream a(scene.path, std::ios::binary), b(scene.model_path, std::ios::binary);
    std::ostringstream both;
    both << a.rdbuf() << b.rdbuf();
    loaded_.source_hash = content_hash(both.str());
  } else {
    loaded_ = load_model(options_.file);
  }
  for (const auto& [name, value] : parse_assignments(options_.params, "--param")) overrides[name] = value;
  if (!options_.form.empty()) target_.settings.form = options_.form;
  target_.dynamics.accelerations = options_.dynamics;
  refold(parameter_values(loaded_, overrides));
}

void add_pipeline_options(CLI::App* cmd, PipelineOptions& options, const PipelineFlags& flags) {
  cmd->add_option("model", options.file, flags.file_help)->required();
  cmd->add_option("--param", options.params, "Parameter value name=value (repeatable; defaults from the model)");
  cmd->add_option("--fold", options.fold,
                  std::string(fold_help()) + " (default: none for models, the scene's `fixed` for scenes)");
  if (flags.form)
    cmd->add_option("--form", options.form,
                    "Bundle models: ep (Euler-Poincare + Euler-Lagrange), lp (Lagrange-Poincare, locked velocity), "
                    "ldap (kinematic connection) or momentum (zero momentum); default lp or ldap by connection, ep "
                    "for kinematic trees");
  if (flags.dynamics) cmd->add_option("--dynamics", options.dynamics, dynamics_help());
}

void Pipeline::refold(const std::vector<double>& parameters) {
  target_.parameters = parameters;
  target_.folded.clear();
  target_.model = apply_fold(loaded_, parameters, fold_, &target_.folded);
  derivation_.reset();
}

const Derivation& Pipeline::derivation() {
  if (!derivation_) {
    if (options_.announce) {
      progress::say("deriving " + target_.model.name);
      derivation_ = derive(target_.model, target_.settings);
    } else {
      progress::Step step("deriving " + target_.model.name);
      derivation_ = derive(target_.model, target_.settings);
    }
    hamel::acceleration_route(target_.model, *derivation_, target_.dynamics.accelerations);  // --dynamics applies?
  }
  return *derivation_;
}

AccelerationRoute Pipeline::acceleration_route() {
  return hamel::acceleration_route(target_.model, derivation(), target_.dynamics.accelerations);
}

KernelSet Pipeline::kernels(const std::set<std::string>& only) {
  const Derivation& d = derivation();
  progress::Step step("building the kernels' expression graph");
  return build_kernels(target_.model, d, only, target_.dynamics);
}

Constants parameter_constants(const Target& target) {
  Constants c;
  // The loaded parameters (a folded one is a number in the model, but its name still means its value here).
  for (std::size_t k = 0; k < target.model.parameters.size() && k < target.parameters.size(); ++k) {
    const GiNaC::realsymbol& s = target.model.parameters[k].symbol;
    c.names[s.get_name()] = s;
    c.values[s] = target.parameters[k];
  }
  return c;
}

std::map<std::string, double> state_default_values(const Target& target) {
  GiNaC::exmap values;
  for (std::size_t k = 0; k < target.model.parameters.size() && k < target.parameters.size(); ++k)
    values[target.model.parameters[k].symbol] = target.parameters[k];
  std::map<std::string, double> out;
  for (const auto& [name, e] : target.model.state_defaults) {
    const GiNaC::ex v = e.subs(values).evalf();
    if (GiNaC::is_a<GiNaC::numeric>(v)) out[name] = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
  }
  return out;
}

std::vector<double> initial_state(const Target& target, const std::vector<std::string>& names, std::vector<double> x0,
                                  const std::map<std::string, double>& init) {
  const Model& model = target.model;
  // `error(name, problem)`: the error for a name that is not a state variable, saying where it was given.
  const auto apply = [&](const std::map<std::string, double>& values, const auto& error) {
    for (const auto& [name, v] : values) {
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end())
        throw error(name, quote(name) + " is not a state variable of model '" + model.name +
                              "' (coordinates and independent quasi-velocities: " + join(names) + ")");
      x0[static_cast<std::size_t>(it - names.begin())] = v;
    }
  };
  const auto at_key = [](const std::map<std::string, SourceLocation>& locations) {  // the file's key initial.<name>
    return [&locations](const std::string& name, const std::string& problem) {
      return InputError(locations.at("initial." + name), "initial." + name, problem);
    };
  };
  if (!model.initial.empty()) x0.assign(names.size(), 0.0);     // the model's state in full: what it does not name is 0
  for (const auto& [name, v] : state_default_values(target)) {  // Γ(0) = g: where such a variable starts
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) x0[static_cast<std::size_t>(it - names.begin())] = v;
  }
  apply(model.initial, at_key(model.locations));
  if (target.scene) apply(target.scene->initial, at_key(target.scene->locations));
  apply(init, [](const std::string&, const std::string& problem) { return InputError("--init: " + problem); });
  return x0;
}

}  // namespace hamel::cli
