#include "model/load_model.hpp"
#include "model/body_energy.hpp"
#include "model/physical_checks.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"

#include "derive/holonomic_constraints.hpp"
#include "derive/tree_loops.hpp"
#include "lie/lie_algebra.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "model/input_file.hpp"
#include "model/yaml_document.hpp"
#include "report/atomic_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>

namespace hamel {

std::string content_hash(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::vector<std::string> tree_body_names(const KinematicTree& tree) {
  std::vector<std::string> names{tree.base.name};
  for (const TreeBody& b : tree.bodies) names.push_back(b.body.name);
  return names;
}

std::vector<int> unconstrained_indices(std::size_t n, const std::vector<int>& constrained) {
  std::vector<int> idx;
  for (int a = 0; a < static_cast<int>(n); ++a)
    if (std::find(constrained.begin(), constrained.end(), a) == constrained.end()) idx.push_back(a);
  return idx;
}

std::vector<int> Model::independent() const { return unconstrained_indices(quasi_velocities.size(), constrained); }

GiNaC::symtab Model::symbols() const {
  GiNaC::symtab table;
  table["t"] = time;
  for (const auto& p : parameters) table[p.symbol.get_name()] = p.symbol;
  for (const auto& s : coordinates) table[s.get_name()] = s;
  for (const auto& s : rates) table[s.get_name()] = s;
  for (const auto& s : quasi_velocities) table[s.get_name()] = s;
  for (const auto& s : inputs) table[s.get_name()] = s;
  if (bundle)
    for (const auto* list : {&bundle->group_velocity, &bundle->constraint_velocities, &bundle->momentum_velocities})
      for (const auto& s : *list) table[s.get_name()] = s;
  return table;
}

std::size_t Model::input_index(const std::string& input, const std::string& option) const {
  for (std::size_t k = 0; k < inputs.size(); ++k)
    if (inputs[k].get_name() == input) return k;
  std::string list;
  for (const auto& u : inputs) list += (list.empty() ? "" : ", ") + u.get_name();
  throw InputError(option + ": " + quote(input) + " is not an input of model '" + name + "'" +
                   (list.empty() ? " (it has none)" : " (inputs: " + list + ")"));
}

namespace {

// A divisor of `e` (the base of a negative power) that is identically zero, such as sin(x)^2 + cos(x)^2 - 1:
// GiNaC sees no zero while parsing, and the derivation's normal form would stop on it with no location.
// Decided exactly: a 50-digit value clearly away from 0 answers "not zero"; otherwise the modular identity
// test, and where that cannot read the divisor, is_zero_almost_surely. A divisor that uses definitions (x/d with d:
// sin(x)^2 + cos(x)^2 - 1) is decided through `program`, the definitions read where they are defined, never
// inlined. Returns the divisor, or nothing.
bool uses_intermediates(const GiNaC::ex& e, const Intermediates& program) {
  if (GiNaC::is_a<GiNaC::symbol>(e)) return program.is_intermediate(e);
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (uses_intermediates(e.op(i), program)) return true;
  return false;
}

std::optional<GiNaC::ex> zero_divisor(const GiNaC::ex& e, const Intermediates& program) {
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (std::optional<GiNaC::ex> d = zero_divisor(e.op(i), program)) return d;
  if (!GiNaC::is_a<GiNaC::power>(e) || !GiNaC::is_a<GiNaC::numeric>(e.op(1)) ||
      !GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_negative())
    return std::nullopt;
  const GiNaC::ex base = e.op(0);
  if (GiNaC::is_a<GiNaC::numeric>(base)) return std::nullopt;
  if (!program.empty() && uses_intermediates(base, program))
    return identically_zero(base, program) == Identity::zero ? std::optional<GiNaC::ex>(base) : std::nullopt;
  if (GiNaC::is_a<GiNaC::symbol>(base) || numerically_nonzero(base)) return std::nullopt;
  const Identity zero = identically_zero(base, Intermediates{});
  if (zero == Identity::zero || (zero == Identity::undecided && is_zero_almost_surely(base))) return base;
  return std::nullopt;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = 3;
  for (const auto& c : candidates) {
    std::string lower_word = word, lower_c = c;
    for (char& ch : lower_word) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    for (char& ch : lower_c) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (lower_word == lower_c) return " (did you mean " + quote(c) + "?)";
    std::size_t d = edit_distance(word, c);
    if (d < best_d && d < word.size()) best_d = d, best = c;  // never suggest 'm' for 'k'
  }
  return best.empty() ? std::string() : " (did you mean " + quote(best) + "?)";
}

// " (beyond the range of a double)" if `text` spells a number too large or too small for a double.
std::string out_of_range(const std::string& text) {
  if (text.empty()) return {};
  char* end = nullptr;
  errno = 0;
  std::strtod(text.c_str(), &end);
  return errno == ERANGE && *end == '\0' ? " (beyond the range of a double, about 2.2e-308 to 1.8e308)" : "";
}

// Reads one file, keeping its name for messages.
class Loader {
 public:
  Loader(const std::string& text, const std::string& path) : text_(text), path_(path) {}

  Model load();

 private:
  SourceLocation where(const YAML::Node& node) const {
    const YAML::Mark m = node.Mark();
    return {path_, m.line >= 0 ? m.line + 1 : 0, m.column >= 0 ? m.column + 1 : 0};
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& problem) const {
    throw InputError(where(node), key, problem);
  }

  YAML::Node require(const std::string& key, YAML::NodeType::value type, const char* expected) const {
    YAML::Node node = root_[key];
    if (!node) throw InputError(where(root_), key, std::string("missing required key; expected ") + expected);
    if (node.Type() != type) fail(node, key, std::string("expected ") + expected);
    return node;
  }

  std::string scalar(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a scalar (an expression string or a number)");
    return node.Scalar();
  }

  double finite_number(const YAML::Node& node, const std::string& key) const {
    const std::string value = scalar(node, key);
    double v = 0;
    try {
      v = node.as<double>();  // YAML's own number syntax, including .inf and .nan
    } catch (const YAML::Exception&) {
      fail(node, key, "expected a number, got " + quote(value) + out_of_range(value));
    }
    if (!std::isfinite(v)) fail(node, key, "expected a finite number, got " + quote(value));
    // yaml-cpp reads 1e-400 as 0 without a word; --param refuses it, so a file does too.
    if (const std::string note = out_of_range(value); !note.empty())
      fail(node, key, "expected a number, got " + quote(value) + note);
    return v;
  }

  void declare_name(const YAML::Node& node, const std::string& key, const std::string& name) {
    std::string why;
    if (!is_valid_identifier(name, &why)) fail(node, key, why);
    auto [it, inserted] = declared_.emplace(name, key);
    if (!inserted) fail(node, key, "the name '" + name + "' is already declared in '" + it->second + "'");
  }

  std::vector<GiNaC::realsymbol> name_list(const YAML::Node& node, const std::string& key) {
    if (!node.IsSequence()) fail(node, key, "expected a list of names");
    std::vector<GiNaC::realsymbol> out;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string item_key = key + "[" + std::to_string(i) + "]";
      const std::string name = scalar(node[i], item_key);
      declare_name(node[i], item_key, name);
      out.emplace_back(name);
    }
    return out;
  }

  GiNaC::ex expression(const YAML::Node& node, const std::string& key, const GiNaC::symtab& table,
                       const std::string& allowed) const {
    const std::string text = scalar(node, key);
    GiNaC::ex e;
    try {
      e = parse_expression(text, table);
    } catch (const std::exception& error) {
      std::string problem = describe_parse_error(error.what());
      if (const std::string unknown = "unknown name '"; problem.rfind(unknown, 0) == 0) {
        std::vector<std::string> names;
        for (const auto& entry : table) names.push_back(entry.first);
        problem += did_you_mean(problem.substr(unknown.size(), problem.size() - unknown.size() - 1), names);
      }
      fail(node, key, "cannot parse expression " + quote(text) + ": " + problem + "; " + allowed);
    }
    if (const std::string part = unsupported_part(e); !part.empty())
      fail(node, key,
           "expression " + quote(text) + " uses " + part +
               ", which emitted code cannot evaluate; expected real "
               "numbers, names, + - * / ^, Pi and the functions " +
               emittable_functions());
    static const Intermediates no_definitions;
    if (const std::optional<GiNaC::ex> divisor = zero_divisor(e, program_ ? *program_ : no_definitions))
      fail(node, key,
           "expression " + quote(text) + " divides by " + quote(to_text(*divisor)) +
               ", which is identically zero; expected denominators that are not identically zero");
    return e;
  }

  GiNaC::matrix matrix_of(const YAML::Node& node, const std::string& key, std::size_t rows, std::size_t cols,
                          const GiNaC::symtab& table, const std::string& allowed) const {
    if (!node.IsSequence() || node.size() != rows)
      fail(node, key, "expected a list of " + std::to_string(rows) + " rows (one per quasi-velocity)");
    GiNaC::matrix m(static_cast<unsigned>(rows), static_cast<unsigned>(cols));
    for (std::size_t i = 0; i < rows; ++i) {
      const std::string row_key = key + "[" + std::to_string(i) + "]";
      if (!node[i].IsSequence() || node[i].size() != cols)
        fail(node[i], row_key, "expected a row of " + std::to_string(cols) + " entries (one per coordinate)");
      for (std::size_t j = 0; j < cols; ++j)
        m(static_cast<unsigned>(i), static_cast<unsigned>(j)) =
            expression(node[i][j], row_key + "[" + std::to_string(j) + "]", table, allowed);
    }
    return m;
  }

  // A: each row a list of n entries A^a_b(q), or one expression u^a = A^a_b(q) q̇^b linear in the rates (a
  // contact-point velocity written with definitions), whose coefficients are its derivatives by the rates
  // (taken through the definitions, so nothing is expanded). Linearity is decided exactly.
  GiNaC::matrix velocity_matrix(Model& model, const YAML::Node& node, const std::string& key,
                                const GiNaC::symtab& geometric, const std::string& allowed, std::size_t rows) {
    const std::size_t n = model.coordinates.size();
    if (!node.IsSequence() || node.size() != rows)
      fail(node, key, "expected a list of " + std::to_string(rows) + " rows (one per quasi-velocity)");
    GiNaC::symtab with_rates = geometric;
    for (const auto& r : model.rates) with_rates[r.get_name()] = r;
    with_rates = with_definitions(with_rates);
    GiNaC::matrix m(static_cast<unsigned>(rows), static_cast<unsigned>(n));
    for (std::size_t i = 0; i < rows; ++i) {
      const std::string row_key = key + "[" + std::to_string(i) + "]";
      if (node[i].IsSequence()) {
        if (node[i].size() != n)
          fail(node[i], row_key, "expected a row of " + std::to_string(n) + " entries (one per coordinate)");
        for (std::size_t j = 0; j < n; ++j)
          m(static_cast<unsigned>(i), static_cast<unsigned>(j)) =
              expression(node[i][j], row_key + "[" + std::to_string(j) + "]", geometric, allowed);
        continue;
      }
      if (!node[i].IsScalar())
        fail(node[i], row_key,
             "expected a row of " + std::to_string(n) +
                 " entries (one per coordinate) or one expression linear in the rates");
      const GiNaC::ex row = expression(node[i], row_key, with_rates,
                                       "a row written as one expression may use coordinates, rates and parameters "
                                       "(and definitions of them); it must be linear in the rates");
      GiNaC::ex rest = row;
      for (std::size_t j = 0; j < n; ++j) {
        const GiNaC::ex c = model.definitions.diff(row, model.rates[j]);
        m(static_cast<unsigned>(i), static_cast<unsigned>(j)) = c;
        rest -= c * model.rates[j];
        for (std::size_t k = 0; k < n; ++k)
          if (!c.is_zero() &&
              identically_zero(model.definitions.diff(c, model.rates[k]), model.definitions) == Identity::nonzero)
            fail(node[i], row_key,
                 "is not linear in the rates: its coefficient of " + model.rates[j].get_name() + " depends on " +
                     model.rates[k].get_name() + " (expected u = A(q) q_dot)");
      }
      if (identically_zero(rest, model.definitions) == Identity::nonzero)
        fail(node[i], row_key, "is not linear in the rates: it has a part without a rate (expected u = A(q) q_dot)");
    }
    return m;
  }

  void check_keys(const YAML::Node& node, const std::string& context, const std::vector<std::string>& known) const {
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(known.begin(), known.end(), key) != known.end()) continue;
      if (context.empty() && bundle_ &&
          (key == "coordinates" || key == "quasi_velocities" || key == "constraints" || key == "lagrangian"))
        fail(kv.first, key,
             "does not belong in a bundle model (one with 'group'): the configuration is (g, r) with r given by "
             "'shape', the Lagrangian by 'kinetic' or 'bodies' and 'potential', constraints by 'connection'");
      if (context.empty() && !bundle_ &&
          (key == "trivialization" || key == "group_velocity" || key == "shape" || key == "connection" ||
           key == "kinetic"))
        fail(kv.first, key, "is a principal-bundle key: a bundle model needs 'group' (and no 'coordinates')");
      fail(kv.first, context.empty() ? key : context + "." + key,
           "unknown key" + did_you_mean(key, known) + "; expected one of: " + join(known));
    }
  }

