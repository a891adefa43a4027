// Command-line values shared by the verbs: "name=value,..." lists and their validation.
#pragma once

#include "model/model.hpp"

#include <map>
#include <string>
#include <vector>

namespace hamel::cli {

/// Parses "a=1,b=2.5" (and repeated occurrences) into a map; throws InputError naming `option`.
std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option);

/// Parameter values: defaults, overridden by --param; unknown names are input errors.
std::vector<double> parameter_values(const Model& model, const std::map<std::string, double>& overrides);

}  // namespace hamel::cli
