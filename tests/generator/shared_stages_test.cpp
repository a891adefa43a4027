// Shared stages (emit/shared_stages.hpp): the work several kernels of a package have in common, computed once per
// call by a stage function each of them calls, which leaves in its array what later work reads. The plan is run
// here function by function as the printed package runs it: each stage computes its work from the arguments and
// from the arrays of the stages it reads (positions as the plan gives them; everything else NaN), then each unit's
// own work the same way. A stage may also write outputs of one unit (its layout) into an array laid out as that
// unit's outputs, which that unit then does not compute again. Its outputs are compared with the generator's own
// evaluation of the whole program (GraphEvaluator), which does not go through the plan. Also: a unit calls every stage
// it reads, before it reads it; no statement is computed twice in one unit's call; and the stages do save statements.
// On random programs of several units sharing work, and on the kernels of a kinematic tree (rhs, jacobian, mass_matrix,
// ...).
#include "emit/shared_stages.hpp"
#include "algebra/operations.hpp"
#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "emit/package_writer.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

using hamel::Argument;
using hamel::ExpressionGraph;
using hamel::Node;
using hamel::Op;
using hamel::SharingPlan;
using hamel::StageReads;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool is_statement(const ExpressionGraph& g, int i) { return g.node(i).op != Op::constant && g.node(i).op != Op::input; }

// The arrays of a unit's call as the printed package has them: s<k> for stage k's exports, m<u> for unit u's outputs.
using Arrays = std::map<std::string, std::vector<double>>;

// One function of the plan: `outputs` from the arguments and from what `reads` names in `arrays` (the arrays of the
// stages called so far); what the function computes itself is added to `computed`.
std::vector<double> run_function(const ExpressionGraph& g, const std::vector<int>& outputs, const StageReads& reads,
                                 const Arrays& arrays, double t, const double* x, const double* p, const double* in,
                                 std::vector<int>& computed) {
  std::vector<char> given(static_cast<std::size_t>(g.size()), 0);
  for (const auto& [node, at] : reads.value) given[static_cast<std::size_t>(node)] = 1;
  std::vector<double> value(static_cast<std::size_t>(g.size()), kNaN);
  for (int i : g.schedule(outputs, given)) {
    const Node& n = g.node(i);
    double& v = value[static_cast<std::size_t>(i)];
    if (given[static_cast<std::size_t>(i)]) {
      const hamel::StageValue at = reads.value.at(i);
      const std::string name = at.layout >= 0 ? "m" + std::to_string(at.layout) : "s" + std::to_string(at.stage);
      const auto array = arrays.find(name);
      if (array == arrays.end()) {
        ADD_FAILURE() << "reads " << name << " before a stage wrote it";
        continue;
      }
      v = array->second.at(static_cast<std::size_t>(at.position));
      EXPECT_FALSE(std::isnan(v)) << name << "[" << at.position << "] read before it was written";
    } else if (n.op == Op::constant) {
      v = n.value;
    } else if (n.op == Op::input) {
      v = n.argument == Argument::time    ? t
          : n.argument == Argument::state ? x[n.index]
          : n.argument == Argument::input ? in[n.index]
                                          : p[n.index];
    } else {
      v = hamel::evaluate(n.op, value[static_cast<std::size_t>(n.a)],
                          value[static_cast<std::size_t>(n.b >= 0 ? n.b : n.a)]);
      computed.push_back(i);
    }
  }
  std::vector<double> out;
  for (int o : outputs) out.push_back(value[static_cast<std::size_t>(o)]);
  return out;
}

