// The one pipeline every verb runs: load (a model file, or a scene and its model) → fold the fixed parameters →
// derive → build the kernels. A verb states what it works on (PipelineOptions, the command line's model, --param,
// --fold, --form and --dynamics, with one set of defaults for all verbs) and asks for what it needs: the folded
// model and the parameter values (target), the derivation (derived once, on first use, saying so on stderr) or
// the kernels (a selection of the registry). What the verbs then do with them (print, emit, integrate,
// linearize, measure) is theirs.
//
// The defaults, the same for every verb:
//   --fold      none for a model file; a scene's `fixed` for a scene;
//   --form      the scene's form, else the model's (bundle_forms: lp or ldap by connection, ep for trees);
//   --dynamics  tree_dynamics_default (emit/equations_of_motion.hpp): aba from 2 bodies on a floating base, 5 on a
//               fixed one; checked against the model when it is derived, whatever the verb.
#pragma once

#include "cli/options.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"
#include "scene/scene.hpp"

#include <CLI/CLI.hpp>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace hamel::cli {

/// What a verb works on, as its command line gives it ("" for an option not given).
struct PipelineOptions {
  std::string file;                 ///< a model file, or a scene file (schema 1 scenes; see scene/scene.hpp)
  std::vector<std::string> params;  ///< --param name=value,... (repeatable)
  std::string fold;                 ///< --fold: all, none or names; "" the default above
  std::string form;                 ///< --form; "" the default above
  std::string dynamics;             ///< --dynamics; "" the default above
  /// Whether the derivation says "deriving <name>" at once (verbs whose result goes to a file or folder), or only
  /// when it has taken a second (derive and simulate, whose standard output may be the result itself).
  bool announce = true;
};

/// The loaded and folded model with its parameter values: what a verb works on.
struct Target {
  Model model;                     ///< with the fixed parameters folded; for scenes named after the scene
  std::vector<double> parameters;  ///< values in model.parameters order: defaults < scene < --param
  DeriveSettings settings;         ///< --form, else the scene's form
  DynamicsOptions dynamics;        ///< --dynamics (emit adds --jacobian-solve)
  std::set<std::string> kernels;   ///< the scene's kernels; empty: all
  std::optional<Scene> scene;
  std::set<std::string> folded;  ///< the parameters folded in as numbers (--fold, or the scene's `fixed`)
};

class Pipeline {
 public:
  /// Loads and folds; throws InputError for a file that does not load or options that do not fit it.
  explicit Pipeline(PipelineOptions options);

  const Target& target() const { return target_; }
  const Model& model() const { return target_.model; }
  const std::vector<double>& parameters() const { return target_.parameters; }
  /// The model as loaded, before folding (parameter sweeps fold it again, refold).
  const Model& loaded() const { return loaded_; }
  /// The --fold in effect: the option, else the scene's `fixed`, else none.
  const std::string& fold() const { return fold_; }
  /// The derivation's settings, which a verb may still change before derivation() (phase chooses the form).
  DeriveSettings& settings() { return target_.settings; }

  /// How u̇ and the Jacobian are computed (--dynamics; a verb may set the column solve before kernels()).
  DynamicsOptions& dynamics() { return target_.dynamics; }

  /// The derivation, derived on first use ("hamel: deriving <name> ..." on stderr unless --quiet; see announce),
  /// with --dynamics checked against it (an InputError when it does not apply).
  const Derivation& derivation();
  /// How rhs computes u̇ for this derivation under --dynamics (emit/equations_of_motion.hpp).
  AccelerationRoute acceleration_route();
  /// The kernels `only` names (all the registry builds by default when empty), from derivation(); "building the
  /// kernels' expression graph" announces itself when it takes a second.
  KernelSet kernels(const std::set<std::string>& only = {});

  /// The same model at other parameter values (model.parameters order): folded again by --fold, the derivation
  /// forgotten.
  void refold(const std::vector<double>& parameters);

 private:
  PipelineOptions options_;
  Model loaded_;
  std::string fold_;  ///< the --fold in effect (the option, the scene's `fixed` or none)
  Target target_;
  std::optional<Derivation> derivation_;
};

/// Which of the pipeline's options a verb offers: all offer the model file, --param and --fold.
struct PipelineFlags {
  const char* file_help = "Model or scene file (YAML, schema 1)";
  bool form = true;      ///< --form
  bool dynamics = true;  ///< --dynamics
};

/// Registers the pipeline's options on `cmd` (the positional model file, --param, --fold, and as `flags` say --form
/// and --dynamics), with the same text and defaults for every verb.
void add_pipeline_options(CLI::App* cmd, PipelineOptions& options, const PipelineFlags& flags = {});

/// The model's parameters at the target's values, as names command-line values may use (Constants, cli/options.hpp).
Constants parameter_constants(const Target& target);

/// The values of the model's state_defaults (Γ(0) = g of a floating base under gravity) at the target's parameters.
std::map<std::string, double> state_default_values(const Target& target);

/// x(0) over the state variables `names` (coordinates, then independent quasi-velocities): the model's key `initial`
/// when it has one (the variables it does not name 0, but those with a state default), else `defaults` with the
/// state defaults over them; overridden by the scene's `initial`, then by
/// --init (`init`, parsed). A name that is not a state variable is an input error that says where it was given:
/// file:line and key for the model's and the scene's values, the option for --init.
std::vector<double> initial_state(const Target& target, const std::vector<std::string>& names,
                                  std::vector<double> defaults, const std::map<std::string, double>& init);

}  // namespace hamel::cli
