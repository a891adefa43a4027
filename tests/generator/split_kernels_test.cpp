// Long kernels printed in parts (emit --split N): every part has at most N statements, values cross parts in
// the stack array v[], and a slot is reused once its value has been read for the last time. The printed text
// is run by a small interpreter of its statements (locals scoped to their part, v[] starting as NaN, so a
// value read after its slot was reused or read from another part's locals shows up) and compared with the
// generator's own evaluation of the graph (GraphEvaluator), for random programs and every part size from 1.
#include "emit/cpp_emitter.hpp"
#include "emit/expression_graph.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using hamel::Argument;
using hamel::ExpressionGraph;
using hamel::Op;

constexpr int kInputs = 4;

// A random program: `statements` nodes, each an add, sub or mul of earlier nodes (a mul takes an input or a
// constant as one factor, so values stay of order one), and `outputs` outputs among them, early ones included.
struct Program {
  ExpressionGraph graph;
  std::vector<int> outputs;
};

Program random_program(unsigned seed, int statements, int outputs) {
  Program prog;
  ExpressionGraph& g = prog.graph;
  std::mt19937 rng(seed);
  std::vector<int> leaves, nodes;
  for (int i = 0; i < kInputs; ++i) leaves.push_back(g.input(Argument::state, i));
  leaves.push_back(g.constant(0.75));
  nodes = leaves;
  const auto pick = [&](const std::vector<int>& from) {
    return from[std::uniform_int_distribution<std::size_t>(0, from.size() - 1)(rng)];
  };
  while (static_cast<int>(nodes.size()) < statements + static_cast<int>(leaves.size())) {
    const int kind = std::uniform_int_distribution<int>(0, 2)(rng);
    const Op op = kind == 0 ? Op::add : kind == 1 ? Op::sub : Op::mul;
    const int a = pick(nodes);
    const int b = op == Op::mul ? pick(leaves) : pick(nodes);
    const int node = g.binary(op, a, b);
    if (node >= 0 && std::find(nodes.begin(), nodes.end(), node) == nodes.end()) nodes.push_back(node);
  }
  for (int o = 0; o < outputs; ++o) prog.outputs.push_back(pick(nodes));
  prog.outputs.push_back(nodes[leaves.size()]);  // the first statement: live to the end
  return prog;
}

hamel::Kernel kernel_of(const std::vector<int>& outputs) {
  hamel::Kernel k;
  k.name = "f";
  k.outputs = outputs;
  for (std::size_t i = 0; i < outputs.size(); ++i) k.output_names.push_back("f" + std::to_string(i));
  return k;
}

// Runs the printed kernel `text` (the statement forms print_kernel writes) at x; fails the test on a line
// it does not know or on a name that is not in scope.
struct Interpreted {
  std::vector<double> out;
  std::map<int, int> statements_per_part;
  int slots = 0;       // size of v[] (0: not split)
  int slot_writes = 0;  // values passed between parts
};

