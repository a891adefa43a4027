// A pass over one program (a kernel's outputs, a part of a package's shared work, a subroutine): what the printing
// loop (emit/statement_printer.hpp) prints, step by step, into the functions the program becomes. It sorts the
// program into leaves, printed where they are read (constants, arguments, values an earlier stage passes), and
// statements; splits a long one into parts (emit/kernel_parts.hpp); decides which statements are printed inside the
// statement that reads them and which get a local w<n> of their own (work-variable allocation, as CasADi does it as
// a pass over its instruction list); and lists each function's steps: compute a statement, pass it on in v[], write
// an output.
#pragma once

#include "emit/expression_graph.hpp"
#include "emit/kernel_parts.hpp"

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

namespace hamel {

/// The most operations one printed statement holds: a statement read once, by a later statement of the same
/// function, and no output, is printed inside that statement's expression, not as a local of its own, up to this.
constexpr int kOperationsPerStatement = 16;

/// One step of a printed function, printed once for every lane of the program (Destination::lanes) in turn.
struct Step {
  enum class Kind : std::uint8_t {
    compute,  ///< const real w<n> = <the statement's expression>;
    pass,     ///< v[<slot>] = w<n>; for a later part
    write,    ///< <output's target> = <the value's name>;
  };
  Kind kind;
  int node;                ///< the statement computed or passed, or the value written
  std::size_t output = 0;  ///< write: the output's position in the program's outputs
  int lane = -1;           ///< write: the one lane it writes; -1: every lane in turn
};

/// The steps of the functions one program is printed as: one function, or its parts called in turn.
struct StatementSchedule {
  std::vector<char> leaf;       ///< by node: a constant, an argument or a value an earlier stage passes
  std::vector<int> statements;  ///< every other node of the program, in the order printed
  std::vector<int> part;        ///< by node: the part that computes a statement; -1 for the others
  std::vector<char> inside;     ///< by node: a statement printed inside the one statement that reads it
  std::map<int, int> local;     ///< statement with a local of its own -> n, its local w<n>, in statement order
  Parts parts;                  ///< a single part unless `split`
  bool split = false;
  /// The functions' steps: the program's (not split), or its parts' and then those of further parts that only copy
  /// outputs (`computing`: how many compute).
  std::vector<std::vector<Step>> functions;
  std::size_t computing = 1;
  /// Split: the copies of outputs no part writes that the kernel's own function makes after calling the parts.
  std::vector<Step> driver;
};

/// How a program is printed.
struct ScheduleOptions {
  /// Split into parts of at most this many printed statements, all lanes together (split / lanes of the program's
  /// own); 0: never.
  int split = 0;
  bool outputs_in_parts = true;  ///< a part writes the outputs it computes; false: all are copied at the end
  int lanes = 1;                 ///< argument sets the program runs on at once (Subroutine::lanes)
};

/// What to print for the program computing `outputs`, with the nodes marked in `given` read from earlier stages and
/// the outputs marked in `written` (by position) already written by them.
StatementSchedule schedule_statements(const ExpressionGraph& g, const std::vector<int>& outputs,
                                      const std::vector<char>& given, const std::vector<char>& written,
                                      const ScheduleOptions& options);

}  // namespace hamel
