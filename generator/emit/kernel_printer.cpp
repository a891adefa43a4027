#include "emit/kernel_printer.hpp"

#include "emit/statement_schedule.hpp"
#include "emit/subroutine_calls.hpp"

#include <algorithm>
#include <set>
#include <sstream>
#include <utility>

namespace hamel {

namespace {

std::string argument_voids(const bool uses[4]) {
  static const char* args[4] = {"t", "x", "p", "in"};
  std::string s;
  for (int a = 0; a < 4; ++a)
    if (!uses[a]) s += std::string("  (void)") + args[a] + ";\n";
  return s;
}

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
std::string stage_arguments(const Destination& d, const StageReads* reads, int unit) {
  std::string text;
  for (const std::string& a : read_arrays(d, reads)) text += ", " + (unit >= 0 && a == layout_array(unit) ? "out" : a);
  return text;
}

// One program printed to `d` as the function <name>, or, split, as its parts <name>_part<k> called in turn.
class ProgramPrinter {
 public:
  ProgramPrinter(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                 const StageReads* reads)
      : g_(g),
        k_(k),
        s_(s),
        d_(d),
        reads_(reads),
        schedule_(schedule(g, k, s, d, reads)),
        printer_(g, schedule_, k, d, reads) {}

  PrintedKernel print() {
    const OpCounts counts = OpCounts{}.add_times(d_.lanes, g_.count(schedule_.statements));
    std::ostringstream os;
    os << kernel_comment(k_, s_, d_.shape, "", counts);
    if (schedule_.split)
      print_parts(os);
    else
      print_whole(os);
    const int n_slots = schedule_.split ? schedule_.parts.n_slots : 0;
    return {k_.name,
            os.str(),
            (static_cast<int>(schedule_.statements.size()) + n_slots) * d_.lanes,
            counts,
            static_cast<int>(schedule_.functions.size()),
            n_slots * d_.lanes};
  }

 private:
  static StatementSchedule schedule(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                                    const StageReads* reads) {
    std::vector<char> given, written;
    if (reads) {
      given.assign(static_cast<std::size_t>(g.size()), 0);
      for (const auto& entry : reads->value) given[static_cast<std::size_t>(entry.first)] = 1;
      written = reads->written;
    }
    return schedule_statements(g, k.outputs, given, written, {s.split, d.outputs_in_parts, d.lanes});
  }
  void print_whole(std::ostringstream& os);
  void print_parts(std::ostringstream& os);
  void print_part(std::ostringstream& os, std::size_t number, const Usage& usage, const std::string& body) const;

