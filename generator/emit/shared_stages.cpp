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

// plan_shared_stages, step by step: the classes (group), a plan for a set of them (make), the candidates whose
// stages pay for their exports (plan_candidates), the units that leave a stage they would read little of
// (leave_light_readers), then where every value a function reads lies (place).
class SharingPlanner {
 public:
  SharingPlanner(const ExpressionGraph& g, const std::vector<std::vector<int>>& units, int min_statements,
                 double min_ratio, const std::vector<char>& writes_out, double min_read)
      : g_(g),
        units_(units),
        min_statements_(min_statements),
        min_ratio_(min_ratio),
        writes_out_(writes_out),
        min_read_(min_read),
        n_units_(units.size()),
        size_(static_cast<std::size_t>(g.size())) {
    plan_.called.resize(n_units_);
    plan_.own.resize(n_units_);
    for (const std::vector<int>& unit : units) plan_.outputs.push_back(static_cast<int>(unit.size()));
  }

  /// No stages: every unit computes all it needs.
  SharingPlan unshared() const { return plan_; }

  SharingPlan planned() {
    // Which units use each statement.
    schedules_.resize(n_units_);
    users_.assign(size_, 0);
    for (std::size_t u = 0; u < n_units_; ++u) {
      schedules_[u] = g_.schedule(units_[u]);
      for (int i : schedules_[u])
        if (is_statement(g_, i)) users_[static_cast<std::size_t>(i)] |= std::uint64_t{1} << u;
    }
    do {
      group();
      plan_candidates();
    } while (leave_light_readers());
    place();
    return plan_;
  }

 private:
  void group();
  std::vector<int> run(const std::vector<int>& roots, std::uint64_t set, std::size_t before, StageReads& reads);
  void make(std::set<std::uint64_t> chosen);
  void plan_candidates();
  bool leave_light_readers();
  void place();

  const ExpressionGraph& g_;
  const std::vector<std::vector<int>>& units_;
  const int min_statements_;
  const double min_ratio_;
  const std::vector<char>& writes_out_;
  const double min_read_;
  const std::size_t n_units_, size_;
  SharingPlan plan_;
  std::vector<std::vector<int>> schedules_;  ///< per unit: g.schedule of its outputs
  std::vector<std::uint64_t> users_;         ///< per node: the units that use it (a bit each)
  std::map<std::uint64_t, std::vector<int>> classes_;
  std::set<std::uint64_t> candidates_;  ///< the classes large enough
  /// Each function in calling order: (units, the class); what it computes; the values later functions read of it.
  std::vector<std::pair<std::uint64_t, std::vector<int>>> shared_;
  std::vector<std::vector<int>> computes_;
  std::vector<std::set<int>> exported_;
};

// The classes, each in the schedule order of the first unit that uses it, and the candidates among them.
void SharingPlanner::group() {
  classes_.clear();
  candidates_.clear();
  for (std::size_t u = 0; u < n_units_; ++u)
    for (int i : schedules_[u]) {
      const std::uint64_t set = users_[static_cast<std::size_t>(i)];
      if (kernels_in(set) >= 2 && (set & (~set + 1)) == std::uint64_t{1} << u) classes_[set].push_back(i);
    }
  for (const auto& [set, nodes] : classes_)
    if (nodes.size() >= static_cast<std::size_t>(min_statements_)) candidates_.insert(set);
}

// What a function of the units `set` computes from its roots, reading what a stage before it (of the first `before`)
// computes that every unit calling it has called (the first such stage).
std::vector<int> SharingPlanner::run(const std::vector<int>& roots, std::uint64_t set, std::size_t before,
                                     StageReads& reads) {
  std::vector<char> boundary(size_, 0);
  std::vector<int> from(size_, -1);
  for (std::size_t s = 0; s < before; ++s) {
    if ((shared_[s].first & set) != set) continue;
    for (int i : computes_[s])
      if (!boundary[static_cast<std::size_t>(i)]) {
        boundary[static_cast<std::size_t>(i)] = 1;
        from[static_cast<std::size_t>(i)] = static_cast<int>(s);
      }
  }
  std::vector<int> statements;
  for (int i : g_.schedule(roots, boundary)) {
    const int stage = from[static_cast<std::size_t>(i)];
    if (stage >= 0) {
      reads.value[i] = {stage, -1, -1};
      exported_[static_cast<std::size_t>(stage)].insert(i);
    } else if (is_statement(g_, i)) {
      statements.push_back(i);
    }
  }
  return statements;
}

