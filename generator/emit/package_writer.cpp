#include "emit/package_writer.hpp"

#include "algebra/expression_text.hpp"
#include "emit/python_module.hpp"
#include "model/fold_parameters.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string_view>

#ifndef HAMEL_VERSION
#define HAMEL_VERSION "unknown"
#endif

namespace hamel {

const char* generator_version() { return HAMEL_VERSION; }

namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

template <class T, class F>
std::string array_decl(const std::string& type, const std::string& name, const std::vector<T>& items, F format) {
  // Every table exists, empty ones as a null pointer (C++ has no arrays of size 0): a generic harness reads
  // name[k] for k below its count without asking first whether the model has any.
  if (items.empty()) return "constexpr " + type + " const* " + name + " = nullptr;  // none\n";
  std::string s = "constexpr " + type + " " + name + "[" + std::to_string(items.size()) + "] = {";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + format(items[i]);
  return s + "};\n";
}

// The fixed-step integrator of the package: classical RK4 on the rhs kernel, in place, with three stack arrays of
// n_state reals (no allocation); inputs are held over the step. The runtime's own rk4_step, printed as it stands
// there (runtime/include/hamel/runtime/rk4.hpp, read at the generator's build by generator/embed_region.cmake).
const char* const rk4_step_text =
#include "emit/rk4_step.inc"
    ;

// Model descriptions are folded YAML text; keep them as one paragraph. They come from the model file, so
// what reaches the package README is made inert: control characters (C0, DEL, and C1 such as U+009B, a
// terminal's CSI) and bidirectional overrides (U+202A..U+202E, U+2066..U+2069) are dropped, and < > & become
// HTML entities, so a description cannot carry terminal sequences, reorder text or inject HTML.
std::string one_paragraph(const std::string& text) {
  std::string out;
  bool space = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char ch = static_cast<unsigned char>(text[i]);
    const unsigned char next = i + 1 < text.size() ? static_cast<unsigned char>(text[i + 1]) : 0;
    const unsigned char third = i + 2 < text.size() ? static_cast<unsigned char>(text[i + 2]) : 0;
    if (ch == '\n' || ch == '\r' || ch == '\t' || ch == ' ') {
      space = !out.empty();
      continue;
    }
    if (ch < 0x20 || ch == 0x7f) continue;
    if (ch == 0xc2 && next >= 0x80 && next <= 0x9f) {  // U+0080..U+009F
      ++i;
      continue;
    }
    if (ch == 0xe2 &&
        ((next == 0x80 && third >= 0xaa && third <= 0xae) || (next == 0x81 && third >= 0xa6 && third <= 0xa9))) {
      i += 2;
      continue;
    }
    if (space) out += ' ';
    space = false;
    if (ch == '<')
      out += "&lt;";
    else if (ch == '>')
      out += "&gt;";
    else if (ch == '&')
      out += "&amp;";
    else
      out += static_cast<char>(ch);
  }
  return out;
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

// The files of one package, each printed by its own member from what the constructor gathers once: sizes,
// names, the kernels as text (emit/package_kernels.hpp), which parameters they read.
class PackageWriter {
 public:
  PackageWriter(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                const EmitSettings& settings);

  std::string header() const;    // <name>.hpp: the ABI, sizes, names and declarations
  std::string source() const;    // <name>.cpp: the kernels, rhs_status, rk4_step, the C entry points
  std::string c_header() const;  // <name>.h: the C entry points
  std::string cmake() const;     // CMakeLists.txt
  std::string readme() const;    // README.md
  /// What the Python module (emit --python, emit/python_module.hpp) prints: the same names, sizes and kernels.
  PythonPackage python_package() const;
  const PackageKernels& printed_kernels() const { return code; }

 private:
  // The header's ABI (its comment, sizes and names), then its kernels' sizes and declarations.
  void header_abi(std::ostream& h) const;
  void header_kernels(std::ostream& h) const;
  // README.md's sections after its head, in order.
  void readme_kernels(std::ostream& md) const;               // the kernels' table, and the prepared ones'
  void readme_layout(std::ostream& md) const;                // x, p and in, element by element
  void readme_integrator(std::ostream& md) const;            // rk4_step, with a loop
  void readme_position_constraints(std::ostream& md) const;  // the projector, with a run
  void readme_build(std::ostream& md) const;                 // with CMake and without
  void readme_python(std::ostream& md) const;                // the Python module (emit --python)
  void readme_bad_input(std::ostream& md) const;             // what kernels return for bad input
  static std::string quoted(const std::string& x) { return "\"" + x + "\""; }
  static std::string str(int x) { return std::to_string(x); }
  // The C signature <name>_<fn>(t, x, p, in, out) with the package's scalar macro.
  // The C entry points' names after the prefix, in order.
  std::vector<std::string> c_functions() const {
    std::vector<std::string> names;
    for (const Kernel& k : kernels.kernels) names.push_back(k.name);
    if (has_rhs) names.push_back("rhs_status");
    if (prepared) {
      names.push_back("prepare_parameters");
      for (const Kernel& k : prepared->kernels) names.push_back(k.name);
    }
    for (const Kernel& k : kernels.kernels) names.push_back(k.name + "_work");
    if (prepared)
      for (const Kernel& k : prepared->kernels) names.push_back(k.name + "_work");
    return names;
  }
  // The work-space form of kernel `name`: <name>_work(t, x, p, in, out, work).
  static std::string work_signature(const std::string& name) {
    return "void " + name + "_work(real t, const real* x, const real* p, const real* in, real* out, real* work)";
  }
  // The work-space form of a kernel printed without one (nothing to keep): the kernel itself.
  static std::string trivial_work(const std::string& name) {
    return work_signature(name) + " {\n  (void)work;\n  " + name + "(t, x, p, in, out);\n}\n";
  }
  std::string c_work_signature(const std::string& fn) const {
    return "void " + prefix + fn + "_work(" + c_real + " t, const " + c_real + "* x, const " + c_real + "* p, const " +
           c_real + "* in, " + c_real + "* out, " + c_real + "* work)";
  }
  std::string c_signature(const std::string& ret, const std::string& fn) const {
    return ret + " " + prefix + fn + "(" + c_real + " t, const " + c_real + "* x, const " + c_real + "* p, const " +
           c_real + "* in, " + c_real + "* out)";
  }