  void load_core(Model& model);
  void load_bundle(Model& model);
  unsigned load_group(Model& model, Bundle& b);
  void load_shape(const YAML::Node& tree, Model& model, const Bundle& b);
  void load_connection(Model& model, Bundle& b, unsigned dim, const GiNaC::symtab& geometric);
  void declare_bundle_constraints(Bundle& b, unsigned dim);
  void load_bundle_constraints(Model& model, Bundle& b, const GiNaC::symtab& velocities);
  void load_bundle_lagrangian(const YAML::Node& tree, Model& model, Bundle& b, const GiNaC::symtab& geometric,
                              const GiNaC::symtab& velocities);
  void load_fixed_tree(Model& model);
  void declare_joints(const YAML::Node& tree, Model& model);
  void declare_gravity_state(const YAML::Node& gravity, const std::string& group, const Model& model);
  void load_wrenches(Model& model, const KinematicTree& tree, const GiNaC::symtab& table);
  std::vector<TreeLoop> load_loops(const Model& model, const KinematicTree& tree);
  KinematicTree load_tree(const YAML::Node& tree, Model& model, const Bundle* bundle = nullptr);
  RigidBody rigid_body(const YAML::Node& body, const std::string& key, const GiNaC::symtab& table,
                       const std::vector<std::string>& keys, const std::string& allowed,
                       const std::vector<std::string>& optional = {});
  // Mass >= 0 and a physical inertia at the parameter defaults, as tree bodies (model/physical_checks.hpp): a body's
  // negative mass was accepted wherever the kinetic energy did not show it (a body that only turns about its centre).
  void check_rigid_body(const YAML::Node& node, const std::string& key, const RigidBody& body, const Model& model) {
    std::string subkey;
    if (const std::string problem = rigid_body_problem(body, parameter_defaults(model), subkey); !problem.empty())
      fail(node[subkey], key + "." + subkey, problem);
  }
  GiNaC::ex load_posed_body(Model& model, const YAML::Node& body, const std::string& key, const GiNaC::symtab& table,
                            std::string& name);
  GiNaC::ex load_twist_body(Model& model, const YAML::Node& body, const std::string& key,
                            const GiNaC::symtab& geometric, const GiNaC::symtab& velocities, std::string& name);
  std::vector<GiNaC::ex> vector_of(const YAML::Node& node, const std::string& key, std::size_t size,
                                   const GiNaC::symtab& table, const std::string& allowed) const {
    if (!node.IsSequence() || node.size() != size)
      fail(node, key, "expected a list of " + std::to_string(size) + " expressions");
    std::vector<GiNaC::ex> out;
    for (std::size_t i = 0; i < size; ++i)
      out.push_back(expression(node[i], key + "[" + std::to_string(i) + "]", table, allowed));
    return out;
  }
  void load_forces(Model& model, const GiNaC::symtab& table, const std::string& allowed);
  void load_definitions(Model& model, const GiNaC::symtab& all);
  std::size_t declare_holonomic(Model& model);
  void load_holonomic(Model& model, const GiNaC::symtab& all);
  std::set<std::string> symbols_used(const GiNaC::ex& e) const;
  GiNaC::symtab with_definitions(GiNaC::symtab table) const;

  const std::string& text_;
  std::string path_;
  const Intermediates* program_ = nullptr;  // the model's definitions, once load_definitions has read them
  YAML::Node root_;
  bool bundle_ = false;
  std::map<std::string, std::string> declared_;   // name -> key that declared it
  std::vector<GiNaC::realsymbol> gravity_state_;  // Γ of a floating base that turns (declare_gravity_state)
  SourceLocation gravity_location_;
  // Per definition (model key `definitions`): its symbol and the names of the model symbols it depends on,
  // through earlier definitions too; a key may use a definition only if it may use all of those.
  std::vector<std::pair<GiNaC::realsymbol, std::set<std::string>>> definition_uses_;
  std::map<std::string, std::size_t> definition_index_;  // name -> position in definition_uses_
};

Model Loader::load() {
  root_ = load_yaml_document(text_, path_);
  if (!root_.IsMap())
    throw InputError(root_.Mark().line >= 0 ? where(root_) : SourceLocation{path_, 1, 1}, "",
                     "expected a YAML mapping of model keys");
  bundle_ = static_cast<bool>(root_["group"]);
  if (bundle_)
    check_keys(root_, "",
               {"schema", "name",       "description", "parameters", "group",       "trivialization", "group_velocity",
                "shape",  "connection", "constraints", "kinetic",    "bodies",      "tree",           "potential",
                "forces", "wrenches",   "loops",       "inputs",     "definitions", "initial"});
  else if (root_["tree"])
    check_keys(root_, "",
               {"schema", "name", "description", "parameters", "tree", "forces", "wrenches", "loops", "inputs",
                "definitions", "initial"});
  else
    check_keys(root_, "",
               {"schema", "name", "description", "parameters", "coordinates", "quasi_velocities", "constraints",
                "holonomic", "lagrangian", "forces", "inputs", "definitions", "initial", "bodies", "potential"});

  Model model;
  model.source_path = path_;
  model.source_hash = content_hash(text_);

  if (YAML::Node schema = root_["schema"]) {
    if (scalar(schema, "schema") != "1") fail(schema, "schema", "unsupported schema version; expected 1");
  }
  YAML::Node name = require("name", YAML::NodeType::Scalar, "a name (a C++ identifier)");
  model.name = name.Scalar();
  {
    std::string why;
    if (!is_valid_model_name(model.name, &why)) fail(name, "name", why + " (the name becomes a C++ namespace)");
  }
  if (YAML::Node d = root_["description"]) model.description = scalar(d, "description");

  if (YAML::Node params = root_["parameters"]) {
    if (!params.IsMap()) fail(params, "parameters", "expected a map of name: default value");
    for (const auto& kv : params) {
      const std::string pname = kv.first.as<std::string>();
      const std::string key = "parameters." + pname;
      declare_name(kv.first, key, pname);
      model.parameters.push_back({GiNaC::realsymbol(pname), finite_number(kv.second, key)});
    }
  }
  // A representative initial state (which a model with a holonomic condition in differential form needs for its
  // studies to mean something): names are checked against the state when a verb uses them.
  if (YAML::Node init = root_["initial"]) {
    if (!init.IsMap()) fail(init, "initial", "expected a map of state variable: value");
    for (const auto& kv : init) {
      const std::string key = "initial." + scalar(kv.first, "initial");
      model.initial[kv.first.Scalar()] = finite_number(kv.second, key);
      model.locations[key] = where(kv.first);
    }
  }

  if (bundle_)
    load_bundle(model);
  else if (root_["tree"])
    load_fixed_tree(model);
  else
    load_core(model);
  return model;
}

