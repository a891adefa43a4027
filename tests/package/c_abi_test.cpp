// The C entry points of an emitted package (<name>.h, extern "C" <name>_<kernel>, <name>_rhs_status): a C
// caller compiled with gcc -std=c11 -Wall -Wextra -Werror -pedantic against the package compiled with g++
// gives, to the last bit printed with %.17g, the rhs that the generator's own interpreter of the expression
// graph (GraphEvaluator) computes, for a kinematic tree with --dynamics aba and ldlt; rhs_status returns 0
// there, and 1 (out untouched) when the leaf body's mass and inertia are zero at run time (its articulated
// inertia D, or the pivot of M, is 0 and rhs would return NaN).
#include "package_support.hpp"

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace hamel::package_test {
namespace {

const char* model_text = R"(schema: 1
name: c_tree
description: two bodies on a floating base, the leaf's mass and inertia as parameters
parameters:
  m2: 0.7
  J2: 0.01
group: SE3
trivialization: left
group_velocity: [wx, wy, wz, vx, vy, vz]
connection: mechanical
tree:
  base:
    name: base
    mass: 3
    com: [0.1, 0, 0]
    inertia: [[0.2, 0, 0], [0, 0.3, 0], [0, 0, 0.25]]
  bodies:
    - name: b1
      parent: base
      joint: {name: q1, type: revolute, axis: [0, 0, 1], offset: [0.2, 0.1, 0.3]}
      mass: 1.1
      com: [0.05, 0.1, 0]
      inertia: [[0.02, 0, 0], [0, 0.03, 0], [0, 0, 0.015]]
    - name: b2
      parent: b1
      joint: {name: q2, type: revolute, axis: [0, 1, 0], offset: [0, 0.3, 0]}
      mass: m2
      com: [0, 0.1, 0]
      inertia: [[J2, 0, 0], [0, J2, 0], [0, 0, J2]]
)";

const char* caller = R"(#include "c_tree.h"

#include <stdio.h>

int main(void) {
  const double x[C_TREE_N_STATE] = {0.3, -0.7, 0.1, -0.2, 0.3, 0.4, -0.5, 0.6, 1.1, -0.9};
  const double p[C_TREE_N_PARAMETERS] = {0.7, 0.01};
  const double zero_leaf[C_TREE_N_PARAMETERS] = {0.0, 0.0};
  double out[C_TREE_N_OUT_RHS];
  double checked[C_TREE_N_OUT_RHS];
  int i;
  c_tree_rhs(0.0, x, p, NULL, out);
  for (i = 0; i < C_TREE_N_OUT_RHS; ++i) printf("%.17g\n", out[i]);
  printf("status %d\n", c_tree_rhs_status(0.0, x, p, NULL, checked));
  for (i = 0; i < C_TREE_N_OUT_RHS; ++i)
    if (checked[i] != out[i]) printf("rhs_status differs at %d\n", i);
  for (i = 0; i < C_TREE_N_OUT_RHS; ++i) checked[i] = 42.0;
  printf("singular status %d\n", c_tree_rhs_status(0.0, x, zero_leaf, NULL, checked));
  for (i = 0; i < C_TREE_N_OUT_RHS; ++i)
    if (checked[i] != 42.0) printf("out written at %d\n", i);
  return 0;
}
)";

// `split`: emit's --split; a small one prints rhs in parts, as rhs_with_pivots, which rhs and rhs_status call.
void check(const std::string& dynamics, int split = 2000) {
  SCOPED_TRACE(dynamics + ", --split " + std::to_string(split));
  Scratch dir("c_abi_" + dynamics + "_" + std::to_string(split));
  {
    std::ofstream(dir.path() / "c_tree.yaml") << model_text;
    std::ofstream(dir.path() / "main.c") << caller;
  }
  const Outcome e =
      emit((dir.path() / "c_tree.yaml").string(),
           "--fold none --dynamics " + dynamics + " --split " + std::to_string(split), dir.path() / "pkg");
  ASSERT_EQ(e.status, 0) << e.out;
  const std::string d = quote(dir.path().string());
  const Outcome cc = run("cd " + d + " && gcc -std=c11 -Wall -Wextra -Werror -pedantic -Ipkg -c main.c -o main.o");
  ASSERT_EQ(cc.status, 0) << cc.out;
  const Outcome cxx =
      run("cd " + d + " && g++ -std=c++17 -O1 -Wall -Wextra -Werror -pedantic -Ipkg -c pkg/c_tree.cpp -o pkg.o");
  ASSERT_EQ(cxx.status, 0) << cxx.out;
  const Outcome link = run("cd " + d + " && g++ main.o pkg.o -o caller -lm && ./caller");
  ASSERT_EQ(link.status, 0) << link.out;

  const Model model = load_model_from_text(model_text, "c_tree.yaml");
  const Derivation derivation = derive(model);
  const KernelSet kernels = build_kernels(model, derivation, {"rhs"}, {dynamics});
  GraphEvaluator rhs(kernels.graph, kernels.get("rhs").outputs);
  const std::vector<double> x = {0.3, -0.7, 0.1, -0.2, 0.3, 0.4, -0.5, 0.6, 1.1, -0.9}, p = {0.7, 0.01};
  std::vector<double> expected(x.size());
  rhs.evaluate(0.0, x.data(), p.data(), nullptr, expected.data());

  std::istringstream lines(link.out);
  double worst = 0;
  for (double v : expected) {
    std::string line;
    ASSERT_TRUE(std::getline(lines, line)) << link.out;
    const double got = std::stod(line);
    worst = std::max(worst, std::fabs(got - v) / std::max(1.0, std::fabs(v)));
  }
  std::string rest((std::istreambuf_iterator<char>(lines)), std::istreambuf_iterator<char>());
  EXPECT_EQ(rest, "status 0\nsingular status 1\n");
  // The compiled kernel and the interpreter evaluate the same operations; only contraction (FMA) or
  // reassociation could differ, and g++ -O1 on x86-64 does neither.
  EXPECT_LE(worst, 1e-14) << link.out;
  std::printf("%s: C caller vs GraphEvaluator, largest relative difference %.1e\n", dynamics.c_str(), worst);
}

TEST(CEntryPoints, CompileAsC11AndAgreeWithTheGenerator) {
  check("aba");
  check("ldlt");
  check("aba", 10);
  check("ldlt", 10);
}

}  // namespace
}  // namespace hamel::package_test
