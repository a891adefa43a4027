// Long kernels printed in parts (emit --split N): every part has at most N operations, values cross parts in
// the stack array v[] (outputs go to out[] from the part that computes them), and a slot is reused once its value
// has been read for the last time. The printed text is run by a small interpreter of its statements (locals
// scoped to their part, v[] starting as NaN, so a value read after its slot was reused or read from another
// part's locals shows up) and compared with the generator's own evaluation of the graph (GraphEvaluator), for
// random programs and every part size from 1. Its expressions are grouped as C++ groups them, so a statement printed
// inside its reader with a missing pair of parentheses gives another value.
#include "emit/expression_graph.hpp"
#include "emit/kernel_printer.hpp"
#include "numeric/graph_evaluator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using hamel::Argument;
using hamel::ExpressionGraph;
using hamel::Op;

constexpr int kInputs = 4;

// A random program: `statements` nodes, each an add, sub, mul, div or negation of earlier nodes (most products and
// quotients take an input or a constant as one operand, so values stay finite), and `outputs` outputs among them,
// early ones included.
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
    const int kind = std::uniform_int_distribution<int>(0, 7)(rng);
    const int a = pick(nodes);
    int node;
    if (kind == 7) {
      node = g.unary(Op::neg, a);
    } else {
      const Op op = kind <= 1 ? Op::add : kind <= 3 ? Op::sub : kind <= 5 ? Op::mul : Op::div;
      // A product of two statements, or a quotient by one, now and then: the printed text then needs a * (b + c).
      const bool any = op == Op::add || op == Op::sub || kind == 5 || (op == Op::div && a % 2 == 0);
      node = g.binary(op, a, any ? pick(nodes) : pick(leaves));
    }
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
  std::map<int, int> statements_per_part;  // operations of the printed statements, by part (-1: not split)
  int lines = 0;                           // statements printed (locals)
  int slots = 0;                           // size of v[] (0: not split)
  int slot_writes = 0;                     // values passed between parts
  std::map<int, int> copies_per_part;      // out[k] = <leaf or v[]> lines, by part (-1: the kernel itself)
};

bool starts(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool ends(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}
// The number in "name[k]" or "name[k];".
std::size_t subscript(const std::string& s) {
  return static_cast<std::size_t>(std::stoul(s.substr(s.find('[') + 1, s.find(']') - s.find('[') - 1)));
}
std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string word; in >> word;) w.push_back(word);
  return w;
}

// One printed expression, evaluated as C++ groups it: sums of products of factors, left to right; a factor is a
// name, a literal, a negated factor or a parenthesized sum. `operations` counts what it executes.
struct Expression {
  const std::string& text;
  std::size_t at;
  std::function<double(const std::string&)> value;  // of a name or literal
  int operations = 0;

  void blanks() {
    while (at < text.size() && text[at] == ' ') ++at;
  }
  double factor() {
    blanks();
    if (text[at] == '-') {
      ++at;
      ++operations;
      return -factor();
    }
    if (text[at] == '(') {
      ++at;
      const double inner = sum();
      blanks();
      EXPECT_EQ(text[at], ')') << text;
      ++at;
      return inner;
    }
    const std::size_t begin = at;
    // A name, x[k], v[k] or real(literal): up to the next blank or closing parenthesis outside its own brackets.
    int depth = 0;
    while (at < text.size() && !(depth == 0 && (text[at] == ' ' || text[at] == ')'))) {
      if (text[at] == '(' || text[at] == '[') ++depth;
      if (text[at] == ')' || text[at] == ']') --depth;
      ++at;
    }
    return value(text.substr(begin, at - begin));
  }
  double product() {
    double r = factor();
    for (blanks(); at < text.size() && (text[at] == '*' || text[at] == '/'); blanks()) {
      const char op = text[at++];
      const double b = factor();
      ++operations;
      r = op == '*' ? r * b : r / b;
    }
    return r;
  }
  double sum() {
    double r = product();
    for (blanks(); at < text.size() && (text[at] == '+' || text[at] == '-'); blanks()) {
      const char op = text[at++];
      const double b = product();
      ++operations;
      r = op == '+' ? r + b : r - b;
    }
    return r;
  }
};