void Loader::load_definitions(Model& model, const GiNaC::symtab& all) {
  const YAML::Node defs = root_["definitions"];
  if (!defs) return;
  if (!defs.IsMap()) fail(defs, "definitions", "expected an ordered map of name: expression");
  program_ = &model.definitions;
  GiNaC::symtab table = all;
  for (const auto& kv : defs) {
    const std::string name = kv.first.as<std::string>();
    const std::string key = "definitions." + name;
    declare_name(kv.first, key, name);
    const GiNaC::ex value =
        expression(kv.second, key, table,
                   "a definition may use the model's symbols (parameters, coordinates, rates, velocities, inputs, "
                   "t) and the definitions above it");
    const std::set<std::string> uses = symbols_used(value);
    const GiNaC::realsymbol symbol = model.definitions.define_named(name, value);
    definition_index_[name] = definition_uses_.size();
    definition_uses_.emplace_back(symbol, uses);
    table[name] = symbol;
  }
}

// The names of the model symbols `e` uses, through the definitions it uses.
std::set<std::string> Loader::symbols_used(const GiNaC::ex& e) const {
  std::set<std::string> uses;
  std::function<void(const GiNaC::ex&)> collect = [&](const GiNaC::ex& x) {
    if (GiNaC::is_a<GiNaC::symbol>(x)) {
      const std::string s = GiNaC::ex_to<GiNaC::symbol>(x).get_name();
      if (const auto it = definition_index_.find(s); it != definition_index_.end()) {
        const std::set<std::string>& deps = definition_uses_[it->second].second;
        uses.insert(deps.begin(), deps.end());
      } else {
        uses.insert(s);
      }
      return;
    }
    for (std::size_t i = 0; i < x.nops(); ++i) collect(x.op(i));
  };
  collect(e);
  return uses;
}

// The names of the holonomic constraints (key `holonomic`), declared before the quasi-velocities: each also names
// the quasi-velocity ġ it becomes. Returns how many there are.
std::size_t Loader::declare_holonomic(Model& model) {
  const YAML::Node node = root_["holonomic"];
  if (!node) return 0;
  model.locations["holonomic"] = where(node);
  if (!node.IsMap()) fail(node, "holonomic", "expected an ordered map of name: expression g(q) (the constraint g = 0)");
  for (const auto& kv : node) {
    const std::string name = scalar(kv.first, "holonomic");
    const std::string key = "holonomic." + name;
    declare_name(kv.first, key, name);
    model.locations[key] = where(kv.second);
    model.holonomic.push_back({GiNaC::realsymbol(name), 0, {}});
  }
  const std::size_t n = model.coordinates.size(), k = model.holonomic.size();
  if (k >= n)
    fail(node, "holonomic",
         std::to_string(k) + " constraints on " + std::to_string(n) + " coordinates leave no degree of freedom; " +
             "expected fewer constraints than coordinates");
  return k;
}

// g(q) of each holonomic constraint: coordinates, parameters and definitions of these only.
void Loader::load_holonomic(Model& model, const GiNaC::symtab& all) {
  const YAML::Node node = root_["holonomic"];
  if (!node) return;
  const std::string allowed =
      "a holonomic constraint g(q) = 0 may use coordinates, parameters and definitions of these";
  std::size_t i = 0;
  for (const auto& kv : node) {
    HolonomicConstraint& c = model.holonomic[i++];
    const std::string key = "holonomic." + c.velocity.get_name();
    c.g = expression(kv.second, key, all, allowed);
    for (const std::string& used : symbols_used(c.g)) {
      bool geometric = false;
      for (const auto& p : model.parameters) geometric = geometric || p.symbol.get_name() == used;
      for (const auto& q : model.coordinates) geometric = geometric || q.get_name() == used;
      if (geometric) continue;
      std::string what = quote(used);
      for (const auto& r : model.rates)
        if (r.get_name() == used) what = "the rate " + quote(used);
      for (const auto& u : model.inputs)
        if (u.get_name() == used) what = "the input " + quote(used);
      for (const auto& u : model.quasi_velocities)
        if (u.get_name() == used) what = "the quasi-velocity " + quote(used);
      if (used == "t")
        fail(kv.second, key,
             "uses the time 't': constraints g(q, t) = 0 that move with time are not supported; expected g(q), " +
                 allowed);
      fail(kv.second, key,
           "uses " + what + ": expected g(q), a condition on the positions; " + allowed +
               " (a condition on velocities is a Pfaffian constraint: a quasi-velocity listed in 'constraints')");
    }
  }
}

GiNaC::symtab Loader::with_definitions(GiNaC::symtab table) const {
  for (const auto& [symbol, uses] : definition_uses_) {
    bool allowed = true;
    for (const std::string& s : uses) allowed = allowed && table.count(s) > 0;
    if (allowed) table[symbol.get_name()] = symbol;
  }
  return table;
}

void Loader::load_forces(Model& model, const GiNaC::symtab& table, const std::string& allowed) {
  const std::size_t n = model.coordinates.size();
  model.forces.assign(n, GiNaC::ex(0));
  if (YAML::Node forces = root_["forces"]) {
    if (!forces.IsSequence() || forces.size() != n)
      fail(forces, "forces",
           "expected a list of " + std::to_string(n) + " expressions (one per " +
               (bundle_ ? "shape coordinate)" : "coordinate)"));
    for (std::size_t i = 0; i < n; ++i) {
      model.locations["forces[" + std::to_string(i) + "]"] = where(forces[i]);
      model.forces[i] = expression(forces[i], "forces[" + std::to_string(i) + "]", table, allowed);
    }
  }
}

