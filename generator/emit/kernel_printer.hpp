// A kernel as the C++ functions of a package: one function; a long one as parts called in turn (the parts of its
// statement schedule, emit/statement_schedule.hpp); a kernel whose repeated solve is a subroutine as a stage and
// the calls of one printed subroutine (emit/subroutine_calls.hpp); a kernel that calls shared stages as those calls
// and its own work; and the shared stages' functions themselves (emit/shared_stages.hpp). The statements inside every
// function are printed by the one printing loop, emit/statement_printer.hpp; here are the functions around them:
// signatures, (void) casts of what a function does not use, the calls, and the comment line with each kernel's
// operation counts.
#pragma once

#include "emit/expression_graph.hpp"
#include "emit/shared_stages.hpp"
#include "emit/statement_printer.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace hamel {

/// emit --split's default (EmitSettings::split_statements).
constexpr int kSplitStatements = 2000;

/// The argument sizes of a package's kernels, and how they are printed.
struct Sizes {
  int n_q, n_u, n_x, n_p, n_in;
  int split = 0;      ///< the most statements a part of a split kernel has; 0: never split
  bool calls = true;  ///< a kernel with a subroutine (Kernel::calls) printed with its calls; false: flat
};

struct PrintedKernel {
  std::string name;
  std::string text;
  int temporaries = 0;  ///< its values, one per operation (locals, printed or inside an expression, and v[] slots)
  OpCounts ops;
  int parts = 1;  ///< functions the kernel is printed as (emit --split)
  /// Reals of the caller's work space <name>_work(..., real* work) takes in place of the stack array v[] through which
  /// the parts of a split kernel pass values (<name> itself declares that array and calls it); 0: no such function.
  int work = 0;
};

/// The kernel ABI's signature of k: void <name>(real t, const real* x, const real* p, const real* in, real* out).
std::string signature(const Kernel& k);

/// Kernel k's comment line: its argument and output sizes, how it is printed (`how`, after the shape), and the
/// operations it executes.
std::string kernel_comment(const Kernel& k, const Sizes& s, const std::string& shape, const std::string& how,
                           const OpCounts& c);

/// The kernel ABI's destination: out[o].
Destination to_out(const Kernel& k);
/// Outputs before `first` to out[], the others to a second array `second`, an extra argument.
Destination to_two_arrays(const Kernel& k, std::size_t first, const std::string& second);

/// Kernel k's outputs as one function printed to `d`, or a long one as parts called in turn. With `reads`, the values
/// of earlier stages it reads are taken from their arrays (extra parameters of the function and of its parts).
PrintedKernel print_program(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                            const StageReads* reads = nullptr);

/// The shared stages a kernel calls before its own work (emit/shared_stages.hpp), as its function prints them.
struct UnitStages {
  const StageReads* reads = nullptr;  ///< what its own work reads from them; null: it calls none
  int unit = -1;                      ///< its unit in the plan: the outputs stages write for it go to its out[]
  std::string prologue;               ///< their arrays declared, then their calls
  std::vector<std::string> names;     ///< their functions, in calling order
  OpCounts ops;                       ///< their statements
  int temporaries = 0;                ///< their arrays, and the most values (temporaries) one of them has
};

/// A kernel printed to `d` when it calls shared stages: its own work as <name>_own, which reads their arrays, and the
/// kernel itself, which calls them and then <name>_own.
PrintedKernel print_after_stages(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                                 const UnitStages& stages);

/// A kernel with the kernel ABI, printed with its calls when it has them, and after the shared stages it calls.
PrintedKernel print_kernel(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const UnitStages& stages = {});

/// The functions of a package's shared stages, each <prefix>shared_<k>(t, x, p, in, out, <the arrays it reads>)
/// writing its exports to out[]; and for every unit, the stages it calls as its function prints them.
struct PrintedStages {
  std::string text;
  std::vector<UnitStages> units;  ///< their `reads` point into the plan, which must outlive them
};

/// The stages of `plan` printed, with the names of its units (the kernels) for their comments.
PrintedStages print_stages(const ExpressionGraph& g, const SharingPlan& plan, const Sizes& s, const std::string& prefix,
                           const std::vector<std::string>& names);

/// One kernel as a package prints it into its source (with argument sizes n_x, n_p, n_in for its comment): for
/// tests of the printed text, e.g. that it does not depend on the order the graph was built in.
std::string kernel_text(const ExpressionGraph& graph, const Kernel& kernel, int n_x, int n_p, int n_in,
                        int split_statements = kSplitStatements);

}  // namespace hamel
