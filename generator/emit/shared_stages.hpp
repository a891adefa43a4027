// Work that several kernels of a package have in common, printed once. The kernels of a model share one
// expression graph (value numbering), so the same statements reach several of them: on the 30-joint chain with
// `--jacobian-solve ldlt`, rhs and jacobian both hold the 13 500 statements of the articulated-body recursion, and
// mass_matrix, connection, locked_inertia, shape_inertia and jacobian the same composite inertias. Printed per kernel,
// the package held and compiled that work once per kernel. A *shared stage* is such common work as a function of its
// own: every kernel that needs it calls it before its own work, and it leaves the values later work reads in an array
// (its exports). This is common-subexpression elimination across the kernels of a package, printed as calls; each
// kernel still computes everything it needs in one call of it.
//
// Which work: every statement (a node that is neither a constant nor an argument) is used by the set of kernels
// whose outputs reach it. The statements used by one same set of two or more kernels form a class; a class of at
// least `min_statements` statements becomes a stage. A statement's operands are used by every kernel that uses it,
// so the work a stage reads lies in classes of supersets of its kernels. Stages are called in the order of their
// number of kernels (most first, then by the set), which puts every stage after the stages it reads. Work of the
// classes that are not stages is computed where it is needed, also inside a stage, as without stages.
//
// What it costs: every caller of a stage writes all its exports to memory, also those only other kernels read, and
// reads them back. A stage of many statements per export (rhs's articulated-body recursion, which the jacobian
// reuses with `--jacobian-solve ldlt`: 13 500 statements, 190 exports on the 30-joint chain) costs nothing measurable;
// one of a few statements per export (the composite inertias that mass_matrix, connection and shape_inertia read, 7 per
// export) made those kernels 10-50 % slower (docs/benchmarks.md). Hence `min_ratio` (emit's default picks it by the
// package's size: EmitSettings::share_ratio). Two things make a stage cheaper
// for its callers: a kernel that would read few of a stage's exports (`min_read`) does not call it but computes that
// work itself, as without stages (a kernel "using" statements, for the classes, means calling their stage); and a stage
// writes the outputs of one of its callers straight into that caller's out[] (Stage::layout), so that the caller does
// not copy them out of the stage's array (the 30-joint chain's mass_matrix: every one of its 1 296 outputs).
#pragma once

#include "emit/expression_graph.hpp"

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace hamel {

/// Where a function finds a value an earlier stage computed: s<stage>[position], or, when the stage writes it as an
/// output of the unit `layout` (SharingPlan::Stage::layout), m<layout>[position], that unit's output position.
struct StageValue {
  int stage = -1;
  int position = -1;
  int layout = -1;
};

/// What one function of a package reads from the stages called before it.
struct StageReads {
  std::map<int, StageValue> value;  ///< node → where it is
  std::vector<int> stages;          ///< the stages whose arrays s<k> it reads, ascending
  std::vector<int> layouts;         ///< the units whose output arrays m<u> it reads, ascending
  /// A unit's own work: its outputs (by position) that the stages it calls wrote already, into its out[].
  std::vector<char> written;
};

struct SharingPlan {
  struct Stage {
    std::vector<int> exports;  ///< the nodes it writes to its array, in this order: what later functions read
    /// The unit whose outputs it also writes, each at its position in that unit's out[] (an array m<layout> its
    /// callers pass: that unit its out, the others one of their own); -1: none. Such outputs are not exports.
    int layout = -1;
    std::vector<std::pair<int, int>> outputs;  ///< (position in m<layout>, node), ascending
    StageReads reads;                          ///< what it reads from earlier stages
    std::vector<int> units;                    ///< the units that call it, ascending
    int statements = 0;                        ///< statements it computes
  };
  std::vector<Stage> stages;             ///< in calling order
  std::vector<std::vector<int>> called;  ///< per unit: the stages it calls, in calling order
  std::vector<StageReads> own;           ///< per unit: what its own work reads from them
  std::vector<int> outputs;              ///< per unit: how many outputs it has (the length of m<unit>)
  bool empty() const { return stages.empty(); }
};

/// The stages of the units (each the outputs of one printed function: a kernel's outputs, or what a kernel with
/// calls computes before them): the classes of at least `min_statements` statements whose stage computes at least
/// `min_ratio` statements per value it exports (0: any), and the classes that two of them would otherwise both
/// compute; none when min_statements is 0 or there are more than 64 units. A unit that would read less than `min_read`
/// of a stage's exports does not call it but computes that work itself (0: every unit using a class calls its stage).
/// A stage writes the outputs of one unit it computes straight into that unit's out[] (Stage::layout): the unit of
/// those `writes_out` (its function's outputs are its out[], in order) with the most of them; the unit's own work then
/// does not copy them.
SharingPlan plan_shared_stages(const ExpressionGraph& g, const std::vector<std::vector<int>>& units, int min_statements,
                               double min_ratio = 0, const std::vector<char>& writes_out = {}, double min_read = 0.1);

}  // namespace hamel
