// The double interpreter (numeric/graph_evaluator, emit/interpreter.hpp) runs a compiled copy of a kernel's schedule:
// dense slots, the constants filled once, one instruction per operation. A regression guard that it computes exactly
// what evaluating the graph node by node (a loop of this test's, over the operation table) gives:
// every kernel of models with trigonometric, square-root, power and division nodes, at random points, bit for bit,
// and again after evaluating other points (no state carried between calls beyond the constants).
#include "numeric/graph_evaluator.hpp"
#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using hamel::test::source_dir;

std::vector<double> node_by_node(const hamel::ExpressionGraph& g, const std::vector<int>& outputs, double t,
                                 const std::vector<double>& x, const std::vector<double>& p,
                                 const std::vector<double>& in) {
  std::vector<double> values(static_cast<std::size_t>(g.size()), 0.0);
  for (int i : g.schedule(outputs)) {
    const hamel::Node& n = g.node(i);
    const auto k = static_cast<std::size_t>(n.index);
    double& v = values[static_cast<std::size_t>(i)];
    if (n.op == hamel::Op::constant) {
      v = n.value;
    } else if (n.op == hamel::Op::input) {
      v = n.argument == hamel::Argument::time        ? t
          : n.argument == hamel::Argument::state     ? x.at(k)
          : n.argument == hamel::Argument::parameter ? p.at(k)
                                                     : in.at(k);
    } else {
      const double a = values[static_cast<std::size_t>(n.a)];
      v = hamel::evaluate(n.op, a, n.b >= 0 ? values[static_cast<std::size_t>(n.b)] : a);
    }
  }
  std::vector<double> out;
  for (int o : outputs) out.push_back(values[static_cast<std::size_t>(o)]);
  return out;
}

TEST(GraphEvaluator, ComputesWhatTheGraphGivesNodeByNode) {
  for (const char* file : {"models/whipple_bicycle.yaml", "models/satellite_se3.yaml", "models/rolling_disk_routh.yaml",
                           "models/satellite_wheels_controlled.yaml"}) {
    SCOPED_TRACE(file);
    const hamel::Model model = hamel::load_model(source_dir() + "/" + file);
    const hamel::Derivation d = hamel::derive(model);
    const hamel::KernelSet set = hamel::build_kernels(model, d);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (const hamel::Kernel& k : set.kernels) {
      SCOPED_TRACE(k.name);
      hamel::GraphEvaluator compiled(set.graph, k.outputs);
      for (int point = 0; point < 3; ++point) {
        const double t = unit(rng);
        std::vector<double> x(d.system.coordinates.size() + d.equations.independent.size()), p, in;
        for (double& v : x) v = unit(rng);
        for (const auto& parameter : model.parameters) p.push_back(parameter.default_value * (1 + 0.1 * unit(rng)));
        for (std::size_t i = 0; i < model.inputs.size(); ++i) in.push_back(unit(rng));
        std::vector<double> out(k.outputs.size());
        compiled.evaluate(t, x.data(), p.data(), in.empty() ? nullptr : in.data(), out.data());
        const std::vector<double> expected = node_by_node(set.graph, k.outputs, t, x, p, in);
        for (std::size_t o = 0; o < out.size(); ++o) {
          if (std::isnan(expected[o])) {
            EXPECT_TRUE(std::isnan(out[o])) << "output " << o;
          } else {
            EXPECT_EQ(out[o], expected[o]) << "output " << o;
          }
        }
      }
    }
  }
}

}  // namespace
