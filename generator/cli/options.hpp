// Command-line values shared by the verbs: "name=value,..." lists and their validation.
#pragma once

#include "derive/derivation.hpp"
#include "model/model.hpp"
#include "scene/scene.hpp"

#include <map>
#include <string>
#include <vector>

namespace hamel::cli {

/// The items of a comma-separated option value, empty ones included ("a,,b" has three; "" has one, empty).
std::vector<std::string> split_list(const std::string& list);

/// Parses "a=1,b=2.5" (and repeated occurrences) into a map; throws InputError naming `option`.
std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option);

/// Parameter values: defaults, overridden by --param; unknown names are input errors.
std::vector<double> parameter_values(const Model& model, const std::map<std::string, double>& overrides);

/// `model` with the parameters named by a --fold value folded in at `values` (see fold_parameters.hpp):
/// "none" (or empty) folds nothing, "all" every parameter, otherwise a comma-separated list of names.
Model apply_fold(const Model& model, const std::vector<double>& values, const std::string& spec);

/// The help text of --fold.
inline const char* fold_help() {
  return "Parameters fixed at generation time, folded in as numbers (values from --param or the defaults): all, "
         "none or name,name,...; keeps derivations of models with many parameters small";
}

/// The help text of --dynamics.
inline const char* dynamics_help() {
  return "Kinematic trees (ep form, or on a fixed base): aba (articulated-body algorithm, O(n)) or ldlt "
         "(M u' = f by an unrolled LDL^T); default aba from two bodies on a floating base and from five on a "
         "fixed base, else ldlt (docs/benchmarks.md)";
}

/// What a verb works on: a model file, or a scene file and its model.
struct Target {
  Model model;                     ///< with the fixed parameters folded; for scenes named after the scene
  std::vector<double> parameters;  ///< values in model.parameters order: defaults < scene < --param
  DeriveSettings settings;         ///< --form, else the scene's form
  std::set<std::string> kernels;   ///< the scene's kernels; empty: all
  std::optional<Scene> scene;
};

/// The values of the model's state_defaults (Γ(0) = g of a floating base under gravity) at the target's parameters.
std::map<std::string, double> state_default_values(const Target& target);

/// x(0) over the state variables `names` (coordinates, then independent quasi-velocities): the model's key `initial`
/// when it has one (the variables it does not name 0, but those with a state default), else `defaults` with the
/// state defaults over them; overridden by the scene's `initial`, then by
/// --init (`init`, parsed). A name that is not a state variable is an input error that says where it was given:
/// file:line and key for the model's and the scene's values, the option for --init.
std::vector<double> initial_state(const Target& target, const std::vector<std::string>& names,
                                  std::vector<double> defaults, const std::map<std::string, double>& init);

/// Loads `file` (model or scene). fold_option/form_option are the command-line values ("" when not
/// given); default_fold applies to models when --fold is not given (scenes use their `fixed`).
Target resolve_target(const std::string& file, const std::vector<std::string>& param_args,
                      const std::string& fold_option, const std::string& form_option, const std::string& default_fold);

}  // namespace hamel::cli