// Runs every unit as its printed function would and compares with the whole program; returns the statements the
// plan computes in all (each stage once, each unit's own work once).
int check_plan(const ExpressionGraph& g, const std::vector<std::vector<int>>& units, const SharingPlan& plan,
               const std::vector<double>& x, const std::vector<double>& p, std::vector<double> in) {
  in.push_back(0);  // never empty
  int printed = 0;
  for (const SharingPlan::Stage& stage : plan.stages) printed += stage.statements;
  for (std::size_t u = 0; u < units.size(); ++u) {
    SCOPED_TRACE("unit " + std::to_string(u));
    Arrays arrays;
    std::vector<int> computed;
    int previous = -1;
    for (int s : plan.called[u]) {
      EXPECT_GT(s, previous) << "stages called out of order";
      previous = s;
      const SharingPlan::Stage& stage = plan.stages[static_cast<std::size_t>(s)];
      EXPECT_TRUE(std::count(stage.units.begin(), stage.units.end(), static_cast<int>(u)));
      EXPECT_FALSE(stage.exports.empty() && stage.outputs.empty()) << "stage " << s << " leaves nothing";
      std::vector<int> writes = stage.exports;
      for (const auto& [position, node] : stage.outputs) writes.push_back(node);
      const std::size_t before = computed.size();
      const std::vector<double> values =
          run_function(g, writes, stage.reads, arrays, 0.25, x.data(), p.data(), in.data(), computed);
      EXPECT_EQ(static_cast<int>(computed.size() - before), stage.statements) << "stage " << s;
      arrays["s" + std::to_string(s)].assign(values.begin(),
                                             values.begin() + static_cast<std::ptrdiff_t>(stage.exports.size()));
      if (stage.layout < 0) continue;
      const auto layout = static_cast<std::size_t>(stage.layout);
      std::vector<double>& m = arrays["m" + std::to_string(layout)];
      m.resize(units[layout].size(), kNaN);
      for (std::size_t o = 0; o < stage.outputs.size(); ++o) {
        const auto [position, node] = stage.outputs[o];
        EXPECT_EQ(units[layout].at(static_cast<std::size_t>(position)), node) << "written where another output goes";
        m.at(static_cast<std::size_t>(position)) = values[stage.exports.size() + o];
      }
    }
    // The unit's own work: the outputs a stage wrote to its out[] are taken from there, the others computed.
    const StageReads& own = plan.own[u];
    const auto mine = arrays.find("m" + std::to_string(u));
    std::vector<int> rest;
    for (std::size_t o = 0; o < units[u].size(); ++o)
      if (o >= own.written.size() || !own.written[o]) rest.push_back(units[u][o]);
    const std::size_t before_own = computed.size();
    const std::vector<double> computed_rest =
        run_function(g, rest, own, arrays, 0.25, x.data(), p.data(), in.data(), computed);
    printed += static_cast<int>(computed.size() - before_own);
    std::vector<double> staged;
    for (std::size_t o = 0, r = 0; o < units[u].size(); ++o)
      if (o < own.written.size() && own.written[o]) {
        EXPECT_NE(mine, arrays.end()) << "output " << o << " marked written, but no stage writes this unit's outputs";
        staged.push_back(mine == arrays.end() ? kNaN : mine->second.at(o));
      } else {
        staged.push_back(computed_rest[r++]);
      }
    std::vector<double> whole(units[u].size());
    hamel::GraphEvaluator(g, units[u]).evaluate(0.25, x.data(), p.data(), in.data(), whole.data());
    for (std::size_t o = 0; o < whole.size(); ++o) EXPECT_EQ(staged[o], whole[o]) << "output " << o;
    std::set<int> once(computed.begin(), computed.end());
    EXPECT_EQ(once.size(), computed.size()) << "a statement computed twice in one call";
  }
  return printed;
}

int statements_per_unit(const ExpressionGraph& g, const std::vector<std::vector<int>>& units) {
  int total = 0;
  for (const auto& outputs : units)
    for (int i : g.schedule(outputs)) total += is_statement(g, i);
  return total;
}

// Units that share work in layers: a common trunk all use, branches some use, leaves one uses.
struct Programs {
  ExpressionGraph graph;
  std::vector<std::vector<int>> units;
};