void Loader::load_core(Model& model) {
  YAML::Node coords = require("coordinates", YAML::NodeType::Sequence, "a list of coordinate names");
  model.coordinates = name_list(coords, "coordinates");
  if (model.coordinates.empty()) fail(coords, "coordinates", "expected at least one coordinate");
  for (std::size_t i = 0; i < model.coordinates.size(); ++i) {
    const std::string rate = model.coordinates[i].get_name() + "_dot";
    declared_.emplace(rate, "coordinates");
    model.rates.emplace_back(rate);
  }
  const std::size_t n = model.coordinates.size();
  // Holonomic constraints g(q) = 0: k of them leave n − k other quasi-velocities, given or (without the key
  // quasi_velocities) the rates of independent coordinates (derive/holonomic_constraints.hpp).
  const std::size_t k = declare_holonomic(model);
  const std::size_t others = n - k;

  YAML::Node qv = root_["quasi_velocities"];
  if (!qv && k == 0) qv = require("quasi_velocities", YAML::NodeType::Map, "a map with keys names, A and optionally B");
  if (qv) {
    if (!qv.IsMap()) fail(qv, "quasi_velocities", "expected a map with keys names, A and optionally B");
    check_keys(qv, "quasi_velocities", {"names", "A", "B"});
    if (!qv["names"]) fail(qv, "quasi_velocities.names", "missing required key; expected a list of names");
    model.quasi_velocities = name_list(qv["names"], "quasi_velocities.names");
    if (model.quasi_velocities.size() != others)
      fail(qv["names"], "quasi_velocities.names",
           k == 0 ? "expected " + std::to_string(n) + " names (one per coordinate), got " +
                        std::to_string(model.quasi_velocities.size())
                  : "expected " + std::to_string(others) +
                        " names (one per coordinate, less one per holonomic "
                        "constraint: " +
                        std::to_string(n) + " - " + std::to_string(k) + "), got " +
                        std::to_string(model.quasi_velocities.size()));
    if (k > 0 && qv["B"])
      fail(qv["B"], "quasi_velocities.B",
           "cannot be given with 'holonomic': hamel inverts A = [dg/dq; A] itself; expected no B");
  }

  if (YAML::Node ins = root_["inputs"]) model.inputs = name_list(ins, "inputs");

  load_definitions(model, model.symbols());
  const GiNaC::symtab all = with_definitions(model.symbols());
  load_holonomic(model, all);
  GiNaC::symtab geometric;  // what A(q) and B(q) may use
  for (const auto& p : model.parameters) geometric[p.symbol.get_name()] = p.symbol;
  for (const auto& s : model.coordinates) geometric[s.get_name()] = s;
  geometric = with_definitions(geometric);
  const std::string geometric_allowed = "A(q) and B(q) may use coordinates and parameters only";

  if (qv && !qv["A"])
    fail(qv, "quasi_velocities.A",
         k == 0 ? "missing required key; expected an n x n matrix (list of rows)"
                : "missing required key; expected " + std::to_string(others) + " rows of " + std::to_string(n) +
                      " entries (list of rows)");
  if (qv) {
    model.locations["quasi_velocities.A"] = where(qv["A"]);
    model.A = velocity_matrix(model, qv["A"], "quasi_velocities.A", geometric, geometric_allowed, others);
  }
  if (qv && qv["B"]) {
    const YAML::Node b = qv["B"];
    model.locations["quasi_velocities.B"] = where(b);
    model.B = matrix_of(b, "quasi_velocities.B", n, n, geometric, geometric_allowed);
    model.B_given = true;
  }

  if (YAML::Node cons = root_["constraints"]) {
    if (!cons.IsSequence()) fail(cons, "constraints", "expected a list of quasi-velocity names");
    model.locations["constraints"] = where(cons);
    std::vector<std::string> names;
    for (const auto& u : model.quasi_velocities) names.push_back(u.get_name());
    for (std::size_t i = 0; i < cons.size(); ++i) {
      const std::string key = "constraints[" + std::to_string(i) + "]";
      const std::string cname = scalar(cons[i], key);
      auto it = std::find(names.begin(), names.end(), cname);
      if (it == names.end())
        fail(cons[i], key,
             quote(cname) + " is not a quasi-velocity" + did_you_mean(cname, names) +
                 "; expected one of: " + join(names));
      const int index = static_cast<int>(it - names.begin());
      if (std::find(model.constrained.begin(), model.constrained.end(), index) != model.constrained.end())
        fail(cons[i], key, quote(cname) + " is listed twice");
      model.constrained.push_back(index);
    }
    if (model.constrained.size() >= others)
      fail(cons, "constraints",
           k == 0 ? "at least one quasi-velocity must stay independent"
                  : "at least one quasi-velocity must stay independent (the holonomic constraints already hold " +
                        std::to_string(k) + " of the " + std::to_string(n) + ")");
  }

  GiNaC::symtab lagrangian_table = model.symbols();
  for (const auto& s : model.inputs) lagrangian_table.erase(s.get_name());
  lagrangian_table = with_definitions(lagrangian_table);
  // The constraint velocities ġ^α join the quasi-velocities (first, held at zero); the Lagrangian and the forces
  // do not see them (they are zero on the motion).
  add_holonomic_quasi_velocities(model, static_cast<bool>(qv));
  // With `bodies`, L = Σ T_body − V + (further terms under `lagrangian`, optional).
  const YAML::Node bodies = root_["bodies"];
  model.lagrangian = 0;
  if (bodies) {
    model.locations["lagrangian"] = model.locations["bodies"] = where(bodies);
    if (!bodies.IsSequence() || bodies.size() == 0) fail(bodies, "bodies", "expected a non-empty list of bodies");
    GiNaC::symtab pose_table = geometric;
    pose_table["t"] = model.time;
    pose_table = with_definitions(pose_table);
    std::vector<std::string> names;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const std::string key = "bodies[" + std::to_string(i) + "]";
      std::string body_name;
      model.lagrangian += load_posed_body(model, bodies[i], key, pose_table, body_name);
      if (std::find(names.begin(), names.end(), body_name) != names.end())
        fail(bodies[i]["name"], key + ".name", "the body '" + body_name + "' is listed twice");
      names.push_back(body_name);
    }
    if (YAML::Node v = root_["potential"]) {
      model.locations["potential"] = where(v);
      model.lagrangian -=
          expression(v, "potential", pose_table, "the potential V(q, t) may use coordinates, parameters and t");
    }
  } else if (YAML::Node v = root_["potential"]) {
    fail(v, "potential",
         "goes with 'bodies' in a model in general coordinates; without bodies write L = T - V as 'lagrangian'");
  }
  if (YAML::Node lag = bodies ? root_["lagrangian"] : require("lagrangian", YAML::NodeType::Scalar, "an expression")) {
    model.locations["lagrangian"] = where(lag);
    model.lagrangian += expression(lag, "lagrangian", lagrangian_table,
                                   "the Lagrangian may use coordinates, their _dot rates, quasi-velocities, "
                                   "parameters and t");
  }
  if (const std::string problem = kinetic_energy_problem(model); !problem.empty())
    fail(bodies ? bodies : root_["lagrangian"], bodies ? "bodies" : "lagrangian", problem);

  load_forces(model, all, "forces may use coordinates, _dot rates, quasi-velocities, parameters, inputs and t");
}

// A bundle model: the group and its velocity, the shape (or a tree's joints), the connection, the Lagrangian and
// the forces on the shape.
void Loader::load_bundle(Model& model) {
  Bundle b;
  const unsigned dim = load_group(model, b);
  const YAML::Node tree = root_["tree"];
  load_shape(tree, model, b);
  declare_bundle_constraints(b, dim);
  if (YAML::Node ins = root_["inputs"]) model.inputs = name_list(ins, "inputs");

  GiNaC::symtab geometric;  // parameters and shape: what inertia data and the connection may use
  for (const auto& p : model.parameters) geometric[p.symbol.get_name()] = p.symbol;
  for (const auto& r : model.coordinates) geometric[r.get_name()] = r;
  GiNaC::symtab velocities = geometric;  // plus ξ and ṙ: what the kinetic energy and twists may use
  for (const auto& r : model.rates) velocities[r.get_name()] = r;
  for (const auto& x : b.group_velocity) velocities[x.get_name()] = x;
  GiNaC::symtab force_table = velocities;
  force_table["t"] = model.time;
  for (const auto& u : model.inputs) force_table[u.get_name()] = u;
  for (const auto& g : gravity_state_) force_table[g.get_name()] = g;
  load_definitions(model, force_table);
  geometric = with_definitions(geometric);
  velocities = with_definitions(velocities);
  force_table = with_definitions(force_table);

  load_connection(model, b, dim, geometric);
  load_bundle_constraints(model, b, velocities);
  load_bundle_lagrangian(tree, model, b, geometric, velocities);
  model.bundle = b;
  load_forces(model, force_table,
              "forces on the shape may use shape coordinates, their _dot rates, the group velocity, parameters, "
              "inputs and t");
  if (YAML::Node w = root_["wrenches"]) {
    if (!tree)
      fail(w, "wrenches",
           "applies to kinematic trees (key 'tree'); in a model with 'kinetic' or 'bodies' write the generalized "
           "forces as 'forces'");
    load_wrenches(model, *model.bundle->tree, force_table);
  }
  if (YAML::Node loops = root_["loops"])
    fail(loops, "loops",
         tree ? "closed loops are supported on trees fixed to the world (base: world, no 'group'); on a floating base "
                "they are not implemented yet; expected a fixed-base tree, or the loop cut open"
              : "applies to kinematic trees (key 'tree'); in general coordinates write the loop's closure as "
                "'holonomic' constraints");
  if (tree) {
    const KinematicTree& t = *model.bundle->tree;
    for (std::size_t i = 0; i < t.gravity_state.size(); ++i)
      model.state_defaults[t.gravity_state[i].get_name()] = t.gravity[i];
  }
}

// 'wrenches': forces and torques applied to bodies of the tree, each in the body's frame or the world's.
void Loader::load_wrenches(Model& model, const KinematicTree& tree, const GiNaC::symtab& table) {
  const YAML::Node list = root_["wrenches"];
  model.locations["wrenches"] = where(list);
  if (!list.IsSequence() || list.size() == 0)
    fail(list, "wrenches", "expected a list of wrenches, each a map with body, frame, point, force, torque");
  std::vector<std::string> bodies = tree_body_names(tree);
  if (tree.fixed_base) bodies.erase(bodies.begin());  // the world takes no wrench
  const std::string allowed =
      "a wrench may use t, the coordinates, their _dot rates, the group velocity, inputs, parameters and definitions";
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = "wrenches[" + std::to_string(i) + "]";
    const YAML::Node w = list[i];
    if (!w.IsMap()) fail(w, key, "expected a map with body, frame, point, force, torque");
    check_keys(w, key, {"body", "frame", "point", "force", "torque"});
    if (!w["body"]) fail(w, key + ".body", "missing; expected the name of a body of the tree: " + join(bodies));
    AppliedWrench out;
    out.body = scalar(w["body"], key + ".body");
    if (std::find(bodies.begin(), bodies.end(), out.body) == bodies.end())
      fail(w["body"], key + ".body",
           quote(out.body) + " is not a body of the tree" + did_you_mean(out.body, bodies) +
               "; expected one of: " + join(bodies));
    if (YAML::Node f = w["frame"]) {
      const std::string frame = scalar(f, key + ".frame");
      if (frame != "body" && frame != "world")
        fail(f, key + ".frame", "expected 'body' (the default) or 'world', got " + quote(frame));
      out.world = frame == "world";
      if (out.world && !tree.fixed_base)
        fail(f, key + ".frame",
             "'world' needs the base's orientation, which the state of a floating base does not hold (only the "
             "direction of gravity in it); expected 'body', the wrench resolved in the body's frame");
    }
    if (!w["force"] && !w["torque"]) fail(w, key, "expected a force, a torque or both");
    const std::pair<const char*, GiNaC::ex*> vectors[] = {
        {"point", out.point}, {"force", out.force}, {"torque", out.torque}};
    for (const auto& [k, target] : vectors)
      if (YAML::Node v = w[k]) {
        const std::vector<GiNaC::ex> e = vector_of(v, key + "." + k, 3, table, allowed);
        for (std::size_t c = 0; c < 3; ++c) target[c] = e[c];
      }
    model.wrenches.push_back(out);
  }
}