  const Model& model;
  const KernelSet& kernels;
  const HamelEquations& eq;
  const HamelSystem& sys;
  Sizes s;
  std::string file, origin, stamp, guard_macro, library, prefix, c_real, c_name_macro;
  std::vector<std::string> coordinate_names, velocity_names, parameter_names, input_names, constraint_names,
      state_names;
  std::vector<double> defaults;
  std::vector<int> upper_index, lower_a, lower_b;
  std::vector<bool> parameter_used;                // by parameter: some kernel reads it (else it was folded)
  std::vector<int> parameter_jacobian_parameters;  // its columns, indices into p; empty without parameter_jacobian
  bool has_rhs = false, has_group_velocity = false, python = false;
  int group_dimension = 0;  // bundle models: the group's dimension (the connection's rows)
  const std::optional<KernelSet::Prepared>& prepared;
  PackageKernels code;  // the kernels as text
};

PackageWriter::PackageWriter(const Model& model_, const Derivation& derivation_, const KernelSet& kernels_,
                             const EmitSettings& settings)
    : model(model_),
      kernels(kernels_),
      eq(derivation_.equations),
      sys(derivation_.system),
      python(settings.python),
      group_dimension(static_cast<int>(derivation_.group_velocity.size())),
      prepared(kernels_.prepared) {
  const int n_q = static_cast<int>(sys.coordinates.size());
  s = Sizes{n_q, static_cast<int>(eq.independent.size()), n_q + static_cast<int>(eq.independent.size()),
            static_cast<int>(model.parameters.size()), static_cast<int>(model.inputs.size())};
  s.split = settings.split_statements;
  s.calls = !settings.inline_calls;
  file = comment_safe(std::filesystem::path(model.source_path).filename().string());
  origin = "Generated by hamel " + std::string(generator_version()) + " from " + file +
           " (FNV-1a 64: " + model.source_hash +
           (settings.options.empty() ? "" : "; emit " + comment_safe(settings.options)) + "). Do not edit.";
  stamp = "// " + origin +
          "\n"
          "// SPDX-License-Identifier: MIT\n"
          "// Emitted code is under the MIT licence, whatever the generator's licence.\n";
  guard_macro = "HAMEL_" + upper(model.name) + "_REAL";
  library = model.name + "_kernels";
  prefix = model.name + "_";
  c_real = guard_macro;
  c_name_macro = "HAMEL_" + upper(model.name) + "_C_NAME";

  for (const auto& q : sys.coordinates) coordinate_names.push_back(q.get_name());
  for (int I : eq.independent) velocity_names.push_back(sys.velocities[static_cast<std::size_t>(I)].get_name());
  for (const auto& p : model.parameters) parameter_names.push_back(p.symbol.get_name());
  for (const auto& u : model.inputs) input_names.push_back(u.get_name());
  for (int a : sys.constrained) constraint_names.push_back(sys.velocities[static_cast<std::size_t>(a)].get_name());
  state_names = coordinate_names;
  state_names.insert(state_names.end(), velocity_names.begin(), velocity_names.end());
  for (const auto& p : model.parameters) defaults.push_back(p.default_value);
  for (const auto& h : sys.gamma) {
    upper_index.push_back(h.upper);
    lower_a.push_back(h.lower_a);
    lower_b.push_back(h.lower_b);
  }

  code = print_package_kernels(kernels, s, settings);
  parameter_used.assign(defaults.size(), false);
  std::vector<int> all;
  for (const Kernel& k : kernels.kernels) all.insert(all.end(), k.outputs.begin(), k.outputs.end());
  for (int i : kernels.graph.schedule(all)) {
    const Node& n = kernels.graph.node(i);
    const auto index = static_cast<std::size_t>(n.index);
    if (n.op == Op::input && n.argument == Argument::parameter && index < parameter_used.size())
      parameter_used[index] = true;
  }
  for (const Kernel& k : kernels.kernels) {
    has_rhs = has_rhs || k.name == "rhs";
    has_group_velocity = has_group_velocity || k.name == "group_velocity";
    if (k.name == "parameter_jacobian")
      for (std::size_t i : symbolic_parameters(model)) parameter_jacobian_parameters.push_back(static_cast<int>(i));
  }
}

std::string PackageWriter::header() const {
  std::ostringstream h;
  header_abi(h);
  header_kernels(h);
  h << "\n}  // namespace " << model.name << "\n";
  return h.str();
}

void PackageWriter::header_abi(std::ostream& h) const {
  h << stamp << "//\n"
    << "// Kernel ABI: every kernel is\n"
    << "//   void name(real t, const real* x, const real* p, const real* in, real* out);\n"
    << "// t: time; x: state (q^1..q^n, then the independent quasi-velocities u^I), n_state entries;\n"
    << "// equations: " << sys.form << ";\n"
    << "// p: parameters (n_parameters, defaults in default_parameters; parameters folded at generation time\n"
    << "// are ignored, see README.md); in: inputs (n_inputs, may be null when n_inputs == 0); out: the\n"
    << "// kernel's outputs, n_out_<kernel> entries. x, p, in and out must not overlap. Kernels are flat and\n"
    << "// branch-free; they allocate nothing, throw nothing and need only <cmath>. Their stack holds what the\n"
    << "// compiler does not keep in registers of their n_temporaries_<kernel> values (one per operation; not a bound\n"
    << "// on the stack in either direction: hamel's docs/firmware.md has measured figures for Cortex-M).\n"
    << (s.split > 0 ? "// A kernel longer than " + std::to_string(s.split) +
                          " operations is printed as functions <kernel>_part<k> of at most that many,\n"
                          "// called in turn, which pass values in an array of n_work_<kernel> reals: on the stack of\n"
                          "// <kernel>, in the caller's work space for <kernel>_work.\n"
                    : std::string("// Every kernel is printed as one function (emit --split 0).\n"))
    << "// Scalar type: define " << guard_macro << " (e.g. to float) before including this header and\n"
    << "// when compiling " << model.name << ".cpp (CMake: -D" << guard_macro << "=float); the kernels' signatures\n"
    << "// change with it, so a mismatch fails to link instead of running wrong.\n"
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
    << "constexpr int n_hamel = " << sys.gamma.size() << ";  // non-zero Hamel coefficients\n"
    << "constexpr bool conservative = " << (eq.conservative ? "true" : "false") << ";  // energy() is an invariant\n\n"
    << array_decl("const char*", "state_names", state_names, quoted)
    << array_decl("const char*", "parameter_names", parameter_names, quoted)
    << (defaults.empty() ? std::string("constexpr const real* default_parameters = nullptr;  // no parameters\n")
                         : array_decl("real", "default_parameters", defaults, real_literal))
    << array_decl("const char*", "input_names", input_names, quoted)
    << array_decl("const char*", "constraint_names", constraint_names, quoted)
    << "// gamma^upper_{lower_a lower_b}: indices into all quasi-velocities, in file order\n"
    << array_decl(
           "const char*", "quasi_velocity_names",
           [&] {
             std::vector<std::string> v;
             for (const auto& u : sys.velocities) v.push_back(u.get_name());
             return v;
           }(),
           quoted)
    << array_decl("int", "hamel_upper", upper_index, str) << array_decl("int", "hamel_lower_a", lower_a, str)
    << array_decl("int", "hamel_lower_b", lower_b, str) << "\n";
}

void PackageWriter::header_kernels(std::ostream& h) const {
  h << "// Output sizes (out[] entries) and named temporaries of each kernel.\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    h << "constexpr int n_out_" << kernels.kernels[i].name << " = " << kernels.kernels[i].outputs.size()
      << ";\nconstexpr int n_temporaries_" << kernels.kernels[i].name << " = " << code.printed[i].temporaries << ";\n";
  std::size_t largest = 0;
  for (const Kernel& k : kernels.kernels) largest = std::max(largest, k.outputs.size());
  h << "constexpr int n_out_max = " << largest << ";  // the largest out[] of any kernel\n\n";
  if (!parameter_jacobian_parameters.empty())
    h << "// parameter_jacobian's columns: the parameters not folded, as indices into p (parameter_names).\n"
      << "constexpr int n_parameter_jacobian_parameters = " << parameter_jacobian_parameters.size() << ";\n"
      << array_decl("int", "parameter_jacobian_parameters", parameter_jacobian_parameters, str) << "\n";
  for (const Kernel& k : kernels.kernels)
    h << "/// " << k.summary << "; out[" << k.outputs.size() << "]\n" << signature(k) << ";\n";
  h << "\n"
    << "// Work-space forms: <kernel>_work(t, x, p, in, out, work) computes what <kernel> does, bit for bit, keeping "
       "in\n"
    << "// work[n_work_<kernel>] (the caller's, e.g. a static array) the values the parts of a split kernel pass on,\n"
    << "// which <kernel> keeps on its stack. n_work_<kernel> = 0: nothing to keep, and work may be null.\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    h << "constexpr int n_work_" << kernels.kernels[i].name << " = " << code.printed[i].work << ";\n"
      << work_signature(kernels.kernels[i].name) << ";\n";
  h << "\n"
    << "using kernel_function = void (*)(real t, const real* x, const real* p, const real* in, real* out);\n"
    << "using kernel_work_function = void (*)(real t, const real* x, const real* p, const real* in, real* out, "
       "real* work);\n"
    << "struct kernel_info {\n"
    << "  const char* name;\n"
    << "  kernel_function function;\n"
    << "  int n_out;\n"
    << "  int n_temporaries;\n"
    << "  kernel_work_function work_function;  // <name>_work\n"
    << "  int n_work;                          // n_work_<name>\n"
    << "};\n"
    << "constexpr int n_kernels = " << kernels.kernels.size() << ";\n";
  if (!kernels.kernels.empty()) {
    h << "constexpr kernel_info kernel_table[n_kernels] = {\n";
    for (const Kernel& k : kernels.kernels)
      h << "    {\"" << k.name << "\", " << k.name << ", n_out_" << k.name << ", n_temporaries_" << k.name << ", "
        << k.name << "_work, n_work_" << k.name << "},\n";
    h << "};\n";
  }
  if (has_rhs)
    h << "\n"
      << "/// rhs with a status instead of NaN: 0 and out[n_out_rhs] written as by rhs; 1 (out untouched) when the\n"
      << "/// mass matrix (or an articulated inertia of the recursive solve) is not positive definite at "
         "(t, x, p), or\n"
      << "/// 2 when a result is not finite. n_pivots_rhs pivots are checked (0: M inverted at generation time).\n"
      << "constexpr int n_pivots_rhs = " << kernels.rhs_pivots.size() << ";\n"
      << "int rhs_status(real t, const real* x, const real* p, const real* in, real* out);\n";
  if (has_rhs)
    h << "\n"
      << "/// Reals of stack rk4_step uses (three arrays of n_state) besides the rhs kernel's temporaries.\n"
      << "constexpr int rk4_stack_reals = 3 * n_state;\n"
      << "/// One classical fourth-order Runge-Kutta step of size h from (t, x), in place: 4 rhs calls, no\n"
      << "/// allocation; the inputs `in` are held over the step (zero-order hold). For a control loop.\n"
      << "void rk4_step(real t, real h, real* x, const real* p, const real* in);\n";
  if (prepared) {
    h << "\n"
      << "// Prepared parameters: the parameter-only work of rhs"
      << (prepared->kernels.size() > 1 ? " and jacobian" : "")
      << " done once per parameter set (rhs: " << prepared->rhs.total()
      << " operations per call, rhs_prepared: " << prepared->rhs_prepared.total()
      << ", prepare_parameters: " << prepared->once.total() << ").\n"
      << "// prepare_parameters(p, P) writes P[n_prepared_parameters]: p itself, then the derived values; each\n"
      << "// <kernel>_prepared(t, x, P, in, out) then equals <kernel>(t, x, p, in, out), without that work. Call it\n"
      << "// again whenever p changes. Not in kernel_table (their p is P, longer than n_parameters).\n"
      << "constexpr int n_prepared_parameters = " << code.n_prepared << ";\n"
      << "void prepare_parameters(const real* p, real* prepared);\n";
    for (std::size_t i = 0; i < prepared->kernels.size(); ++i)
      h << "constexpr int n_temporaries_" << prepared->kernels[i].name << " = " << code.prepared[i].temporaries
        << ";\n/// " << prepared->kernels[i].summary << "; out[" << prepared->kernels[i].outputs.size() << "]\n"
        << signature(prepared->kernels[i]) << ";\n"
        << "constexpr int n_work_" << prepared->kernels[i].name << " = " << code.prepared[i].work << ";\n"
        << work_signature(prepared->kernels[i].name) << ";\n";
  }
}

std::string PackageWriter::source() const {
  std::ostringstream c;  // everything after the includes
  c << "\nnamespace " << model.name << " {\n";
  if (!code.stage_text.empty()) c << "\nnamespace {\n\n" << code.stage_text << "}  // namespace\n";
  if (!code.rhs_with_pivots.empty()) c << "\nnamespace {\n\n" << code.rhs_with_pivots << "\n}  // namespace\n";
  for (const PrintedKernel& k : code.printed) c << "\n" << k.text << (k.work > 0 ? "" : "\n" + trivial_work(k.name));
  if (has_rhs) {
    // The checks are in rhs_status, outside the branch-free kernel.
    c << "\nint rhs_status(real t, const real* x, const real* p, const real* in, real* out) {\n"
      << "  real all[n_out_rhs];\n";
    if (code.rhs_with_pivots.empty()) {
      c << "  rhs(t, x, p, in, all);\n";
    } else {
      c << "  real pivots[n_pivots_rhs];\n"
        << "  rhs_with_pivots(t, x, p, in, all, pivots);\n"
        << "  for (int i = 0; i < n_pivots_rhs; ++i)\n"
        << "    if (!(pivots[i] > real(0)) || !std::isfinite(pivots[i])) return 1;\n";
    }
    c << "  for (int i = 0; i < n_out_rhs; ++i)\n"
      << "    if (!std::isfinite(all[i])) return 2;\n"
      << "  for (int i = 0; i < n_out_rhs; ++i) out[i] = all[i];\n"
      << "  return 0;\n"
      << "}\n";
    c << "\n" << rk4_step_text;
  }
  if (prepared) {
    c << "\nnamespace {\n\n"
      << code.prepare_text << "\n"
      << code.prepared_stage_text << "}  // namespace\n\n"
      << "void prepare_parameters(const real* p, real* prepared) {\n"
      << "  prepare_parameters_kernel(real(0), nullptr, p, nullptr, prepared);\n"
      << "}\n";
    for (const PrintedKernel& k : code.prepared) c << "\n" << k.text << (k.work > 0 ? "" : "\n" + trivial_work(k.name));
  }
  c << "\n}  // namespace " << model.name << "\n";
  c << "\nextern \"C\" {\n\n";
  for (const Kernel& k : kernels.kernels)
    c << c_signature("void", k.name) << " { " << model.name << "::" << k.name << "(t, x, p, in, out); }\n";
  if (has_rhs)
    c << c_signature("int", "rhs_status") << " { return " << model.name << "::rhs_status(t, x, p, in, out); }\n";
  if (prepared) {
    c << "void " << prefix << "prepare_parameters(const " << c_real << "* p, " << c_real << "* prepared) { "
      << model.name << "::prepare_parameters(p, prepared); }\n";
    for (const Kernel& k : prepared->kernels)
      c << c_signature("void", k.name) << " { " << model.name << "::" << k.name << "(t, x, p, in, out); }\n";
  }
  for (const Kernel& k : kernels.kernels)
    c << c_work_signature(k.name) << " { " << model.name << "::" << k.name << "_work(t, x, p, in, out, work); }\n";
  if (prepared)
    for (const Kernel& k : prepared->kernels)
      c << c_work_signature(k.name) << " { " << model.name << "::" << k.name << "_work(t, x, p, in, out, work); }\n";
  c << "\n}  // extern \"C\"\n";
  const std::string body = c.str();
  // GCC passes that find nothing to improve in branch-free kernels on x86-64 and cost a long straight-line function
  // compile time out of proportion to its length: partial redundancy elimination (no branch makes a redundancy
  // partial; value numbering removes the full ones), dead store elimination (the printer writes each slot once before
  // it is read), points-to analysis (the kernels' pointers are arguments it cannot tell apart), value ranges and
  // straight-line strength reduction (integer work; the kernels' is floating point), CSE rerun after the loop passes
  // (no loops), mod/ref summaries of the parts (called once each, with pointer arguments), and the second scheduling
  // pass (an out-of-order core reorders by itself). The 30-joint chain's package at --share-ratio 32: g++ -O2 about
  // 18 -> 14 s, every kernel bit-identical and within the host's spread (docs/emit.md). x86-64 only: the firmware
  // targets keep the code docs/firmware.md measured. -fipa-modref is GCC 11's; an older GCC would warn.
  static const std::string unused_passes =
      "// Passes that buy branch-free kernels nothing on x86-64 and cost large packages compile time (GCC; "
      "docs/emit.md).\n"
      "#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)\n"
      "#pragma GCC optimize(\"no-tree-pre\", \"no-tree-dse\", \"no-dse\", \"no-tree-pta\", \"no-tree-vrp\", "
      "\"no-tree-slsr\", \"no-rerun-cse-after-loop\", \"no-schedule-insns2\")\n"
      "#if __GNUC__ >= 11\n#pragma GCC optimize(\"no-ipa-modref\")\n#endif\n#endif\n";
  // GCC's first scheduling pass (on at -O2 for Arm, off for x86-64) moves a long straight-line function's loads far
  // ahead of their uses, where they wait in stack spills: the Whipple bicycle's jacobian parts took 5.1 KB of stack
  // each in double on a Cortex-M7, 2.1 KB without the pass (docs/firmware.md). Off for the package's functions; on
  // x86-64 the objects are byte-identical.
  const std::string includes = stamp + "#include \"" + model.name + ".hpp\"\n#include \"" + model.name +
                               ".h\"\n\n#include <cmath>\n\n"
                               "// Keeps the stack of long kernels small on in-order cores (GCC; docs/firmware.md).\n"
                               "#if defined(__GNUC__) && !defined(__clang__)\n"
                               "#pragma GCC optimize(\"no-schedule-insns\")\n#endif\n" +
                               unused_passes;
  // The macro emit/kernel_printer.cpp puts before long internal functions, defined where the compiler has a way,
  // when some function uses it
  const std::string noinline =
      body.find("HAMEL_NOINLINE ") == std::string::npos
          ? ""
          : "\n#ifndef HAMEL_NOINLINE\n#if defined(__GNUC__)\n#define HAMEL_NOINLINE __attribute__((noinline))\n"
            "#elif defined(_MSC_VER)\n#define HAMEL_NOINLINE __declspec(noinline)\n#else\n#define HAMEL_NOINLINE\n"
            "#endif\n#endif\n";
  return includes + noinline + body;
}

std::string PackageWriter::c_header() const {
  // The C ABI: extern "C" entry points <name>_<kernel> beside the namespace, declared in <name>.h (C11).
  std::ostringstream ch;
  ch << stamp << "//\n"
     << "// C entry points of the " << model.name << " kernels (C99/C11 or C++): " << prefix
     << "<kernel>(t, x, p, in, out) with the\n"
     << "// arguments and sizes of " << model.name << ".hpp (documented there); link the same library.\n"
     << "#ifndef HAMEL_" << upper(model.name) << "_H\n#define HAMEL_" << upper(model.name) << "_H\n\n"
     << "#ifndef " << guard_macro << "\n#define " << guard_macro << " double\n#endif\n\n"
     << "/* The linked name of every entry point carries the scalar type: " << prefix << "rhs is the symbol " << prefix
     << "rhs_double,\n"
     << "   or " << prefix << "rhs_float when " << guard_macro
     << " is float. A caller built with another type than the library\n"
     << "   then fails to link instead of passing doubles where floats are read. " << guard_macro
     << " must be one token\n"
     << "   (float or double). */\n"
     << "#define " << c_name_macro << "(f) " << c_name_macro << "_EXPAND(f, " << guard_macro << ")\n"
     << "#define " << c_name_macro << "_EXPAND(f, r) " << c_name_macro << "_JOIN(f, r)\n"
     << "#define " << c_name_macro << "_JOIN(f, r) " << prefix << "##f##_##r\n";
  for (const std::string& f : c_functions())
    ch << "#define " << prefix << f << " " << c_name_macro << "(" << f << ")\n";
  ch << "\n"
     << "#define " << upper(prefix) << "N_STATE " << s.n_x << "\n"
     << "#define " << upper(prefix) << "N_PARAMETERS " << s.n_p << "\n"
     << "#define " << upper(prefix) << "N_INPUTS " << s.n_in << "\n";
  for (const Kernel& k : kernels.kernels)
    ch << "#define " << upper(prefix) << "N_OUT_" << upper(k.name) << " " << k.outputs.size() << "\n";
  if (prepared) ch << "#define " << upper(prefix) << "N_PREPARED_PARAMETERS " << code.n_prepared << "\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    ch << "#define " << upper(prefix) << "N_WORK_" << upper(kernels.kernels[i].name) << " " << code.printed[i].work
       << "\n";
  if (prepared)
    for (std::size_t i = 0; i < prepared->kernels.size(); ++i)
      ch << "#define " << upper(prefix) << "N_WORK_" << upper(prepared->kernels[i].name) << " " << code.prepared[i].work
         << "\n";
  ch << "\n#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n";
  for (const Kernel& k : kernels.kernels) ch << "/* " << k.summary << " */\n" << c_signature("void", k.name) << ";\n";
  if (has_rhs)
    ch << "/* rhs with a status: 0 ok (out written), 1 mass matrix or articulated inertia not positive definite,\n"
       << "   2 a non-finite result (out untouched when not 0) */\n"
       << c_signature("int", "rhs_status") << ";\n";
  if (prepared) {
    ch << "/* P = (p, then the parameter-only values), " << upper(prefix)
       << "N_PREPARED_PARAMETERS entries, for the _prepared kernels */\n"
       << "void " << prefix << "prepare_parameters(const " << c_real << "* p, " << c_real << "* prepared);\n";
    for (const Kernel& k : prepared->kernels)
      ch << "/* " << k.summary << " */\n" << c_signature("void", k.name) << ";\n";
  }
  ch << "/* Work-space forms (" << model.name << ".hpp): <kernel>_work(t, x, p, in, out, work) with work["
     << upper(prefix) << "N_WORK_<KERNEL>]\n   of the caller's in place of the kernel's stack array */\n";
  for (const Kernel& k : kernels.kernels) ch << c_work_signature(k.name) << ";\n";
  if (prepared)
    for (const Kernel& k : prepared->kernels) ch << c_work_signature(k.name) << ";\n";
  ch << "\n#ifdef __cplusplus\n}\n#endif\n\n#endif\n";
  return ch.str();
}

std::string PackageWriter::cmake() const {
  // CMakeLists.txt: a static library and nothing else, so that a firmware project can add_subdirectory it.
  std::ostringstream cm;
  cm << "# " << origin << "\n"
     << "# SPDX-License-Identifier: MIT\n"
     << "# The " << model.name << " kernels as a static library " << library
     << " (C++17, no dependency beyond <cmath>).\n"
     << "# Standalone, built out of tree (a build folder inside would stop hamel emit from replacing this one):\n"
     << "#   cmake -S " << model.name << " -B " << model.name << "-build [-D" << guard_macro
     << "=float] && cmake --build " << model.name << "-build\n"
     << "# In a project: add_subdirectory(<this folder>) and target_link_libraries(app PRIVATE " << library << ").\n"
     << "cmake_minimum_required(VERSION 3.13)\n"
     << "project(" << library << " LANGUAGES CXX)\n\n"
     << "set(" << guard_macro << " \"\" CACHE STRING \"Scalar type of the " << model.name
     << " kernels (float or double; empty: double)\")\n\n"
     << "add_library(" << library << " STATIC " << model.name << ".cpp " << model.name << ".hpp " << model.name
     << ".h)\n"
     << "add_library(" << model.name << "::kernels ALIAS " << library << ")\n"
     << "target_include_directories(" << library << " PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})\n"
     << "target_compile_features(" << library << " PUBLIC cxx_std_17)\n"
     << "set_target_properties(" << library << " PROPERTIES CXX_EXTENSIONS OFF)\n"
     << "if(" << guard_macro << ")\n"
     << "  # PUBLIC: users of the library see the same scalar type.\n"
     << "  target_compile_definitions(" << library << " PUBLIC " << guard_macro << "=${" << guard_macro << "})\n"
     << "endif()\n"
     << "# -fno-math-errno: std::sqrt compiles to the FPU's square root; with errno semantics it is a compare, a "
        "branch\n"
     << "# and a libm call that may set errno (the kernels never read errno), so the kernels would not be "
        "branch-free.\n"
     << "# -ffp-contract=off: a*b + c stays two roundings; contracted into fused multiply-adds (GCC's default outside\n"
     << "# ISO modes, Clang's within an expression) firmware with an FMA unit and a desktop without differ by ulps.\n"
     << "if(CMAKE_CXX_COMPILER_ID MATCHES \"GNU|Clang\")\n"
     << "  target_compile_options(" << library << " PRIVATE -fno-math-errno -ffp-contract=off)\n"
     << "endif()\n\n"
     << "# Optional, when hamel is installed (find_package(hamel): hamel::runtime, header-only): the target "
     << model.name << "::with_runtime,\n"
     << "# the kernels plus hamel's integrators (dopri5, dop853, radau5, RKMK on Lie groups) for a desktop "
        "application.\n"
     << "# The kernels themselves never depend on it.\n"
     << "if(NOT TARGET hamel::runtime)\n"
     << "  find_package(hamel QUIET CONFIG)\n"
     << "endif()\n"
     << "if(TARGET hamel::runtime)\n"
     << "  add_library(" << library << "_with_runtime INTERFACE)\n"
     << "  target_link_libraries(" << library << "_with_runtime INTERFACE " << library << " hamel::runtime)\n"
     << "  add_library(" << model.name << "::with_runtime ALIAS " << library << "_with_runtime)\n"
     << "endif()\n";
  if (python) cm << python_cmake(python_package());
  return cm.str();
}

PythonPackage PackageWriter::python_package() const {
  PythonPackage py;
  py.name = model.name;
  py.origin = origin;
  py.n_coordinates = s.n_q;
  py.n_independent = s.n_u;
  py.n_state = s.n_x;
  py.n_parameters = s.n_p;
  py.n_inputs = s.n_in;
  py.n_hamel = static_cast<int>(sys.gamma.size());
  py.conservative = eq.conservative;
  py.state_names = state_names;
  py.parameter_names = parameter_names;
  py.input_names = input_names;
  py.constraint_names = constraint_names;
  for (const auto& u : sys.velocities) py.quasi_velocity_names.push_back(u.get_name());
  py.default_parameters = defaults;
  py.hamel_upper = upper_index;
  py.hamel_lower_a = lower_a;
  py.hamel_lower_b = lower_b;
  const auto add = [&](const Kernel& k, bool reads_prepared) {
    const int n_out = static_cast<int>(k.outputs.size());
    py.kernels.push_back({k.name, k.summary, python_output_shape(k.name, n_out, s.n_q, s.n_u, s.n_x, group_dimension),
                          k.output_names, reads_prepared});
  };
  for (const Kernel& k : kernels.kernels) add(k, false);
  if (prepared)
    for (const Kernel& k : prepared->kernels) add(k, true);
  py.has_rhs = has_rhs;
  py.n_prepared_parameters = prepared ? code.n_prepared : 0;
  py.parameter_jacobian_parameters = parameter_jacobian_parameters;
  return py;
}

std::string PackageWriter::readme() const {
  // README.md: what the package is, its ABI and layout, how to build it, its licence.
  std::ostringstream md;
  md << "<!-- " << origin << " -->\n"
     << "<!-- SPDX-License-Identifier: MIT -->\n"
     << "# " << model.name << ": generated kernels\n\n";
  if (!model.description.empty()) md << one_paragraph(model.description) << "\n\n";
  md << "Equations: " << sys.form << ". Generated by `hamel emit` from `" << file
     << "`. Flat, branch-free C++17 that needs only a C++ compiler and `<cmath>`: no heap, no exceptions, no RTTI, "
        "no other library.\n\n"
     << "| File | Content |\n|---|---|\n"
     << "| `" << model.name << ".hpp` | declarations, sizes and names (the ABI, documented at the top) |\n"
     << "| `" << model.name << ".cpp` | the kernels" << (has_rhs ? " and the integrator step `rk4_step`" : "") << " |\n"
     << "| `" << model.name << ".h` | C entry points `" << model.name << "_<kernel>` (C99/C11) |\n"
     << "| `CMakeLists.txt` | static library `" << library << "` (alias `" << model.name
     << "::kernels`); with an installed hamel (`find_package(hamel)`) also `" << model.name
     << "::with_runtime`, the kernels plus hamel's header-only integrators"
     << (python ? "; and the Python module's shared library `lib" + model.name + "_python`" : std::string()) << " |\n";
  if (python)
    md << "| `" << model.name << ".py`, `" << model.name << "_python.cpp` | the Python module (NumPy, ctypes) and its "
       << "batch entry points `" << model.name << "_<kernel>_batch`: after `cmake --build`, `import " << model.name
       << "` from the build folder (hamel's docs/python.md) |\n";
  md << "\n";
  readme_kernels(md);
  readme_layout(md);
  readme_integrator(md);
  readme_build(md);
  if (python) readme_python(md);
  readme_bad_input(md);
  md << "## Licence\n\n"
     << "MIT (`SPDX-License-Identifier: MIT` in every file of this folder). The emitted files carry this licence "
        "separately from the generator's (hamel is GPL-licensed, as GiNaC), so they may ship in closed firmware.\n";
  return md.str();
}

void PackageWriter::readme_kernels(std::ostream& md) const {
  md << "## Kernels\n\n"
     << "Everything is in namespace `" << model.name << "`. Every kernel is\n\n"
     << "```cpp\nvoid kernel(real t, const real* x, const real* p, const real* in, real* out);\n```\n\n"
     << "reading the time `t`, the state `x[n_state]`, the parameters `p[n_parameters]` and the inputs "
        "`in[n_inputs]` (may be null when `n_inputs == 0`), and writing `out[n_out_<kernel>]`. `kernel_table` "
        "lists them with their sizes.\n\n"
     << "Each has a work-space form `<kernel>_work(t, x, p, in, out, work)` (C: `" << prefix
     << "<kernel>_work`) with the same results, for callers with little stack (firmware tasks): a kernel long enough "
        "to be split into parts passes values between them in an array of `n_work_<kernel>` reals (column Work; a "
        "tree's jacobian also the arguments of its column solves), which the kernel keeps on its stack and the "
        "work-space form in the caller's `work` (a static array, say). "
        "The stack each needs on a Cortex-M is measured in hamel's docs/firmware.md.\n\n"
     << "| Kernel | Outputs | Temporaries | Work | Operations (add, mul, div, call) | Computes |\n"
        "|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i) {
    const Kernel& k = kernels.kernels[i];
    const OpCounts& o = code.printed[i].ops;
    md << "| `" << k.name << "` | " << k.outputs.size() << " | " << code.printed[i].temporaries << " | "
       << code.printed[i].work << " | " << o.add << ", " << o.mul << ", " << o.div << ", " << o.call << " | "
       << k.summary << " |\n";
  }
  if (prepared) {
    md << "\n### Prepared parameters\n\n"
       << "Part of `rhs` depends on the parameters alone (with symbolic parameters, e.g. the factors of a mass "
          "matrix that does not depend on the state). `prepare_parameters(p, P)` computes it once into "
          "`P[n_prepared_parameters]` (`p` first; "
       << prepared->once.total()
       << " operations); then "
          "`rhs_prepared(t, x, P, in, out)` ("
       << prepared->rhs_prepared.total() << " operations per call against " << prepared->rhs.total() << " for `rhs`)"
       << (prepared->kernels.size() > 1 ? " and `jacobian_prepared`" : "")
       << " give the same outputs as `rhs(t, x, p, in, out)` without that work. Recompute `P` when `p` changes.\n\n"
       << "| Kernel | Temporaries | Operations (add, mul, div, call) |\n|---|---|---|\n";
    for (const PrintedKernel& k : code.prepared)
      md << "| `" << k.name << "` | " << k.temporaries << " | " << k.ops.add << ", " << k.ops.mul << ", " << k.ops.div
         << ", " << k.ops.call << " |\n";
  }
}

