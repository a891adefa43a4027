#include "emit/python_module.hpp"

#include "algebra/expression_text.hpp"

#include <cctype>
#include <cmath>
#include <sstream>

namespace hamel {

namespace {

// The generic part of every module, generator/emit/python_module.py's region (generator/embed_region.cmake).
const char* const python_module_text =
#include "emit/python_module.inc"
    ;

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// A Python string literal; bytes outside printable ASCII are escaped (names are identifiers, so none are expected).
std::string py_string(const std::string& text) {
  std::string s = "\"";
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\\' || c == '"') {
      s += '\\';
      s += ch;
    } else if (c < 0x20 || c > 0x7e) {
      static const char* const hex = "0123456789abcdef";
      s += "\\x";
      s += hex[c >> 4];
      s += hex[c & 15];
    } else {
      s += ch;
    }
  }
  return s + "\"";
}

std::string py_number(double v) {
  if (std::isnan(v)) return "float(\"nan\")";
  if (std::isinf(v)) return v > 0 ? "float(\"inf\")" : "-float(\"inf\")";
  return shortest_decimal(v);
}

template <class T, class F>
std::string py_tuple(const std::vector<T>& items, F format) {
  std::string s = "(";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + format(items[i]);
  return s + (items.size() == 1 ? ",)" : ")");
}

std::string py_names(const std::vector<std::string>& names) { return py_tuple(names, py_string); }
std::string py_ints(const std::vector<int>& items) {
  return py_tuple(items, [](int v) { return std::to_string(v); });
}
std::string py_bool(bool b) { return b ? "True" : "False"; }

}  // namespace

std::vector<int> python_output_shape(const std::string& name, int n_out, int n_coordinates, int n_independent,
                                     int n_state, int group_dimension) {
  const auto side = [](int n) {
    const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(n))));
    return k * k == n ? k : 0;
  };
  std::vector<int> shape;
  if (name == "mass_matrix")
    shape = {n_independent, n_independent};
  else if (name == "jacobian" || name == "jacobian_prepared")
    shape = {n_state, n_state};
  else if ((name == "input_jacobian" || name == "parameter_jacobian") && n_state > 0)
    shape = {n_state, n_out / n_state};
  else if (name == "constraint_position_jacobian" && n_coordinates > 0)
    shape = {n_out / n_coordinates, n_coordinates};
  else if ((name == "locked_inertia" || name == "shape_inertia") && side(n_out) > 0)
    shape = {side(n_out), side(n_out)};
  else if (name == "connection" && group_dimension > 0)
    shape = {group_dimension, n_out / group_dimension};
  else if (name == "riemann_linearization" && n_out % 4 == 0 && side(n_out / 4) > 0)
    shape = {4, side(n_out / 4), side(n_out / 4)};
  long product = 1;
  for (int d : shape) product *= d;
  if (shape.empty() || product != n_out) shape = {n_out};  // a layout the rules above do not describe: flat
  return shape;
}