  const ExpressionGraph& g_;
  const Kernel& k_;
  const Sizes& s_;
  const Destination& d_;
  const StageReads* reads_;
  const StatementSchedule schedule_;
  StatementPrinter printer_;
};

// One function: a local per statement not printed inside another, then the outputs.
void ProgramPrinter::print_whole(std::ostringstream& os) {
  Usage usage;
  const std::string body = printer_.print(schedule_.functions.front(), 0, usage);
  const int work = static_cast<int>(schedule_.statements.size()), n_out = static_cast<int>(k_.outputs.size());
  os << out_of_line(d_.internal, (work + n_out) * d_.lanes) << head_of(d_, k_.name, reads_) << " {\n"
     << argument_voids(usage.arguments) << stage_voids(d_, reads_, usage.read);
  for (const std::string& a : d_.arrays)
    if (!usage.wrote.count(a)) os << "  (void)" << a << ";\n";
  os << body << "}\n";
}

// Part `number`: (t, x, p, in, v, the arrays of d, the stage arrays), voiding what it does not use. Parts of a kernel
// split in more than two, and those that copy outputs, are kept out of line.
void ProgramPrinter::print_part(std::ostringstream& os, std::size_t number, const Usage& usage,
                                const std::string& body) const {
  std::string voids;
  for (const std::string& a : d_.arrays)
    if (!usage.wrote.count(a)) voids += "  (void)" + a + ";\n";
  if (!usage.wrote.count("v")) voids += "  (void)v;\n";
  Destination with_v = d_;  // a part also gets v[]
  with_v.arrays.insert(with_v.arrays.begin(), "v");
  const bool kept_out_of_line = number >= schedule_.computing || schedule_.computing > 2;
  os << out_of_line(kept_out_of_line, out_of_line_statements)
     << head_of(with_v, k_.name + "_part" + std::to_string(number), reads_) << " {\n"
     << argument_voids(usage.arguments) << voids << stage_voids(d_, reads_, usage.read) << body << "}\n\n";
}

// The parts, each a function of the kernel's statements between two part boundaries, passing values in v[], and the
// parts that copy outputs; then the function that calls them (and makes the copies no part makes).
void ProgramPrinter::print_parts(std::ostringstream& os) {
  os << "namespace {\n\n";
  for (std::size_t part = 0; part < schedule_.functions.size(); ++part) {
    Usage usage;
    const std::string body = printer_.print(schedule_.functions[part], static_cast<int>(part), usage);
    print_part(os, part, usage, body);
  }
  Usage calling;  // the function calling the parts passes all it is given on
  const std::string copies = printer_.print(schedule_.driver, -1, calling);
  // v[] holds the values parts pass to later parts; when they pass none the parts are given a null pointer.
  const int n_slots = schedule_.parts.n_slots;
  const std::string v = n_slots > 0 ? "v" : "nullptr";
  std::ostringstream calls;
  for (std::size_t part = 0; part < schedule_.functions.size(); ++part)
    calls << "  " << k_.name << "_part" << part << "(t, x, p, in, " << v << array_arguments(d_)
          << stage_arguments(d_, reads_, -1) << ");\n";
  const int driver_statements = static_cast<int>(schedule_.functions.size() + schedule_.driver.size());
  os << "}  // namespace\n\n";
  if (n_slots == 0) {
    os << out_of_line(d_.internal, driver_statements) << head_of(d_, k_.name, reads_) << " {\n"
       << calls.str() << copies << "}\n";
    return;
  }
  // v[] in the caller's work space (<name>_work, for a caller with little stack: firmware), or on the stack.
  const std::string head = head_of(d_, k_.name + "_work", reads_);
  os << out_of_line(d_.internal, driver_statements) << head.substr(0, head.size() - 1) << ", real* work) {\n"
     << "  real* const v = work;\n"
     << calls.str() << copies
     << "}\n\n"
     // An internal function's callers may all take the work-space form (a kernel's stage, its column solve).
     << (d_.internal ? "[[maybe_unused]] " : "") << head_of(d_, k_.name, reads_) << " {\n"
     << "  real work[" << n_slots * d_.lanes << "];\n"
     << "  " << k_.name << "_work(t, x, p, in" << array_arguments(d_) << stage_arguments(d_, reads_, -1)
     << ", work);\n}\n";
}

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
  const PrintedKernel called = print_program(
      sub.graph, column, Sizes{0, 0, static_cast<int>(n_arguments), static_cast<int>(n_shared), 0, s.split}, placed);

  const StageBeforeCalls staging = stage_before_calls(k, sub);
  const Kernel& stage = staging.kernel;
  const std::vector<std::size_t>&direct = staging.direct, &slot = staging.slot;
  const std::size_t first = direct.size(), n_scratch = stage.outputs.size() - first;
  Destination into = to_two_arrays(stage, first, "scratch");
  into.internal = true;
  into.target = [&](std::size_t o) {
    return o < first ? "out[" + std::to_string(direct[o]) + "]" : "scratch[" + std::to_string(slot[o - first]) + "]";
  };
  const PrintedKernel staged = print_program(g, stage, s, into, stages.reads);

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
                       total);
  const int temporaries = stages.temporaries + staged.temporaries + called.temporaries + static_cast<int>(n_scratch);
  const std::size_t scratch_size = std::max<std::size_t>(n_scratch, 1);
  if (stages.reads) {  // the shared stages' arrays stay on the stack: no work-space form
    os << signature(k) << " {\n  real scratch[" << scratch_size << "];\n"
       << stages.prologue << "  " << k.name << "_stage(t, x, p, in, out, scratch"
       << stage_arguments(into, stages.reads, stages.unit) << ");\n";
    for (std::size_t c = 0; c < sub.calls.size(); ++c)
      os << "  " << k.name << "_column(t, scratch + " << n_shared + c * n_arguments << ", scratch, in, out + "
         << sub.calls[c].results.front() << ");\n";
    os << "}\n";
    return {k.name, os.str(), temporaries, total, staged.parts};
  }
  // scratch[] and what the stage's and the column's parts pass on (the calls run one after another) in the caller's
  // work space (<name>_work), or on the stack.
  const std::string after_scratch = "work + " + std::to_string(scratch_size);
  os << "void " << k.name << "_work(real t, const real* x, const real* p, const real* in, real* out, real* work) {\n"
     << "  real* const scratch = work;\n"
     << "  " << k.name << (staged.work > 0 ? "_stage_work" : "_stage") << "(t, x, p, in, out, scratch"
     << (staged.work > 0 ? ", " + after_scratch : std::string()) << ");\n";
  for (std::size_t c = 0; c < sub.calls.size(); ++c)
    os << "  " << k.name << (called.work > 0 ? "_column_work" : "_column") << "(t, scratch + "
       << n_shared + c * n_arguments << ", scratch, in, out + " << sub.calls[c].results.front()
       << (called.work > 0 ? ", " + after_scratch : std::string()) << ");\n";
  const int work = static_cast<int>(scratch_size) + std::max(staged.work, called.work);
  os << "}\n\n"
     << signature(k) << " {\n  real work[" << work << "];\n  " << k.name << "_work(t, x, p, in, out, work);\n}\n";
  return {k.name, os.str(), temporaries, total, staged.parts, work};
}

