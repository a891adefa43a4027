#include "emit/cpp_emitter.hpp"
#include "emit/shared_stages.hpp"

#include "algebra/expression_text.hpp"

#include "model/input_error.hpp"
#include "model/load_model.hpp"
#include "report/atomic_file.hpp"
#include "report/temporaries.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#ifndef HAMEL_VERSION
#define HAMEL_VERSION "unknown"
#endif

namespace hamel {

const char* generator_version() { return HAMEL_VERSION; }

namespace {

// Shortest decimal that reads back to the same double, always spelled as a floating literal.
std::string literal(double v) {
  if (std::isnan(v)) return "real(NAN)";
  if (std::isinf(v)) return v > 0 ? "real(HUGE_VAL)" : "real(-HUGE_VAL)";
  std::string s = shortest_decimal(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return "real(" + s + ")";
}

const char* function_name(Op op) {
  if (op == Op::pow) return "std::pow";
  const Function* f = function_of(op);
  return f ? f->cpp : nullptr;
}

const char* argument_name(Argument a) {
  switch (a) {
    case Argument::time:
      return "t";
    case Argument::state:
      return "x";
    case Argument::parameter:
      return "p";
    case Argument::input:
      return "in";
  }
  return "";
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

struct Sizes {
  int n_q, n_u, n_x, n_p, n_in;
  int split = 0;      ///< the most statements a part of a split kernel has; 0: never split
  bool calls = true;  ///< a kernel with a subroutine (Kernel::calls) printed with its calls; false: flat
};

std::string signature(const Kernel& k) {
  return "void " + k.name + "(real t, const real* x, const real* p, const real* in, real* out)";
}

struct PrintedKernel {
  std::string name;
  std::string text;
  int temporaries = 0;  ///< its values, one per operation (locals, printed or inside an expression, and v[] slots)
  OpCounts ops;
  int parts = 1;  ///< functions the kernel is printed as (emit --split)
};

// How tightly a node's expression binds: sums 1, products and quotients 2, a negation 3, a call 4 (names and
// literals bind like calls).
int binding(Op op) {
  switch (op) {
    case Op::add:
    case Op::sub:
      return 1;
    case Op::mul:
    case Op::div:
      return 2;
    case Op::neg:
      return 3;
    default:
      return 4;
  }
}

// The right-hand side of node i's statement: an operand printed inside it (`inside`, by node) as its own expression,
// parenthesized where C++ would otherwise group it differently (a - (b + c), a * (b + c), a / (b * c), -(a * b)); any
// other operand by the name `name_of` gives it. C++ groups a + b + c as (a + b) + c, so the operations and their
// order are exactly those of one statement per node.
std::string statement_text(const ExpressionGraph& g, int i, const std::vector<char>& inside,
                           const std::function<std::string(int)>& name_of) {
  const Node& n = g.node(i);
  // Operand j, parenthesized when it binds no tighter than `needs`.
  const auto operand = [&](int j, int needs) {
    if (!inside[static_cast<std::size_t>(j)]) return name_of(j);
    const std::string text = statement_text(g, j, inside, name_of);
    return binding(g.node(j).op) <= needs ? "(" + text + ")" : text;
  };
  switch (n.op) {
    case Op::add:
      return operand(n.a, 0) + " + " + operand(n.b, 1);
    case Op::sub:
      return operand(n.a, 0) + " - " + operand(n.b, 1);
    case Op::mul:
      return operand(n.a, 1) + " * " + operand(n.b, 2);
    case Op::div:
      return operand(n.a, 1) + " / " + operand(n.b, 2);
    case Op::neg:
      return "-" + operand(n.a, 3);
    case Op::pow:
      return std::string(function_name(n.op)) + "(" + operand(n.a, 0) + ", " + operand(n.b, 0) + ")";
    default:
      return std::string(function_name(n.op)) + "(" + operand(n.a, 0) + ")";
  }
}

// The statements printed inside the one statement that reads them (by node): a statement read exactly once, by a
// later statement of the same function (`same_function(value, reader)`), that is not an output (`output`, by node),
// is written in its reader's expression instead of as a local of its own, while that expression stays at most
// kOperationsPerStatement operations. A chain of single-use values becomes one line: the 30-joint chain's package
// shrinks from 6.3 to 2.7 MB of C++ (148 907 locals to 25 796), with the same operations in the same order.
std::vector<char> printed_inside(const ExpressionGraph& g, const std::vector<int>& statements,
                                 const std::vector<char>& output, const std::function<bool(int, int)>& same_function) {
  const std::size_t n = static_cast<std::size_t>(g.size());
  std::vector<char> statement(n, 0), inside(n, 0);
  std::vector<int> reads(n, 0), size(n, 1);  // size: the operations of its printed expression
  for (int r : statements) {
    statement[static_cast<std::size_t>(r)] = 1;
    for (int operand : {g.node(r).a, g.node(r).b})
      if (operand >= 0) ++reads[static_cast<std::size_t>(operand)];
  }
  for (int r : statements) {
    int total = 1;
    for (int operand : {g.node(r).a, g.node(r).b}) {
      if (operand < 0) continue;
      const std::size_t j = static_cast<std::size_t>(operand);
      if (!statement[j] || reads[j] != 1 || output[j] || !same_function(operand, r) ||
          total + size[j] > kOperationsPerStatement)
        continue;
      inside[j] = 1;
      total += size[j];
    }
    size[static_cast<std::size_t>(r)] = total;
  }
  return inside;
}

std::string argument_voids(const bool uses[4]) {
  static const char* args[4] = {"t", "x", "p", "in"};
  std::string s;
  for (int a = 0; a < 4; ++a)
    if (!uses[a]) s += std::string("  (void)") + args[a] + ";\n";
  return s;
}

// Where a printed kernel's outputs go: the arrays its signature takes (head_of), the shape in its comment, and output
// o's target.
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
  /// when long (out_of_line).
  bool internal = false;
};

// A long function the package calls, never inlined into its caller: g++ inlines a static function called once,
// which glues a split kernel's parts back into one function and a kernel's own work into the function that calls
// the shared stages before it, and its passes over memory accesses grow faster than linearly with a function's
// length (the 30-joint chain's package: g++ -O2 21.3 -> 19.0 s, best of several runs; with --share-ratio 0,
// 15.1-15.6 s with only the parts out of line, 14.0-15.0 s with every long function; docs/benchmarks.md). A short
// one (a small model's rhs_with_pivots) may still be inlined, and so may the parts of a kernel split in two: g++
// inlines about two parts into their caller anyway, and the 30-joint chain's energy (two parts) ran 14 % slower
// with them out of line.
constexpr int out_of_line_statements = 64;
std::string out_of_line(bool internal, int statements) {
  return internal && statements >= out_of_line_statements ? "HAMEL_NOINLINE " : "";
}
// At most this many output copies in one function (print_kernel, after a split kernel's parts).
constexpr std::size_t writes_per_part = 128;

// The kernel ABI: out[o].
Destination to_out(const Kernel& k) {
  return {{"out"}, "out[" + std::to_string(k.outputs.size()) + "]", [](std::size_t o) {
            return "out[" + std::to_string(o) + "]";
          }};
}

// Outputs before `first` to out[], the others to a second array `second`, an extra argument.
Destination to_two_arrays(const Kernel& k, std::size_t first, const std::string& second) {
  return {{"out", second},
          "out[" + std::to_string(first) + "], " + second + "[" + std::to_string(k.outputs.size() - first) + "]",
          [first, second](std::size_t o) {
            return o < first ? "out[" + std::to_string(o) + "]" : second + "[" + std::to_string(o - first) + "]";
          }};
}

// Kernel k's comment line: its argument and output sizes, how it is printed, and the operations it executes.
std::string kernel_comment(const Kernel& k, const Sizes& s, const std::string& shape, const std::string& how,
                           const OpCounts& c) {
  return "/* " + k.name + ": (t, x[" + std::to_string(s.n_x) + "], p[" + std::to_string(s.n_p) + "], in[" +
         std::to_string(s.n_in) + "]) -> " + shape + how + "  ops: " + std::to_string(c.add) + " add, " +
         std::to_string(c.mul) + " mul, " + std::to_string(c.div) + " div, " + std::to_string(c.call) + " call */\n";
}

// Shared stages (emit/shared_stages.hpp): stage k's exports are the array s<k>, and the outputs of unit u a stage
// writes are unit u's out[], passed as m<u> (by the other units, an array of their own); a function reading some is
// passed them.
std::string stage_array(int stage) { return "s" + std::to_string(stage); }
std::string layout_array(int unit) { return "m" + std::to_string(unit); }
std::string value_array(const StageValue& at) {
  return at.layout >= 0 ? layout_array(at.layout) : stage_array(at.stage);
}
std::string stage_value(const StageValue& at) { return value_array(at) + "[" + std::to_string(at.position) + "]"; }
// The arrays of earlier stages a function printed to `d` reads, but for those it writes (a stage writing m<u>).
std::vector<std::string> read_arrays(const Destination& d, const StageReads* reads) {
  std::vector<std::string> names;
  if (!reads) return names;
  for (int stage : reads->stages) names.push_back(stage_array(stage));
  for (int unit : reads->layouts)
    if (std::find(d.arrays.begin(), d.arrays.end(), layout_array(unit)) == d.arrays.end())
      names.push_back(layout_array(unit));
  return names;
}
std::string stage_parameters(const Destination& d, const StageReads* reads) {
  std::string text;
  for (const std::string& a : read_arrays(d, reads)) text += ", const real* " + a;
  return text;
}
// (void)s<k>; for every stage array a function is passed and does not read (`read`: the arrays it does).
std::string stage_voids(const Destination& d, const StageReads* reads, const std::set<std::string>& read) {
  std::string text;
  for (const std::string& a : read_arrays(d, reads))
    if (!read.count(a)) text += "  (void)" + a + ";\n";
  return text;
}
// The signature of a function `name` printed to `d`: (t, x, p, in), the arrays of `d`, the stage arrays it reads.
std::string head_of(const Destination& d, const std::string& name, const StageReads* reads) {
  std::string text = "void " + name + "(real t, const real* x, const real* p, const real* in";
  for (const std::string& a : d.arrays) text += ", real* " + a;
  return text + stage_parameters(d, reads) + ")";
}
// Its arrays as a call passes them on: ", out" or ", out, <second>".
std::string array_arguments(const Destination& d) {
  std::string text;
  for (const std::string& a : d.arrays) text += ", " + a;
  return text;
}
// The stage arrays of a function printed to `d` as its caller passes them; unit `unit` passes its out[] as m<unit>.
std::string stage_arguments(const Destination& d, const StageReads* reads, int unit = -1) {
  std::string text;
  for (const std::string& a : read_arrays(d, reads)) text += ", " + (unit >= 0 && a == layout_array(unit) ? "out" : a);
  return text;
}

// A long kernel is split into parts of at most part_size consecutive statements, each a function of its own: an
// optimizing compiler's register allocation grows faster than linearly with the length of one function
// (g++ -O2 spent 75 % of a 63 s compile in LRA on a 44 000-statement file), and a part's code stays
// closer to the instruction cache. A value one part computes and a later part reads is passed in the kernel's
// stack array v[]; a slot is reused once its value has been read for the last time. Outputs go to out[] from
// the part that computes them (`outputs_in_parts`), or else from v[] at the kernel's end.
// Where the parts end: near equal lengths (a short last part would read most of what it needs from v[]: the
// 4-body tree's rhs, 2 207 statements, ran 11 % slower in parts of 2 000 + 207), and within a quarter of a
// part of that, at the boundary the fewest values cross (live[b]: statements before b read at or after b).
struct Parts {
  std::vector<int> start;   ///< position of each part's first statement
  std::map<int, int> slot;  ///< statement node passed to a later part (or to the kernel's end) -> its slot of v[]
  int n_slots = 0;
  /// The part of the statement at position w.
  int part_at(int w) const {
    return static_cast<int>(std::upper_bound(start.begin(), start.end(), w) - start.begin()) - 1;
  }
};

Parts plan_parts(const ExpressionGraph& g, const std::vector<int>& statements, const std::map<int, int>& index,
                 const std::map<int, std::string>& leaf, const std::vector<int>& outputs, bool outputs_in_parts,
                 int part_size) {
  const int work = static_cast<int>(statements.size());
  const int parts = (work + part_size - 1) / part_size;
  std::vector<int> live(static_cast<std::size_t>(work) + 1, 0);
  {
    // Position of the last reader; work: out[]; a statement nothing reads after it (an output written in its part)
    // is its own last reader, so it crosses no boundary.
    std::vector<int> last_use(static_cast<std::size_t>(work));
    for (int w = 0; w < work; ++w) last_use[static_cast<std::size_t>(w)] = w;
    for (int w = 0; w < work; ++w) {
      const Node& n = g.node(statements[static_cast<std::size_t>(w)]);
      for (int operand : {n.a, n.b})
        if (operand >= 0 && !leaf.count(operand)) last_use[static_cast<std::size_t>(index.at(operand))] = w;
    }
    if (!outputs_in_parts)
      for (int o : outputs)
        if (!leaf.count(o)) last_use[static_cast<std::size_t>(index.at(o))] = work;
    std::vector<int> change(static_cast<std::size_t>(work) + 2, 0);
    for (int w = 0; w < work; ++w) {
      ++change[static_cast<std::size_t>(w) + 1];
      --change[static_cast<std::size_t>(last_use[static_cast<std::size_t>(w)]) + 1];
    }
    for (int b = 1; b <= work; ++b)
      live[static_cast<std::size_t>(b)] = live[static_cast<std::size_t>(b) - 1] + change[static_cast<std::size_t>(b)];
  }
  Parts plan;
  std::vector<int>& start = plan.start;
  start.push_back(0);
  for (int part = 1; part < parts; ++part) {
    const int ideal = static_cast<int>(static_cast<long long>(part) * work / parts);
    const int slack = work / parts / 4;
    // Every part nonempty and at most part_size long, this one and those left.
    const int first = std::max(start.back() + 1, work - (parts - part) * part_size);
    const int last = std::min(start.back() + part_size, work - (parts - part));
    int lo = std::max(first, ideal - slack), hi = std::min(last, ideal + slack);
    if (lo > hi) lo = hi = std::clamp(ideal, first, last);
    int best = std::clamp(ideal, lo, hi);
    for (int b = lo; b <= hi; ++b)
      if (live[static_cast<std::size_t>(b)] < live[static_cast<std::size_t>(best)]) best = b;
    start.push_back(best);
  }
  const auto part_of = [&](int i) { return plan.part_at(index.at(i)); };
  const auto end_of = [&](int part) { return part + 1 < parts ? start[static_cast<std::size_t>(part) + 1] : work; };
  std::map<int, int> last_part;  // statement node read outside its part -> last part reading it (parts: out[])
  for (int i : statements)
    for (int operand : {g.node(i).a, g.node(i).b})
      if (operand >= 0 && !leaf.count(operand) && part_of(operand) != part_of(i))
        last_part[operand] = std::max(last_part[operand], part_of(i));
  if (!outputs_in_parts)
    for (int o : outputs)
      if (!leaf.count(o)) last_part[o] = parts;
  std::vector<std::vector<int>> expiring(static_cast<std::size_t>(parts) + 1);
  std::set<int> free_slots;
  for (int part = 0; part < parts; ++part) {
    for (int i : expiring[static_cast<std::size_t>(part)]) free_slots.insert(plan.slot.at(i));
    for (int w = start[static_cast<std::size_t>(part)]; w < end_of(part); ++w) {
      const int i = statements[static_cast<std::size_t>(w)];
      const auto last = last_part.find(i);
      if (last == last_part.end()) continue;
      if (free_slots.empty()) free_slots.insert(plan.n_slots++);
      plan.slot[i] = *free_slots.begin();
      free_slots.erase(free_slots.begin());
      // Free from the part after its last reader on (a part may read it after writing its own values).
      expiring[static_cast<std::size_t>(std::min(last->second + 1, parts))].push_back(i);
    }
  }
  return plan;
}

// A split kernel's statements in the order that passes fewer values from part to part: the depth-first schedule from
// its outputs in their order, or in the reverse order. Which is better depends on the program: the Jacobian of a
// tree lists its columns from the root's joint to the leaves' while its composites are summed from the leaves in,
// so the reverse order computes each composite next to the columns that read it (the 30-joint chain's
// jacobian_stage passed 5 699 values in v[] in the order of its outputs, 4 506 in reverse, and g++ -O2 took 11.5
// and 9.7 s on the jacobian-only package). Every value passed is a store and a load that g++'s passes over memory
// walk (docs/benchmarks.md). Both orders are planned in full (0.15 s of chain 30's 2.2 s of emission); the kernel is
// printed with the plan kept.
struct PlannedParts {
  std::vector<int> statements;
  Parts plan;
};
PlannedParts fewer_passed(const ExpressionGraph& g, const std::vector<int>& statements, const std::vector<int>& outputs,
                          const std::vector<char>& given, const std::map<int, std::string>& leaf, bool outputs_in_parts,
                          int part_size) {
  const auto planned = [&](std::vector<int> order) {
    std::map<int, int> index;
    for (std::size_t w = 0; w < order.size(); ++w) index[order[w]] = static_cast<int>(w);
    Parts plan = plan_parts(g, order, index, leaf, outputs, outputs_in_parts, part_size);
    return PlannedParts{std::move(order), std::move(plan)};
  };
  std::vector<int> reversed;
  for (int i : g.schedule(std::vector<int>(outputs.rbegin(), outputs.rend()), given))
    if (!leaf.count(i)) reversed.push_back(i);
  PlannedParts forward = planned(statements), backward = planned(std::move(reversed));
  return backward.plan.slot.size() < forward.plan.slot.size() ? backward : forward;
}

// Kernel k's outputs as one function, or a long one as parts called in turn. With `reads`, the values of earlier
// stages it reads are taken from their arrays (extra parameters of the function and of its parts), not computed.
// One printer per kernel: the constructor sorts the program into leaves (written in place) and statements, and
// plans the parts of a long kernel; print() writes the function, or its parts and the function that calls them.
class KernelPrinter {
 public:
  KernelPrinter(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                const StageReads* reads);
  PrintedKernel print();

 private:
  PrintedKernel print_whole(std::ostringstream& os);
  PrintedKernel print_parts(std::ostringstream& os);

  // A leaf as the lane being printed reads it: the program's x[k] is x[k·lanes + lane].
  std::string leaf_of(int i) const {
    const Node& n = g_.node(i);
    if (lanes_ == 1 || n.op != Op::input || n.argument != Argument::state) return leaf_.at(i);
    return "x[" + std::to_string(n.index * lanes_ + lane_) + "]";
  }
  // Runs `print` once for every lane, lane_ set to it.
  template <class F>
  void each_lane(F print) {
    for (lane_ = 0; lane_ < lanes_; ++lane_) print();
    lane_ = 0;
  }
  bool is_given(int i) const { return reads_ && given_[static_cast<std::size_t>(i)]; }
  // Every statement not printed inside another gets a local w<n>, numbered in statement order.
  void name_locals(const std::vector<char>& inside) {
    for (int i : statements_)
      if (!inside[static_cast<std::size_t>(i)]) named_.emplace(i, static_cast<int>(named_.size()));
  }
  std::string local(int i) const {
    return "w" + std::to_string(named_.at(i)) + (lanes_ > 1 ? "_" + std::to_string(lane_) : std::string());
  }
  std::size_t in_lane(std::size_t o) const {
    return o * static_cast<std::size_t>(lanes_) + static_cast<std::size_t>(lane_);
  }
  std::string output_target(std::size_t o) const { return d_.target(in_lane(o)); }
  const std::string& output_name(std::size_t o) const { return k_.output_names[in_lane(o)]; }
  // An output a stage it called wrote to out[] already (SharingPlan::Stage::layout) is not written again.
  bool written(std::size_t o) const { return reads_ && o < reads_->written.size() && reads_->written[o]; }

  const ExpressionGraph& g_;
  const Kernel& k_;
  const Sizes& s_;
  const Destination& d_;
  const StageReads* reads_;
  std::vector<char> given_;  ///< by node: a value read from a stage's array
  std::string head_;
  int lanes_;
  int lane_ = 0;                                 ///< the lane being printed
  std::map<int, std::string> leaf_;              ///< constants, arguments and values read from stages
  std::vector<int> statements_;                  ///< every other node, in the order printed
  bool uses_[4] = {false, false, false, false};  ///< t, x, p, in
  std::optional<Parts> split_;                   ///< planned with the order, when the kernel is split
  OpCounts counts_;
  int work_ = 0;              ///< statements
  std::vector<char> output_;  ///< by node: an output of the kernel
  std::map<int, int> named_;  ///< statement node with a local of its own -> n, its local w<n>
};

KernelPrinter::KernelPrinter(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                             const StageReads* reads)
    : g_(g), k_(k), s_(s), d_(d), reads_(reads), head_(head_of(d, k.name, reads)), lanes_(d.lanes) {
  if (reads) {
    given_.assign(static_cast<std::size_t>(g.size()), 0);
    for (const auto& entry : reads->value) given_[static_cast<std::size_t>(entry.first)] = 1;
  }
  for (int i : g.schedule(k.outputs, given_)) {
    const Node& n = g.node(i);
    if (is_given(i)) {
      leaf_[i] = stage_value(reads->value.at(i));
    } else if (n.op == Op::constant) {
      leaf_[i] = literal(n.value);
    } else if (n.op == Op::input) {
      uses_[static_cast<int>(n.argument)] = true;
      leaf_[i] = n.argument == Argument::time
                     ? std::string("t")
                     : std::string(argument_name(n.argument)) + "[" + std::to_string(n.index) + "]";
    } else {
      statements_.push_back(i);
    }
  }
  const int part_size = s.split > 0 ? std::max(1, s.split / lanes_) : s.split;  // statements of one lane
  if (part_size > 0 && static_cast<int>(statements_.size()) > part_size) {
    PlannedParts chosen = fewer_passed(g, statements_, k.outputs, given_, leaf_, d.outputs_in_parts, part_size);
    statements_ = std::move(chosen.statements);
    split_ = std::move(chosen.plan);
  }
  counts_ = OpCounts{}.add_times(lanes_, g.count(statements_));
  work_ = static_cast<int>(statements_.size());
  output_.assign(static_cast<std::size_t>(g.size()), 0);
  for (int o : k.outputs) output_[static_cast<std::size_t>(o)] = 1;
}

PrintedKernel KernelPrinter::print() {
  std::ostringstream os;
  os << kernel_comment(k_, s_, d_.shape, "", counts_);
  return split_ ? print_parts(os) : print_whole(os);
}

// One function: a local per statement not printed inside another, then the outputs.
PrintedKernel KernelPrinter::print_whole(std::ostringstream& os) {
  std::ostringstream body;
  std::set<std::string> read;
  const auto name_of = [&](int i) {
    if (is_given(i)) read.insert(value_array(reads_->value.at(i)));
    return leaf_.count(i) ? leaf_of(i) : local(i);
  };
  const std::vector<char> inside = printed_inside(g_, statements_, output_, [](int, int) { return true; });
  name_locals(inside);
  for (int i : statements_)
    if (!inside[static_cast<std::size_t>(i)])
      each_lane(
          [&] { body << "  const real " << local(i) << " = " << statement_text(g_, i, inside, name_of) << ";\n"; });
  std::set<std::string> wrote;  // the arrays of `d` it writes
  for (std::size_t o = 0; o < k_.outputs.size(); ++o)
    if (!written(o))
      each_lane([&] {
        const std::string to = output_target(o);
        wrote.insert(to.substr(0, to.find('[')));
        body << "  " << to << " = " << name_of(k_.outputs[o]) << ";  // " << output_name(o) << "\n";
      });
  os << out_of_line(d_.internal, work_ * lanes_ + static_cast<int>(k_.outputs.size()) * lanes_) << head_ << " {\n"
     << argument_voids(uses_) << stage_voids(d_, reads_, read);
  for (const std::string& a : d_.arrays)
    if (!wrote.count(a)) os << "  (void)" << a << ";\n";
  os << body.str() << "}\n";
  return {k_.name, os.str(), work_ * lanes_, counts_};
}

// The parts, each a function of the kernel's statements between two part boundaries, passing values in v[]; then
// the function that calls them (and the copies of the outputs no part writes).
PrintedKernel KernelPrinter::print_parts(std::ostringstream& os) {
  const Parts& plan = *split_;
  const std::vector<int>& start = plan.start;
  const std::map<int, int>& slot = plan.slot;
  const int parts = static_cast<int>(start.size()), n_slots = plan.n_slots;
  std::map<int, int> index;  // statement node -> its position
  for (int w = 0; w < work_; ++w) index[statements_[static_cast<std::size_t>(w)]] = w;
  const auto part_of = [&](int i) { return plan.part_at(index.at(i)); };
  const auto end_of = [&](int part) { return part + 1 < parts ? start[static_cast<std::size_t>(part) + 1] : work_; };
  const auto passed = [&](int i) { return "v[" + std::to_string(slot.at(i) * lanes_ + lane_) + "]"; };
  const std::vector<char> inside = printed_inside(
      g_, statements_, output_, [&](int value, int reader) { return part_of(value) == part_of(reader); });
  name_locals(inside);
  // An output a statement computes is written by the part that computes it, right after it: no slot of v[] unless
  // a later part reads it too, and no copy at the end. The kernel itself writes the outputs that are leaves.
  std::map<int, std::vector<std::size_t>> gives;  // statement node -> the outputs it is
  for (std::size_t o = 0; o < k_.outputs.size(); ++o)
    if (!leaf_.count(k_.outputs[o]) && d_.outputs_in_parts) gives[k_.outputs[o]].push_back(o);
  // Part `number` of the kernel: (t, x, p, in, v, its arrays, the stage arrays), voiding what it does not use.
  const auto print_part = [&](int number, bool kept_out_of_line, const bool part_uses[4],
                              const std::set<std::string>& read, const std::set<std::string>& wrote,
                              const std::string& body) {
    std::string voids;
    for (const std::string& a : d_.arrays)
      if (!wrote.count(a)) voids += "  (void)" + a + ";\n";
    if (!wrote.count("v")) voids += "  (void)v;\n";
    Destination with_v = d_;  // a part also gets v[]
    with_v.arrays.insert(with_v.arrays.begin(), "v");
    os << out_of_line(kept_out_of_line, out_of_line_statements)
       << head_of(with_v, k_.name + "_part" + std::to_string(number), reads_) << " {\n"
       << argument_voids(part_uses) << voids << stage_voids(d_, reads_, read) << body << "}\n\n";
  };
  // Node i in a part that does not compute it: a leaf, or the value passed in v[]; noting what the part uses
  // (arguments, stage arrays read, and v among the arrays it writes, read or written).
  const auto outside = [&](int i, bool part_uses[4], std::set<std::string>& read, std::set<std::string>& wrote) {
    if (!leaf_.count(i)) {
      wrote.insert("v");
      return passed(i);
    }
    const Node& n = g_.node(i);
    if (is_given(i))
      read.insert(value_array(reads_->value.at(i)));
    else if (n.op == Op::input)
      part_uses[static_cast<int>(n.argument)] = true;
    return leaf_of(i);
  };
  os << "namespace {\n\n";
  for (int part = 0; part < parts; ++part) {
    std::ostringstream body;
    bool part_uses[4] = {false, false, false, false};
    std::set<std::string> read;
    std::set<std::string> wrote;  // arrays it uses: v (read or written), out, ... (written)
    const auto name_of = [&](int i) {
      return !leaf_.count(i) && part_of(i) == part ? local(i) : outside(i, part_uses, read, wrote);
    };
    for (int w = start[static_cast<std::size_t>(part)]; w < end_of(part); ++w) {
      const int i = statements_[static_cast<std::size_t>(w)];
      if (inside[static_cast<std::size_t>(i)]) continue;
      each_lane(
          [&] { body << "  const real " << local(i) << " = " << statement_text(g_, i, inside, name_of) << ";\n"; });
      if (slot.count(i)) {
        each_lane([&] { body << "  " << passed(i) << " = " << local(i) << ";\n"; });
        wrote.insert("v");
      }
      const auto outputs = gives.find(i);
      if (outputs == gives.end()) continue;
      for (std::size_t o : outputs->second)
        each_lane([&] {
          const std::string to = output_target(o);
          wrote.insert(to.substr(0, to.find('[')));
          body << "  " << to << " = " << local(i) << ";  // " << output_name(o) << "\n";
        });
    }
    print_part(part, parts > 2, part_uses, read, wrote, body.str());
  }
  // The outputs no part writes (leaves, or every output without outputs_in_parts), copied in after the parts: by
  // the kernel itself, or, when there are more than writes_per_part of them, by further parts of at most that many
  // copies each. g++ -O2's time on a run of stores grows about with the square of its length: the 1 984 constant
  // entries of the 30-joint chain's Jacobian took 2.2 s of its SLP vectorizer and alias walks in one function,
  // 0.2-0.4 s in functions of 25-250 (docs/benchmarks.md). Those parts are never inlined: g++ would glue them
  // back. Fewer copies stay in the kernel (a Jacobian column's 72), where a call would cost more than they do.
  std::vector<std::pair<std::size_t, int>> copies;  // output, lane
  for (std::size_t o = 0; o < k_.outputs.size(); ++o)
    if ((leaf_.count(k_.outputs[o]) || !d_.outputs_in_parts) && !written(o))
      each_lane([&] { copies.emplace_back(o, lane_); });
  const auto copy = [&](const std::pair<std::size_t, int>& c, bool part_uses[4], std::set<std::string>& read,
                        std::set<std::string>& wrote) {
    lane_ = c.second;
    const std::string to = output_target(c.first);
    wrote.insert(to.substr(0, to.find('[')));
    const std::string text = "  " + to + " = " + outside(k_.outputs[c.first], part_uses, read, wrote) + ";  // " +
                             output_name(c.first) + "\n";
    lane_ = 0;
    return text;
  };
  std::string driver_copies;
  int copy_parts = 0;
  if (copies.size() <= writes_per_part) {
    bool unused[4] = {false, false, false, false};
    std::set<std::string> read, wrote;
    for (const auto& c : copies) driver_copies += copy(c, unused, read, wrote);
  } else {
    const std::size_t n = copies.size(), blocks = (n + writes_per_part - 1) / writes_per_part;
    for (std::size_t b = 0; b < blocks; ++b) {
      bool part_uses[4] = {false, false, false, false};
      std::set<std::string> read, wrote;
      std::string body;
      for (std::size_t c = b * n / blocks; c < (b + 1) * n / blocks; ++c)
        body += copy(copies[c], part_uses, read, wrote);
      print_part(parts + copy_parts++, true, part_uses, read, wrote, body);
    }
  }
  // v[] holds the values parts pass to later parts; when they pass none the parts are given a null pointer.
  const std::string v = n_slots > 0 ? "v" : "nullptr";
  std::ostringstream calls;
  for (int part = 0; part < parts + copy_parts; ++part)
    calls << "  " << k_.name << "_part" << part << "(t, x, p, in, " << v << array_arguments(d_)
          << stage_arguments(d_, reads_) << ");\n";
  const int driver_statements = parts + copy_parts + (copy_parts ? 0 : static_cast<int>(copies.size()));
  os << "}  // namespace\n\n"
     << out_of_line(d_.internal, driver_statements) << head_ << " {\n"
     << (n_slots > 0 ? "  real v[" + std::to_string(n_slots * lanes_) + "];\n" : std::string()) << calls.str()
     << driver_copies << "}\n";
  return {k_.name, os.str(), (work_ + n_slots) * lanes_, counts_, parts + copy_parts};
}

PrintedKernel print_kernel(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                           const StageReads* reads = nullptr) {
  return KernelPrinter(g, k, s, d, reads).print();
}

// Where a Subroutine's calls leave their results: the subroutine writes them into out[] itself, at the offsets of
// the first call's results from its first result (a Jacobian's columns: out[0], out[1], out[nx], out[nx + 1], ...),
// and each call is given out + its first result. Every call's results must lie in that pattern.
std::vector<int> result_offsets(const Subroutine& sub) {
  const auto pattern = [](const Subroutine::Call& call) {
    std::vector<int> d;
    for (int r : call.results) d.push_back(r - call.results.front());
    return d;
  };
  const std::vector<int> offset = pattern(sub.calls.front());
  std::vector<int> sorted = offset;
  std::sort(sorted.begin(), sorted.end());
  bool regular = sub.calls.front().results.front() >= 0 && sorted.front() == 0 &&
                 std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end();
  for (const Subroutine::Call& call : sub.calls)
    regular = regular && call.results.front() >= 0 && pattern(call) == offset;
  if (!regular) throw std::logic_error("a subroutine's calls place their results in different patterns");
  return offset;
}

// The stage of a kernel with calls: the outputs no call gives (`direct`: their positions in the kernel's outputs),
// then the values the calls share, then every call's arguments in turn, lane by lane (`slot`: the position in
// scratch[] of each output after the direct ones, where a call's arguments lie as its lanes read them). Computing one
// lane's arguments before the next keeps the stage's depth-first order column by column: with the arguments in
// their interleaved order instead, g++ -O2 took 7 s longer on the 30-joint chain's rhs and jacobian.
struct Stage {
  Kernel kernel;
  std::vector<std::size_t> direct, slot;
};

Stage stage_of(const Kernel& k, const Subroutine& sub) {
  Stage staged{{k.name + "_stage", "", {}, {}, nullptr}, {}, {}};
  Kernel& stage = staged.kernel;
  std::vector<std::size_t>&direct = staged.direct, &slot = staged.slot;
  std::vector<bool> by_call(k.outputs.size(), false);
  for (const Subroutine::Call& call : sub.calls)
    for (int r : call.results)
      if (r >= 0) by_call[static_cast<std::size_t>(r)] = true;
  for (std::size_t o = 0; o < k.outputs.size(); ++o) {
    if (by_call[o]) continue;
    stage.outputs.push_back(k.outputs[o]);
    stage.output_names.push_back(k.output_names[o]);
    direct.push_back(o);
  }
  for (std::size_t j = 0; j < sub.shared.size(); ++j) {
    stage.outputs.push_back(sub.shared[j]);
    stage.output_names.push_back("shared " + std::to_string(j));
    slot.push_back(j);
  }
  const std::size_t lanes = sub.lanes;
  for (std::size_t c = 0; c < sub.calls.size(); ++c) {
    const std::vector<int>& arguments = sub.calls[c].arguments;
    const std::size_t per_lane = arguments.size() / lanes;
    for (std::size_t l = 0; l < lanes; ++l)
      for (std::size_t a = 0; a < per_lane; ++a) {
        stage.outputs.push_back(arguments[a * lanes + l]);
        stage.output_names.push_back("call " + std::to_string(c) + ", argument " + std::to_string(a) +
                                     (lanes > 1 ? ", lane " + std::to_string(l) : std::string()));
        slot.push_back(sub.shared.size() + c * arguments.size() + a * lanes + l);
      }
  }
  return staged;
}

// The shared stages a kernel calls before its own work (emit/shared_stages.hpp), as its function prints them.
struct UnitStages {
  const StageReads* reads = nullptr;  ///< what its own work reads from them; null: it calls none
  int unit = -1;                      ///< its unit in the plan: the outputs stages write for it go to its out[]
  std::string prologue;               ///< their arrays declared, then their calls
  std::vector<std::string> names;     ///< their functions, in calling order
  OpCounts ops;                       ///< their statements
  int temporaries = 0;                ///< their arrays, and the most values (temporaries) one of them has
};

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + names[i];
  return text;
}

// A kernel whose repeated solve is a subroutine (Kernel::calls): the subroutine printed once as <name>_column; the
// kernel as a stage, <name>_stage, that writes the outputs no call gives and, into the stack array scratch[], the
// values the calls share and each call's arguments; then the calls, each writing its results into out[] in place.
// With shared stages, they are called first and <name>_stage reads their arrays.
PrintedKernel print_with_calls(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const UnitStages& stages) {
  const Subroutine& sub = *k.calls;
  const std::size_t n_shared = sub.shared.size(), n_results = sub.calls.front().results.size();
  const std::size_t n_arguments = sub.calls.front().arguments.size();
  const std::vector<int> offset = result_offsets(sub);
  Kernel column{k.name + "_column", "", sub.outputs, {}, nullptr};
  for (int r : sub.calls.front().results)
    column.output_names.push_back(k.output_names[static_cast<std::size_t>(r)] + " (first call)");
  Destination placed = to_out(column);
  placed.target = [&offset](std::size_t r) { return "out[" + std::to_string(offset[r]) + "]"; };
  // Measured: tree 30's jacobian ran a third slower with its calls' parts writing out[].
  placed.outputs_in_parts = false;
  placed.lanes = static_cast<int>(sub.lanes);
  placed.internal = true;
  placed.shape = "out[" + std::to_string(*std::max_element(offset.begin(), offset.end()) + 1) + "], " +
                 std::to_string(n_results) + " of them";
  const PrintedKernel called = print_kernel(
      sub.graph, column, Sizes{0, 0, static_cast<int>(n_arguments), static_cast<int>(n_shared), 0, s.split}, placed);

  const Stage staging = stage_of(k, sub);
  const Kernel& stage = staging.kernel;
  const std::vector<std::size_t>&direct = staging.direct, &slot = staging.slot;
  const std::size_t first = direct.size(), n_scratch = stage.outputs.size() - first;
  Destination into = to_two_arrays(stage, first, "scratch");
  into.internal = true;
  into.target = [&](std::size_t o) {
    return o < first ? "out[" + std::to_string(direct[o]) + "]" : "scratch[" + std::to_string(slot[o - first]) + "]";
  };
  const PrintedKernel staged = print_kernel(g, stage, s, into, stages.reads);

  OpCounts total = stages.ops;
  total.add_times(1, staged.ops);
  const int n_calls = static_cast<int>(sub.calls.size());
  total.add_times(n_calls, called.ops);
  std::vector<std::string> steps = stages.names;
  steps.push_back(k.name + "_stage");
  std::ostringstream os;
  os << "namespace {\n\n" << called.text << "\n" << staged.text << "\n}  // namespace\n\n";
  os << kernel_comment(k, s, "out[" + std::to_string(k.outputs.size()) + "]",
                       ": " + joined(steps) + ", then " + std::to_string(n_calls) + " calls of " + k.name + "_column",
                       total)
     << signature(k) << " {\n  real scratch[" << std::max<std::size_t>(n_scratch, 1) << "];\n"
     << stages.prologue << "  " << k.name << "_stage(t, x, p, in, out, scratch"
     << stage_arguments(into, stages.reads, stages.unit) << ");\n";
  for (std::size_t c = 0; c < sub.calls.size(); ++c)
    os << "  " << k.name << "_column(t, scratch + " << n_shared + c * n_arguments << ", scratch, in, out + "
       << sub.calls[c].results.front() << ");\n";
  os << "}\n";
  return {k.name, os.str(), stages.temporaries + staged.temporaries + called.temporaries + static_cast<int>(n_scratch),
          total, staged.parts};
}

// A kernel printed to `d` when it calls shared stages: its own work as <name>_own, which reads their arrays, and the
// kernel itself, which calls them and then <name>_own.
PrintedKernel print_after_stages(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                                 const UnitStages& stages) {
  Kernel own = k;
  own.name = k.name + "_own";
  own.calls = nullptr;
  Destination internal = d;
  internal.internal = true;
  const PrintedKernel printed = print_kernel(g, own, s, internal, stages.reads);
  OpCounts total = stages.ops;
  total.add_times(1, printed.ops);
  std::vector<std::string> steps = stages.names;
  steps.push_back(own.name);
  std::ostringstream os;
  os << "namespace {\n\n"
     << printed.text << "\n}  // namespace\n\n"
     << kernel_comment(k, s, d.shape, ": " + joined(steps), total) << head_of(d, k.name, nullptr) << " {\n"
     << stages.prologue << "  " << own.name << "(t, x, p, in" << array_arguments(d)
     << stage_arguments(internal, stages.reads, stages.unit) << ");\n}\n";
  return {k.name, os.str(), stages.temporaries + printed.temporaries, total, printed.parts};
}

// A kernel with the kernel ABI, printed with its calls when it has them, and after the shared stages it calls.
PrintedKernel print_kernel(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const UnitStages& stages = {}) {
  if (k.calls && s.calls) return print_with_calls(g, k, s, stages);
  return stages.reads ? print_after_stages(g, k, s, to_out(k), stages) : print_kernel(g, k, s, to_out(k));
}

// The functions of a package's shared stages, each <prefix>shared_<k>(t, x, p, in, out, <the arrays it reads>)
// writing its exports to out[]; and for every unit, the stages it calls as its function prints them.
struct PrintedStages {
  std::string text;
  std::vector<UnitStages> units;  ///< their `reads` point into the plan, which must outlive them
};

PrintedStages print_stages(const ExpressionGraph& g, const SharingPlan& plan, const Sizes& s, const std::string& prefix,
                           const std::vector<std::string>& names) {
  PrintedStages out;
  std::vector<PrintedKernel> printed;
  std::vector<Destination> into;
  for (std::size_t i = 0; i < plan.stages.size(); ++i) {
    const SharingPlan::Stage& stage = plan.stages[i];
    Kernel fn{prefix + "shared_" + std::to_string(i), "", stage.exports, {}, nullptr};
    for (std::size_t e = 0; e < stage.exports.size(); ++e) fn.output_names.push_back("export " + std::to_string(e));
    const std::size_t n_exports = stage.exports.size();
    std::vector<int> position;  // of the outputs it writes for unit `layout`, in m<layout>
    for (const auto& [j, node] : stage.outputs) {
      fn.outputs.push_back(node);
      fn.output_names.push_back("output " + std::to_string(j) + " of " + names[static_cast<std::size_t>(stage.layout)]);
      position.push_back(j);
    }
    Destination d = to_out(fn);
    d.shape = "out[" + std::to_string(n_exports) + "]";
    if (stage.layout >= 0) {
      const std::string m = layout_array(stage.layout);
      d.arrays.push_back(m);
      d.shape += ", " + m + "[" + std::to_string(plan.outputs[static_cast<std::size_t>(stage.layout)]) + "] (" +
                 names[static_cast<std::size_t>(stage.layout)] + "'s out)";
      d.target = [n_exports, m, position](std::size_t o) {
        return o < n_exports ? "out[" + std::to_string(o) + "]"
                             : m + "[" + std::to_string(position[o - n_exports]) + "]";
      };
    }
    d.shape += ", called by " + std::to_string(stage.units.size()) + " kernels";
    d.internal = true;
    printed.push_back(print_kernel(g, fn, s, d, &stage.reads));
    into.push_back(d);
    out.text += printed.back().text + "\n";
  }
  for (std::size_t u = 0; u < plan.called.size(); ++u) {
    UnitStages unit;
    unit.unit = static_cast<int>(u);
    if (!plan.called[u].empty()) {
      unit.reads = &plan.own[u];
      int most = 0;
      std::set<int> layouts;  // the units whose out[] a stage it calls writes, but its own
      for (int i : plan.called[u]) {
        const SharingPlan::Stage& stage = plan.stages[static_cast<std::size_t>(i)];
        const PrintedKernel& fn = printed[static_cast<std::size_t>(i)];
        if (!stage.exports.empty())  // a stage with no exports (it only writes outputs) is given a null pointer
          unit.prologue += "  real " + stage_array(i) + "[" + std::to_string(stage.exports.size()) + "];\n";
        if (stage.layout >= 0 && stage.layout != static_cast<int>(u)) layouts.insert(stage.layout);
        unit.names.push_back(fn.name);
        unit.ops.add_times(1, fn.ops);
        unit.temporaries += static_cast<int>(stage.exports.size());
        most = std::max(most, fn.temporaries);
      }
      for (int l : layouts) {
        const int n = plan.outputs[static_cast<std::size_t>(l)];
        unit.prologue += "  real " + layout_array(l) + "[" + std::to_string(std::max(n, 1)) + "];  // " +
                         names[static_cast<std::size_t>(l)] + "'s outputs, as the stages write them\n";
        unit.temporaries += n;
      }
      for (int i : plan.called[u]) {
        const SharingPlan::Stage& stage = plan.stages[static_cast<std::size_t>(i)];
        const Destination& d = into[static_cast<std::size_t>(i)];
        std::string arrays = stage.exports.empty() ? std::string("nullptr") : stage_array(i);
        if (stage.layout >= 0)
          arrays += ", " + (stage.layout == static_cast<int>(u) ? std::string("out") : layout_array(stage.layout));
        unit.prologue += "  " + printed[static_cast<std::size_t>(i)].name + "(t, x, p, in, " + arrays +
                         stage_arguments(d, &stage.reads, static_cast<int>(u)) + ");\n";
      }
      unit.temporaries += most;
    }
    out.units.push_back(unit);
  }
  return out;
}

template <class T, class F>
std::string array_decl(const std::string& type, const std::string& name, const std::vector<T>& items, F format) {
  if (items.empty()) return "// " + name + ": none\n";
  std::string s = "constexpr " + type + " " + name + "[" + std::to_string(items.size()) + "] = {";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + format(items[i]);
  return s + "};\n";
}

}  // namespace

std::string kernel_text(const ExpressionGraph& graph, const Kernel& kernel, int n_x, int n_p, int n_in,
                        int split_statements) {
  return print_kernel(graph, kernel, Sizes{0, 0, n_x, n_p, n_in, split_statements}).text;
}

std::vector<EmittedFile> EmittedPackage::files() const {
  std::vector<EmittedFile> all{{header_name, header}, {source_name, source}};
  all.insert(all.end(), extra.begin(), extra.end());
  return all;
}

namespace {

// The fixed-step integrator of the package: classical RK4 on the rhs kernel, in place, with three stack
// arrays of n_state reals (no allocation); inputs are held over the step.
const char* rk4_source =
    "\n"
    "/* rk4_step: classical Runge-Kutta step of size h on x' = rhs(t, x), in place; 4 rhs calls, "
    "rk4_stack_reals reals of stack */\n"
    "void rk4_step(real t, real h, real* x, const real* p, const real* in) {\n"
    "  real k[n_state];\n"
    "  real xs[n_state];\n"
    "  real sum[n_state];\n"
    "  const real half = h * real(0.5);\n"
    "  rhs(t, x, p, in, k);\n"
    "  for (int i = 0; i < n_state; ++i) {\n"
    "    sum[i] = k[i];\n"
    "    xs[i] = x[i] + half * k[i];\n"
    "  }\n"
    "  rhs(t + half, xs, p, in, k);\n"
    "  for (int i = 0; i < n_state; ++i) {\n"
    "    sum[i] += real(2.0) * k[i];\n"
    "    xs[i] = x[i] + half * k[i];\n"
    "  }\n"
    "  rhs(t + half, xs, p, in, k);\n"
    "  for (int i = 0; i < n_state; ++i) {\n"
    "    sum[i] += real(2.0) * k[i];\n"
    "    xs[i] = x[i] + h * k[i];\n"
    "  }\n"
    "  rhs(t + h, xs, p, in, k);\n"
    "  const real sixth = h / real(6.0);\n"
    "  for (int i = 0; i < n_state; ++i) x[i] += sixth * (sum[i] + k[i]);\n"
    "}\n";

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

}  // namespace

namespace {

// The files of one package, each printed by its own member from what the constructor gathers once: sizes,
// names, the kernels as text, which parameters and inputs they read.
class PackageWriter {
 public:
  PackageWriter(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                const EmitSettings& settings);