// (Parsed by hand: GCC 12's <regex> trips -Wmaybe-uninitialized in the sanitized build.)
Interpreted interpret(const std::string& text, const double* x, std::size_t n_out) {
  std::map<int, std::vector<std::string>> parts;
  // The function calling the parts: f, or when the parts pass values, f_work (v[] in the caller's work space), which
  // f calls with its stack array (`wrapper`).
  std::vector<std::string> main_body, wrapper, work_body;
  std::vector<std::string>* current = nullptr;
  std::istringstream lines(text);
  std::string line;
  Interpreted run;
  while (std::getline(lines, line)) {
    const std::string out_of_line = "HAMEL_NOINLINE ";  // a long function kept out of line
    if (starts(line, out_of_line)) line = line.substr(out_of_line.size());
    if (starts(line, "void f_part") && ends(line, ") {")) {
      current = &parts[std::stoi(line.substr(11, line.find('(') - 11))];
    } else if (starts(line, "void f(") && ends(line, ") {")) {
      current = &main_body;
    } else if (starts(line, "void f_work(") && ends(line, ", real* work) {")) {
      current = &work_body;
    } else if (line == "}") {
      current = nullptr;
    } else if (current && !starts(line, "  (void)")) {
      current->push_back(line);
    }
  }
  std::vector<double> v;
  run.out.assign(n_out, std::numeric_limits<double>::quiet_NaN());
  if (!work_body.empty()) {
    // f declares the array and passes it on: `real work[n];` and `f_work(t, x, p, in, out, work);`, nothing else.
    wrapper = main_body;
    main_body = work_body;
    EXPECT_EQ(wrapper.size(), 2u);
    if (wrapper.size() == 2) {
      const std::vector<std::string> w = words(wrapper[0]);
      EXPECT_TRUE(w.size() == 2 && w[0] == "real" && starts(w[1], "work[") && ends(w[1], "];")) << wrapper[0];
      if (w.size() == 2 && starts(w[1], "work[")) {
        run.slots = static_cast<int>(subscript(w[1]));
        v.assign(static_cast<std::size_t>(run.slots), std::numeric_limits<double>::quiet_NaN());
      }
      EXPECT_EQ(wrapper[1], "  f_work(t, x, p, in, out, work);");
    }
  }
  std::function<void(const std::vector<std::string>&, int)> execute = [&](const std::vector<std::string>& body,
                                                                          int part) {
    std::map<std::string, double> locals;
    const auto value = [&](const std::string& token) -> double {
      if (starts(token, "x[")) return x[subscript(token)];
      if (starts(token, "v[")) return v.at(subscript(token));
      if (starts(token, "real(")) return std::stod(token.substr(5));
      const auto it = locals.find(token);
      if (it == locals.end()) ADD_FAILURE() << "'" << token << "' is not in scope in part " << part;
      return it == locals.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
    };
    for (const std::string& l : body) {
      const std::vector<std::string> w = words(l);
      if (!starts(l, "  ") || w.empty()) {
        ADD_FAILURE() << "unexpected line: " << l;
      } else if (w.size() >= 5 && w[0] == "const" && w[1] == "real" && w[3] == "=" && ends(l, ";")) {
        const std::string expression = l.substr(l.find(" = ") + 3, l.size() - l.find(" = ") - 4);
        Expression e{expression, 0, value};
        locals[w[2]] = e.sum();
        EXPECT_EQ(e.at, expression.size()) << "not one expression: " << l;
        EXPECT_LE(e.operations, hamel::kOperationsPerStatement) << l;
        run.statements_per_part[part] += e.operations;
        ++run.lines;
      } else if (w.size() == 3 && starts(w[0], "v[") && w[1] == "=" && starts(w[2], "w") && ends(w[2], ";")) {
        v.at(subscript(w[0])) = value(w[2].substr(0, w[2].size() - 1));
        ++run.slot_writes;
      } else if (l == "  real* const v = work;") {
        EXPECT_GT(run.slots, 0) << "v[] in a work space of no size";
      } else if (starts(l, "  f_part") &&
                 (ends(l, "(t, x, p, in, v, out);") || ends(l, "(t, x, p, in, nullptr, out);"))) {
        if (ends(l, "nullptr, out);")) {
          EXPECT_EQ(run.slots, 0) << "v[] declared and not passed: " << l;
        }
        const int called = std::stoi(l.substr(8, l.find('(') - 8));
        EXPECT_TRUE(parts.count(called)) << l;
        if (parts.count(called)) execute(parts.at(called), called);
      } else if (w.size() >= 4 && starts(w[0], "out[") && w[1] == "=" && ends(w[2], ";") && w[3] == "//") {
        const std::string from = w[2].substr(0, w[2].size() - 1);
        run.out.at(subscript(w[0])) = value(from);
        if (starts(from, "x[") || starts(from, "v[") || starts(from, "real(")) ++run.copies_per_part[part];
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
    for (double e : expected)
      ASSERT_TRUE(std::isfinite(e)) << "seed " << seed << ": the comparison needs finite values";

    const Interpreted whole = interpret(hamel::kernel_text(prog.graph, k, kInputs, 0, 0, 0), x, prog.outputs.size());
    int statements = 0;
    for (const auto& [part, count] : whole.statements_per_part) statements += count;
    ASSERT_GT(statements, 40);
    EXPECT_LT(whole.lines, statements) << "single-use statements are printed inside their readers";
    EXPECT_EQ(whole.slots, 0);
    for (int size : {1, 2, 3, 7, 16, 50, statements - 1, statements, statements + 1}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", parts of " + std::to_string(size));
      const std::string text = hamel::kernel_text(prog.graph, k, kInputs, 0, 0, size);
      const Interpreted split = interpret(text, x, prog.outputs.size());
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
        const int parts = (statements + size - 1) / size;
        EXPECT_EQ(static_cast<int>(split.statements_per_part.size()), parts);
        // The parts of a kernel split in more than two are kept out of line (g++ would inline them back).
        std::size_t outlined = 0;
        for (std::size_t at = text.find("HAMEL_NOINLINE void f_part"); at != std::string::npos;
             at = text.find("HAMEL_NOINLINE void f_part", at + 1))
          ++outlined;
        EXPECT_EQ(outlined, static_cast<std::size_t>(parts > 2 ? parts : 0));
        EXPECT_GT(split.slots, 0);
        if (size <= 3) {
          EXPECT_LT(split.slots, split.slot_writes) << "slots are reused";
        }
      }
    }
  }
}