// The function of stage i of `plan`: <prefix>shared_<i>, writing its exports to out[] and the outputs it writes for
// its unit `layout` to m<layout>.
std::pair<Kernel, Destination> stage_function(const SharingPlan& plan, std::size_t i, const std::string& prefix,
                                              const std::vector<std::string>& names) {
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
      return o < n_exports ? "out[" + std::to_string(o) + "]" : m + "[" + std::to_string(position[o - n_exports]) + "]";
    };
  }
  d.shape += ", called by " + std::to_string(stage.units.size()) + " kernels";
  d.internal = true;
  return {fn, d};
}

// Unit u's calls of the stages it calls (`printed`, printed to `into`), as its function prints them.
UnitStages unit_stages(const SharingPlan& plan, std::size_t u, const std::vector<PrintedKernel>& printed,
                       const std::vector<Destination>& into, const std::vector<std::string>& names) {
  UnitStages unit;
  unit.unit = static_cast<int>(u);
  if (plan.called[u].empty()) return unit;
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
  return unit;
}

}  // namespace

std::string signature(const Kernel& k) {
  return "void " + k.name + "(real t, const real* x, const real* p, const real* in, real* out)";
}

Destination to_out(const Kernel& k) {
  return {{"out"}, "out[" + std::to_string(k.outputs.size()) + "]", [](std::size_t o) {
            return "out[" + std::to_string(o) + "]";
          }};
}

Destination to_two_arrays(const Kernel& k, std::size_t first, const std::string& second) {
  return {{"out", second},
          "out[" + std::to_string(first) + "], " + second + "[" + std::to_string(k.outputs.size() - first) + "]",
          [first, second](std::size_t o) {
            return o < first ? "out[" + std::to_string(o) + "]" : second + "[" + std::to_string(o - first) + "]";
          }};
}

std::string kernel_comment(const Kernel& k, const Sizes& s, const std::string& shape, const std::string& how,
                           const OpCounts& c) {
  return "/* " + k.name + ": (t, x[" + std::to_string(s.n_x) + "], p[" + std::to_string(s.n_p) + "], in[" +
         std::to_string(s.n_in) + "]) -> " + shape + how + "  ops: " + std::to_string(c.add) + " add, " +
         std::to_string(c.mul) + " mul, " + std::to_string(c.div) + " div, " + std::to_string(c.call) + " call */\n";
}

PrintedKernel print_program(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                            const StageReads* reads) {
  return ProgramPrinter(g, k, s, d, reads).print();
}

PrintedKernel print_after_stages(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const Destination& d,
                                 const UnitStages& stages) {
  Kernel own = k;
  own.name = k.name + "_own";
  own.calls = nullptr;
  Destination internal = d;
  internal.internal = true;
  const PrintedKernel printed = print_program(g, own, s, internal, stages.reads);
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

PrintedKernel print_kernel(const ExpressionGraph& g, const Kernel& k, const Sizes& s, const UnitStages& stages) {
  if (k.calls && s.calls) return print_with_calls(g, k, s, stages);
  return stages.reads ? print_after_stages(g, k, s, to_out(k), stages) : print_program(g, k, s, to_out(k));
}

PrintedStages print_stages(const ExpressionGraph& g, const SharingPlan& plan, const Sizes& s, const std::string& prefix,
                           const std::vector<std::string>& names) {
  PrintedStages out;
  std::vector<PrintedKernel> printed;
  std::vector<Destination> into;
  for (std::size_t i = 0; i < plan.stages.size(); ++i) {
    const auto [fn, d] = stage_function(plan, i, prefix, names);
    printed.push_back(print_program(g, fn, s, d, &plan.stages[i].reads));
    into.push_back(d);
    out.text += printed.back().text + "\n";
  }
  for (std::size_t u = 0; u < plan.called.size(); ++u) out.units.push_back(unit_stages(plan, u, printed, into, names));
  return out;
}

std::string kernel_text(const ExpressionGraph& graph, const Kernel& kernel, int n_x, int n_p, int n_in,
                        int split_statements) {
  return print_kernel(graph, kernel, Sizes{0, 0, n_x, n_p, n_in, split_statements}).text;
}

}  // namespace hamel
