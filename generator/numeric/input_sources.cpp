#include "numeric/input_sources.hpp"

#include "emit/expression_graph.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "model/input_file.hpp"
#include "numeric/graph_evaluator.hpp"
#include "report/atomic_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace hamel {

namespace {

std::string to_text(const GiNaC::ex& e) {
  std::ostringstream os;
  os << e;
  return os.str();
}

}  // namespace

namespace {

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

bool parse_double(const std::string& text, double& v) {
  try {
    std::size_t used = 0;
    v = std::stod(text, &used);
    return used == text.size() && std::isfinite(v);
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

// The laws as one graph (t as Argument::time, the state as Argument::state; parameters are numbers by now), run by
// the interpreter in double: about 16 µs per call through GiNaC's subs and evalf made 10^6 RK4 steps with
// tau = sin(t) take 50 times as long as with a constant.
struct InputSources::CompiledLaws {
  ExpressionGraph graph;
  std::unique_ptr<GraphEvaluator> evaluator;
  std::vector<double> values;  // one per compiled law, the last evaluation's
};

void InputSources::compile_laws() {
  auto laws = std::make_shared<CompiledLaws>();
  std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves;
  leaves[model_.time] = laws->graph.input(Argument::time, 0);
  for (std::size_t k = 0; k < state_symbols_.size(); ++k)
    leaves[state_symbols_[k]] = laws->graph.input(Argument::state, static_cast<int>(k));
  std::vector<int> outputs;
  for (Source& s : sources_) {
    s.compiled = -1;
    if (s.kind != Source::law) continue;
    try {
      const int node = laws->graph.from_expression(s.expression, leaves);
      s.compiled = static_cast<int>(outputs.size());
      outputs.push_back(node);
    } catch (const std::exception&) {
      // What the IR does not hold (a complex constant) stays with GiNaC, as before.
    }
  }
  laws->values.assign(outputs.size(), 0.0);
  laws->evaluator = std::make_unique<GraphEvaluator>(laws->graph, outputs);
  compiled_ = std::move(laws);
}

InputSources::InputSources(const Model& model, std::vector<std::string> state_names,
                           const std::vector<double>& parameters)
    : model_(model), state_names_(std::move(state_names)), sources_(model.inputs.size()) {
  table_["t"] = model.time;
  for (std::size_t k = 0; k < model.parameters.size(); ++k) {
    table_[model.parameters[k].symbol.get_name()] = model.parameters[k].symbol;
    parameter_values_[model.parameters[k].symbol] = k < parameters.size() ? parameters[k] : 0.0;
  }
  for (const std::string& s : state_names_) {
    state_symbols_.emplace_back(s);
    table_[s] = state_symbols_.back();
  }
}

void InputSources::claim(std::size_t k, const std::string& origin, const std::string& option) {
  if (!sources_[k].origin.empty() && sources_[k].origin != "scene")
    throw InputError(option + ": " + quote(model_.inputs[k].get_name()) + " is given twice (also by " +
                     sources_[k].origin + "); give each input once");
  sources_[k] = Source{};
  sources_[k].origin = origin;
}

void InputSources::set_constant(const std::string& name, double value, const std::string& option) {
  const std::size_t k = model_.input_index(name, option);
  claim(k, option, option);
  sources_[k].value = value;
}

void InputSources::add_assignments(const std::vector<std::string>& items, const std::string& option) {
  for (const std::string& item : items)
    for (const std::string& raw : split_top_level(item)) {
      const std::string part = trim(raw);
      if (part.empty()) continue;
      const std::size_t eq = part.find('=');
      if (eq == std::string::npos || eq == 0)
        throw InputError(option + ": expected name=value or name=expression, got " + quote(part));
      const std::string name = trim(part.substr(0, eq)), text = trim(part.substr(eq + 1));
      double v = 0;
      if (parse_double(text, v)) {
        set_constant(name, v, option);
        continue;
      }
      const std::size_t k = model_.input_index(name, option);
      GiNaC::ex e;
      try {
        e = parse_expression(text, table_);
      } catch (const std::exception& err) {
        std::string names;
        for (const auto& s : state_names_) names += (names.empty() ? "" : ", ") + s;
        throw InputError(option + ": the law of " + quote(name) +
                         " is not a number or an expression in t, the state (" + names +
                         ") and parameters: " + describe_parse_error(err.what()));
      }
      claim(k, option, option);
      sources_[k].kind = Source::law;
      sources_[k].expression = e.subs(parameter_values_);
      // A law without t or the state is a number now: it must be real (sqrt(-4), asin(3), log(-1), I are not).
      const GiNaC::ex now = sources_[k].expression.evalf();
      if (GiNaC::is_a<GiNaC::numeric>(now) && !GiNaC::ex_to<GiNaC::numeric>(now).is_real())
        throw InputError(option + ": the law of " + quote(name) + " = " + quote(text) + " has the complex value " +
                         quote(to_text(now)) + "; expected a real-valued input");
      varying_ = true;
    }
  compile_laws();
}

void InputSources::load_csv(const std::string& path) {
  note_input_file(path, "the --input-file");  // no output of this run may replace it
  InputFile in(path, "input file", kMaxTableFileBytes);
  std::string line;
  int line_no = 0;
  std::vector<std::size_t> targets;
  std::vector<std::string> cells;
  while (in.next_line(line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    cells.clear();  // as getline(',') split it: no cell after a trailing comma
    for (std::size_t start = 0; start < line.size();) {
      const std::size_t comma = std::min(line.find(',', start), line.size());
      cells.push_back(trim(line.substr(start, comma - start)));
      start = comma + 1;
    }
    if (targets.empty() && times_.empty()) {  // header
      if (cells.empty() || cells[0] != "t")
        throw InputError(SourceLocation{path, line_no, 1}, "t", "expected a header line t,<input names>");
      if (cells.size() < 2)
        throw InputError(SourceLocation{path, line_no, 1}, "", "expected input names after t in the header");
      for (std::size_t c = 1; c < cells.size(); ++c) {
        const std::size_t k = model_.input_index(cells[c], path + ":" + std::to_string(line_no));
        claim(k, "--input-file " + path, "--input-file");
        sources_[k].kind = Source::table;
        sources_[k].column = static_cast<int>(c - 1);
        targets.push_back(k);
      }
      columns_ = targets.size();
      continue;
    }
    if (cells.size() != targets.size() + 1)
      throw InputError(SourceLocation{path, line_no, 1}, "",
                       "expected " + std::to_string(targets.size() + 1) + " values (t and one per input), got " +
                           std::to_string(cells.size()));
    int column = 1;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      double v = 0;
      if (!parse_double(cells[c], v)) {
        errno = 0;
        char* end = nullptr;
        std::strtod(cells[c].c_str(), &end);
        const bool range = errno == ERANGE && end && *end == '\0' && !cells[c].empty();
        throw InputError(SourceLocation{path, line_no, column}, c == 0 ? "t" : model_.inputs[targets[c - 1]].get_name(),
                         (range ? "the number " + quote(cells[c]) +
                                      " is beyond the range of a double (about 2.2e-308 to 1.8e308 in magnitude, or 0)"
                                : "expected a finite number, got " + quote(cells[c])) +
                             (range ? "; expected a finite number in that range" : ""));
      }
      if (c == 0) {
        if (!times_.empty() && !(v > times_.back()))
          throw InputError(SourceLocation{path, line_no, column}, "t", "times must increase from row to row");
        times_.push_back(v);
      } else {
        rows_.push_back(v);
      }
      column += static_cast<int>(cells[c].size()) + 1;
    }
  }
  if (targets.empty())
    throw InputError(SourceLocation{path, 0, 0}, "", "the input file is empty; expected a header t,<input names>");
  if (times_.empty()) throw InputError(SourceLocation{path, line_no, 0}, "", "expected at least one row of values");
  varying_ = varying_ || times_.size() > 1;
}

void InputSources::evaluate(double t, const double* x, double* in) const {
  // The table row pair around t (held at the ends).
  std::size_t hi = 0;
  double w = 0;
  if (!times_.empty()) {
    hi = static_cast<std::size_t>(std::upper_bound(times_.begin(), times_.end(), t) - times_.begin());
    if (hi == 0 || hi == times_.size()) {
      hi = hi == 0 ? 0 : times_.size() - 1;
      w = 1;
    } else {
      w = (t - times_[hi - 1]) / (times_[hi] - times_[hi - 1]);
    }
  }
  if (compiled_ && !compiled_->values.empty())
    compiled_->evaluator->evaluate(t, x, nullptr, nullptr, compiled_->values.data());
  GiNaC::exmap at;  // t and the state, for the laws GiNaC evaluates: filled when the first needs it
  const auto point = [&]() -> const GiNaC::exmap& {
    if (at.empty()) {
      at[model_.time] = t;
      for (std::size_t k = 0; k < state_symbols_.size(); ++k) at[state_symbols_[k]] = x[k];
    }
    return at;
  };
  for (std::size_t k = 0; k < sources_.size(); ++k) {
    const Source& s = sources_[k];
    switch (s.kind) {
      case Source::constant:
        in[k] = s.value;
        break;
      case Source::table: {
        const std::size_t c = static_cast<std::size_t>(s.column);
        const double b = rows_[hi * columns_ + c];
        in[k] = w == 1 ? b : (1 - w) * rows_[(hi - 1) * columns_ + c] + w * b;
        break;
      }
      case Source::law: {
        if (s.compiled >= 0) {
          in[k] = compiled_->values[static_cast<std::size_t>(s.compiled)];
          // A value that is not finite (sqrt, log, asin outside their real domains give NaN in double) is
          // evaluated once more by GiNaC below, which tells a complex value from a pole.
          if (std::isfinite(in[k])) break;
        }
        GiNaC::ex v;
        try {
          v = s.expression.subs(point()).evalf();
        } catch (const std::exception& e) {  // a pole (log(0), 1/0 at this t): the law's, not the model's
          throw InputError(s.origin + ": the law of " + quote(model_.inputs[k].get_name()) + " has no value at t = " +
                           std::to_string(t) + " (" + e.what() + "); expected a law defined along the motion");
        }
        if (GiNaC::is_a<GiNaC::numeric>(v) && !GiNaC::ex_to<GiNaC::numeric>(v).is_real())  // not its real part
          throw InputError(s.origin + ": the law of " + quote(model_.inputs[k].get_name()) +
                           " takes the complex value " + quote(to_text(v)) + " at t = " + std::to_string(t) +
                           "; expected a real-valued input");
        in[k] = GiNaC::is_a<GiNaC::numeric>(v) ? GiNaC::ex_to<GiNaC::numeric>(v).to_double() : std::nan("");
        break;
      }
    }
  }
}

}  // namespace hamel
