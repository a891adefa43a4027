#include "scene/scene.hpp"

#include "emit/kernel_registry.hpp"
#include "model/expression_parser.hpp"
#include "model/input_file.hpp"
#include "model/load_model.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace hamel {

const std::map<std::string, std::vector<std::string>>& scene_tasks() {
  static const std::map<std::string, std::vector<std::string>> tasks = {
      {"dynamics", {"kinematics", "rhs"}},
      {"jacobian", {"jacobian"}},
      {"linearization", {"rhs", "linearization"}},
      {"mass_matrix", {"mass_matrix", "forcing"}},
      {"hamel_coefficients", {"hamel_coefficients"}},
      {"monitors", {"energy", "constraint_residual"}},
      {"reconstruction", {"group_velocity"}},
      {"phase", {"group_velocity", "connection", "locked_inertia"}},
      {"locked_velocity_blocks", {"locked_inertia", "shape_inertia"}},
  };
  return tasks;
}

std::set<std::string> scene_kernels(const Scene& scene) {
  std::set<std::string> out;
  for (const std::string& task : scene.compute)
    for (const std::string& k : scene_tasks().at(task)) out.insert(kernel_spec(k).name);  // registered names only
  return out;
}

namespace {

std::string read(const std::string& path) { return read_input_file(path, "scene file"); }

SourceLocation where(const std::string& path, const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return {path, m.line >= 0 ? m.line + 1 : 0, m.column >= 0 ? m.column + 1 : 0};
}

}  // namespace

bool is_scene_file(const std::string& path) {
  std::string text;
  try {
    // Not recorded as an input here: the scene or model loader that reads it next does, with its kind.
    text = InputFile(path, "model file", kMaxInputFileBytes).read_all();
  } catch (const InputError&) {
    return false;  // the model loader reports it
  }
  try {
    const YAML::Node root = YAML::Load(text);
    return root.IsMap() && root["scene"];
  } catch (const YAML::Exception&) {
    return false;  // the model loader reports the syntax error with its location
  }
}

Scene load_scene(const std::string& path) {
  const std::string text = read(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(SourceLocation{path, e.mark.line + 1, e.mark.column + 1}, "", "YAML syntax error: " + e.msg);
  }
  Scene s;
  s.path = path;
  auto fail = [&](const YAML::Node& n, const std::string& key, const std::string& problem) {
    throw InputError(where(path, n), key, problem);
  };
  static const std::vector<std::string> keys = {"schema",     "scene", "description", "model",   "form",
                                                "compute",    "fixed", "parameters",  "initial", "inputs",
                                                "integrator", "dt",    "tol",         "t_end",   "sample"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      std::string list;
      for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
      fail(kv.first, key, "unknown scene key; expected one of: " + list);
    }
    s.locations[key] = where(path, kv.first);
  }
  auto scalar = [&](const char* key) {
    const YAML::Node n = root[key];
    if (!n.IsScalar()) fail(n, key, "expected a scalar");
    return n.Scalar();
  };
  auto number = [&](const YAML::Node& n, const std::string& key) {
    double v = 0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, key, "expected a number");
    }
    if (!std::isfinite(v)) fail(n, key, "expected a finite number");
    return v;
  };
  if (root["schema"] && scalar("schema") != "1")
    fail(root["schema"], "schema", "unsupported schema version; expected 1");
  s.name = scalar("scene");
  std::string why;
  if (!is_valid_identifier(s.name, &why)) fail(root["scene"], "scene", why + " (the name becomes a C++ namespace)");
  if (!root["model"])
    throw InputError(SourceLocation{path, 1, 1}, "model", "missing; expected the path of a model file");
  s.model_path = (std::filesystem::path(path).parent_path() / scalar("model")).lexically_normal().string();
  if (!std::filesystem::exists(s.model_path))
    fail(root["model"], "model", "no such model file: " + s.model_path + " (paths are relative to the scene file)");
  if (root["description"]) s.description = scalar("description");
  if (root["form"]) s.form = scalar("form");
  if (YAML::Node c = root["compute"]) {
    if (!c.IsSequence() || c.size() == 0) fail(c, "compute", "expected a non-empty list of tasks");
    for (std::size_t i = 0; i < c.size(); ++i) {
      const std::string task = c[i].Scalar();
      if (!scene_tasks().count(task)) {
        std::string list;
        for (const auto& [name, _] : scene_tasks()) list += (list.empty() ? "" : ", ") + name;
        fail(c[i], "compute[" + std::to_string(i) + "]", "unknown task '" + task + "'; expected one of: " + list);
      }
      s.compute.push_back(task);
    }
  } else {
    s.compute = {"dynamics", "monitors"};
  }
  if (YAML::Node f = root["fixed"]) {
    if (f.IsScalar()) {
      s.fixed = f.Scalar();
      if (s.fixed != "all" && s.fixed != "none") fail(f, "fixed", "expected all, none or a list of parameter names");
    } else if (f.IsSequence()) {
      s.fixed.clear();
      for (std::size_t i = 0; i < f.size(); ++i) s.fixed += (i ? "," : "") + f[i].Scalar();
    } else {
      fail(f, "fixed", "expected all, none or a list of parameter names");
    }
  }
  for (const char* key : {"parameters", "initial", "inputs"}) {
    if (YAML::Node m = root[key]) {
      if (!m.IsMap()) fail(m, key, "expected a map of name: number");
      auto& target = std::string(key) == "parameters" ? s.parameters
                     : std::string(key) == "initial"  ? s.initial
                                                      : s.inputs;
      for (const auto& kv : m) {
        const std::string name = std::string(key) + "." + kv.first.as<std::string>();
        target[kv.first.as<std::string>()] = number(kv.second, name);
        s.locations[name] = where(path, kv.first);
      }
    }
  }
  if (root["integrator"]) s.integrator = scalar("integrator");
  // The run's numbers get the checks of the options they stand for (--dt, --tol, --t-end, --sample), at the scene's
  // line: tol: 0 or sample: -1 were taken without a word, and dt: -1 was reported as the option's.
  const auto positive = [&](const char* key, const std::string& what) {
    const double v = number(root[key], key);
    if (!(v > 0)) fail(root[key], key, "expected " + what + ", got " + root[key].Scalar());
    return v;
  };
  if (root["dt"]) s.dt = positive("dt", "a positive step");
  if (root["tol"]) {
    s.tol = number(root["tol"], "tol");
    if (!(*s.tol >= 1e-15 && *s.tol < 1))
      fail(root["tol"], "tol", "expected a tolerance in [1e-15, 1), got " + root["tol"].Scalar());
  }
  if (root["t_end"]) s.t_end = positive("t_end", "a positive end time");
  if (root["sample"]) s.sample = positive("sample", "a positive output interval");
  return s;
}

}  // namespace hamel
