#include "emit/kernel_parts.hpp"

#include <set>
#include <utility>

namespace hamel {

namespace {

using Index = std::map<int, int>;  // statement node -> its position

// live[b] for every boundary b (0..work): how many statements before b are read at or after b.
std::vector<int> crossing_values(const ExpressionGraph& g, const std::vector<int>& statements, const Index& index,
                                 const std::vector<char>& leaf, const std::vector<int>& outputs,
                                 bool outputs_in_parts) {
  const int work = static_cast<int>(statements.size());
  // Position of the last reader; work: out[]; a statement nothing reads after it (an output written in its part)
  // is its own last reader, so it crosses no boundary.
  std::vector<int> last_use(static_cast<std::size_t>(work));
  for (int w = 0; w < work; ++w) last_use[static_cast<std::size_t>(w)] = w;
  for (int w = 0; w < work; ++w) {
    const Node& n = g.node(statements[static_cast<std::size_t>(w)]);
    for (int operand : {n.a, n.b})
      if (operand >= 0 && !leaf[static_cast<std::size_t>(operand)])
        last_use[static_cast<std::size_t>(index.at(operand))] = w;
  }
  if (!outputs_in_parts)
    for (int o : outputs)
      if (!leaf[static_cast<std::size_t>(o)]) last_use[static_cast<std::size_t>(index.at(o))] = work;
  std::vector<int> change(static_cast<std::size_t>(work) + 2, 0), live(static_cast<std::size_t>(work) + 1, 0);
  for (int w = 0; w < work; ++w) {
    ++change[static_cast<std::size_t>(w) + 1];
    --change[static_cast<std::size_t>(last_use[static_cast<std::size_t>(w)]) + 1];
  }
  for (int b = 1; b <= work; ++b)
    live[static_cast<std::size_t>(b)] = live[static_cast<std::size_t>(b) - 1] + change[static_cast<std::size_t>(b)];
  return live;
}

// The first position of every part: near equal lengths, moved within a quarter of a part to where the fewest values
// cross (`live`).
std::vector<int> part_starts(const std::vector<int>& live, int work, int part_size) {
  const int parts = (work + part_size - 1) / part_size;
  std::vector<int> start{0};
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
  return start;
}

// The slots of v[] of the values read outside their part (or, without outputs_in_parts, the outputs, read at the
// kernel's end): a slot is free again from the part after the last one reading its value.
void assign_slots(Parts& plan, const ExpressionGraph& g, const std::vector<int>& statements, const Index& index,
                  const std::vector<char>& leaf, const std::vector<int>& outputs, bool outputs_in_parts) {
  const int work = static_cast<int>(statements.size()), parts = static_cast<int>(plan.start.size());
  const auto part_of = [&](int i) { return plan.part_at(index.at(i)); };
  const auto end_of = [&](int part) {
    return part + 1 < parts ? plan.start[static_cast<std::size_t>(part) + 1] : work;
  };
  std::map<int, int> last_part;  // statement node read outside its part -> last part reading it (parts: out[])
  for (int i : statements)
    for (int operand : {g.node(i).a, g.node(i).b})
      if (operand >= 0 && !leaf[static_cast<std::size_t>(operand)] && part_of(operand) != part_of(i))
        last_part[operand] = std::max(last_part[operand], part_of(i));
  if (!outputs_in_parts)
    for (int o : outputs)
      if (!leaf[static_cast<std::size_t>(o)]) last_part[o] = parts;
  std::vector<std::vector<int>> expiring(static_cast<std::size_t>(parts) + 1);
  std::set<int> free_slots;
  for (int part = 0; part < parts; ++part) {
    for (int i : expiring[static_cast<std::size_t>(part)]) free_slots.insert(plan.slot.at(i));
    for (int w = plan.start[static_cast<std::size_t>(part)]; w < end_of(part); ++w) {
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
}

// The parts of `statements` in this order.
PlannedParts parts_in_order(const ExpressionGraph& g, std::vector<int> statements, const std::vector<char>& leaf,
                            const std::vector<int>& outputs, bool outputs_in_parts, int part_size) {
  Index index;
  for (std::size_t w = 0; w < statements.size(); ++w) index[statements[w]] = static_cast<int>(w);
  Parts plan;
  const int work = static_cast<int>(statements.size());
  plan.start = part_starts(crossing_values(g, statements, index, leaf, outputs, outputs_in_parts), work, part_size);
  assign_slots(plan, g, statements, index, leaf, outputs, outputs_in_parts);
  return PlannedParts{std::move(statements), std::move(plan)};
}

}  // namespace

PlannedParts plan_parts(const ExpressionGraph& g, const std::vector<int>& statements, const std::vector<int>& outputs,
                        const std::vector<char>& given, const std::vector<char>& leaf, bool outputs_in_parts,
                        int part_size) {
  std::vector<int> reversed;
  for (int i : g.schedule(std::vector<int>(outputs.rbegin(), outputs.rend()), given))
    if (!leaf[static_cast<std::size_t>(i)]) reversed.push_back(i);
  PlannedParts forward = parts_in_order(g, statements, leaf, outputs, outputs_in_parts, part_size);
  PlannedParts backward = parts_in_order(g, std::move(reversed), leaf, outputs, outputs_in_parts, part_size);
  return backward.plan.slot.size() < forward.plan.slot.size() ? backward : forward;
}

}  // namespace hamel