// Outputs that are leaves (constants, inputs) are copied in after the parts, in blocks of at most 128 per function
// when there are more (g++'s time on a run of stores grows about with the square of its length): the 30-joint
// chain's Jacobian has 1 984 constant entries. Every output still gets the graph's value, and parts that compute
// keep their sizes.
TEST(SplitKernels, ManyLeafOutputsAreCopiedInBlocks) {
  Program prog = random_program(7, 150, 24);
  std::vector<int> outputs = prog.outputs;
  for (int k = 0; k < 300; ++k)
    outputs.push_back(k % 3 == 0 ? prog.graph.input(Argument::state, k % kInputs)
                                 : prog.graph.constant(k % 3 == 1 ? 0.0 : 1.0 + k));
  const hamel::Kernel k = kernel_of(outputs);
  const double x[kInputs] = {0.9, -1.1, 0.4, 1.3};
  std::vector<double> expected(outputs.size());
  hamel::GraphEvaluator evaluator(prog.graph, outputs);
  evaluator.evaluate(0.0, x, nullptr, nullptr, expected.data());
  for (int size : {7, 50}) {
    SCOPED_TRACE("parts of " + std::to_string(size));
    const std::string text = hamel::kernel_text(prog.graph, k, kInputs, 0, 0, size);
    const Interpreted split = interpret(text, x, outputs.size());
    for (std::size_t o = 0; o < expected.size(); ++o) EXPECT_EQ(split.out[o], expected[o]) << "output " << o;
    int copies = 0;
    for (const auto& [part, count] : split.copies_per_part) {
      EXPECT_NE(part, -1) << "the kernel itself copies no outputs";
      EXPECT_LE(count, 128) << "part " << part;
      EXPECT_EQ(split.statements_per_part.count(part), 0U) << "part " << part << " computes and copies";
      copies += count;
    }
    EXPECT_EQ(copies, 300);
    EXPECT_EQ(split.copies_per_part.size(), 3U) << "300 copies in three blocks of 100";
    for (const auto& [part, count] : split.statements_per_part) EXPECT_LE(count, size) << "part " << part;
  }
}

// Parts that pass no values to later parts (every output its own short computation) are given a null pointer for
// v[] and the kernel declares no array for it (it declared real v[1] before).
TEST(SplitKernels, PartsThatPassNothingDeclareNoArray) {
  ExpressionGraph g;
  std::vector<int> outputs;
  for (int k = 0; k < 12; ++k)
    outputs.push_back(g.binary(Op::add, g.binary(Op::mul, g.input(Argument::state, k % kInputs), g.constant(1.5 + k)),
                               g.input(Argument::state, (k + 1) % kInputs)));
  const hamel::Kernel k = kernel_of(outputs);
  const double x[kInputs] = {0.9, -1.1, 0.4, 1.3};
  std::vector<double> expected(outputs.size());
  hamel::GraphEvaluator evaluator(g, outputs);
  evaluator.evaluate(0.0, x, nullptr, nullptr, expected.data());
  const std::string text = hamel::kernel_text(g, k, kInputs, 0, 0, 4);
  const Interpreted split = interpret(text, x, outputs.size());
  EXPECT_GT(split.statements_per_part.size(), 2U) << text;
  EXPECT_EQ(split.slots, 0);
  EXPECT_EQ(split.slot_writes, 0);
  EXPECT_EQ(text.find("real v["), std::string::npos) << text;
  EXPECT_NE(text.find("f_part0(t, x, p, in, nullptr, out);"), std::string::npos) << text;
  for (std::size_t o = 0; o < expected.size(); ++o) EXPECT_EQ(split.out[o], expected[o]) << "output " << o;
}

}  // namespace