  std::string header() const;    // <name>.hpp: the ABI, sizes, names and declarations
  std::string source() const;    // <name>.cpp: the kernels, rhs_status, rk4_step, the C entry points
  std::string c_header() const;  // <name>.h: the C entry points
  std::string cmake() const;     // CMakeLists.txt
  std::string readme() const;    // README.md
  std::vector<std::pair<std::string, OpCounts>> operations() const;  // EmittedPackage::operations
  int shared_stages() const { return static_cast<int>(sharing.stages.size() + prepared_sharing.stages.size()); }
  int share_ratio = 0;  // EmittedPackage::share_ratio
  long statements = 0;  // EmittedPackage::statements

 private:
  // README.md's sections after its head, in order.
  void readme_kernels(std::ostream& md) const;               // the kernels' table, and the prepared ones'
  void readme_layout(std::ostream& md) const;                // x, p and in, element by element
  void readme_integrator(std::ostream& md) const;            // rk4_step, with a loop
  void readme_position_constraints(std::ostream& md) const;  // the projector, with a run
  void readme_build(std::ostream& md) const;                 // with CMake and without
  void readme_bad_input(std::ostream& md) const;             // what kernels return for bad input
  static std::string quoted(const std::string& x) { return "\"" + x + "\""; }
  static std::string str(int x) { return std::to_string(x); }
  // The C signature <name>_<fn>(t, x, p, in, out) with the package's scalar macro.
  std::string c_signature(const std::string& ret, const std::string& fn) const {
    return ret + " " + prefix + fn + "(" + c_real + " t, const " + c_real + "* x, const " + c_real + "* p, const " +
           c_real + "* in, " + c_real + "* out)";
  }