Programs layered_programs(unsigned seed, int units, int trunk, int branch) {
  Programs prog;
  ExpressionGraph& g = prog.graph;
  std::mt19937 rng(seed);
  std::vector<int> leaves;
  for (int i = 0; i < 4; ++i) leaves.push_back(g.input(Argument::state, i));
  leaves.push_back(g.input(Argument::parameter, 0));
  leaves.push_back(g.constant(0.75));
  const auto pick = [&](const std::vector<int>& from) {
    return from[std::uniform_int_distribution<std::size_t>(0, from.size() - 1)(rng)];
  };
  const auto grow = [&](std::vector<int> from, int n) {
    std::vector<int> made;
    while (static_cast<int>(made.size()) < n) {
      const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
      const int a = pick(from);
      const int node = kind == 3   ? g.unary(Op::sin, a)
                       : kind == 2 ? g.binary(Op::mul, a, pick(leaves))
                                   : g.binary(kind == 0 ? Op::add : Op::sub, a, pick(from));
      if (is_statement(g, node) && std::find(from.begin(), from.end(), node) == from.end()) {
        from.push_back(node);
        made.push_back(node);
      }
    }
    return made;
  };
  std::vector<int> base = leaves;
  const std::vector<int> common = grow(base, trunk);
  base.insert(base.end(), common.begin(), common.end());
  // Branch b is used by units b and b + 1 (and the last by the first unit too); each unit has work of its own.
  std::vector<std::vector<int>> branches;
  for (int b = 0; b < units; ++b) branches.push_back(grow(base, branch));
  for (int u = 0; u < units; ++u) {
    std::vector<int> from = base;
    for (int b : {u, (u + units - 1) % units})
      from.insert(from.end(), branches[static_cast<std::size_t>(b)].begin(),
                  branches[static_cast<std::size_t>(b)].end());
    const std::vector<int> own = grow(from, 5);
    std::vector<int> outputs = own;
    outputs.push_back(branches[static_cast<std::size_t>(u)].back());
    outputs.push_back(common.front());  // a stage's value that is itself an output
    prog.units.push_back(outputs);
  }
  return prog;
}

TEST(SharedStages, RandomProgramsRunAsTheirWholePrograms) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Programs prog = layered_programs(seed, 2 + static_cast<int>(seed % 4), 60, 30);
    // Which units' functions write their outputs to out[] in order (a stage may write them there): none, or some.
    std::vector<char> some(prog.units.size());
    for (std::size_t u = 0; u < some.size(); ++u) some[u] = (u + seed) % 3 != 0;
    // With min_read 0.5 and 0.9, units leave stages they read little of and compute that work themselves.
    for (int min : {1, 4, 10})
      for (double ratio : {0.0, 2.0})
        for (const std::vector<char>& writes_out : {std::vector<char>{}, some})
          for (double read : {0.0, 0.5, 0.9}) {
            SCOPED_TRACE("min_statements " + std::to_string(min) + ", min_ratio " + std::to_string(ratio) +
                         (writes_out.empty() ? ", no layouts" : ", layouts") + ", min_read " + std::to_string(read));
            const SharingPlan plan = hamel::plan_shared_stages(prog.graph, prog.units, min, ratio, writes_out, read);
            for (const SharingPlan::Stage& stage : plan.stages)
              if (stage.layout >= 0) {
                EXPECT_TRUE(writes_out.at(static_cast<std::size_t>(stage.layout)));
                EXPECT_TRUE(std::count(stage.units.begin(), stage.units.end(), stage.layout));
              }
            if (min == 1 && ratio == 0 && read == 0) {
              ASSERT_FALSE(plan.empty());
            }
            for (const SharingPlan::Stage& stage : plan.stages) EXPECT_GE(stage.statements, min);
            const std::vector<double> x = {0.3, -1.1, 0.7, 2.0}, p = {1.5};
            const int printed = check_plan(prog.graph, prog.units, plan, x, p, {});
            if (!plan.empty()) {
              EXPECT_LT(printed, statements_per_unit(prog.graph, prog.units));
            }
          }
  }
}

TEST(SharedStages, NoneBelowTheThresholdOrForOneUnit) {
  const Programs prog = layered_programs(7, 3, 60, 30);
  EXPECT_TRUE(hamel::plan_shared_stages(prog.graph, prog.units, 0).empty());
  EXPECT_TRUE(hamel::plan_shared_stages(prog.graph, prog.units, 1000).empty());
  EXPECT_TRUE(hamel::plan_shared_stages(prog.graph, {prog.units.front()}, 1).empty());
}

using hamel::test::source_dir;

