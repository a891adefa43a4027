// Run-time inputs of `hamel simulate`: constants, feedback laws in t and the state (e.g. a PD controller,
// --input "tau=-k*(q-1)-d*q_dot"), and tables of t and input values read from a CSV file and interpolated
// linearly (--input-file), held at their end values outside the table.
#pragma once

#include "model/model.hpp"

#include <memory>
#include <string>
#include <vector>

namespace hamel {

class InputSources {
 public:
  /// `state_names`: the state in order (coordinates, independent quasi-velocities), what laws may use
  /// besides t and the model's parameters (at `parameters`, in model order).
  InputSources(const Model& model, std::vector<std::string> state_names, const std::vector<double>& parameters);

  /// "name=value" or "name=expression" items, comma-separated at the top level of parentheses (`option`
  /// names the command-line option in errors).
  void add_assignments(const std::vector<std::string>& items, const std::string& option);
  void set_constant(const std::string& name, double value, const std::string& option);
  /// Columns t, then input names; linear interpolation. Throws InputError naming file:line:column. The file is
  /// read line by line (at most kMaxTableFileBytes, a regular file: model/input_file.hpp), in time and memory
  /// linear in its size (8 bytes per value).
  void load_csv(const std::string& path);

  /// The times of the --input-file table (empty without one): its knots, where a linearly interpolated input has a
  /// kink; the adaptive integrators end steps on them (numeric/integrators.hpp).
  const std::vector<double>& knots() const { return times_; }
  /// True when some input depends on t or the state (else one evaluation serves the whole run).
  bool varying() const { return varying_; }
  /// in[k] for the model's k-th input at (t, x). Laws run compiled, in the IR's interpreter in double
  /// (numeric/graph_evaluator.hpp, as the model's kernels do), not through GiNaC on every call.
  void evaluate(double t, const double* x, double* in) const;
  /// Whether the model's k-th input is a law that runs compiled (what the IR does not hold stays with GiNaC).
  bool compiled(std::size_t k) const { return sources_.at(k).kind == Source::law && sources_.at(k).compiled >= 0; }

 private:
  struct Source {
    enum Kind { constant, law, table } kind = constant;
    double value = 0;
    GiNaC::ex expression;
    int column = 0;      // into the table
    std::string origin;  // where it was set, for "given twice"
    int compiled = -1;   // a law's position among the compiled laws' outputs (-1: evaluated through GiNaC)
  };
  struct CompiledLaws;  // the laws' graph and its evaluator
  void compile_laws();
  void claim(std::size_t k, const std::string& origin, const std::string& option);

  const Model& model_;
  std::vector<std::string> state_names_;
  std::vector<Source> sources_;
  GiNaC::symtab table_;  // t, state, parameters (as symbols)
  GiNaC::exmap parameter_values_;
  std::vector<GiNaC::realsymbol> state_symbols_;
  std::vector<double> times_;
  std::vector<double> rows_;  // per time, one value per table column, row after row (no allocation per row)
  std::size_t columns_ = 0;   // table columns besides t
  bool varying_ = false;
  std::shared_ptr<CompiledLaws> compiled_;
};

}  // namespace hamel