  const Model& model;
  const KernelSet& kernels;
  const HamelEquations& eq;
  const HamelSystem& sys;
  Sizes s;
  std::string file, origin, stamp, guard_macro, library, prefix, c_real;
  std::vector<std::string> coordinate_names, velocity_names, parameter_names, input_names, constraint_names,
      state_names;
  std::vector<double> defaults;
  std::vector<int> upper_index, lower_a, lower_b;
  SharingPlan sharing, prepared_sharing;  // the work kernels.kernels share (emit/shared_stages.hpp), and the prepared
  std::string stage_text, prepared_stage_text;  // the functions of their stages
  std::vector<PrintedKernel> printed;           // kernels.kernels as text
  std::string rhs_with_pivots;  // rhs and the pivots of its solve, which rhs and rhs_status call; or empty
  std::vector<bool> parameter_used, input_used;
  bool has_rhs = false, has_group_velocity = false;
  const std::optional<KernelSet::Prepared>& prepared;
  std::vector<PrintedKernel> printed_prepared;
  int n_prepared = 0;
};

PackageWriter::PackageWriter(const Model& model_, const Derivation& derivation_, const KernelSet& kernels_,
                             const EmitSettings& settings)
    : model(model_),
      kernels(kernels_),
      eq(derivation_.equations),
      sys(derivation_.system),
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