void PackageWriter::readme_layout(std::ostream& md) const {
  md << "\n## State `x` (n_state = " << s.n_x << ")\n\n"
     << "| Index | Name | Meaning |\n|---|---|---|\n";
  for (int i = 0; i < s.n_x; ++i)
    md << "| " << i << " | `" << state_names[static_cast<std::size_t>(i)] << "` | "
       << (i < s.n_q ? "coordinate" : "independent quasi-velocity") << " |\n";
  md << "\n## Parameters `p` (n_parameters = " << s.n_p << ")\n\n";
  if (s.n_p == 0) {
    md << "None; pass `nullptr`.\n";
  } else {
    md << "Defaults in `default_parameters`. A parameter marked folded was fixed at generation time: the kernels "
          "do not read it (the array keeps its place so that the layout stays the same).\n\n"
       << "| Index | Name | Default | |\n|---|---|---|---|\n";
    for (std::size_t i = 0; i < defaults.size(); ++i)
      md << "| " << i << " | `" << parameter_names[i] << "` | " << shortest_decimal(defaults[i]) << " | "
         << (parameter_used[i] ? "run-time" : "folded") << " |\n";
  }
  md << "\n## Inputs `in` (n_inputs = " << s.n_in << ")\n\n";
  if (s.n_in == 0) {
    md << "None; pass `nullptr`.\n";
  } else {
    md << "| Index | Name |\n|---|---|\n";
    for (std::size_t i = 0; i < input_names.size(); ++i) md << "| " << i << " | `" << input_names[i] << "` |\n";
  }
}

