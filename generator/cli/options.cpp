#include "cli/options.hpp"

#include "model/expression_parser.hpp"
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

std::map<std::string, GiNaC::ex> parse_expression_assignments(const std::vector<std::string>& items,
                                                              const std::string& option, const Constants& constants) {
  std::map<std::string, GiNaC::ex> out;
  for (const std::string& item : items)
    for (const std::string& part : split_top_level(item)) {
      if (part.empty()) continue;
      const std::size_t eq = part.find('=');
      if (eq == std::string::npos || eq == 0)
        throw InputError(option + ": expected name=value or name=expression, got " + quote(part));
      const std::string name = part.substr(0, eq), text = part.substr(eq + 1);
      GiNaC::ex value;
      try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument(text);
        value = v;
      } catch (const std::exception&) {
        try {
          value = parse_expression(text, constants.names);
        } catch (const std::exception& e) {
          std::string names;
          for (const auto& [n, s] : constants.names) names += (names.empty() ? "" : ", ") + n;
          throw InputError(option + ": value of " + quote(name) + " is not a number nor an expression in " +
                           (names.empty() ? std::string("numbers and pi") : "the parameters (" + names + ")") + ": " +
                           quote(text) + " (" + e.what() + ")");
        }
      }
      if (!out.emplace(name, value).second)
        throw InputError(option + ": " + quote(name) + " is given twice; give each name once");
    }
  return out;
}

double constant_value(const GiNaC::ex& e, const GiNaC::exmap& values, const std::string& option,
                      const std::string& name) {
  const GiNaC::ex v = e.subs(values).evalf();
  if (GiNaC::is_a<GiNaC::numeric>(v) && GiNaC::ex_to<GiNaC::numeric>(v).is_real()) {
    const double d = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
    if (std::isfinite(d)) return d;
  }
  std::ostringstream text;
  text << e << " = " << v;
  throw InputError(option + ": value of " + quote(name) + " is not a finite real number: " + quote(text.str()) +
                   "; expected a number or an expression in the parameters with a finite real value");
}

std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option,
                                                const Constants& constants) {
  std::map<std::string, double> out;
  for (const auto& [name, e] : parse_expression_assignments(items, option, constants))
    out[name] = constant_value(e, constants.values, option, name);
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

Model apply_fold(const Model& model, const std::vector<double>& values, const std::string& spec,
                 std::set<std::string>* folded) {
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
  if (folded)
    for (const auto& [name, value] : fold) folded->insert(name);
  return fold_parameters(model, fold);
}

std::vector<GiNaC::ex> parse_path(const std::string& text, const Model& model) {
  GiNaC::symtab table;
  table["t"] = model.time;
  for (const auto& p : model.parameters) table[p.symbol.get_name()] = p.symbol;
  std::vector<GiNaC::ex> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(';', start);
    const std::string part = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    try {
      out.push_back(parse_expression(part, table));
    } catch (const std::exception& e) {
      throw InputError("--path: cannot parse \"" + part + "\" (entry " + std::to_string(out.size() + 1) +
                       "): expected an expression in t and the model's parameters");
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

}  // namespace hamel::cli