// The plan with the classes `chosen` as stages. Work of a class that is not a stage but that two stages of one unit
// both compute (the joints' sines and cosines, read by the stages of M and of f) would be done twice in that unit:
// such a class becomes a stage too, and the plan is made again.
void SharingPlanner::make(std::set<std::uint64_t> chosen) {
  for (;;) {
    shared_.clear();
    for (std::uint64_t set : chosen) shared_.emplace_back(set, classes_.at(set));
    std::stable_sort(shared_.begin(), shared_.end(),
                     [](const auto& a, const auto& b) { return kernels_in(a.first) > kernels_in(b.first); });
    const std::size_t n_stages = shared_.size();
    plan_.stages.assign(n_stages, {});
    plan_.called.assign(n_units_, {});
    plan_.own.assign(n_units_, {});
    computes_.assign(n_stages, {});
    exported_.assign(n_stages, {});
    for (std::size_t s = 0; s < n_stages; ++s) {
      computes_[s] = run(shared_[s].second, shared_[s].first, s, plan_.stages[s].reads);
      plan_.stages[s].statements = static_cast<int>(computes_[s].size());
      for (std::size_t u = 0; u < n_units_; ++u)
        if (shared_[s].first >> u & 1) {
          plan_.stages[s].units.push_back(static_cast<int>(u));
          plan_.called[u].push_back(static_cast<int>(s));
        }
    }
    const std::size_t before = chosen.size();
    for (std::size_t u = 0; u < n_units_; ++u) {
      std::vector<char> done(size_, 0);
      for (int s : plan_.called[u])
        for (int i : computes_[static_cast<std::size_t>(s)]) {
          if (done[static_cast<std::size_t>(i)]) chosen.insert(users_[static_cast<std::size_t>(i)]);
          done[static_cast<std::size_t>(i)] = 1;
        }
    }
    if (chosen.size() == before) break;
  }
  for (std::size_t u = 0; u < n_units_; ++u) run(units_[u], std::uint64_t{1} << u, shared_.size(), plan_.own[u]);
}

// A stage whose exports are many for its work costs more in stores and loads than it saves (every caller writes all
// of them): such a candidate is dropped, and the plan made again without it.
void SharingPlanner::plan_candidates() {
  for (;;) {
    make(candidates_);
    bool dropped = false;
    for (std::size_t s = 0; s < shared_.size(); ++s)
      if (candidates_.count(shared_[s].first) &&
          static_cast<double>(computes_[s].size()) < min_ratio_ * static_cast<double>(exported_[s].size())) {
        candidates_.erase(shared_[s].first);
        dropped = true;
      }
    if (!dropped) break;
  }
}

// A unit that reads less than `min_read` of what a stage it calls exports (it calls it, and so stores all of it, for
// a few values: locked_inertia reads 10 of the composite inertias' 713, the bicycle's rhs 80 of the 4 129 values its
// jacobian reads) computes that work in its own function instead: it no longer counts as a user of the stage's
// statements nor of the statements that depend on them (so that no stage it calls needs them). True when one did:
// the classes are formed again, and so is the plan.
bool SharingPlanner::leave_light_readers() {
  std::vector<std::pair<std::size_t, std::size_t>> leave;  // (unit, stage)
  for (std::size_t u = 0; u < n_units_; ++u)
    for (int st : plan_.called[u]) {
      const auto s = static_cast<std::size_t>(st);
      std::set<int> read;
      const auto count = [&](const StageReads& reads) {
        for (const auto& [node, at] : reads.value)
          if (at.stage == st) read.insert(node);
      };
      count(plan_.own[u]);
      for (int other : plan_.called[u]) count(plan_.stages[static_cast<std::size_t>(other)].reads);
      if (static_cast<double>(read.size()) < min_read_ * static_cast<double>(exported_[s].size()))
        leave.emplace_back(u, s);
    }
  for (const auto& [u, s] : leave) {
    const std::uint64_t bit = std::uint64_t{1} << u;
    std::vector<char> depends(size_, 0);
    for (int i : shared_[s].second) depends[static_cast<std::size_t>(i)] = 1;
    for (int i : schedules_[u]) {
      const Node& n = g_.node(i);
      const auto index = static_cast<std::size_t>(i);
      depends[index] = depends[index] || (n.a >= 0 && depends[static_cast<std::size_t>(n.a)]) ||
                       (n.b >= 0 && depends[static_cast<std::size_t>(n.b)]);
      if (depends[index]) users_[index] &= ~bit;
    }
  }
  return !leave.empty();
}

