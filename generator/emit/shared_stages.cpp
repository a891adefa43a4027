#include "emit/shared_stages.hpp"

#include <algorithm>
#include <bitset>
#include <set>

namespace hamel {

namespace {

bool is_statement(const ExpressionGraph& g, int i) {
  const Op op = g.node(i).op;
  return op != Op::constant && op != Op::input;
}

std::size_t kernels_in(std::uint64_t set) { return std::bitset<64>(set).count(); }

}  // namespace

SharingPlan plan_shared_stages(const ExpressionGraph& g, const std::vector<std::vector<int>>& units, int min_statements,
                               double min_ratio, const std::vector<char>& writes_out, double min_read) {
  SharingPlan plan;
  const std::size_t n_units = units.size();
  plan.called.resize(n_units);
  plan.own.resize(n_units);
  for (const std::vector<int>& unit : units) plan.outputs.push_back(static_cast<int>(unit.size()));
  if (min_statements <= 0 || n_units < 2 || n_units > 64) return plan;
  const auto size = static_cast<std::size_t>(g.size());

  // Which units use each statement; the classes, each in the schedule order of the first unit that uses it.
  std::vector<std::vector<int>> schedules(n_units);
  std::vector<std::uint64_t> users(size, 0);
  for (std::size_t u = 0; u < n_units; ++u) {
    schedules[u] = g.schedule(units[u]);
    for (int i : schedules[u])
      if (is_statement(g, i)) users[static_cast<std::size_t>(i)] |= std::uint64_t{1} << u;
  }
  std::map<std::uint64_t, std::vector<int>> classes;
  std::set<std::uint64_t> candidates;  // the classes large enough
  const auto group = [&] {
    classes.clear();
    candidates.clear();
    for (std::size_t u = 0; u < n_units; ++u)
      for (int i : schedules[u]) {
        const std::uint64_t set = users[static_cast<std::size_t>(i)];
        if (kernels_in(set) >= 2 && (set & (~set + 1)) == std::uint64_t{1} << u) classes[set].push_back(i);
      }
    for (const auto& [set, nodes] : classes)
      if (nodes.size() >= static_cast<std::size_t>(min_statements)) candidates.insert(set);
  };

  // Each function in calling order: what it computes from its roots, reading what a stage before it computes that
  // every unit calling it has called (the first such stage).
  std::vector<std::pair<std::uint64_t, std::vector<int>>> shared;  // (units, the class), in calling order
  std::vector<std::vector<int>> computes;
  std::vector<std::set<int>> exported;
  const auto run = [&](const std::vector<int>& roots, std::uint64_t set, std::size_t before, StageReads& reads) {
    std::vector<char> boundary(size, 0);
    std::vector<int> from(size, -1);
    for (std::size_t s = 0; s < before; ++s) {
      if ((shared[s].first & set) != set) continue;
      for (int i : computes[s])
        if (!boundary[static_cast<std::size_t>(i)]) {
          boundary[static_cast<std::size_t>(i)] = 1;
          from[static_cast<std::size_t>(i)] = static_cast<int>(s);
        }
    }
    std::vector<int> statements;
    for (int i : g.schedule(roots, boundary)) {
      const int stage = from[static_cast<std::size_t>(i)];
      if (stage >= 0) {
        reads.value[i] = {stage, -1, -1};
        exported[static_cast<std::size_t>(stage)].insert(i);
      } else if (is_statement(g, i)) {
        statements.push_back(i);
      }
    }
    return statements;
  };
  // The plan with the classes `chosen` as stages. Work of a class that is not a stage but that two stages of one
  // unit both compute (the joints' sines and cosines, read by the stages of M and of f) would be done twice in that
  // unit: such a class becomes a stage too, and the plan is made again.
  const auto make = [&](std::set<std::uint64_t> chosen) {
    for (;;) {
      shared.clear();
      for (std::uint64_t set : chosen) shared.emplace_back(set, classes.at(set));
      std::stable_sort(shared.begin(), shared.end(),
                       [](const auto& a, const auto& b) { return kernels_in(a.first) > kernels_in(b.first); });
      const std::size_t n_stages = shared.size();
      plan.stages.assign(n_stages, {});
      plan.called.assign(n_units, {});
      plan.own.assign(n_units, {});
      computes.assign(n_stages, {});
      exported.assign(n_stages, {});
      for (std::size_t s = 0; s < n_stages; ++s) {
        computes[s] = run(shared[s].second, shared[s].first, s, plan.stages[s].reads);
        plan.stages[s].statements = static_cast<int>(computes[s].size());
        for (std::size_t u = 0; u < n_units; ++u)
          if (shared[s].first >> u & 1) {
            plan.stages[s].units.push_back(static_cast<int>(u));
            plan.called[u].push_back(static_cast<int>(s));
          }
      }
      const std::size_t before = chosen.size();
      for (std::size_t u = 0; u < n_units; ++u) {
        std::vector<char> done(size, 0);
        for (int s : plan.called[u])
          for (int i : computes[static_cast<std::size_t>(s)]) {
            if (done[static_cast<std::size_t>(i)]) chosen.insert(users[static_cast<std::size_t>(i)]);
            done[static_cast<std::size_t>(i)] = 1;
          }
      }
      if (chosen.size() == before) break;
    }
    for (std::size_t u = 0; u < n_units; ++u) run(units[u], std::uint64_t{1} << u, shared.size(), plan.own[u]);
  };
  // A stage whose exports are many for its work costs more in stores and loads than it saves (every caller writes
  // all of them): such a candidate is dropped, and the plan made again without it.
  const auto plan_candidates = [&] {
    for (;;) {
      make(candidates);
      bool dropped = false;
      for (std::size_t s = 0; s < shared.size(); ++s)
        if (candidates.count(shared[s].first) &&
            static_cast<double>(computes[s].size()) < min_ratio * static_cast<double>(exported[s].size())) {
          candidates.erase(shared[s].first);
          dropped = true;
        }
      if (!dropped) break;
    }
  };
  // A unit that reads less than `min_read` of what a stage it calls exports (it calls it, and so stores all of it, for
  // a few values: locked_inertia reads 10 of the composite inertias' 713, the bicycle's rhs 80 of the 4 129 values its
  // jacobian reads) computes that work in its own function instead: it no longer counts as a user of the stage's
  // statements nor of the statements that depend on them (so that no stage it calls needs them), the classes are
  // formed again, and so is the plan.
  for (;;) {
    group();
    plan_candidates();
    std::vector<std::pair<std::size_t, std::size_t>> leave;  // (unit, stage)
    for (std::size_t u = 0; u < n_units; ++u)
      for (int st : plan.called[u]) {
        const auto s = static_cast<std::size_t>(st);
        std::set<int> read;
        const auto count = [&](const StageReads& reads) {
          for (const auto& [node, at] : reads.value)
            if (at.stage == st) read.insert(node);
        };
        count(plan.own[u]);
        for (int other : plan.called[u]) count(plan.stages[static_cast<std::size_t>(other)].reads);
        if (static_cast<double>(read.size()) < min_read * static_cast<double>(exported[s].size()))
          leave.emplace_back(u, s);
      }
    if (leave.empty()) break;
    for (const auto& [u, s] : leave) {
      const std::uint64_t bit = std::uint64_t{1} << u;
      std::vector<char> depends(size, 0);
      for (int i : shared[s].second) depends[static_cast<std::size_t>(i)] = 1;
      for (int i : schedules[u]) {
        const Node& n = g.node(i);
        const auto index = static_cast<std::size_t>(i);
        depends[index] = depends[index] || (n.a >= 0 && depends[static_cast<std::size_t>(n.a)]) ||
                         (n.b >= 0 && depends[static_cast<std::size_t>(n.b)]);
        if (depends[index]) users[index] &= ~bit;
      }
    }
  }
  const std::size_t n_stages = shared.size();

  // Which unit's outputs each stage writes into that unit's out[]: of the units that call it and whose function writes
  // its outputs in order to out[], the one with the most outputs the stage computes.
  std::vector<std::map<int, int>> at_output(n_stages);  // per stage: node -> its first position in m<layout>
  for (std::size_t s = 0; s < n_stages; ++s) {
    SharingPlan::Stage& stage = plan.stages[s];
    std::vector<char> here(size, 0);
    for (int i : computes[s]) here[static_cast<std::size_t>(i)] = 1;
    std::size_t most = 0;
    for (int u : stage.units) {
      const auto unit = static_cast<std::size_t>(u);
      if (unit >= writes_out.size() || !writes_out[unit]) continue;
      const auto n = static_cast<std::size_t>(std::count_if(
          units[unit].begin(), units[unit].end(), [&](int i) { return here[static_cast<std::size_t>(i)] != 0; }));
      if (n > most) most = n, stage.layout = u;
    }
    if (stage.layout < 0) continue;
    const std::vector<int>& outputs = units[static_cast<std::size_t>(stage.layout)];
    for (std::size_t j = 0; j < outputs.size(); ++j)
      if (here[static_cast<std::size_t>(outputs[j])]) {
        stage.outputs.emplace_back(static_cast<int>(j), outputs[j]);
        at_output[s].emplace(outputs[j], static_cast<int>(j));
      }
  }
  // The other exports in the order the stage computes them; every read names its array and position.
  std::vector<std::map<int, int>> position(n_stages);
  for (std::size_t s = 0; s < n_stages; ++s)
    for (int i : computes[s])
      if (exported[s].count(i) && !at_output[s].count(i)) {
        position[s][i] = static_cast<int>(plan.stages[s].exports.size());
        plan.stages[s].exports.push_back(i);
      }
  const auto resolve = [&](StageReads& reads) {
    std::set<int> stages, layouts;
    for (auto& [node, at] : reads.value) {
      const auto s = static_cast<std::size_t>(at.stage);
      const auto out = at_output[s].find(node);
      if (out != at_output[s].end()) {
        at.layout = plan.stages[s].layout;
        at.position = out->second;
        layouts.insert(at.layout);
      } else {
        at.position = position[s].at(node);
        stages.insert(at.stage);
      }
    }
    reads.stages.assign(stages.begin(), stages.end());
    reads.layouts.assign(layouts.begin(), layouts.end());
  };
  for (SharingPlan::Stage& stage : plan.stages) resolve(stage.reads);
  for (StageReads& reads : plan.own) resolve(reads);
  for (const SharingPlan::Stage& stage : plan.stages) {
    if (stage.layout < 0) continue;
    std::vector<char>& written = plan.own[static_cast<std::size_t>(stage.layout)].written;
    written.resize(units[static_cast<std::size_t>(stage.layout)].size(), 0);
    for (const auto& [j, node] : stage.outputs) written[static_cast<std::size_t>(j)] = 1;
  }
  return plan;
}

}  // namespace hamel