// 'group', 'trivialization' and 'group_velocity'; returns the group's dimension.
unsigned Loader::load_group(Model& model, Bundle& b) {
  YAML::Node group = require("group", YAML::NodeType::Scalar, "a group name");
  model.locations["group"] = where(group);
  b.group = group.Scalar();
  unsigned dim = 0;
  try {
    dim = lie_algebra(b.group).dim();
  } catch (const std::invalid_argument& e) {
    fail(group, "group", e.what());
  }
  if (YAML::Node triv = root_["trivialization"]) {
    const std::string t = scalar(triv, "trivialization");
    if (t != "left" && t != "right")
      fail(triv, "trivialization",
           "expected 'left' (body velocities, xi^ = g^-1 g_dot) or 'right' (spatial, xi^ = g_dot g^-1), got '" + t +
               "'");
    b.right = t == "right";
  }
  YAML::Node gv = require("group_velocity", YAML::NodeType::Sequence, "a list of names, one per group direction");
  b.group_velocity = name_list(gv, "group_velocity");
  if (b.group_velocity.size() != dim)
    fail(gv, "group_velocity",
         "expected " + std::to_string(dim) + " names for " + b.group + " (basis order: angular before linear), got " +
             std::to_string(b.group_velocity.size()));
  return dim;
}

// The shape coordinates ('shape', or the joints of 'tree') and their rates.
void Loader::load_shape(const YAML::Node& tree, Model& model, const Bundle& b) {
  YAML::Node group = root_["group"];
  if (tree) {
    for (const char* other : {"shape", "kinetic", "bodies"})
      if (YAML::Node o = root_[other])
        fail(o, other,
             "does not belong in a tree model: the shape coordinates are the joints of 'tree' and the kinetic "
             "energy follows from its bodies");
    if (b.right)
      fail(root_["trivialization"], "trivialization",
           "a kinematic tree needs 'left' (the base frame's body twist); 'right' is not supported for trees");
    if (tree_base_directions(b.group).empty())
      fail(group, "group",
           "a kinematic tree's floating base must be " + tree_base_groups() +
               " (the group frame carries the base body), got '" + b.group + "'");
    model.locations["kinetic"] = model.locations["tree"] = where(tree);
    declare_joints(tree, model);
    if (tree.IsMap() && tree["gravity"]) declare_gravity_state(tree["gravity"], b.group, model);
  } else if (YAML::Node shape = root_["shape"]) {
    model.coordinates = name_list(shape, "shape");
  }
  for (const auto& r : model.coordinates) {
    const std::string rate = r.get_name() + "_dot";
    auto [it, inserted] = declared_.emplace(rate, "shape");
    if (!inserted)
      fail(tree ? tree : root_["shape"], tree ? "tree" : "shape",
           "the rate '" + rate + "' of shape coordinate '" + r.get_name() + "' clashes with the name declared in '" +
               it->second + "'");
    model.rates.emplace_back(rate);
  }
}

// 'connection': mechanical (the default) or kinematic rows A^alpha_I(r).
void Loader::load_connection(Model& model, Bundle& b, unsigned dim, const GiNaC::symtab& geometric) {
  const std::size_t n = model.coordinates.size();
  if (YAML::Node conn = root_["connection"]) {
    model.locations["connection"] = where(conn);
    if (b.nonholonomic && !(conn.IsScalar() && conn.Scalar() == "nonholonomic"))
      fail(conn, "connection",
           "a model with 'constraints' has the nonholonomic connection (kinematic part from the constraints, "
           "mechanical part from the locked inertia on the free group directions); expected 'nonholonomic' or no "
           "'connection' key");
    if (conn.IsScalar()) {
      if (conn.Scalar() == "nonholonomic") {
        if (!b.nonholonomic)
          fail(conn, "connection",
               "'nonholonomic' needs the constraints it is built from: a map 'constraints' of name: expression "
               "linear in the group velocity and the shape rates");
      } else if (conn.Scalar() != "mechanical") {
        fail(conn, "connection",
             "expected 'mechanical', 'nonholonomic' (with 'constraints') or a map {kinematic: [[...]]}, got '" +
                 conn.Scalar() + "'");
      }
    } else if (conn.IsMap()) {
      check_keys(conn, "connection", {"kinematic"});
      YAML::Node k = conn["kinematic"];
      if (!k) fail(conn, "connection.kinematic", "missing; expected a list of rows A^alpha_I(r)");
      if (!k.IsSequence() || k.size() != dim)
        fail(k, "connection.kinematic", "expected " + std::to_string(dim) + " rows (one per group direction)");
      GiNaC::matrix a(dim, static_cast<unsigned>(n));
      for (unsigned i = 0; i < dim; ++i) {
        const std::string row_key = "connection.kinematic[" + std::to_string(i) + "]";
        if (!k[i].IsSequence() || k[i].size() != n)
          fail(k[i], row_key, "expected a row of " + std::to_string(n) + " entries (one per shape coordinate)");
        for (unsigned j = 0; j < n; ++j)
          a(i, j) = expression(k[i][j], row_key + "[" + std::to_string(j) + "]", geometric,
                               "the connection A(r) may use shape coordinates and parameters only");
      }
      b.mechanical = false;
      b.kinematic_connection = a;
    } else {
      fail(conn, "connection", "expected 'mechanical' or a map {kinematic: [[...]]}");
    }
  }
}

// 'constraints' on a bundle: the names of the constraints (each names the velocity C_ξ ξ + C_r ṙ held at zero) and the
// velocities Ω_S along the group directions they leave free, declared with the other names.
void Loader::declare_bundle_constraints(Bundle& b, unsigned dim) {
  const YAML::Node node = root_["constraints"];
  if (!node) return;
  if (!node.IsMap() || node.size() == 0)
    fail(node, "constraints",
         "on a bundle model, expected an ordered map of name: expression linear in the group velocity and the shape "
         "rates (each constraint C(r) (xi, r_dot) = 0)");
  if (root_["tree"])
    fail(node, "constraints",
         "constraints on a kinematic tree's floating base are not implemented; expected a model "
         "with 'kinetic' or 'bodies'");
  for (const auto& kv : node) {
    const std::string name = scalar(kv.first, "constraints");
    declare_name(kv.first, "constraints." + name, name);
    b.constraint_velocities.emplace_back(name);
  }
  const std::size_t k = b.constraint_velocities.size();
  if (k >= dim)
    fail(node, "constraints",
         std::to_string(k) + " constraints on the " + std::to_string(dim) + " group directions of " + b.group +
             " leave none free; expected fewer than " + std::to_string(dim) +
             " (constraints that fix the group velocity are a kinematic connection: connection: {kinematic: [[...]]})");
  for (std::size_t j = 0; j < dim - k; ++j) {
    const std::string name = dim - k == 1 ? "Omega_S" : "Omega_S" + std::to_string(j + 1);
    auto [it, inserted] = declared_.emplace(name, "constraints");
    if (!inserted)
      fail(node, "constraints",
           "the velocity along the free group directions is named '" + name +
               "', which clashes with the name "
               "declared in '" +
               it->second + "'; expected another name there");
    b.momentum_velocities.emplace_back(name);
  }
  b.nonholonomic = true;
  b.mechanical = false;
}

// Each constraint as C_ξ(r) ξ + C_r(r) ṙ: its coefficients are its derivatives by ξ and ṙ (through the definitions),
// which may use shape coordinates and parameters only; linearity is decided exactly.
void Loader::load_bundle_constraints(Model& model, Bundle& b, const GiNaC::symtab& velocities) {
  const YAML::Node node = root_["constraints"];
  if (!node) return;
  model.locations["constraints"] = where(node);
  const std::size_t k = b.constraint_velocities.size(), m = b.group_velocity.size(), d = model.rates.size();
  std::vector<GiNaC::realsymbol> v(b.group_velocity);
  v.insert(v.end(), model.rates.begin(), model.rates.end());
  b.constraint_group = GiNaC::matrix(static_cast<unsigned>(k), static_cast<unsigned>(m));
  b.constraint_shape = GiNaC::matrix(static_cast<unsigned>(k), static_cast<unsigned>(d == 0 ? 1 : d));
  std::size_t i = 0;
  for (const auto& kv : node) {
    const std::string key = "constraints." + b.constraint_velocities[i].get_name();
    model.locations[key] = where(kv.second);
    const GiNaC::ex row =
        expression(kv.second, key, velocities,
                   "a constraint may use the group velocity, shape coordinates, their _dot rates and parameters, and "
                   "must be linear in the velocities");
    GiNaC::ex rest = row;
    bool group = false;
    for (std::size_t j = 0; j < v.size(); ++j) {
      const GiNaC::ex c = model.definitions.diff(row, v[j]);
      rest -= c * v[j];
      for (const GiNaC::realsymbol& w : v)
        if (!c.is_zero() && identically_zero(model.definitions.diff(c, w), model.definitions) == Identity::nonzero)
          fail(kv.second, key,
               "is not linear in the velocities: its coefficient of " + v[j].get_name() + " depends on " +
                   w.get_name() + " (expected C(r) (xi, r_dot) = 0)");
      if (j < m) {
        b.constraint_group(static_cast<unsigned>(i), static_cast<unsigned>(j)) = c;
        group = group || identically_zero(c, model.definitions) != Identity::zero;
      } else {
        b.constraint_shape(static_cast<unsigned>(i), static_cast<unsigned>(j - m)) = c;
      }
    }
    if (identically_zero(rest, model.definitions) == Identity::nonzero)
      fail(kv.second, key,
           "is not linear in the velocities: it has a part without a velocity (expected C(r) (xi, r_dot) = 0)");
    if (!group)
      fail(kv.second, key,
           "does not involve the group velocity: a condition on the shape rates alone is not a constraint of the "
           "bundle's symmetry; expected C_xi(r) xi + C_r(r) r_dot = 0 with C_xi not zero");
    ++i;
  }
}

