#include "cli/options.hpp"

#include "model/input_error.hpp"

#include <cmath>

namespace hamel::cli {

std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option) {
  std::map<std::string, double> out;
  for (const std::string& item : items) {
    std::size_t start = 0;
    while (start <= item.size()) {
      std::size_t end = item.find(',', start);
      if (end == std::string::npos) end = item.size();
      const std::string part = item.substr(start, end - start);
      start = end + 1;
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