std::string python_module(const PythonPackage& m) {
  std::ostringstream py;
  py << "# " << m.origin << "\n"
     << "# SPDX-License-Identifier: MIT\n"
     << "# Emitted code is under the MIT licence, whatever the generator's licence.\n"
     << "\"\"\"The " << m.name << " kernels from Python with NumPy (hamel emit --python).\n\n"
     << "Every kernel is a function kernel(t, x, p=None, inputs=None): x of shape (n_state,) gives the outputs of one\n"
     << "state, x of shape (N, n_state) those of N states in one call, shape (N,) + kernels[kernel][0]; t, p and "
        "inputs\n"
     << "are one value for all states or one row per state. p=None: default_parameters. rhs_status raises StatusError\n"
     << "(with the status) for a bad state. Loads lib" << m.name << "_python from the folder of this file (CMake puts\n"
     << "both into the package's build folder); the package's README.md documents the state, parameters and inputs.\n"
     << "\"\"\"\n\n"
     << "name = " << py_string(m.name) << "\n"
     << "stamp = " << py_string(m.origin) << "\n"
     << "n_coordinates = " << m.n_coordinates << "\n"
     << "n_independent = " << m.n_independent << "  # independent quasi-velocities u^I\n"
     << "n_state = " << m.n_state << "\n"
     << "n_parameters = " << m.n_parameters << "\n"
     << "n_inputs = " << m.n_inputs << "\n"
     << "n_constraints = " << m.constraint_names.size() << "\n"
     << "n_hamel = " << m.n_hamel << "  # non-zero Hamel coefficients\n"
     << "conservative = " << py_bool(m.conservative) << "  # energy is an invariant\n"
     << "state_names = " << py_names(m.state_names) << "\n"
     << "parameter_names = " << py_names(m.parameter_names) << "\n"
     << "input_names = " << py_names(m.input_names) << "\n"
     << "constraint_names = " << py_names(m.constraint_names) << "\n"
     << "quasi_velocity_names = " << py_names(m.quasi_velocity_names) << "\n"
     << "# gamma^upper_{lower_a lower_b}: indices into quasi_velocity_names\n"
     << "hamel_upper = " << py_ints(m.hamel_upper) << "\n"
     << "hamel_lower_a = " << py_ints(m.hamel_lower_a) << "\n"
     << "hamel_lower_b = " << py_ints(m.hamel_lower_b) << "\n"
     << "_default_parameters = " << py_tuple(m.default_parameters, py_number) << "\n";
  if (m.n_prepared_parameters > 0) py << "n_prepared_parameters = " << m.n_prepared_parameters << "\n";
  if (!m.parameter_jacobian_parameters.empty())
    py << "# parameter_jacobian's columns: indices into parameter_names of the parameters not folded\n"
       << "parameter_jacobian_parameters = " << py_ints(m.parameter_jacobian_parameters) << "\n";
  py << "# kernel: (shape of its outputs, their names, what it computes)\n"
     << "kernels = {\n";
  for (const PythonKernel& k : m.kernels)
    py << "    " << py_string(k.name) << ": (" << py_ints(k.shape) << ", " << py_names(k.output_names) << ", "
       << py_string(k.summary) << "),\n";
  py << "}\n\n" << python_module_text << "\n";
  for (const PythonKernel& k : m.kernels)
    if (!k.prepared) py << k.name << " = _kernel(\"" << k.name << "\")\n";
  if (m.has_rhs) py << "rhs_status = _rhs_status()\nrk4_step = _rk4_step()\n";
  if (m.n_prepared_parameters > 0) {
    py << "prepare_parameters = _prepare_parameters()\n"
       << "default_prepared_parameters = prepare_parameters()\n"
       << "default_prepared_parameters.flags.writeable = False\n";
    for (const PythonKernel& k : m.kernels)
      if (k.prepared) py << k.name << " = _kernel(\"" << k.name << "\", prepared=True)\n";
  }
  return py.str();
}

std::string python_batch_source(const PythonPackage& m) {
  const std::string& n = m.name;
  const std::string export_macro = "HAMEL_" + upper(n) + "_EXPORT";
  const std::string c_name = "HAMEL_" + upper(n) + "_C_NAME";
  const std::string rows = "std::ptrdiff_t n, const real* t, std::ptrdiff_t t_step, ";
  const std::string state =
      "const real* x, std::ptrdiff_t x_step, const real* p, std::ptrdiff_t p_step, const real* in, "
      "std::ptrdiff_t in_step, real* out, std::ptrdiff_t out_step";
  std::ostringstream c;
  c << "// " << m.origin << "\n"
    << "// SPDX-License-Identifier: MIT\n"
    << "// Emitted code is under the MIT licence, whatever the generator's licence.\n"
    << "//\n"
    << "// Batch entry points of the " << n << " kernels for the Python module " << n << ".py (emit --python), which\n"
    << "// loads them with ctypes from lib" << n << "_python (CMakeLists.txt: this file and " << n << ".cpp). " << n
    << "_<kernel>_batch\n"
    << "// calls the kernel once per state i < n, reading row i of each argument at i * <argument>_step (0: the same\n"
    << "// row for every state; the rows of x, p, in and out are n_state, n_parameters, n_inputs and n_out_<kernel>\n"
    << "// reals long). The loops are outside the kernels, which stay branch-free. Symbols carry the scalar type as\n"
    << "// those of " << n << ".h do (" << n << "_rhs_batch_double).\n"
    << "#include \"" << n << ".hpp\"\n"
    << "#include \"" << n << ".h\"\n\n"
    << "#include <cstddef>\n\n"
    << "#if defined(_WIN32)\n#define " << export_macro << " __declspec(dllexport)\n"
    << "#elif defined(__GNUC__)\n#define " << export_macro << " __attribute__((visibility(\"default\")))\n"
    << "#else\n#define " << export_macro << "\n#endif\n\n";
  std::vector<std::string> entries;
  for (const PythonKernel& k : m.kernels) entries.push_back(k.name + "_batch");
  if (m.has_rhs) entries.insert(entries.end(), {"rhs_status_batch", "rk4_step_batch"});
  if (m.n_prepared_parameters > 0) entries.push_back("prepare_parameters_batch");
  entries.push_back("python_stamp");
  for (const std::string& e : entries) c << "#define " << n << "_" << e << " " << c_name << "(" << e << ")\n";
  c << "\nnamespace {\n\n"
    << "using " << n << "::real;\n\n"
    << "template <void (*kernel)(real, const real*, const real*, const real*, real*)>\n"
    << "void each_state(" << rows << state << ") {\n"
    << "  for (std::ptrdiff_t i = 0; i < n; ++i)\n"
    << "    kernel(t[i * t_step], x + i * x_step, p + i * p_step, in + i * in_step, out + i * out_step);\n"
    << "}\n\n"
    << "}  // namespace\n\n"
    << "extern \"C\" {\n\n"
    << export_macro << " const char* " << n << "_python_stamp(void) { return \"" << m.origin << "\"; }\n";
  for (const PythonKernel& k : m.kernels)
    c << export_macro << " void " << n << "_" << k.name << "_batch(" << rows << state << ") {\n"
      << "  each_state<" << n << "::" << k.name << ">(n, t, t_step, x, x_step, p, p_step, in, in_step, out, "
      << "out_step);\n}\n";
  if (m.has_rhs)
    c << "/* statuses[i]: rhs_status of state i (out's row untouched when not 0); returns how many are not 0 */\n"
      << export_macro << " std::ptrdiff_t " << n << "_rhs_status_batch(" << rows << state << ", int* statuses) {\n"
      << "  std::ptrdiff_t bad = 0;\n"
      << "  for (std::ptrdiff_t i = 0; i < n; ++i) {\n"
      << "    statuses[i] = " << n
      << "::rhs_status(t[i * t_step], x + i * x_step, p + i * p_step, in + i * in_step, out + i * out_step);\n"
      << "    bad += statuses[i] != 0;\n"
      << "  }\n"
      << "  return bad;\n"
      << "}\n"
      << "/* out's row i: x's row i advanced by one rk4_step of h[i * h_step] from t[i * t_step] */\n"
      << export_macro << " void " << n << "_rk4_step_batch(" << rows << "const real* h, std::ptrdiff_t h_step, "
      << state << ") {\n"
      << "  for (std::ptrdiff_t i = 0; i < n; ++i) {\n"
      << "    real* y = out + i * out_step;\n"
      << "    for (int k = 0; k < " << n << "::n_state; ++k) y[k] = x[i * x_step + k];\n"
      << "    " << n << "::rk4_step(t[i * t_step], h[i * h_step], y, p + i * p_step, in + i * in_step);\n"
      << "  }\n"
      << "}\n";
  if (m.n_prepared_parameters > 0)
    c << export_macro << " void " << n
      << "_prepare_parameters_batch(std::ptrdiff_t n, const real* p, std::ptrdiff_t p_step, real* out, "
         "std::ptrdiff_t out_step) {\n"
      << "  for (std::ptrdiff_t i = 0; i < n; ++i) " << n
      << "::prepare_parameters(p + i * p_step, out + i * out_step);\n"
      << "}\n";
  c << "\n}  // extern \"C\"\n";
  return c.str();
}