Interpreted interpret(const std::string& text, const double* x, std::size_t n_out) {
  static const std::regex part_def(R"(^void f_part(\d+)\(.*\) \{$)");
  static const std::regex kernel_def(R"(^void f\(.*\) \{$)");
  static const std::regex local_def(R"(^  const real (w\d+) = (\S+)(?: ([-+*/]) (\S+))?;$)");
  static const std::regex slot_write(R"(^  v\[(\d+)\] = (w\d+);$)");
  static const std::regex slot_decl(R"(^  real v\[(\d+)\];$)");
  static const std::regex call(R"(^  f_part(\d+)\(t, x, p, in, v\);$)");
  static const std::regex output(R"(^  out\[(\d+)\] = (\S+);  // .*$)");
  std::map<int, std::vector<std::string>> parts;
  std::vector<std::string> main_body;
  std::vector<std::string>* current = nullptr;
  std::istringstream lines(text);
  std::string line;
  std::smatch m;
  Interpreted run;
  while (std::getline(lines, line)) {
    if (std::regex_match(line, m, part_def)) {
      current = &parts[std::stoi(m[1])];
    } else if (std::regex_match(line, m, kernel_def)) {
      current = &main_body;
    } else if (line == "}") {
      current = nullptr;
    } else if (current && line.rfind("  (void)", 0) != 0) {
      current->push_back(line);
    }
  }
  std::vector<double> v;
  run.out.assign(n_out, std::numeric_limits<double>::quiet_NaN());
  std::function<void(const std::vector<std::string>&, int)> execute = [&](const std::vector<std::string>& body,
                                                                         int part) {
    std::map<std::string, double> locals;
    std::function<double(const std::string&)> value = [&](const std::string& token) -> double {
      std::smatch t;
      if (token.size() > 1 && token[0] == '-') return -value(token.substr(1));
      if (std::regex_match(token, t, std::regex(R"(x\[(\d+)\])"))) return x[std::stoi(t[1])];
      if (std::regex_match(token, t, std::regex(R"(v\[(\d+)\])"))) return v.at(std::stoul(t[1]));
      if (std::regex_match(token, t, std::regex(R"(real\((.*)\))"))) return std::stod(t[1]);
      const auto it = locals.find(token);
      if (it == locals.end()) ADD_FAILURE() << "'" << token << "' is not in scope in part " << part;
      return it == locals.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
    };
    for (const std::string& l : body) {
      if (std::regex_match(l, m, local_def)) {
        const double a = value(m[2]);
        double r = a;
        if (m[3].matched) {
          const double b = value(m[4]);
          const char op = m[3].str()[0];
          r = op == '+' ? a + b : op == '-' ? a - b : op == '*' ? a * b : a / b;
        }
        locals[m[1]] = r;
        ++run.statements_per_part[part];
      } else if (std::regex_match(l, m, slot_write)) {
        v.at(std::stoul(m[1])) = value(m[2]);
        ++run.slot_writes;
      } else if (std::regex_match(l, m, slot_decl)) {
        run.slots = std::stoi(m[1]);
        v.assign(static_cast<std::size_t>(run.slots), std::numeric_limits<double>::quiet_NaN());
      } else if (std::regex_match(l, m, call)) {
        const int called = std::stoi(m[1]);
        EXPECT_TRUE(parts.count(called)) << l;
        if (parts.count(called)) execute(parts.at(called), called);
      } else if (std::regex_match(l, m, output)) {
        run.out.at(std::stoul(m[1])) = value(m[2]);
      } else {
        ADD_FAILURE() << "unexpected line: " << l;
      }
    }
  };
  execute(main_body, -1);
  return run;
}

TEST(SplitKernels, EveryPartSizeGivesTheGraphsValuesAndReusesSlots) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Program prog = random_program(seed, 150, 24);
    const hamel::Kernel k = kernel_of(prog.outputs);
    const double x[kInputs] = {0.9, -1.1, 0.4, 1.3};
    std::vector<double> expected(prog.outputs.size());
    hamel::GraphEvaluator evaluator(prog.graph, prog.outputs);
    evaluator.evaluate(0.0, x, nullptr, nullptr, expected.data());

    const Interpreted whole = interpret(hamel::kernel_text(prog.graph, k, kInputs, 0, 0, 0), x, prog.outputs.size());
    int statements = 0;
    for (const auto& [part, count] : whole.statements_per_part) statements += count;
    ASSERT_GT(statements, 40);
    EXPECT_EQ(whole.slots, 0);
    for (int size : {1, 2, 3, 7, 16, 50, statements - 1, statements, statements + 1}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", parts of " + std::to_string(size));
      const Interpreted split = interpret(hamel::kernel_text(prog.graph, k, kInputs, 0, 0, size), x, prog.outputs.size());
      for (std::size_t o = 0; o < expected.size(); ++o)
        EXPECT_EQ(split.out[o], expected[o]) << "output " << o;  // the same operations in the same order
      int total = 0;
      for (const auto& [part, count] : split.statements_per_part) {
        EXPECT_LE(count, size) << "part " << part;
        total += count;
      }
      EXPECT_EQ(total, statements);
      if (size >= statements) {
        EXPECT_EQ(split.slots, 0) << "a kernel of at most `size` statements is printed whole";
        EXPECT_EQ(whole.out, split.out);
      } else {
        EXPECT_EQ(static_cast<int>(split.statements_per_part.size()), (statements + size - 1) / size);
        EXPECT_GT(split.slots, 0);
        if (size <= 3) {
          EXPECT_LT(split.slots, split.slot_writes) << "slots are reused";
        }
      }
    }
  }
}

}  // namespace
