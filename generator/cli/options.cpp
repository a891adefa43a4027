#include "cli/options.hpp"

#include "model/fold_parameters.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace hamel::cli {

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    out.push_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option) {
  std::map<std::string, double> out;
  for (const std::string& item : items) {
    for (const std::string& part : split_list(item)) {
      if (part.empty()) continue;
      const std::size_t eq = part.find('=');
      if (eq == std::string::npos || eq == 0) throw InputError(option + ": expected name=value, got " + quote(part));
      const std::string name = part.substr(0, eq), value = part.substr(eq + 1);
      double v = 0;
      try {
        std::size_t used = 0;
        v = std::stod(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
      } catch (const std::out_of_range&) {
        throw InputError(option + ": value of " + quote(name) + " is beyond the range of a double: " + quote(value));
      } catch (const std::exception&) {
        throw InputError(option + ": value of " + quote(name) + " is not a number: " + quote(value));
      }
      if (!std::isfinite(v))
        throw InputError(option + ": value of " + quote(name) + " is not finite: " + quote(value) +
                         "; expected a finite number");
      if (!out.emplace(name, v).second)
        throw InputError(option + ": " + quote(name) + " is given twice; give each name once");
    }
  }
  return out;
}

std::vector<double> parameter_values(const Model& model, const std::map<std::string, double>& overrides) {
  std::vector<double> values;
  for (const auto& p : model.parameters) {
    auto it = overrides.find(p.symbol.get_name());
    values.push_back(it == overrides.end() ? p.default_value : it->second);
  }
  for (const auto& [name, value] : overrides) {
    bool known = false;
    for (const auto& p : model.parameters) known = known || p.symbol.get_name() == name;
    if (!known) {
      std::string list;
      for (const auto& p : model.parameters) list += (list.empty() ? "" : ", ") + p.symbol.get_name();
      throw InputError("--param: " + quote(name) + " is not a parameter of model '" + model.name +
                       "' (parameters: " + (list.empty() ? "none" : list) + ")");
    }
  }
  return values;
}

}  // namespace hamel::cli

namespace hamel::cli {

Model apply_fold(const Model& model, const std::vector<double>& values, const std::string& spec) {
  std::map<std::string, double> fold;
  if (spec == "none" || spec.empty()) return model;
  if (spec == "all") {
    for (std::size_t k = 0; k < model.parameters.size(); ++k) fold[model.parameters[k].symbol.get_name()] = values[k];
  } else {
    for (const std::string& name : split_list(spec)) {
      if (name.empty()) continue;
      bool found = false;
      for (std::size_t k = 0; k < model.parameters.size(); ++k)
        if (model.parameters[k].symbol.get_name() == name) {
          fold[name] = values[k];
          found = true;
        }
      if (!found)
        throw InputError("--fold: '" + name + "' is not a parameter of model '" + model.name +
                         "'; expected all, none or a list of parameter names");
    }
  }
  return fold_parameters(model, fold);
}

}  // namespace hamel::cli

namespace hamel::cli {

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

Target resolve_target(const std::string& file, const std::vector<std::string>& param_args,
                      const std::string& fold_option, const std::string& form_option, const std::string& default_fold) {
  Target target;
  std::string fold = fold_option.empty() ? default_fold : fold_option;
  std::map<std::string, double> overrides;
  Model model;
  if (is_scene_file(file)) {
    target.scene = load_scene(file);
    const Scene& scene = *target.scene;
    model = load_model(scene.model_path);
    overrides = scene.parameters;
    if (fold_option.empty()) fold = scene.fixed;
    target.settings.form = scene.form;
    target.kernels = scene_kernels(scene);
    // The emitted code is the scene's: its namespace and its stamp (scene file, hash of scene + model).
    model.name = scene.name;
    model.source_path = scene.path;
    std::ifstream a(scene.path, std::ios::binary), b(scene.model_path, std::ios::binary);
    std::ostringstream both;
    both << a.rdbuf() << b.rdbuf();
    model.source_hash = content_hash(both.str());
  } else {
    model = load_model(file);
  }
  for (const auto& [name, value] : parse_assignments(param_args, "--param")) overrides[name] = value;
  target.parameters = parameter_values(model, overrides);
  if (!form_option.empty()) target.settings.form = form_option;
  target.model = apply_fold(model, target.parameters, fold);
  return target;
}

}  // namespace hamel::cli