  // The kernels as text, with their sizes for the ABI constants; which parameters and inputs any kernel reads. The
  // work several kernels share is printed once, as stages they call (emit/shared_stages.hpp).
  const auto is_checked_rhs = [&](const Kernel& k) { return k.name == "rhs" && !kernels.rhs_pivots.empty(); };
  std::vector<std::vector<int>> units;  // what each kernel's function computes
  std::vector<char> writes_out;         // ... as its out[], in order: a stage may write them there
  std::vector<std::string> names;
  for (const Kernel& k : kernels.kernels) {
    const bool called = k.calls && s.calls;
    units.push_back(called ? stage_of(k, *k.calls).kernel.outputs : k.outputs);
    if (is_checked_rhs(k))
      units.back().insert(units.back().end(), kernels.rhs_pivots.begin(), kernels.rhs_pivots.end());
    writes_out.push_back(!called && !is_checked_rhs(k));
    names.push_back(k.name);
  }
  statements = 0;
  for (const std::vector<int>& unit : units) statements += kernels.graph.count(kernels.graph.schedule(unit)).total();
  share_ratio = settings.share_ratio != kShareRatioAuto ? settings.share_ratio
                : statements >= settings.large_package  ? kShareRatioLarge
                                                        : kShareRatioSmall;
  sharing = plan_shared_stages(kernels.graph, units, settings.share_statements, share_ratio, writes_out);
  const PrintedStages stages = print_stages(kernels.graph, sharing, s, "", names);
  stage_text = stages.text;
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    printed.push_back(print_kernel(kernels.graph, kernels.kernels[i], s, stages.units[i]));
  // rhs_status needs the pivots of rhs's solve, intermediate values of rhs: rhs_with_pivots computes both. When
  // rhs is long enough to be split, rhs calls it with a scratch array for the pivots, so that the package holds
  // and compiles rhs once; a shorter rhs keeps its own copy, which saves the call (2-8 ns, 1-4 % of a rhs of
  // 700-1 400 operations, docs/benchmarks.md).
  // The same holds when rhs calls shared stages.
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i) {
    if (!is_checked_rhs(kernels.kernels[i])) continue;
    const bool shared = printed[i].parts > 1 || stages.units[i].reads;
    Kernel checked = kernels.kernels[i];
    checked.name = "rhs_with_pivots";
    for (std::size_t k = 0; k < kernels.rhs_pivots.size(); ++k) {
      checked.outputs.push_back(kernels.rhs_pivots[k]);
      checked.output_names.push_back("pivot " + std::to_string(k));
    }
    Destination two = to_two_arrays(checked, kernels.kernels[i].outputs.size(), "pivots");
    two.internal = true;
    rhs_with_pivots = (stages.units[i].reads ? print_after_stages(kernels.graph, checked, s, two, stages.units[i])
                                             : print_kernel(kernels.graph, checked, s, two))
                          .text;
    if (!shared) continue;
    std::string& text = printed[i].text;
    text = kernel_comment(kernels.kernels[i], s, "out[" + std::to_string(kernels.kernels[i].outputs.size()) + "]",
                          ": rhs_with_pivots", printed[i].ops) +
           signature(kernels.kernels[i]) +
           " {\n"
           "  real pivots[n_pivots_rhs];  // computed on the way, not checked (rhs_status checks them)\n"
           "  rhs_with_pivots(t, x, p, in, out, pivots);\n"
           "}\n";
  }
  parameter_used.assign(defaults.size(), false);
  input_used.assign(input_names.size(), false);
  {
    std::vector<int> all;
    for (const Kernel& k : kernels.kernels) all.insert(all.end(), k.outputs.begin(), k.outputs.end());
    for (int i : kernels.graph.schedule(all)) {
      const Node& n = kernels.graph.node(i);
      if (n.op != Op::input) continue;
      const auto index = static_cast<std::size_t>(n.index);
      if (n.argument == Argument::parameter && index < parameter_used.size()) parameter_used[index] = true;
      if (n.argument == Argument::input && index < input_used.size()) input_used[index] = true;
    }
  }
  for (const Kernel& k : kernels.kernels) {
    has_rhs = has_rhs || k.name == "rhs";
    has_group_velocity = has_group_velocity || k.name == "group_velocity";
  }
  n_prepared = s.n_p;
  if (prepared) {
    n_prepared = static_cast<int>(prepared->prepare.outputs.size());
    Sizes wide = s;
    wide.n_p = n_prepared;
    std::vector<std::vector<int>> prepared_units;
    std::vector<char> prepared_writes_out;
    std::vector<std::string> prepared_names;
    for (const Kernel& k : prepared->kernels) {
      prepared_units.push_back(k.outputs);
      prepared_writes_out.push_back(!(k.calls && s.calls));
      prepared_names.push_back(k.name);
    }
    prepared_sharing =
        plan_shared_stages(kernels.graph, prepared_units, settings.share_statements, share_ratio, prepared_writes_out);
    const PrintedStages prepared_stages =
        print_stages(kernels.graph, prepared_sharing, wide, "prepared_", prepared_names);
    prepared_stage_text = prepared_stages.text;
    for (std::size_t i = 0; i < prepared->kernels.size(); ++i)
      printed_prepared.push_back(print_kernel(kernels.graph, prepared->kernels[i], wide, prepared_stages.units[i]));
  }
}

