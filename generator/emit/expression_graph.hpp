// A small intermediate representation between algebra and text (after CasADi's instruction list):
// a DAG of scalar operations in which every node is created once (value numbering over operation and
// operands), so common subexpressions are shared across all kernels of a model. Constants are folded
// and trivial identities (x+0, x·1, x·0) removed while building. Printing (emit/cpp_emitter) and numeric
// evaluation (emit/interpreter.hpp, in double, 50 digits or residues) are passes over this list.
//
// Canonical order: every node carries a structural key (a hash over its operation, constant, argument and
// the keys of its operands) and nodes are totally ordered by key, ties broken by comparing structure. The
// operands of add and mul, the terms of a GiNaC sum and the factors of a product are put in that order,
// and schedule() is a depth-first order from the outputs. So the graph reachable from the outputs, and the
// emitted text, depend only on the mathematical expressions, not on the order in which GiNaC iterates over
// terms (hash values that include addresses) nor on the order in which nodes were created.
#pragma once

#include "algebra/intermediates.hpp"
#include "algebra/operations.hpp"

#include <ginac/ginac.h>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hamel {

/// Kernel argument arrays, in the order of the kernel ABI: (t, x, p, in).
enum class Argument : std::uint8_t { time, state, parameter, input };

struct Node {
  Op op = Op::constant;
  int a = -1;          ///< first operand (node index)
  int b = -1;          ///< second operand
  double value = 0.0;  ///< constant value
  Argument argument = Argument::time;
  /// Input: element of the argument array. Constant: 0, or k > 0 for a constant whose exact value is not a
  /// finite double (beyond ±1.8e308, or nonzero and below the smallest double): `value` holds what reading it
  /// as a double gives (±inf, 0) and the k-th entry of ExpressionGraph::unrepresentable_values the exact value.
  /// Such a constant is never folded nor taken for 0 or 1; a kernel that reaches one is not emitted.
  int index = 0;
};

/// Operation counts of a kernel (what its signature comment reports).
struct OpCounts {
  int add = 0, mul = 0, div = 0, call = 0;
  int total() const { return add + mul + div + call; }
  OpCounts& add_times(int n, const OpCounts& o) {
    add += n * o.add;
    mul += n * o.mul;
    div += n * o.div;
    call += n * o.call;
    return *this;
  }
};

class ExpressionGraph {
 public:
  int constant(double value);
  /// The exact number `v` (real) as a constant: constant(v as a double) when that is finite and, for v ≠ 0,
  /// nonzero; otherwise a constant marked unrepresentable (Node::index), which kernels_unrepresentable reports.
  int exact_constant(const GiNaC::numeric& v);
  int input(Argument argument, int index);
  int unary(Op op, int a);
  int binary(Op op, int a, int b);

  /// Converts a GiNaC expression; `leaves` maps every symbol it may contain to a node.
  /// Throws std::logic_error for a symbol or function it cannot translate.
  int from_expression(const GiNaC::ex& e, const std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves);

  const Node& node(int i) const { return nodes_[static_cast<std::size_t>(i)]; }
  int size() const { return static_cast<int>(nodes_.size()); }

  /// Nodes reachable from `outputs`, in evaluation order (operands before users).
  std::vector<int> schedule(const std::vector<int>& outputs) const;
  /// The same, with every node marked in `boundary` (indexed by node) taken as given: it is scheduled like a leaf,
  /// its operands are not (the values a function reads from work computed before it, emit/shared_stages.hpp).
  std::vector<int> schedule(const std::vector<int>& outputs, const std::vector<char>& boundary) const;
  OpCounts count(const std::vector<int>& schedule) const;