std::string python_cmake(const PythonPackage& m) {
  const std::string& n = m.name;
  const std::string target = n + "_python";
  const std::string real = "HAMEL_" + upper(n) + "_REAL";
  std::ostringstream cm;
  cm << "\n"
     << "# The Python module (hamel emit --python): " << n << ".py loads the shared library lib" << target << " (the\n"
     << "# kernels and the batch entry points of " << target << ".cpp) with ctypes from its own folder; both go into\n"
     << "# this build folder, so that `PYTHONPATH=<build folder> python3 -c \"import " << n << "\"` works (NumPy "
     << "needed).\n"
     << "# Optimized (Release) unless a build type is given: Python calls it for speed.\n"
     << "if(CMAKE_SOURCE_DIR STREQUAL CMAKE_CURRENT_SOURCE_DIR AND NOT CMAKE_BUILD_TYPE AND NOT "
        "CMAKE_CONFIGURATION_TYPES)\n"
     << "  set(CMAKE_BUILD_TYPE Release)\n"
     << "endif()\n"
     << "add_library(" << target << " MODULE " << n << ".cpp " << target << ".cpp)\n"
     << "target_include_directories(" << target << " PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})\n"
     << "target_compile_features(" << target << " PRIVATE cxx_std_17)\n"
     << "# Only the entry points of " << target << ".cpp are exported; the kernels are called directly inside.\n"
     << "set_target_properties(" << target << " PROPERTIES PREFIX \"lib\" CXX_EXTENSIONS OFF CXX_VISIBILITY_PRESET "
     << "hidden\n"
     << "  LIBRARY_OUTPUT_DIRECTORY $<1:${CMAKE_CURRENT_BINARY_DIR}>)\n"
     << "if(" << real << ")\n"
     << "  target_compile_definitions(" << target << " PRIVATE " << real << "=${" << real << "})\n"
     << "endif()\n"
     << "if(CMAKE_CXX_COMPILER_ID MATCHES \"GNU|Clang\")\n"
     << "  target_compile_options(" << target << " PRIVATE -fno-math-errno -ffp-contract=off)\n"
     << "endif()\n"
     << "configure_file(" << n << ".py ${CMAKE_CURRENT_BINARY_DIR}/" << n << ".py COPYONLY)\n";
  return cm.str();
}

}  // namespace hamel