std::vector<std::pair<std::string, OpCounts>> PackageWriter::operations() const {
  std::vector<std::pair<std::string, OpCounts>> all;
  for (const PrintedKernel& k : printed) all.emplace_back(k.name, k.ops);
  if (prepared) {
    all.emplace_back("prepare_parameters", kernels.graph.count(kernels.graph.schedule(prepared->prepare.outputs)));
    for (const PrintedKernel& k : printed_prepared) all.emplace_back(k.name, k.ops);
  }
  return all;
}

std::string PackageWriter::header() const {
  std::ostringstream h;
  h << stamp << "//\n"
    << "// Kernel ABI: every kernel is\n"
    << "//   void name(real t, const real* x, const real* p, const real* in, real* out);\n"
    << "// t: time; x: state (q^1..q^n, then the independent quasi-velocities u^I), n_state entries;\n"
    << "// equations: " << sys.form << ";\n"
    << "// p: parameters (n_parameters, defaults in default_parameters; parameters folded at generation time\n"
    << "// are ignored, see README.md); in: inputs (n_inputs, may be null when n_inputs == 0); out: the\n"
    << "// kernel's outputs, n_out_<kernel> entries. x, p, in and out must not overlap. Kernels are flat and\n"
    << "// branch-free; they allocate nothing, throw nothing and need only <cmath>; their only stack use is\n"
    << "// n_temporaries_<kernel> reals, one per operation (an upper bound; the compiler keeps most in registers).\n"
    << (s.split > 0 ? "// A kernel longer than " + std::to_string(s.split) +
                          " operations is printed as functions <kernel>_part<k> of at most that many,\n"
                          "// called in turn, which pass values in a local array v[] (counted in n_temporaries).\n"
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
                         : array_decl("real", "default_parameters", defaults, literal))
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
  h << "// Output sizes (out[] entries) and named temporaries of each kernel.\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    h << "constexpr int n_out_" << kernels.kernels[i].name << " = " << kernels.kernels[i].outputs.size()
      << ";\nconstexpr int n_temporaries_" << kernels.kernels[i].name << " = " << printed[i].temporaries << ";\n";
  std::size_t largest = 0;
  for (const Kernel& k : kernels.kernels) largest = std::max(largest, k.outputs.size());
  h << "constexpr int n_out_max = " << largest << ";  // the largest out[] of any kernel\n\n";
  for (const Kernel& k : kernels.kernels)
    h << "/// " << k.summary << "; out[" << k.outputs.size() << "]\n" << signature(k) << ";\n";
  h << "\n"
    << "using kernel_function = void (*)(real t, const real* x, const real* p, const real* in, real* out);\n"
    << "struct kernel_info {\n"
    << "  const char* name;\n"
    << "  kernel_function function;\n"
    << "  int n_out;\n"
    << "  int n_temporaries;\n"
    << "};\n"
    << "constexpr int n_kernels = " << kernels.kernels.size() << ";\n";
  if (!kernels.kernels.empty()) {
    h << "constexpr kernel_info kernel_table[n_kernels] = {\n";
    for (const Kernel& k : kernels.kernels)
      h << "    {\"" << k.name << "\", " << k.name << ", n_out_" << k.name << ", n_temporaries_" << k.name << "},\n";
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
      << "constexpr int n_prepared_parameters = " << n_prepared << ";\n"
      << "void prepare_parameters(const real* p, real* prepared);\n";
    for (std::size_t i = 0; i < prepared->kernels.size(); ++i)
      h << "constexpr int n_temporaries_" << prepared->kernels[i].name << " = " << printed_prepared[i].temporaries
        << ";\n/// " << prepared->kernels[i].summary << "; out[" << prepared->kernels[i].outputs.size() << "]\n"
        << signature(prepared->kernels[i]) << ";\n";
  }
  h << "\n}  // namespace " << model.name << "\n";
  return h.str();
}