// Which unit's outputs each stage writes into that unit's out[] (of the units that call it and whose function writes
// its outputs in order to out[], the one with the most outputs the stage computes), the other exports in the order
// the stage computes them, and where every read finds its value.
void SharingPlanner::place() {
  const std::size_t n_stages = shared_.size();
  std::vector<std::map<int, int>> at_output(n_stages);  // per stage: node -> its first position in m<layout>
  for (std::size_t s = 0; s < n_stages; ++s) {
    SharingPlan::Stage& stage = plan_.stages[s];
    std::vector<char> here(size_, 0);
    for (int i : computes_[s]) here[static_cast<std::size_t>(i)] = 1;
    std::size_t most = 0;
    for (int u : stage.units) {
      const auto unit = static_cast<std::size_t>(u);
      if (unit >= writes_out_.size() || !writes_out_[unit]) continue;
      const auto n = static_cast<std::size_t>(std::count_if(
          units_[unit].begin(), units_[unit].end(), [&](int i) { return here[static_cast<std::size_t>(i)] != 0; }));
      if (n > most) most = n, stage.layout = u;
    }
    if (stage.layout < 0) continue;
    const std::vector<int>& outputs = units_[static_cast<std::size_t>(stage.layout)];
    for (std::size_t j = 0; j < outputs.size(); ++j)
      if (here[static_cast<std::size_t>(outputs[j])]) {
        stage.outputs.emplace_back(static_cast<int>(j), outputs[j]);
        at_output[s].emplace(outputs[j], static_cast<int>(j));
      }
  }
  std::vector<std::map<int, int>> position(n_stages);
  for (std::size_t s = 0; s < n_stages; ++s)
    for (int i : computes_[s])
      if (exported_[s].count(i) && !at_output[s].count(i)) {
        position[s][i] = static_cast<int>(plan_.stages[s].exports.size());
        plan_.stages[s].exports.push_back(i);
      }
  const auto resolve = [&](StageReads& reads) {
    std::set<int> stages, layouts;
    for (auto& [node, at] : reads.value) {
      const auto s = static_cast<std::size_t>(at.stage);
      const auto out = at_output[s].find(node);
      if (out != at_output[s].end()) {
        at.layout = plan_.stages[s].layout;
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
  for (SharingPlan::Stage& stage : plan_.stages) resolve(stage.reads);
  for (StageReads& reads : plan_.own) resolve(reads);
  for (const SharingPlan::Stage& stage : plan_.stages) {
    if (stage.layout < 0) continue;
    std::vector<char>& written = plan_.own[static_cast<std::size_t>(stage.layout)].written;
    written.resize(units_[static_cast<std::size_t>(stage.layout)].size(), 0);
    for (const auto& [j, node] : stage.outputs) written[static_cast<std::size_t>(j)] = 1;
  }
}

}  // namespace

SharingPlan plan_shared_stages(const ExpressionGraph& g, const std::vector<std::vector<int>>& units, int min_statements,
                               double min_ratio, const std::vector<char>& writes_out, double min_read) {
  SharingPlanner planner(g, units, min_statements, min_ratio, writes_out, min_read);
  if (min_statements <= 0 || units.size() < 2 || units.size() > 64) return planner.unshared();
  return planner.planned();
}

}  // namespace hamel
