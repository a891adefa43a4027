#include "emit/cpp_emitter.hpp"

#include "algebra/expression_text.hpp"

#include "model/input_error.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string_view>

#ifndef HAMEL_VERSION
#define HAMEL_VERSION "unknown"
#endif

namespace hamel {

const char* generator_version() { return HAMEL_VERSION; }

namespace {

// Shortest decimal that reads back to the same double, always spelled as a floating literal.
std::string literal(double v) {
  if (std::isnan(v)) return "NAN";
  if (std::isinf(v)) return v > 0 ? "HUGE_VAL" : "-HUGE_VAL";
  std::string s = shortest_decimal(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return "real(" + s + ")";
}

const char* function_name(Op op) {
  switch (op) {
    case Op::sqrt:
      return "std::sqrt";
    case Op::sin:
      return "std::sin";
    case Op::cos:
      return "std::cos";
    case Op::tan:
      return "std::tan";
    case Op::exp:
      return "std::exp";
    case Op::log:
      return "std::log";
    case Op::asin:
      return "std::asin";
    case Op::acos:
      return "std::acos";
    case Op::atan:
      return "std::atan";
    case Op::sinh:
      return "std::sinh";
    case Op::cosh:
      return "std::cosh";
    case Op::tanh:
      return "std::tanh";
    case Op::abs:
      return "std::fabs";
    case Op::pow:
      return "std::pow";
    default:
      return nullptr;
  }
}

const char* argument_name(Argument a) {
  switch (a) {
    case Argument::time:
      return "t";
    case Argument::state:
      return "x";
    case Argument::parameter:
      return "p";
    case Argument::input:
      return "in";
  }
  return "";
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Text from outside (the model file's name) made safe to print inside a // or /* */ comment: only
// letters, digits and . _ + - , = @ % : ~ ( ) and space are kept, anything else becomes '_'. So no
// newline, no backslash (line splice), no '?' (the trigraph ??/ is a backslash before C++17), no '*'
// or '/' (comment delimiters) and no control or non-ASCII byte can reach the emitted code.
std::string comment_safe(const std::string& text) {
  std::string s;
  for (char c : text) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) ||
                      std::string_view("._+-,=@%:~() ").find(c) != std::string_view::npos;
    s += keep && c != '\0' ? c : '_';
  }
  return s;
}

struct Sizes {
  int n_q, n_u, n_x, n_p, n_in;
};

std::string signature(const Kernel& k) {
  return "void " + k.name + "(real t, const real* x, const real* p, const real* in, real* out)";
}

std::string print_kernel(const ExpressionGraph& g, const Kernel& k, const Sizes& s) {
  const std::vector<int> order = g.schedule(k.outputs);
  const OpCounts c = g.count(order);
  std::map<int, std::string> name;  // node -> operand text
  bool uses[4] = {false, false, false, false};
  std::ostringstream body;
  int work = 0;
  for (int i : order) {
    const Node& n = g.node(i);
    if (n.op == Op::constant) {
      name[i] = literal(n.value);
      continue;
    }
    if (n.op == Op::input) {
      uses[static_cast<int>(n.argument)] = true;
      name[i] = n.argument == Argument::time
                    ? std::string("t")
                    : std::string(argument_name(n.argument)) + "[" + std::to_string(n.index) + "]";
      continue;
    }
    const std::string a = name.at(n.a);
    std::string rhs;
    switch (n.op) {
      case Op::add:
        rhs = a + " + " + name.at(n.b);
        break;
      case Op::sub:
        rhs = a + " - " + name.at(n.b);
        break;
      case Op::mul:
        rhs = a + " * " + name.at(n.b);
        break;
      case Op::div:
        rhs = a + " / " + name.at(n.b);
        break;
      case Op::neg:
        rhs = "-" + a;
        break;
      case Op::pow:
        rhs = std::string(function_name(n.op)) + "(" + a + ", " + name.at(n.b) + ")";
        break;
      default:
        rhs = std::string(function_name(n.op)) + "(" + a + ")";
        break;
    }
    const std::string w = "w" + std::to_string(work++);
    body << "  const real " << w << " = " << rhs << ";\n";
    name[i] = w;
  }
  for (std::size_t o = 0; o < k.outputs.size(); ++o)
    body << "  out[" << o << "] = " << name.at(k.outputs[o]) << ";  // " << k.output_names[o] << "\n";

  std::ostringstream os;
  os << "/* " << k.name << ": (t, x[" << s.n_x << "], p[" << s.n_p << "], in[" << s.n_in << "]) -> out["
     << k.outputs.size() << "]  ops: " << c.add << " add, " << c.mul << " mul, " << c.div << " div, " << c.call
     << " call */\n";
  os << signature(k) << " {\n";
  static const char* args[4] = {"t", "x", "p", "in"};
  for (int a = 0; a < 4; ++a)
    if (!uses[a]) os << "  (void)" << args[a] << ";\n";
  if (k.outputs.empty()) os << "  (void)out;\n";
  os << body.str() << "}\n";
  return os.str();
}

template <class T, class F>
std::string array_decl(const std::string& type, const std::string& name, const std::vector<T>& items, F format) {
  if (items.empty()) return "// " + name + ": none\n";
  std::string s = "constexpr " + type + " " + name + "[" + std::to_string(items.size()) + "] = {";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + format(items[i]);
  return s + "};\n";
}

}  // namespace

EmittedPackage emit_cpp(const Model& model, const Derivation& derivation, const KernelSet& kernels) {
  const HamelEquations& eq = derivation.equations;
  const Sizes s{static_cast<int>(model.n()), static_cast<int>(eq.independent.size()),
                static_cast<int>(model.n() + eq.independent.size()), static_cast<int>(model.parameters.size()),
                static_cast<int>(model.inputs.size())};
  const std::string file = comment_safe(std::filesystem::path(model.source_path).filename().string());
  const std::string stamp = "// Generated by hamel " + std::string(generator_version()) + " from " + file +
                            " (FNV-1a 64: " + model.source_hash +
                            "). Do not edit.\n"
                            "// SPDX-License-Identifier: MIT\n"
                            "// Emitted code is under the MIT licence, whatever the generator's licence.\n";
  const std::string guard_macro = "HAMEL_" + upper(model.name) + "_REAL";
  auto quoted = [](const std::string& x) { return "\"" + x + "\""; };
  auto str = [](int x) { return std::to_string(x); };

  std::vector<std::string> coordinate_names, velocity_names, parameter_names, input_names, constraint_names,
      state_names;
  for (const auto& q : model.coordinates) coordinate_names.push_back(q.get_name());
  for (int I : eq.independent) velocity_names.push_back(model.quasi_velocities[static_cast<std::size_t>(I)].get_name());
  for (const auto& p : model.parameters) parameter_names.push_back(p.symbol.get_name());
  for (const auto& u : model.inputs) input_names.push_back(u.get_name());
  for (int a : model.constrained)
    constraint_names.push_back(model.quasi_velocities[static_cast<std::size_t>(a)].get_name());
  state_names = coordinate_names;
  state_names.insert(state_names.end(), velocity_names.begin(), velocity_names.end());
  std::vector<double> defaults;
  for (const auto& p : model.parameters) defaults.push_back(p.default_value);
  std::vector<int> upper_index, lower_a, lower_b;
  for (const auto& h : derivation.hamel) {
    upper_index.push_back(h.upper);
    lower_a.push_back(h.lower_a);
    lower_b.push_back(h.lower_b);
  }

  std::ostringstream h;
  h << stamp << "//\n"
    << "// Kernel ABI: every kernel is\n"
    << "//   void name(real t, const real* x, const real* p, const real* in, real* out);\n"
    << "// t: time; x: state (q^1..q^n, then the independent quasi-velocities u^I), n_state entries;\n"
    << "// p: parameters (n_parameters, defaults in default_parameters); in: inputs (n_inputs, may be null\n"
    << "// when n_inputs == 0); out: the kernel's outputs (sizes below). Kernels are flat and branch-free;\n"
    << "// they allocate nothing, throw nothing and need only <cmath>. Define " << guard_macro << "\n"
    << "// (e.g. to float) before including this header to change the scalar type.\n"
    << "#pragma once\n\n"
    << "#ifndef " << guard_macro << "\n#define " << guard_macro << " double\n#endif\n\n"
    << "namespace " << model.name << " {\n\n"
    << "using real = " << guard_macro << ";\n\n"
    << "constexpr int n_coordinates = " << s.n_q << ";\n"
    << "constexpr int n_independent = " << s.n_u << ";  // independent quasi-velocities u^I\n"
    << "constexpr int n_state = " << s.n_x << ";\n"
    << "constexpr int n_parameters = " << s.n_p << ";\n"
    << "constexpr int n_inputs = " << s.n_in << ";\n"
    << "constexpr int n_constraints = " << constraint_names.size() << ";\n"
    << "constexpr int n_hamel = " << derivation.hamel.size() << ";  // non-zero Hamel coefficients\n"
    << "constexpr bool conservative = " << (eq.conservative ? "true" : "false") << ";  // energy() is an invariant\n\n"
    << array_decl("const char*", "state_names", state_names, quoted)
    << array_decl("const char*", "parameter_names", parameter_names, quoted)
    << array_decl("double", "default_parameters", defaults,
                  [](double v) {
                    std::string l = literal(v);
                    return l.substr(5, l.size() - 6);
                  })
    << array_decl("const char*", "input_names", input_names, quoted)
    << array_decl("const char*", "constraint_names", constraint_names, quoted)
    << "// gamma^upper_{lower_a lower_b}: indices into all quasi-velocities, in file order\n"
    << array_decl(
           "const char*", "quasi_velocity_names",
           [&] {
             std::vector<std::string> v;
             for (const auto& u : model.quasi_velocities) v.push_back(u.get_name());
             return v;
           }(),
           quoted)
    << array_decl("int", "hamel_upper", upper_index, str) << array_decl("int", "hamel_lower_a", lower_a, str)
    << array_decl("int", "hamel_lower_b", lower_b, str) << "\n";
  for (const Kernel& k : kernels.kernels)
    h << "/// " << k.summary << "; out[" << k.outputs.size() << "]\n" << signature(k) << ";\n";
  h << "\n}  // namespace " << model.name << "\n";

  std::ostringstream c;
  c << stamp << "#include \"" << model.name << ".hpp\"\n\n#include <cmath>\n\nnamespace " << model.name << " {\n";
  for (const Kernel& k : kernels.kernels) c << "\n" << print_kernel(kernels.graph, k, s);
  c << "\n}  // namespace " << model.name << "\n";

  return {model.name + ".hpp", h.str(), model.name + ".cpp", c.str()};
}

namespace {

// An existing output folder is replaced only if it holds nothing but files an earlier emit wrote (first
// line "// Generated by hamel ..."): pointing -o at a folder of one's own must not delete it.
void check_replaceable(const std::filesystem::path& target) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(target, ec);
  if (ec || !fs::exists(status)) return;
  if (!fs::is_directory(status))
    throw InputError("-o: " + quote(target.string()) + " exists and is not a folder" +
                     (fs::is_symlink(status) ? " (a symbolic link)" : "") +
                     "; expected a new folder or one written by an earlier emit");
  for (const fs::directory_entry& entry : fs::directory_iterator(target, ec)) {
    std::string first_line;
    if (entry.is_regular_file(ec) && !entry.is_symlink(ec)) {
      std::ifstream in(entry.path(), std::ios::binary);
      std::getline(in, first_line);
    }
    if (first_line.rfind("// Generated by hamel", 0) != 0)
      throw InputError("-o: " + quote(target.string()) + " holds " + quote(entry.path().filename().string()) +
                       ", which hamel did not write; refusing to replace the folder (expected a new folder or one "
                       "written by an earlier emit)");
  }
  if (ec) throw InputError("-o: cannot read " + quote(target.string()) + ": " + ec.message());
}

}  // namespace

void write_package(const EmittedPackage& package, const std::string& directory) {
  namespace fs = std::filesystem;
  fs::path target = fs::path(directory).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "out/" -> "out"
  if (target.empty() || target.filename() == "." || target.filename() == ".." || target == target.root_path())
    throw InputError("-o: " + quote(directory) + " is not a folder hamel can replace; expected a folder name");
  check_replaceable(target);
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw InputError("-o: cannot create " + quote(parent.string()) + ": " + ec.message());
  const std::string tag = std::to_string(std::random_device{}());
  const fs::path staging = parent / (target.filename().string() + ".tmp-" + tag);
  const fs::path old = parent / (target.filename().string() + ".old-" + tag);
  auto cannot = [&](const fs::path& what, const std::error_code& why) {
    return InputError("-o: cannot write " + quote(what.string()) + (why ? ": " + why.message() : std::string()));
  };
  if (!fs::create_directory(staging, ec) || ec) throw cannot(staging, ec);
  try {
    for (const auto& [name, text] :
         {std::pair{package.header_name, &package.header}, std::pair{package.source_name, &package.source}}) {
      std::ofstream out(staging / name, std::ios::binary);
      out << *text;
      out.close();
      if (!out) throw cannot(staging / name, {});
    }
    if (fs::exists(fs::symlink_status(target))) {
      fs::rename(target, old, ec);
      if (ec) throw cannot(target, ec);
      fs::rename(staging, target, ec);
      if (ec) {
        std::error_code ignored;
        fs::rename(old, target, ignored);  // put the previous package back
        throw cannot(target, ec);
      }
      fs::remove_all(old, ec);  // the new package is in place; a leftover of the old one is only untidy
    } else {
      fs::rename(staging, target, ec);
      if (ec) throw cannot(target, ec);
    }
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
}

}  // namespace hamel