std::string PackageWriter::source() const {
  std::ostringstream c;  // everything after the includes
  c << "\nnamespace " << model.name << " {\n";
  if (!stage_text.empty()) c << "\nnamespace {\n\n" << stage_text << "}  // namespace\n";
  if (!rhs_with_pivots.empty()) c << "\nnamespace {\n\n" << rhs_with_pivots << "\n}  // namespace\n";
  for (const PrintedKernel& k : printed) c << "\n" << k.text;
  if (has_rhs) {
    // The checks are in rhs_status, outside the branch-free kernel.
    c << "\nint rhs_status(real t, const real* x, const real* p, const real* in, real* out) {\n"
      << "  real all[n_out_rhs];\n";
    if (rhs_with_pivots.empty()) {
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
    c << rk4_source;
  }
  if (prepared) {
    Kernel prepare = prepared->prepare;
    prepare.name = "prepare_parameters_kernel";
    c << "\nnamespace {\n\n"
      << print_kernel(kernels.graph, prepare, s).text << "\n"
      << prepared_stage_text << "}  // namespace\n\n"
      << "void prepare_parameters(const real* p, real* prepared) {\n"
      << "  prepare_parameters_kernel(real(0), nullptr, p, nullptr, prepared);\n"
      << "}\n";
    for (const PrintedKernel& k : printed_prepared) c << "\n" << k.text;
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
  c << "\n}  // extern \"C\"\n";
  const std::string body = c.str();
  const std::string includes =
      stamp + "#include \"" + model.name + ".hpp\"\n#include \"" + model.name + ".h\"\n\n#include <cmath>\n";
  // out_of_line's macro, defined where the compiler has a way, when some function uses it
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
     << "#define " << upper(prefix) << "N_STATE " << s.n_x << "\n"
     << "#define " << upper(prefix) << "N_PARAMETERS " << s.n_p << "\n"
     << "#define " << upper(prefix) << "N_INPUTS " << s.n_in << "\n";
  for (const Kernel& k : kernels.kernels)
    ch << "#define " << upper(prefix) << "N_OUT_" << upper(k.name) << " " << k.outputs.size() << "\n";
  if (prepared) ch << "#define " << upper(prefix) << "N_PREPARED_PARAMETERS " << n_prepared << "\n";
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
  return cm.str();
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
     << "::with_runtime`, the kernels plus hamel's header-only integrators |\n\n";
  readme_kernels(md);
  readme_layout(md);
  readme_integrator(md);
  readme_build(md);
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
     << "| Kernel | Outputs | Temporaries | Operations (add, mul, div, call) | Computes |\n|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i) {
    const Kernel& k = kernels.kernels[i];
    const OpCounts& o = printed[i].ops;
    md << "| `" << k.name << "` | " << k.outputs.size() << " | " << printed[i].temporaries << " | " << o.add << ", "
       << o.mul << ", " << o.div << ", " << o.call << " | " << k.summary << " |\n";
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
    for (const PrintedKernel& k : printed_prepared)
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
        "mismatch fails to link.\n\n";
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

EmittedPackage emit_cpp(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                        const EmitSettings& settings) {
  const PackageWriter writer(model, derivation, kernels, settings);
  EmittedPackage package{model.name + ".hpp", writer.header(), model.name + ".cpp", writer.source(), {}, {}, 0};
  package.extra.push_back({model.name + ".h", writer.c_header()});
  package.extra.push_back({"CMakeLists.txt", writer.cmake()});
  package.extra.push_back({"README.md", writer.readme()});
  package.operations = writer.operations();
  package.shared_stages = writer.shared_stages();
  package.share_ratio = writer.share_ratio;
  package.statements = writer.statements;
  return package;
}

namespace {

namespace fs = std::filesystem;

// Ownership of an output folder is decided by the manifest emit writes into it: every file's name and
// content hash. A user's file cannot carry that by accident (a first line claiming "Generated by hamel" can),
// and a package file edited since it was emitted no longer matches its hash, so the edit is not lost either.
constexpr const char* kManifestName = ".hamel-manifest";
constexpr const char* kManifestHeader = "hamel-manifest 1";

std::string manifest_text(const std::vector<EmittedFile>& files) {
  std::string text = std::string(kManifestHeader) + "\n# SPDX-License-Identifier: MIT\n";
  for (const EmittedFile& f : files) text += content_hash(f.text) + "  " + f.name + "\n";
  return text;
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Empty if the folder holds only what an earlier emit wrote, else the reason to refuse it. Folders written
// before emit kept a manifest qualify only if they hold nothing but the four file names this package
// writes, each with the generator's stamp on its first line.
std::string foreign_content(const fs::path& folder, const std::vector<EmittedFile>& package_files) {
  std::error_code ec;
  std::map<std::string, std::string> listed;  // name -> hash
  const fs::path manifest = folder / kManifestName;
  const bool has_manifest = fs::is_regular_file(fs::symlink_status(manifest, ec));
  if (has_manifest) {
    std::istringstream in(read_all(manifest));
    std::string line;
    if (!std::getline(in, line) || line != kManifestHeader) return quote(kManifestName) + " is not a hamel manifest";
    while (std::getline(in, line)) {
      if (!line.empty() && line[0] == '#') continue;  // the licence line
      const std::size_t gap = line.find("  ");
      if (gap == std::string::npos) return quote(kManifestName) + " is not a hamel manifest";
      listed[line.substr(gap + 2)] = line.substr(0, gap);
    }
  }
  std::set<std::string> package_names;
  for (const EmittedFile& f : package_files) package_names.insert(f.name);
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (has_manifest && name == kManifestName) continue;
    const bool regular = entry.is_regular_file(ec) && !entry.is_symlink(ec);
    if (has_manifest) {
      const auto it = listed.find(name);
      if (!regular || it == listed.end()) return "holds " + quote(name) + ", which hamel did not write";
      if (content_hash(read_all(entry.path())) != it->second)
        return "holds " + quote(name) + ", which was changed since hamel wrote it";
    } else {
      std::string first_line;
      if (regular) {
        std::ifstream in(entry.path(), std::ios::binary);
        std::getline(in, first_line);
      }
      if (!package_names.count(name) || first_line.find("Generated by hamel") == std::string::npos ||
          first_line.size() > 512)
        return "holds " + quote(name) + ", which hamel did not write";
    }
  }
  if (ec) return "cannot be read: " + ec.message();
  return "";
}

void check_replaceable(const fs::path& target, const std::vector<EmittedFile>& package_files) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(target, ec);
  if (ec || !fs::exists(status)) return;
  if (!fs::is_directory(status))
    throw InputError("-o: " + quote(target.string()) + " exists and is not a folder" +
                     (fs::is_symlink(status) ? " (a symbolic link)" : "") +
                     "; expected a new folder or one written by an earlier emit");
  const std::string why = foreign_content(target, package_files);
  if (!why.empty())
    throw InputError("-o: " + quote(target.string()) + " " + why +
                     "; refusing to replace the folder (expected a new folder or one written by an earlier emit)");
}

bool write_and_sync(const fs::path& path, const std::string& text) {
  {
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.close();
    if (!out) return false;
  }
  return sync_file(path.string());
}

}  // namespace

namespace {

// The folder -o names, normalized; an InputError for names that are no folder hamel could replace.
fs::path package_target(const std::string& directory) {
  fs::path target = fs::path(directory).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "out/" -> "out"
  if (target.empty() || target.filename() == "." || target.filename() == ".." || target == target.root_path())
    throw InputError("-o: " + quote(directory) + " is not a folder hamel can replace; expected a folder name");
  return target;
}

}  // namespace

void check_package_folder(const std::string& directory, const std::string& model_name) {
  const std::vector<EmittedFile> files{{model_name + ".hpp", ""},
                                       {model_name + ".cpp", ""},
                                       {model_name + ".h", ""},
                                       {"CMakeLists.txt", ""},
                                       {"README.md", ""}};
  check_replaceable(package_target(directory), files);
}

void write_package(const EmittedPackage& package, const std::string& directory) {
  const fs::path target = package_target(directory);
  const std::vector<EmittedFile> files = package.files();
  check_replaceable(target, files);
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw InputError("-o: cannot create " + quote(parent.string()) + ": " + ec.message());
  sweep_stale_temporaries(target.string());
  const fs::path staging = temporary_name_for(target.string());
  auto cannot = [&](const fs::path& what, const std::error_code& why) {
    return InputError("-o: cannot write " + quote(what.string()) + (why ? ": " + why.message() : std::string()));
  };
  if (!fs::create_directory(staging, ec) || ec) throw cannot(staging, ec);
  // From here until it is gone, a SIGINT/SIGTERM/SIGHUP removes the staging folder (report/temporaries.hpp).
  const int slot = register_temporary(staging.string(), true);
  try {
    for (const EmittedFile& f : files)
      if (!write_and_sync(staging / f.name, f.text))
        throw OutputError("cannot write " + quote((staging / f.name).string()) + ": " + std::strerror(errno));
    if (!write_and_sync(staging / kManifestName, manifest_text(files)))
      throw OutputError("cannot write " + quote((staging / kManifestName).string()) + ": " + std::strerror(errno));
    if (fs::exists(fs::symlink_status(target))) {
      // Checked again right before the swap: a file put into the folder during the derivation is kept.
      check_replaceable(target, files);
      // One atomic exchange: at every instant `target` holds either the old or the new package.
      if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0)
        throw cannot(target, std::error_code(errno, std::generic_category()));
      // A file written into the old folder after the second check travelled with it: swap back.
      const std::string late = foreign_content(staging, files);
      if (!late.empty()) {
        ::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE);
        throw InputError("-o: " + quote(target.string()) + " " + late +
                         "; refusing to replace the folder (expected a new folder or one written by an earlier emit)");
      }
    } else if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) != 0) {
      throw cannot(target, std::error_code(errno, std::generic_category()));
    }
  } catch (...) {
    fs::remove_all(staging, ec);
    unregister_temporary(slot);
    throw;
  }
  fs::remove_all(staging, ec);  // the previous package, if there was one
  unregister_temporary(slot);
}

}  // namespace hamel
