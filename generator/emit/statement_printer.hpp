// The one printing loop: the steps of a statement schedule (emit/statement_schedule.hpp) as C++ statements, one line
// per step and lane. Each operation is printed as the operation table (algebra/operations.hpp) spells it, with its
// operands named as the function reads them: a constant as a literal, an argument as t, x[k], p[k] or in[k], a value
// an earlier stage passed as its array's entry, a statement of this function as its local w<n> (or its expression,
// when printed inside its reader), one of another part as its slot of v[].
#pragma once

#include "emit/expression_graph.hpp"
#include "emit/shared_stages.hpp"
#include "emit/statement_schedule.hpp"

#include <cstddef>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace hamel {

/// A double as a C++ literal of the packages' scalar type: real(<shortest decimal that reads back to it>).
std::string real_literal(double v);

/// Where a printed function's outputs go: the arrays its signature takes, the shape in its comment, and output o's
/// target.
struct Destination {
  /// The arrays it writes, its parameters after (t, x, p, in): out, or out and a second.
  std::vector<std::string> arrays;
  std::string shape;
  std::function<std::string(std::size_t)> target;
  /// A split kernel's parts write the outputs they compute; false: the kernel copies them all at its end.
  bool outputs_in_parts = true;
  /// The program is run on this many argument sets at once (Subroutine::lanes): lane l reads x[k·lanes + l] for the
  /// program's x[k] and writes its output o to target(o·lanes + l), named by the kernel's output_names[o·lanes + l];
  /// each statement is printed once per lane, in turn.
  int lanes = 1;
  /// A function of the package's own (its anonymous namespace), called by the package's kernels: kept out of line
  /// when long (emit/kernel_printer.cpp).
  bool internal = false;
};

/// Shared stages (emit/shared_stages.hpp): stage k's exports are the array s<k>, and the outputs of unit u a stage
/// writes are unit u's out[], passed as m<u> (by the other units, an array of their own).
std::string stage_array(int stage);
std::string layout_array(int unit);
/// The array a value an earlier stage computed is read from.
std::string value_array(const StageValue& at);

/// What the steps a function prints use: for its (void) casts of what it does not.
struct Usage {
  bool arguments[4] = {false, false, false, false};  ///< t, x, p, in
  std::set<std::string> read;                        ///< the arrays of earlier stages it reads
  std::set<std::string> wrote;                       ///< the arrays it writes, and v when it reads or writes v[]
};

/// The printing loop of one program printed to `destination` (its outputs and their names from `kernel`), reading
/// the values in `reads` from the stages called before it.
class StatementPrinter {
 public:
  StatementPrinter(const ExpressionGraph& g, const StatementSchedule& schedule, const Kernel& kernel,
                   const Destination& destination, const StageReads* reads);
  /// The steps of function `part` of the schedule (a part's number, or -1 for the function calling the parts) as
  /// statement lines, noting what they use in `usage`.
  std::string print(const std::vector<Step>& steps, int part, Usage& usage);

 private:
  std::string line(const Step& step, int part, Usage& usage) const;
  std::string name(int i, int part, Usage& usage) const;
  std::string leaf(int i, Usage& usage) const;
  std::string local(int i) const;
  std::string passed(int i) const;

  const ExpressionGraph& g_;
  const StatementSchedule& s_;
  const Kernel& k_;
  const Destination& d_;
  const StageReads* reads_;
  int lane_ = 0;  ///< the lane being printed
};

}  // namespace hamel