// The kernels of a floating tree with two branches (the model of jacobian_calls_test): the jacobian as what its
// stage computes before its calls, rhs with its pivots, as the package prints them.
TEST(SharedStages, TreeKernelsRunAsTheirWholePrograms) {
  const hamel::Model model = hamel::load_model(source_dir() + "/tests/kernels/calls/calls_floating.yaml");
  const hamel::Derivation d = hamel::derive(model);
  const hamel::KernelSet set = hamel::build_kernels(model, d);
  std::vector<std::vector<int>> units;
  for (const hamel::Kernel& k : set.kernels) {
    units.push_back(k.outputs);
    if (k.name == "rhs") units.back().insert(units.back().end(), set.rhs_pivots.begin(), set.rhs_pivots.end());
  }
  std::vector<double> x(d.system.coordinates.size() + d.equations.independent.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = 0.4 * std::sin(1.7 * static_cast<double>(i) + 0.3);
  std::vector<double> p;
  for (const auto& q : model.parameters) p.push_back(q.default_value);
  p.push_back(0);
  std::vector<double> in;
  for (std::size_t i = 0; i < model.inputs.size(); ++i) in.push_back(0.3 - 0.2 * static_cast<double>(i));
  // As the package printer plans them: every kernel but rhs (whose function also writes the pivots) and the
  // jacobian (whose function is its stage) may have its outputs written by a stage.
  std::vector<char> writes_out;
  for (const hamel::Kernel& k : set.kernels) writes_out.push_back(k.name != "rhs" && k.name != "jacobian");
  bool any_layout = false;
  for (int min : {20, 100}) {
    SCOPED_TRACE("min_statements " + std::to_string(min));
    const SharingPlan plan = hamel::plan_shared_stages(set.graph, units, min, 0, writes_out, 0);
    ASSERT_GE(plan.stages.size(), 2u);
    for (const SharingPlan::Stage& stage : plan.stages) any_layout = any_layout || stage.layout >= 0;
    const int printed = check_plan(set.graph, units, plan, x, p, in);
    EXPECT_LT(printed, statements_per_unit(set.graph, units));
  }
  EXPECT_TRUE(any_layout) << "no stage writes a kernel's outputs (mass_matrix's come from the composite inertias)";
  // With the package printer's default ratio (32 statements per export): fewer stages, still exact; and with units
  // leaving the stages they read less than half of.
  const SharingPlan narrow = hamel::plan_shared_stages(set.graph, units, 20, 32);
  check_plan(set.graph, units, narrow, x, p, in);
  const SharingPlan read_most = hamel::plan_shared_stages(set.graph, units, 20, 0, writes_out, 0.5);
  check_plan(set.graph, units, read_most, x, p, in);
}

// --share-ratio auto (the default): the ratio of a small package, or of a large one when the kernels print at least
// EmitSettings::large_package statements together; here the tree's package is made "large" by lowering that bound.
// Each choice prints exactly what the explicit ratio prints, and the large package's lower ratio shares more.
TEST(SharedStages, AutoRatioFollowsThePackageSize) {
  const hamel::Model model = hamel::load_model(source_dir() + "/tests/kernels/calls/calls_floating.yaml");
  const hamel::Derivation d = hamel::derive(model);
  const hamel::KernelSet set = hamel::build_kernels(model, d);
  const auto emit = [&](int ratio, long large) {
    hamel::EmitSettings settings;
    settings.share_statements = 20;
    settings.share_ratio = ratio;
    settings.large_package = large;
    return hamel::emit_cpp(model, d, set, settings);
  };
  const hamel::EmittedPackage small = emit(hamel::kShareRatioAuto, hamel::kLargePackage);
  ASSERT_GT(small.statements, 100);
  ASSERT_LT(small.statements, hamel::kLargePackage);
  EXPECT_EQ(small.share_ratio, hamel::kShareRatioSmall);
  EXPECT_EQ(small.source, emit(hamel::kShareRatioSmall, hamel::kLargePackage).source);

  const hamel::EmittedPackage large = emit(hamel::kShareRatioAuto, small.statements);
  EXPECT_EQ(large.statements, small.statements);
  EXPECT_EQ(large.share_ratio, hamel::kShareRatioLarge);
  EXPECT_EQ(large.source, emit(hamel::kShareRatioLarge, hamel::kLargePackage).source);
  EXPECT_GT(large.shared_stages, small.shared_stages);
  EXPECT_LT(large.source.size(), small.source.size());
  // An explicit ratio is kept whatever the size.
  EXPECT_EQ(emit(0, 1).share_ratio, 0);
}

}  // namespace