void PackageWriter::readme_integrator(std::ostream& md) const {
  if (has_rhs)
    md << "\n## Integrator step\n\n"
       << "`void rk4_step(real t, real h, real* x, const real* p, const real* in)` advances `x` in place by one "
          "classical Runge-Kutta step of size `h` (4 calls of `rhs`, `rk4_stack_reals` reals of stack, no "
          "allocation), holding `in` over the step: one call per tick of a fixed-rate loop."
       << (has_group_velocity ? " It advances the reduced state only; the group element g follows from the "
                                "velocity `group_velocity` returns (xi: g' = g xi^ for left, xi^ g for right "
                                "trivialization), e.g. integrated alongside as in hamel's tools/control_loop_example."
                              : "")
       << "\n\n"
       << "```cpp\n#include \"" << model.name << ".hpp\"\n\n"
       << model.name << "::real x[" << model.name << "::n_state] = {};  // initial state\n"
       << "for (long tick = 0; tick < ticks; ++tick) " << model.name << "::rk4_step(tick * h, h, x, "
       << (s.n_p ? model.name + "::default_parameters" : std::string("nullptr")) << ", " << (s.n_in ? "in" : "nullptr")
       << ");\n```\n";
  readme_position_constraints(md);
}

// Models with position constraints g(q) = 0 (holonomic constraints): how the runtime's projector keeps them.
void PackageWriter::readme_position_constraints(std::ostream& md) const {
  std::vector<std::string> names;
  bool jacobian = false;
  for (const Kernel& k : kernels.kernels) {
    if (k.name == "constraint_position") names = k.output_names;
    jacobian = jacobian || k.name == "constraint_position_jacobian";
  }
  if (names.empty() || !jacobian || !has_rhs) return;
  const std::string& m = model.name;
  const std::string p = s.n_p ? m + "::default_parameters" : std::string("nullptr");
  const std::string in = s.n_in ? "in" : "nullptr";
  md << "\n## Position constraints\n\n"
     << "The model has " << names.size() << " position constraints g(q) = 0 (";
  for (std::size_t i = 0; i < names.size(); ++i) md << (i ? ", " : "") << "`" << names[i] << "`";
  md << ") that its equations hold in velocity form only: G(q) q_dot = 0 holds exactly along every computed motion "
        "(G = dg/dq), but the integration error moves q off g(q) = 0, and that drift accumulates. "
        "`constraint_position` gives g(q), `constraint_position_jacobian` G (row-major, `n_out_constraint_position` x "
        "`n_coordinates`). The hamel runtime's projector (`hamel/runtime/projection.hpp`, in `"
     << m
     << "::with_runtime`) moves q back onto g(q) = 0 by Gauss-Newton with minimum-norm corrections q <- q - G^T (G "
        "G^T)^-1 g(q) until they are at rounding level, in a work space of the caller's (no allocation); every "
        "integrator of the runtime takes it as its last argument and projects each accepted state and each sample "
        "(dopri5, dop853 and radau5 then evaluate `rhs` once more per step). Project the initial state too "
        "(`project_positions`), as `hamel simulate` does. `rk4_step` does not project: call `project_positions` after "
        "it.\n\n"
     << "```cpp\n#include \"" << m << ".hpp\"\n#include <hamel/runtime/dopri5.hpp>\n#include "
     << "<hamel/runtime/projection.hpp>\n\n"
     << "using namespace hamel::runtime;\n"
     << "constexpr std::size_t n = " << m << "::n_state, nq = " << m << "::n_coordinates, k = " << m
     << "::n_out_constraint_position;\n"
     << "auto rhs = [&](double t, const double* x, double* f) { " << m << "::rhs(t, x, " << p << ", " << in
     << ", f); };\n"
     << "auto g = [&](double t, const double* x, double* out) { " << m << "::constraint_position(t, x, " << p << ", "
     << in << ", out); };\n"
     << "auto G = [&](double t, const double* x, double* out) { " << m << "::constraint_position_jacobian(t, x, " << p
     << ", " << in << ", out); };\n"
     << "static double pwork[ProjectionWorkspace::doubles(nq, k)], work[Dopri5Workspace::doubles(n)];\n"
     << "const ProjectionWorkspace pw{pwork, ProjectionWorkspace::doubles(nq, k)};\n"
     << "double x[n] = {};  // initial state\n"
     << "project_positions(g, G, 0.0, x, nq, k, pw);  // Status::ok: x is on g(q) = 0\n"
     << "ConstraintProjector project(g, G, nq, k, pw);\n"
     << "integrate_dopri5(rhs, x, n, 0.0, 10.0, Dopri5Options{}, 0.0, NoObserver{}, "
        "Dopri5Workspace{work, Dopri5Workspace::doubles(n)}, project);\n```\n";
}