// The kinetic energy ('kinetic', 'bodies', or a tree's bodies in the derivation) and 'potential'.
void Loader::load_bundle_lagrangian(const YAML::Node& tree, Model& model, Bundle& b, const GiNaC::symtab& geometric,
                                    const GiNaC::symtab& velocities) {
  YAML::Node kinetic = root_["kinetic"];
  YAML::Node bodies = root_["bodies"];
  if (!tree && static_cast<bool>(kinetic) == static_cast<bool>(bodies))
    throw InputError(where(kinetic ? kinetic : root_), kinetic ? "kinetic" : "bodies",
                     kinetic ? "give the kinetic energy either as 'kinetic' or as 'bodies', not both"
                             : "missing; expected 'kinetic' (an expression), 'bodies' (a list of rigid bodies) "
                               "or 'tree' (a kinematic tree)");
  if (tree) {
    b.tree = load_tree(tree, model, &b);  // T follows from the bodies in the derivation (derive/kinematic_tree.hpp)
    b.kinetic = 0;
  } else if (kinetic) {
    model.locations["kinetic"] = where(kinetic);
    b.kinetic = expression(kinetic, "kinetic", velocities,
                           "the kinetic energy may use the group velocity, shape coordinates, their _dot rates and "
                           "parameters");
  } else {
    model.locations["kinetic"] = model.locations["bodies"] = where(bodies);
    if (!bodies.IsSequence() || bodies.size() == 0) fail(bodies, "bodies", "expected a non-empty list of bodies");
    b.kinetic = 0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      std::string body_name;
      b.kinetic +=
          load_twist_body(model, bodies[i], "bodies[" + std::to_string(i) + "]", geometric, velocities, body_name);
      if (std::find(b.bodies.begin(), b.bodies.end(), body_name) != b.bodies.end())
        fail(bodies[i]["name"], "bodies[" + std::to_string(i) + "].name",
             "the body '" + body_name + "' is listed twice");
      b.bodies.push_back(body_name);
    }
  }
  b.potential = 0;
  if (YAML::Node v = root_["potential"]) {
    model.locations["potential"] = where(v);
    b.potential = expression(v, "potential", geometric, "the potential V(r) may use shape coordinates and parameters");
  }
  model.lagrangian = b.kinetic - b.potential;
  model.locations["lagrangian"] = model.locations["kinetic"];
}

RigidBody Loader::rigid_body(const YAML::Node& body, const std::string& key, const GiNaC::symtab& table,
                             const std::vector<std::string>& keys, const std::string& allowed,
                             const std::vector<std::string>& optional) {
  if (!body.IsMap()) fail(body, key, "expected a map with keys " + join(keys));
  std::vector<std::string> known = keys;
  known.insert(known.end(), optional.begin(), optional.end());
  check_keys(body, key, known);
  for (const std::string& k : keys)
    if (!body[k]) fail(body, key + "." + k, "missing required key of a body");
  RigidBody out;
  out.name = scalar(body["name"], key + ".name");
  out.mass = expression(body["mass"], key + ".mass", table, allowed);
  const std::vector<GiNaC::ex> com = vector_of(body["com"], key + ".com", 3, table, allowed);
  for (std::size_t i = 0; i < 3; ++i) out.com[i] = com[i];
  const YAML::Node in = body["inertia"];
  if (!in.IsSequence() || in.size() != 3) fail(in, key + ".inertia", "expected 3 rows of a 3x3 matrix");
  for (std::size_t i = 0; i < 3; ++i) {
    const std::vector<GiNaC::ex> row = vector_of(in[i], key + ".inertia[" + std::to_string(i) + "]", 3, table, allowed);
    for (std::size_t j = 0; j < 3; ++j) out.inertia[i][j] = row[j];
  }
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = i + 1; j < 3; ++j)
      if (!(out.inertia[i][j] - out.inertia[j][i]).expand().is_zero())
        fail(in, key + ".inertia",
             "expected a symmetric matrix; entries (" + std::to_string(i) + "," + std::to_string(j) + ") and (" +
                 std::to_string(j) + "," + std::to_string(i) + ") differ");
  return out;
}

// Why R is not a rotation (RᵀR = I, det R = 1), or "" when it is or when that cannot be decided. Numbers are
// checked as a tree joint's rotation is (to 1e-6); expressions exactly at random points through the program
// (algebra/identity_test.hpp), and where that cannot decide (floats, exp) numerically at random values of their
// symbols. 2R, a shear, a reflection (det −1) and the zero matrix are refused.
std::string rotation_problem(const GiNaC::matrix& R, const Intermediates& program) {
  std::vector<std::pair<GiNaC::ex, std::string>> conditions;
  for (unsigned r = 0; r < 3; ++r)
    for (unsigned c = r; c < 3; ++c) {
      GiNaC::ex dot = 0;
      for (unsigned k = 0; k < 3; ++k) dot += R(k, r) * R(k, c);
      conditions.emplace_back(dot - (r == c ? 1 : 0), "its columns are not orthonormal (R^T R != I)");
    }
  conditions.emplace_back(R.determinant() - 1, "its determinant is not 1 (a reflection or a singular matrix)");
  const auto random_values = [&](const GiNaC::ex& e, unsigned seed) {
    GiNaC::exmap values;
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> draw(0.3, 1.7);
    std::set<GiNaC::ex, GiNaC::ex_is_less> free;
    std::vector<GiNaC::ex> stack{e};
    while (!stack.empty()) {
      const GiNaC::ex x = stack.back();
      stack.pop_back();
      if (GiNaC::is_a<GiNaC::symbol>(x)) {
        if (!program.is_intermediate(x)) free.insert(x);
        if (const auto d = program.definition_of(x)) stack.push_back(*d);
        continue;
      }
      for (std::size_t i = 0; i < x.nops(); ++i) stack.push_back(x.op(i));
    }
    for (const GiNaC::ex& s : free) values[s] = draw(random);
    return program.evaluate(values);
  };
  for (const auto& [deviation, why] : conditions) {
    const GiNaC::ex d = deviation.expand();
    if (GiNaC::is_a<GiNaC::numeric>(d)) {
      if (GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(d)) > GiNaC::numeric(1, 1000000)) return why;
      continue;
    }
    const Identity zero = identically_zero(deviation, program);
    if (zero == Identity::nonzero) return why;
    if (zero == Identity::zero) continue;
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const GiNaC::ex v = deviation.subs(random_values(deviation, seed)).evalf();
      if (GiNaC::is_a<GiNaC::numeric>(v) && GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(v)) > GiNaC::numeric(1, 1000000))
        return why;
    }
  }
  return "";
}

// A rigid body of a model in general coordinates (key `bodies` beside `coordinates`): inertial data in its
// own frame and its pose (R(q, t), p(q, t)) as expressions; its kinetic energy (model/body_energy.hpp).
GiNaC::ex Loader::load_posed_body(Model& model, const YAML::Node& body, const std::string& key,
                                  const GiNaC::symtab& table, std::string& name) {
  const std::string allowed = "a body's pose and inertia may use coordinates, parameters, t and definitions of these";
  const RigidBody rb =
      rigid_body(body, key, table, {"name", "mass", "com", "inertia", "position"}, allowed, {"rotation"});
  name = rb.name;
  check_rigid_body(body, key, rb, model);
  // R: a 3x3 matrix, or a product of elementary rotations [[axis, angle], ...] applied left to right.
  GiNaC::matrix R = GiNaC::ex_to<GiNaC::matrix>(GiNaC::unit_matrix(3));
  const YAML::Node rot = body["rotation"];
  const bool elementary = rot && rot.IsSequence() && rot.size() > 0 && rot[0].IsSequence() && rot[0].size() == 2;
  if (!rot) {
  } else if (elementary) {
    for (std::size_t k = 0; k < rot.size(); ++k) {
      const std::string item = key + ".rotation[" + std::to_string(k) + "]";
      if (!rot[k].IsSequence() || rot[k].size() != 2) fail(rot[k], item, "expected [axis, angle] with axis x, y or z");
      const std::string axis = scalar(rot[k][0], item + "[0]");
      if (axis != "x" && axis != "y" && axis != "z")
        fail(rot[k][0], item + "[0]", "expected the axis x, y or z, got " + quote(axis));
      const GiNaC::ex angle = expression(rot[k][1], item + "[1]", table, allowed);
      R = R.mul(rotation_about(axis == "x" ? 0 : axis == "y" ? 1 : 2, angle));
    }
  } else {
    const std::vector<std::vector<GiNaC::ex>> rows = [&] {
      if (!rot.IsSequence() || rot.size() != 3)
        fail(rot, key + ".rotation", "expected a 3x3 matrix (three rows) or a list of [axis, angle] rotations");
      std::vector<std::vector<GiNaC::ex>> r;
      for (std::size_t i = 0; i < 3; ++i)
        r.push_back(vector_of(rot[i], key + ".rotation[" + std::to_string(i) + "]", 3, table, allowed));
      return r;
    }();
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = 0; j < 3; ++j) R(i, j) = rows[i][j];
    if (const std::string problem = rotation_problem(R, model.definitions); !problem.empty())
      fail(rot, key + ".rotation", problem + "; expected a rotation matrix (orthonormal columns, det R = 1)");
  }
  const std::vector<GiNaC::ex> position = vector_of(body["position"], key + ".position", 3, table, allowed);
  PosedBody posed{rb, {}, {}};
  for (unsigned i = 0; i < 3; ++i) {
    posed.position[i] = position[i];
    for (unsigned j = 0; j < 3; ++j) posed.rotation[i][j] = R(i, j);
  }
  model.posed_bodies.push_back(posed);
  return posed_body_kinetic_energy(model, rb, R, position);
}