  bool is_constant(int i, double v) const {
    return node(i).op == Op::constant && node(i).index == 0 && node(i).value == v;
  }
  /// True for a constant whose exact value is not a finite double (see Node::index).
  bool is_unrepresentable(int i) const { return node(i).op == Op::constant && node(i).index > 0; }
  /// The exact value of such a constant, about 6 digits ("1.0e400", "-2.5e-330"), or of a folded one the
  /// operation that overflowed or underflowed.
  const std::string& unrepresentable_value(int i) const {
    return unrepresentable_values_[static_cast<std::size_t>(node(i).index - 1)];
  }
  /// The first output (position in `outputs`) whose computation reaches an unrepresentable constant, and
  /// that constant's node; {-1, -1} when there is none.
  std::pair<int, int> first_unrepresentable(const std::vector<int>& outputs) const;

  /// Structural key of node `i`: a function of its operation, constant value, argument, index and the keys
  /// of its operands only (not of node indices), the same in every graph that builds the same expression.
  std::uint64_t key(int i) const { return keys_[static_cast<std::size_t>(i)]; }
  /// Total structural order: by key, ties (hash collisions) broken by comparing the nodes' structure.
  bool structurally_less(int i, int j) const;

 private:
  int intern(const Node& n);
  int integer_power(int base, long exponent);
  int unrepresentable_constant(double value, const std::string& exact);
  /// constant(r) for r = op(x, y) folded in doubles, or an unrepresentable constant when the fold overflowed
  /// (finite operands, non-finite result) or underflowed (a nonzero product, quotient or power gave 0).
  int folded(Op op, double x, double y, double r);

  std::vector<std::string> unrepresentable_values_;  ///< exact values of unrepresentable constants (Node::index)

  std::vector<Node> nodes_;
  std::vector<std::uint64_t> keys_;  ///< structural key per node
  struct Key {
    std::array<std::uint64_t, 3> words;
    bool operator==(const Key& o) const { return words == o.words; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ULL;
      for (std::uint64_t w : k.words) h = (h ^ w) * 1099511628211ULL;
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<Key, int, KeyHash> index_;
  /// `e` as (node, sign) with e = sign·node, the sign of every sum chosen structurally (its first term in
  /// structural order is added): GiNaC keeps a sum inside a product as S or −S depending on its term order.
  std::pair<int, int> signed_expression(const GiNaC::ex& e, const std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves);
  /// The same for a sum, a product and a power: signed_expression's cases.
  std::pair<int, int> signed_sum(const GiNaC::ex& e, const std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves);
  std::pair<int, int> signed_product(const GiNaC::ex& e, const std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves);
  std::pair<int, int> signed_power(const GiNaC::ex& e, const std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves);
  std::map<GiNaC::ex, std::pair<int, int>, GiNaC::ex_is_less> memo_;
};

/// One program a kernel runs several times on different arguments (the same solve for every column of a
/// Jacobian), printed once as a function of its own and called: the emitted text then holds it once instead of
/// once per call. Its own graph reads one argument set as x[k] (Argument::state) and the values all calls share as
/// p[k] (Argument::parameter).
///
/// Lanes: a call runs the program on `lanes` argument sets at once (a Jacobian's consecutive columns), printed
/// statement by statement for each lane in turn, so that the lanes' copies of a statement are adjacent, alike and
/// independent: a compiler's straight-line (SLP) vectorizer then computes them in one SIMD instruction (g++ -O2
/// does, with two doubles per SSE2 or NEON register), and a scalar build still interleaves two dependent chains.
struct Subroutine {
  ExpressionGraph graph;
  std::vector<int> outputs;  ///< nodes of `graph`: one lane's results
  std::vector<int> shared;   ///< nodes of the kernel's graph, passed as p[k]
  std::size_t lanes = 1;
  struct Call {
    /// Nodes of the kernel's graph: argument k of lane l at k·lanes + l, passed as x[k·lanes + l].
    std::vector<int> arguments;
    /// The kernel's output that output r of lane l is, at r·lanes + l. Every call's results lie in one pattern, the
    /// first call's shifted (the printer passes out + the first result): a Jacobian's columns, shifted by a column.
    std::vector<int> results;
  };
  std::vector<Call> calls;
};

/// One emitted function: named outputs computed from the graph.
struct Kernel {
  std::string name;
  std::string summary;                    ///< one line: what it computes and which equation
  std::vector<int> outputs;               ///< graph nodes, one per output element
  std::vector<std::string> output_names;  ///< for comments, same length as outputs
  /// If set, how the printer forms the outputs its calls' results name (the others as usual): by calling the
  /// subroutine. `outputs` is still the whole program, which every other pass reads; whoever rewrites
  /// `outputs` must clear this.
  std::shared_ptr<const Subroutine> calls;
};

/// Converts expressions that may use intermediate symbols (algebra/intermediates.hpp) into `graph`: each
/// definition becomes a node when an expression first needs it, after the definitions it uses. `tape` may
/// grow between calls (differentiation adds definitions); symbols that only some definitions use (the
/// acceleration symbols of a tree's TreeRecursion) may get their leaves late.
class ProgramConverter {
 public:
  using Leaves = std::map<GiNaC::ex, int, GiNaC::ex_is_less>;
  ProgramConverter(ExpressionGraph& graph, Leaves& leaves, const Intermediates& tape)
      : graph_(graph), leaves_(leaves), tape_(tape) {}
  int operator()(const GiNaC::ex& e);