void PackageWriter::readme_build(std::ostream& md) const {
  md << "\n## Build\n\n"
     << "Out of tree, from the folder that holds this package (called `" << model.name
     << "` here; `hamel emit` replaces only a folder it wrote, so a build folder inside this one would stop it from "
        "regenerating the package):\n\n"
     << "```sh\ncmake -S " << model.name << " -B " << model.name << "-build       # double\ncmake -S " << model.name
     << " -B " << model.name << "-build -D" << guard_macro << "=float   # or float\ncmake --build " << model.name
     << "-build\n```\n\n"
     << "or, in a CMake project, `add_subdirectory(" << model.name << ")` and `target_link_libraries(app PRIVATE "
     << library << ")`. Without CMake compile `" << model.name
     << ".cpp` with any C++17 compiler (flags such as `-fno-exceptions -fno-rtti -Wall -Wextra -Werror -pedantic` "
        "are fine). The scalar type is the macro `"
     << guard_macro
     << "` (default `double`); it must be the same for the library and its users (CMake sets it PUBLIC); a "
        "mismatch fails to link, in C++ and in C (the C symbols carry the type: `"
     << prefix << "rhs` links as `" << prefix << "rhs_double` or `" << prefix << "rhs_float`).\n\n"
     << "Two flags matter for firmware, and CMakeLists.txt sets both for GCC and Clang (set them yourself in another "
        "build):\n\n"
     << "- `-fno-math-errno`: without it `std::sqrt` keeps C's errno semantics and compiles to a compare, a branch and "
        "a libm call next to the FPU's square root instruction, so kernels that take square roots are no longer "
        "branch-free (and link errno). The kernels never read errno.\n"
     << "- `-ffp-contract=off`: no fusing of `a*b + c` into fused multiply-adds. With FMA contraction (GCC's default "
        "in GNU modes, e.g. for a Cortex-M4F or M7 with `-std=gnu++17`) results differ from a desktop build by a few "
        "ulps; with it off the firmware reproduces the host's numbers bit for bit.\n\n"
     << "On a microcontroller, use float where the FPU is single-precision (Cortex-M4F, M33, M7 with fpv5-sp-d16): "
        "double arithmetic there is emulated in software and costs 24 to 51 times the instructions of float per "
        "kernel (measured on a Cortex-M4F under QEMU; hamel's docs/firmware.md has the figures per kernel). A "
        "double-precision FPU (Cortex-M7 with fpv5-d16) runs double in hardware.\n\n";
}