// A rigid body of a bundle model (key `bodies`): inertial data and its twist; its kinetic energy
// (model/body_energy.hpp).
GiNaC::ex Loader::load_twist_body(Model& model, const YAML::Node& body, const std::string& key,
                                  const GiNaC::symtab& geometric, const GiNaC::symtab& velocities, std::string& name) {
  const RigidBody rb = rigid_body(body, key, geometric, {"name", "mass", "com", "inertia", "twist"},
                                  "mass, com and inertia may use shape coordinates and parameters only");
  check_rigid_body(body, key, rb, model);
  name = rb.name;
  const std::vector<GiNaC::ex> twist =
      vector_of(body["twist"], key + ".twist", 6, velocities,
                "the twist may use the group velocity, shape coordinates, their _dot rates and parameters");
  return twist_body_kinetic_energy(model, rb, twist);
}

void Loader::declare_joints(const YAML::Node& tree, Model& model) {
  if (!tree.IsMap()) fail(tree, "tree", "expected a map with keys base and bodies");
  check_keys(tree, "tree", {"base", "gravity", "bodies"});
  YAML::Node list = tree["bodies"];
  if (!list) fail(tree, "tree.bodies", "missing; expected a list of bodies, each with a joint");
  if (!list.IsSequence() || list.size() == 0) fail(list, "tree.bodies", "expected a non-empty list of bodies");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = "tree.bodies[" + std::to_string(i) + "].joint";
    // A body that is not a map cannot be indexed (yaml-cpp throws on a scalar): test that first.
    if (!list[i].IsMap() || !list[i]["joint"])
      fail(list[i], key, "missing; every body of a tree needs a joint (name, type, axis, offset)");
    YAML::Node joint = list[i]["joint"];
    if (!joint.IsMap() || !joint["name"]) fail(joint, key + ".name", "missing; expected the joint coordinate's name");
    model.coordinates.emplace_back(scalar(joint["name"], key + ".name"));
    declare_name(joint["name"], key + ".name", model.coordinates.back().get_name());
  }
}

// The state Γ = Rᵀ g of a floating base that turns relative to gravity (model.hpp, KinematicTree::gravity): three
// coordinates gravity_x, gravity_y, gravity_z, declared here so that later keys may use them. None when every direction
// the base turns about is parallel to g (an SE2 base under vertical gravity) or the base only translates: Γ = g.
void Loader::declare_gravity_state(const YAML::Node& gravity, const std::string& group, const Model& model) {
  GiNaC::symtab constants;
  for (const auto& p : model.parameters) constants[p.symbol.get_name()] = p.symbol;
  const std::vector<GiNaC::ex> g = vector_of(gravity, "tree.gravity", 3, constants, "gravity may use parameters only");
  bool component[3];  // which components are not identically zero
  for (std::size_t i = 0; i < 3; ++i) component[i] = !g[i].is_zero();
  bool turns = false;  // some angular direction e of the base with e × g ≠ 0
  for (int k : tree_base_directions(group)) {
    if (k >= 3) continue;
    for (int j = 0; j < 3; ++j) turns = turns || (j != k && component[j]);
  }
  if (!turns) return;
  for (const char* axis : {"x", "y", "z"}) {
    const std::string name = std::string("gravity_") + axis;
    declare_name(gravity, "tree.gravity", name);
    gravity_state_.emplace_back(name);
  }
}

// A tree fixed to the world (no `group`): general coordinates q = the joints, quasi-velocities u = q̇.
void Loader::load_fixed_tree(Model& model) {
  const YAML::Node tree = root_["tree"];
  declare_joints(tree, model);
  for (const auto& q : model.coordinates) {
    const std::string rate = q.get_name() + "_dot";
    auto [it, inserted] = declared_.emplace(rate, "tree");
    if (!inserted)
      fail(tree, "tree",
           "the rate '" + rate + "' of joint '" + q.get_name() + "' clashes with the name declared in '" + it->second +
               "'");
    model.rates.emplace_back(rate);
  }
  model.quasi_velocities = model.rates;
  // u = q̇: A = B = I, not stored (n^2 entries: 1.6 GB for a chain of 10 000 joints); the derivation states them.
  model.B_given = true;
  if (YAML::Node ins = root_["inputs"]) model.inputs = name_list(ins, "inputs");
  model.locations["lagrangian"] = model.locations["tree"] = where(tree);
  model.tree = load_tree(tree, model);
  model.lagrangian = 0;  // T − V follows from the bodies in the derivation
  GiNaC::symtab table;
  for (const auto& p : model.parameters) table[p.symbol.get_name()] = p.symbol;
  for (const auto& q : model.coordinates) table[q.get_name()] = q;
  for (const auto& r : model.rates) table[r.get_name()] = r;
  for (const auto& u : model.inputs) table[u.get_name()] = u;
  table["t"] = model.time;
  load_definitions(model, table);
  table = with_definitions(table);
  load_forces(model, table,
              "forces on the joints may use joint coordinates, their _dot rates, parameters, inputs, t and "
              "definitions of these");
  if (root_["wrenches"]) load_wrenches(model, *model.tree, table);
  if (YAML::Node loops = root_["loops"]) {
    model.locations["loops"] = where(loops);
    close_tree_loops(model, load_loops(model, *model.tree));
  }
}

// 'loops': closures of a fixed-base tree, each a connect (a point of a body on a point of another, or of the world)
// or a weld (a frame of a body on a frame of another).
std::vector<TreeLoop> Loader::load_loops(const Model& model, const KinematicTree& tree) {
  const YAML::Node list = root_["loops"];
  if (!list.IsSequence() || list.size() == 0)
    fail(list, "loops", "expected a list of loops, each a map with name, type (connect or weld), body, point, to");
  GiNaC::symtab constants;
  for (const auto& p : model.parameters) constants[p.symbol.get_name()] = p.symbol;
  const std::string allowed = "loop points and rotations are fixed in the bodies: they may use parameters only";
  const std::vector<std::string> bodies = tree_body_names(tree);
  std::vector<std::string> movable(bodies.begin() + 1, bodies.end());
  std::vector<TreeLoop> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = "loops[" + std::to_string(i) + "]";
    const YAML::Node l = list[i];
    if (!l.IsMap()) fail(l, key, "expected a map with name, type (connect or weld), body, point, to");
    check_keys(l, key, {"name", "type", "body", "point", "rotation", "to", "to_point", "to_rotation"});
    for (const char* k : {"name", "type", "body", "to"})
      if (!l[k]) fail(l, key + "." + k, "missing required key of a loop (name, type, body, to)");
    TreeLoop loop;
    loop.where = where(l);
    loop.name = scalar(l["name"], key + ".name");
    const std::string type = scalar(l["type"], key + ".type");
    if (type != "connect" && type != "weld")
      fail(
          l["type"], key + ".type",
          "expected 'connect' (a point on a point: 3 equations) or 'weld' (a frame on a frame: 6), got " + quote(type));
    loop.weld = type == "weld";
    // The closure's equations are named <name>_x, _y, _z (and _rx, _ry, _rz for a weld): declared like any name.
    for (const char* suffix : {"_x", "_y", "_z", "_rx", "_ry", "_rz"}) {
      if (!loop.weld && suffix[1] == 'r') break;
      declare_name(l["name"], key + ".name", loop.name + suffix);
    }
    const std::pair<const char*, std::string*> ends[] = {{"body", &loop.body}, {"to", &loop.to}};
    for (const auto& [k, target] : ends) {
      *target = scalar(l[k], key + "." + k);
      const std::vector<std::string>& allowed_bodies = std::string(k) == "body" ? movable : bodies;
      if (std::find(allowed_bodies.begin(), allowed_bodies.end(), *target) == allowed_bodies.end())
        fail(l[k], key + "." + k,
             quote(*target) + " is not a " + (std::string(k) == "body" ? "moving " : "") + "body of the tree" +
                 did_you_mean(*target, allowed_bodies) + "; expected one of: " + join(allowed_bodies));
    }
    if (loop.body == loop.to)
      fail(l["to"], key + ".to", "a loop joins two different bodies; both are " + quote(loop.to));
    if (l["point"]) {
      const std::vector<GiNaC::ex> v = vector_of(l["point"], key + ".point", 3, constants, allowed);
      for (std::size_t c = 0; c < 3; ++c) loop.point[c] = v[c];
    }
    if (l["to_point"]) loop.to_point = vector_of(l["to_point"], key + ".to_point", 3, constants, allowed);
    for (const char* k : {"rotation", "to_rotation"}) {
      const YAML::Node rot = l[k];
      if (!rot) continue;
      if (!loop.weld) fail(rot, key + "." + k, "a connect holds points only; a frame's rotation belongs to a weld");
      if (!rot.IsSequence() || rot.size() != 3) fail(rot, key + "." + k, "expected 3 rows of a 3x3 rotation");
      std::vector<GiNaC::ex> entries;
      for (std::size_t r = 0; r < 3; ++r)
        for (const GiNaC::ex& e :
             vector_of(rot[r], key + "." + k + "[" + std::to_string(r) + "]", 3, constants, allowed))
          entries.push_back(e);
      for (std::size_t r = 0; r < 3; ++r)  // RᵀR = I where numbers decide it
        for (std::size_t c = 0; c < 3; ++c) {
          GiNaC::ex dot = 0;
          for (std::size_t m = 0; m < 3; ++m) dot += entries[3 * m + r] * entries[3 * m + c];
          const GiNaC::ex dev = (dot - (r == c ? 1 : 0)).expand();
          if (GiNaC::is_a<GiNaC::numeric>(dev) &&
              GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(dev)) > GiNaC::numeric(1, 1000000))
            fail(rot, key + "." + k, "expected a rotation matrix (orthonormal columns, R^T R = I)");
        }
      if (std::string(k) == "rotation")
        for (std::size_t r = 0; r < 3; ++r)
          for (std::size_t c = 0; c < 3; ++c) loop.rotation[r][c] = entries[3 * r + c];
      else
        loop.to_rotation = entries;
    }
    out.push_back(loop);
  }
  return out;
}

