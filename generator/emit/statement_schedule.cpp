#include "emit/statement_schedule.hpp"

#include <algorithm>
#include <functional>
#include <utility>

namespace hamel {

namespace {

// At most this many output copies in one function (after a split kernel's parts).
constexpr std::size_t writes_per_part = 128;

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

bool is_written(const std::vector<char>& written, std::size_t o) { return o < written.size() && written[o]; }

// One function: its statements, then its outputs.
void schedule_whole(StatementSchedule& s, const std::vector<int>& outputs, const std::vector<char>& written) {
  std::vector<Step> steps;
  for (int i : s.statements)
    if (!s.inside[static_cast<std::size_t>(i)]) steps.push_back({Step::Kind::compute, i});
  for (std::size_t o = 0; o < outputs.size(); ++o)
    if (!is_written(written, o)) steps.push_back({Step::Kind::write, outputs[o], o});
  s.functions.push_back(std::move(steps));
}

// The parts, each computing its statements, passing those later parts read and writing the outputs it computes right
// after them (no slot of v[] unless a later part reads them too, and no copy at the end); then the outputs no part
// writes (leaves, or every output without outputs_in_parts), copied in after the parts: by the kernel itself, or,
// when there are more than writes_per_part of them, by further parts of at most that many copies each. g++ -O2's
// time on a run of stores grows about with the square of its length: the 1 984 constant entries of the 30-joint
// chain's Jacobian took 2.2 s of its SLP vectorizer and alias walks in one function, 0.2-0.4 s in functions of
// 25-250 (docs/benchmarks.md). Fewer copies stay in the kernel (a Jacobian column's 72), where a call would cost
// more than they do.
void schedule_parts(StatementSchedule& s, const std::vector<int>& outputs, const std::vector<char>& written,
                    const ScheduleOptions& options) {
  const std::size_t parts = s.parts.start.size(), work = s.statements.size();
  std::map<int, std::vector<std::size_t>> gives;  // statement node -> the outputs it is
  for (std::size_t o = 0; o < outputs.size(); ++o)
    if (!s.leaf[static_cast<std::size_t>(outputs[o])] && options.outputs_in_parts) gives[outputs[o]].push_back(o);
  for (std::size_t part = 0; part < parts; ++part) {
    std::vector<Step> steps;
    const std::size_t end = part + 1 < parts ? static_cast<std::size_t>(s.parts.start[part + 1]) : work;
    for (std::size_t w = static_cast<std::size_t>(s.parts.start[part]); w < end; ++w) {
      const int i = s.statements[w];
      if (s.inside[static_cast<std::size_t>(i)]) continue;
      steps.push_back({Step::Kind::compute, i});
      if (s.parts.slot.count(i)) steps.push_back({Step::Kind::pass, i});
      const auto given = gives.find(i);
      if (given != gives.end())
        for (std::size_t o : given->second) steps.push_back({Step::Kind::write, i, o});
    }
    s.functions.push_back(std::move(steps));
  }
  s.computing = parts;
  std::vector<Step> copies;
  for (std::size_t o = 0; o < outputs.size(); ++o)
    if ((s.leaf[static_cast<std::size_t>(outputs[o])] || !options.outputs_in_parts) && !is_written(written, o))
      for (int lane = 0; lane < options.lanes; ++lane) copies.push_back({Step::Kind::write, outputs[o], o, lane});
  if (copies.size() <= writes_per_part) {
    s.driver = std::move(copies);
    return;
  }
  const std::size_t n = copies.size(), blocks = (n + writes_per_part - 1) / writes_per_part;
  for (std::size_t b = 0; b < blocks; ++b)
    s.functions.emplace_back(copies.begin() + static_cast<std::ptrdiff_t>(b * n / blocks),
                             copies.begin() + static_cast<std::ptrdiff_t>((b + 1) * n / blocks));
}

}  // namespace

StatementSchedule schedule_statements(const ExpressionGraph& g, const std::vector<int>& outputs,
                                      const std::vector<char>& given, const std::vector<char>& written,
                                      const ScheduleOptions& options) {
  StatementSchedule s;
  const std::size_t n = static_cast<std::size_t>(g.size());
  s.leaf.assign(n, 0);
  for (int i : g.schedule(outputs, given)) {
    const Op op = g.node(i).op;
    const bool read = static_cast<std::size_t>(i) < given.size() && given[static_cast<std::size_t>(i)];
    if (read || op == Op::constant || op == Op::input)
      s.leaf[static_cast<std::size_t>(i)] = 1;
    else
      s.statements.push_back(i);
  }
  const int part_size = options.split > 0 ? std::max(1, options.split / options.lanes) : options.split;
  if (part_size > 0 && static_cast<int>(s.statements.size()) > part_size) {
    PlannedParts chosen = plan_parts(g, s.statements, outputs, given, s.leaf, options.outputs_in_parts, part_size);
    s.statements = std::move(chosen.statements);
    s.parts = std::move(chosen.plan);
    s.split = true;
  }
  s.part.assign(n, -1);
  for (std::size_t w = 0; w < s.statements.size(); ++w)
    s.part[static_cast<std::size_t>(s.statements[w])] = s.parts.part_at(static_cast<int>(w));
  std::vector<char> output(n, 0);
  for (int o : outputs) output[static_cast<std::size_t>(o)] = 1;
  s.inside = printed_inside(g, s.statements, output, [&](int value, int reader) {
    return s.part[static_cast<std::size_t>(value)] == s.part[static_cast<std::size_t>(reader)];
  });
  for (int i : s.statements)
    if (!s.inside[static_cast<std::size_t>(i)]) s.local.emplace(i, static_cast<int>(s.local.size()));
  if (s.split)
    schedule_parts(s, outputs, written, options);
  else
    schedule_whole(s, outputs, written);
  return s;
}

}  // namespace hamel