void PackageWriter::readme_python(std::ostream& md) const {
  const std::string& m = model.name;
  md << "## Python\n\n"
     << "`cmake --build " << m << "-build` also builds the shared library `lib" << m << "_python` and copies `" << m
     << ".py` beside it (NumPy needed, nothing else). Every kernel is a function `kernel(t, x, p=None, inputs=None)` "
        "of one state (x of shape `(n_state,)`) or of N states in one call (`(N, n_state)`); `rhs_status` raises "
        "`StatusError` with the status for a bad state (hamel's docs/python.md)"
     << (kernels.kernels.empty() ? ".\n\n" : ":\n\n");
  if (kernels.kernels.empty()) return;
  md << "```python\n# PYTHONPATH=" << m << "-build\nimport numpy as np, " << m << "\n"
     << "x = np.zeros((100, " << m << ".n_state))\n"
     << "f = " << m << "." << (has_rhs ? std::string("rhs") : kernels.kernels.front().name) << "(0.0, x"
     << (s.n_in ? ", None, np.zeros(" + m + ".n_inputs)" : std::string()) << ")\n```\n\n";
}

void PackageWriter::readme_bad_input(std::ostream& md) const {
  md << "## What kernels return for bad input\n\n"
        "The kernels are straight-line arithmetic: no branches, no checks, no exceptions; they never stop or "
        "report anything themselves.\n\n"
        "- NaN or infinite input (state, parameter or input) is not detected: it propagates through the "
        "arithmetic, so outputs that depend on it come out NaN or infinite (an infinity can also vanish, as in "
        "1/x), and nothing is raised. Outputs that do not depend on the value, and folded parameters, are "
        "unaffected.\n";
  if (has_rhs) {
    md << "- A singular mass matrix M: the right-hand side solves M u' = f without pivoting or checks, so a singular "
          "M gives infinities or NaN, and an indefinite one finite but meaningless values or NaN.\n"
       << "- `int rhs_status(real t, const real* x, const real* p, const real* in, real* out)` (C: `" << model.name
       << "_rhs_status`) is `rhs` with checks made after the same branch-free evaluation: it returns 0 and writes "
          "`out` as `rhs` does; ";
    if (kernels.rhs_pivots.empty())
      md << "2, leaving `out` untouched, when an output is not finite. It never returns 1 here: M was inverted at "
            "generation time (`n_pivots_rhs` = 0), so a singular M shows only as 2.";
    else
      md << "1, leaving `out` untouched, when one of the `n_pivots_rhs` = " << kernels.rhs_pivots.size()
         << " pivots of the solve (of M, or of an articulated inertia of the recursive solve) is not positive and "
            "finite, which is also what a non-finite input that reaches a pivot gives; 2, leaving `out` untouched, "
            "when an output is not finite.";
    md << " `rk4_step` calls `rhs` and does not check.\n";
  }
  md << "- " << (has_rhs ? "Other kernels have" : "The kernels have")
     << " no checking form: callers test `std::isfinite` on their outputs. The hamel runtime's integrators report a "
        "non-finite derivative or state as `non_finite_state` (the adaptive ones first retry shorter steps).\n\n";
}

}  // namespace