 private:
  void convert_used(const GiNaC::ex& e);
  ExpressionGraph& graph_;
  Leaves& leaves_;
  const Intermediates& tape_;
  std::vector<bool> converted_;
};

/// Forward-mode (tangent) differentiation of the program that computes `outputs`: the tangent of every
/// output when the input nodes in `seed` carry the given tangent nodes (all other inputs: 0). One pass
/// over the program, each operation replaced by its derivative rule, so the result has at most a few
/// operations per operation of the program; zero tangents fold away (value numbering), so only what
/// depends on the seeded inputs is differentiated.
std::vector<int> tangent(ExpressionGraph& g, const std::vector<int>& outputs, const std::map<int, int>& seed);

/// `outputs` with every node `k` of `replace` taken as `replace[k]`: the program above the replaced nodes is
/// rebuilt (value numbering shares what does not depend on them).
std::vector<int> substitute(ExpressionGraph& g, const std::vector<int>& outputs, const std::map<int, int>& replace);

/// The parameter-only work of a program, to be done once per parameter set instead of on every call
/// (loop-invariant code motion with the parameters as the invariants): the operations that depend on
/// parameters and constants alone and that are outputs or operands of an operation depending on t, x or in,
/// in evaluation order. Everything they need is parameter-only too: schedule(result) is the work moved out.
std::vector<int> parameter_frontier(const ExpressionGraph& g, const std::vector<int>& outputs);

/// `outputs` rewritten so that parameter-only values gather into as few per-call operations as possible: a
/// division a / k by a parameter-only k becomes a · (1/k), and a product of factors of the form v · k (v
/// depending on t, x or in, k parameter-only) becomes (v · v′) · (k · k′). The parameter-only products and
/// reciprocals join the work parameter_frontier moves out; what is left per call has no more operations than
/// before (each rewritten multiplication replaces one), usually fewer. Reassociation: results may differ from
/// the original program in the last bits.
std::vector<int> group_invariants(ExpressionGraph& g, const std::vector<int>& outputs);

/// Moves the work of `sub` that depends on its shared values alone (parameter_frontier of its program) into the
/// kernel's graph `g`, where it is done once instead of once per call: those values become shared values of
/// their own, and shared values no longer read are dropped. False (and `sub` unchanged) when that work reaches a
/// constant that is not a finite double.
bool hoist_shared_work(ExpressionGraph& g, Subroutine& sub);

/// The operations of the program computing `outputs` that depend on t, x or in: what a kernel whose
/// parameter-only work is prepared (parameter_frontier) still does per call.
OpCounts run_time_operations(const ExpressionGraph& g, const std::vector<int>& outputs);

}  // namespace hamel
