// Scenes (docs/scenes.md): a task on a model — which results are computed, which parameters are fixed at
// generation time (folded into the code as numbers) and which stay run-time inputs, initial conditions,
// integrator and horizon. The generator emits only the kernels a scene needs, and the kernels contain only
// the terms those outputs need.
#pragma once

#include "model/input_error.hpp"

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace hamel {

struct Scene {
  std::string name;        ///< identifier; the namespace of the emitted code
  std::string path;        ///< the scene file
  std::string model_path;  ///< resolved relative to the scene file
  std::string description;
  std::string form;                  ///< bundle models: ep, lp, ldap, momentum; empty: default
  std::vector<std::string> compute;  ///< tasks, see scene_kernels()
  std::string fixed = "none";        ///< all, none, or comma-separated parameter names (as --fold)
  std::map<std::string, double> parameters, initial, inputs;
  std::string integrator;  ///< empty: the verb's default
  std::optional<double> dt, tol, t_end, sample;
  std::map<std::string, SourceLocation> locations;
};

/// The tasks a scene may list, with the kernels each needs.
const std::map<std::string, std::vector<std::string>>& scene_tasks();

/// The kernels of a scene (union over its tasks).
std::set<std::string> scene_kernels(const Scene& scene);

/// True when the YAML file at `path` is a scene (it has a top-level `scene` key).
bool is_scene_file(const std::string& path);

/// Loads a scene; errors name file:line:column and the key.
Scene load_scene(const std::string& path);

}  // namespace hamel