std::vector<EmittedFile> EmittedPackage::files() const {
  std::vector<EmittedFile> all{{header_name, header}, {source_name, source}};
  all.insert(all.end(), extra.begin(), extra.end());
  return all;
}

EmittedPackage emit_cpp(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                        const EmitSettings& settings) {
  const PackageWriter writer(model, derivation, kernels, settings);
  EmittedPackage package{model.name + ".hpp", writer.header(), model.name + ".cpp", writer.source(), {}, {}, 0};
  package.extra.push_back({model.name + ".h", writer.c_header()});
  package.extra.push_back({"CMakeLists.txt", writer.cmake()});
  package.extra.push_back({"README.md", writer.readme()});
  if (settings.python) {
    const PythonPackage py = writer.python_package();
    package.extra.push_back({model.name + ".py", python_module(py)});
    package.extra.push_back({model.name + "_python.cpp", python_batch_source(py)});
  }
  const PackageKernels& code = writer.printed_kernels();
  package.operations = code.operations;
  package.shared_stages = code.shared_stages;
  package.share_ratio = code.share_ratio;
  package.statements = code.statements;
  return package;
}

void check_package_folder(const std::string& directory, const std::string& model_name) {
  check_folder_replaceable(directory, {model_name + ".hpp", model_name + ".cpp", model_name + ".h", "CMakeLists.txt",
                                       "README.md", model_name + ".py", model_name + "_python.cpp"});
}

void write_package(const EmittedPackage& package, const std::string& directory) {
  write_folder(directory, package.files());
}

}  // namespace hamel
