// A pass over one long program (a kernel, a stage, a subroutine): where it is split into parts, each printed as a
// function of its own (emit --split N), in which order its statements go, and which values one part passes to a
// later one in the kernel's stack array v[], in which slot.
//
// Why: an optimizing compiler's register allocation grows faster than linearly with the length of one function
// (g++ -O2 spent 75 % of a 63 s compile in LRA on a 44 000-statement file), and a part's code stays closer to the
// instruction cache. A value one part computes and a later part reads is passed in v[]; a slot is reused once its
// value has been read for the last time. Outputs go to out[] from the part that computes them (`outputs_in_parts`),
// or else from v[] at the kernel's end.
#pragma once

#include "emit/expression_graph.hpp"

#include <algorithm>
#include <map>
#include <vector>

namespace hamel {

/// The parts of a program's statements (positions in their printing order).
struct Parts {
  std::vector<int> start{0};  ///< position of each part's first statement
  std::map<int, int> slot;    ///< statement node passed to a later part (or to the kernel's end) -> its slot of v[]
  int n_slots = 0;
  /// The part of the statement at position w.
  int part_at(int w) const {
    return static_cast<int>(std::upper_bound(start.begin(), start.end(), w) - start.begin()) - 1;
  }
};

/// Statements in an order, and the parts planned with that order.
struct PlannedParts {
  std::vector<int> statements;
  Parts plan;
};

/// The parts of at most `part_size` statements of the program computing `outputs` (`statements`: its statements in
/// their depth-first schedule; `leaf`, by node: the constants, arguments and values read from stages, which no part
/// computes; `given`: the nodes scheduled as given, ExpressionGraph::schedule). Where the parts end: near equal
/// lengths (a short last part would read most of what it needs from v[]: the 4-body tree's rhs, 2 207 statements,
/// ran 11 % slower in parts of 2 000 + 207), and within a quarter of a part of that, at the boundary the fewest values
/// cross. The statements in the order that passes fewer values from part to part: the depth-first schedule from the
/// outputs in their order, or in the reverse order. Which is better depends on the program: the Jacobian of a tree
/// lists its columns from the root's joint to the leaves' while its composites are summed from the leaves in, so the
/// reverse order computes each composite next to the columns that read it (the 30-joint chain's jacobian_stage
/// passed 5 699 values in v[] in the order of its outputs, 4 506 in reverse, and g++ -O2 took 11.5 and 9.7 s on the
/// jacobian-only package). Every value passed is a store and a load that g++'s passes over memory walk
/// (docs/benchmarks.md). Both orders are planned in full (0.15 s of chain 30's 2.2 s of emission).
PlannedParts plan_parts(const ExpressionGraph& g, const std::vector<int>& statements, const std::vector<int>& outputs,
                        const std::vector<char>& given, const std::vector<char>& leaf, bool outputs_in_parts,
                        int part_size);

}  // namespace hamel