KinematicTree Loader::load_tree(const YAML::Node& tree, Model& model, const Bundle* bundle) {
  KinematicTree out;
  // Inertial data and joint geometry are constant: parameters only (the joints move the bodies).
  GiNaC::symtab constants;
  for (const auto& p : model.parameters) constants[p.symbol.get_name()] = p.symbol;
  const std::string inertial = "mass, com and inertia of a tree body may use parameters only";
  YAML::Node base = tree["base"];
  if (!base) fail(tree, "tree.base", "missing; expected the base body (name, mass, com, inertia)");
  const GiNaC::exmap defaults = parameter_defaults(model);
  auto check_body = [&](const YAML::Node& node, const std::string& key, const RigidBody& body) {
    std::string subkey;
    if (const std::string problem = rigid_body_problem(body, defaults, subkey); !problem.empty())
      fail(node[subkey], key + "." + subkey, problem);
  };
  if (!bundle_) {
    if (!base.IsScalar() || base.Scalar() != "world")
      fail(base, "tree.base",
           "expected 'world' (a model without 'group' is fixed to the world; a floating base needs 'group')");
    out.fixed_base = true;
    out.base.name = "world";
    out.base.mass = 0;
    for (int i = 0; i < 3; ++i) {
      out.base.com[i] = 0;
      for (int j = 0; j < 3; ++j) out.base.inertia[i][j] = 0;
    }
  } else {
    out.base = rigid_body(base, "tree.base", constants, {"name", "mass", "com", "inertia"}, inertial);
    check_body(base, "tree.base", out.base);
  }
  if (YAML::Node g = tree["gravity"]) {
    gravity_location_ = where(g);
    const std::vector<GiNaC::ex> gv = vector_of(g, "tree.gravity", 3, constants, "gravity may use parameters only");
    for (int i = 0; i < 3; ++i) out.gravity[i] = gv[static_cast<std::size_t>(i)];
    out.gravity_state = gravity_state_;
    model.locations["tree.gravity"] = gravity_location_;
  }
  std::vector<std::string> names{out.base.name};
  std::map<std::string, int> position{{out.base.name, 0}};  // name -> index in `names` (a lookup per body)
  const YAML::Node list = tree["bodies"];
  const std::string geometry = "joint axes, offsets and rotations may use parameters only";
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = "tree.bodies[" + std::to_string(i) + "]";
    TreeBody tb;
    tb.body = rigid_body(list[i], key, constants, {"name", "parent", "joint", "mass", "com", "inertia"}, inertial);
    check_body(list[i], key, tb.body);
    if (position.count(tb.body.name))
      fail(list[i]["name"], key + ".name", "the body '" + tb.body.name + "' is listed twice");
    const std::string parent = scalar(list[i]["parent"], key + ".parent");
    const auto it = position.find(parent);
    if (it == position.end())
      fail(list[i]["parent"], key + ".parent",
           quote(parent) + " is not an earlier body" + did_you_mean(parent, names) +
               "; expected the base or a body listed before this one: " + join(names));
    tb.parent = it->second - 1;
    position.emplace(tb.body.name, static_cast<int>(names.size()));
    names.push_back(tb.body.name);

    const YAML::Node joint = list[i]["joint"];
    const std::string jkey = key + ".joint";
    check_keys(joint, jkey,
               {"name", "type", "axis", "offset", "rotation", "armature", "damping", "stiffness", "reference"});
    for (const char* k : {"type", "axis", "offset"})
      if (!joint[k]) fail(joint, jkey + "." + k, "missing required key of a joint");
    const std::string type = scalar(joint["type"], jkey + ".type");
    if (type != "revolute" && type != "prismatic")
      fail(joint["type"], jkey + ".type", "expected 'revolute' or 'prismatic', got " + quote(type));
    tb.prismatic = type == "prismatic";
    tb.coordinate = model.coordinates[i];
    const std::vector<GiNaC::ex> axis = vector_of(joint["axis"], jkey + ".axis", 3, constants, geometry);
    const std::vector<GiNaC::ex> offset = vector_of(joint["offset"], jkey + ".offset", 3, constants, geometry);
    for (std::size_t k = 0; k < 3; ++k) {
      tb.axis[k] = axis[k];
      tb.offset[k] = offset[k];
    }
    const GiNaC::ex norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).expand();
    if (GiNaC::is_a<GiNaC::numeric>(norm) &&
        GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(norm) - 1) > GiNaC::numeric(1, 1000000))
      fail(joint["axis"], jkey + ".axis",
           "expected a unit vector (its squared length is " +
               std::to_string(GiNaC::ex_to<GiNaC::numeric>(norm).to_double()) + ")");
    if (const std::string problem = joint_axis_problem(tb, defaults); !problem.empty())
      fail(joint["axis"], jkey + ".axis", problem);
    const std::pair<const char*, GiNaC::ex*> properties[] = {{"armature", &tb.armature},
                                                             {"damping", &tb.damping},
                                                             {"stiffness", &tb.stiffness},
                                                             {"reference", &tb.reference}};
    for (const auto& [k, target] : properties)
      if (YAML::Node v = joint[k]) {
        *target = expression(v, jkey + "." + k, constants,
                             "joint armature, damping, stiffness and reference may use parameters only");
        if (std::string(k) == "reference") continue;
        if (const std::string problem = joint_property_problem(*target, defaults, k); !problem.empty())
          fail(v, jkey + "." + k, problem);
      }
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) tb.rotation[r][c] = r == c ? 1 : 0;
    if (YAML::Node rot = joint["rotation"]) {
      if (!rot.IsSequence() || rot.size() != 3) fail(rot, jkey + ".rotation", "expected 3 rows of a 3x3 rotation");
      for (std::size_t r = 0; r < 3; ++r) {
        const std::vector<GiNaC::ex> row =
            vector_of(rot[r], jkey + ".rotation[" + std::to_string(r) + "]", 3, constants, geometry);
        for (std::size_t c = 0; c < 3; ++c) tb.rotation[r][c] = row[c];
      }
      // RᵀR = I where it can be decided (numbers): a scaled or sheared frame is a modelling error.
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) {
          GiNaC::ex dot = 0;
          for (std::size_t k = 0; k < 3; ++k) dot += tb.rotation[k][r] * tb.rotation[k][c];
          const GiNaC::ex dev = (dot - (r == c ? 1 : 0)).expand();
          if (GiNaC::is_a<GiNaC::numeric>(dev) &&
              GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(dev)) > GiNaC::numeric(1, 1000000))
            fail(rot, jkey + ".rotation", "expected a rotation matrix (orthonormal columns, R^T R = I)");
        }
    }
    out.bodies.push_back(tb);
  }
  // A massless body, a point mass on its joint's axis, coaxial joints on a massless link: M singular everywhere,
  // which the derivation cannot see through its intermediates and emit met as "matrix::inverse(): singular matrix".
  // Not with loops: the tree's M may then be singular and the loops' constrained one regular (a massless body welded
  // to another, tests/loops/four_bar_weld.yaml).
  if (root_["loops"]) return out;
  std::vector<int> directions;
  std::vector<std::string> direction_names;
  if (bundle) {
    directions = tree_base_directions(bundle->group);
    for (const auto& v : bundle->group_velocity) direction_names.push_back(v.get_name());
  }
  int singular = -1;
  if (const std::string problem = tree_mass_matrix_problem(model, out, directions, direction_names, singular);
      !problem.empty()) {
    if (singular == -2) fail(base, "tree.base", problem);
    fail(list[static_cast<std::size_t>(singular)]["joint"], "tree.bodies[" + std::to_string(singular) + "].joint",
         problem);
  }
  return out;
}

}  // namespace

Model load_model_from_text(const std::string& text, const std::string& path) {
  Loader loader(text, path);
  return loader.load();
}

std::string read_input_file(const std::string& path, const std::string& what) {
  note_input_file(path, "the " + what);  // no output of this run may replace it
  return InputFile(path, what, kMaxInputFileBytes).read_all();
}

Model load_model(const std::string& path) { return load_model_from_text(read_input_file(path, "model file"), path); }

}  // namespace hamel
