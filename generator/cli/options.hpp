// Command-line values shared by the verbs: "name=value,..." lists and their validation.
#pragma once

#include "model/model.hpp"

#include <map>
#include <set>
#include <string>
#include <vector>

namespace hamel::cli {

/// The items of a comma-separated option value, empty ones included ("a,,b" has three; "" has one, empty).
std::vector<std::string> split_list(const std::string& list);

/// Parses "a=1,b=2.5" (and repeated occurrences) into a map; throws InputError naming `option`.
std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option);

/// What a value on the command line may name besides numbers and pi: symbols with their values, e.g. the model's
/// parameters at the run's values (parameter_constants in cli/pipeline.hpp), so that `linearize --input
/// "f=(mq+mL)*g"` holds the weight whatever the masses.
struct Constants {
  GiNaC::symtab names;
  GiNaC::exmap values;
};

/// "a=1,b=(m1+m2)*g": values that are numbers or expressions in `constants`' names and pi, parsed (items split at
/// commas outside parentheses, so atan2(y,x) is one value); throws InputError naming `option`.
std::map<std::string, GiNaC::ex> parse_expression_assignments(const std::vector<std::string>& items,
                                                              const std::string& option, const Constants& constants);

/// The value of such an expression at `values`: a finite real number, else an InputError naming `option` and `name`.
double constant_value(const GiNaC::ex& e, const GiNaC::exmap& values, const std::string& option,
                      const std::string& name);

/// parse_expression_assignments with every value evaluated at `constants.values`.
std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option,
                                                const Constants& constants);

/// Parameter values: defaults, overridden by --param; unknown names are input errors.
std::vector<double> parameter_values(const Model& model, const std::map<std::string, double>& overrides);

/// `model` with the parameters named by a --fold value folded in at `values` (see fold_parameters.hpp):
/// "none" (or empty) folds nothing, "all" every parameter, otherwise a comma-separated list of names.
Model apply_fold(const Model& model, const std::vector<double>& values, const std::string& spec,
                 std::set<std::string>* folded = nullptr);

/// --path "r1(t);r2(t);...": one expression in t and the model's parameters per shape coordinate (phase, animate);
/// throws InputError naming the entry that does not parse.
std::vector<GiNaC::ex> parse_path(const std::string& text, const Model& model);

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

}  // namespace hamel::cli
