#include "emit/statement_printer.hpp"

#include "algebra/expression_text.hpp"

#include <cmath>
#include <stdexcept>

namespace hamel {

namespace {

const char* argument_name(Argument a) {
  switch (a) {
    case Argument::time:
      return "t";
    case Argument::state:
      return "x";
    case Argument::parameter:
      return "p";
    case Argument::input:
      return "in";
  }
  return "";
}

// The right-hand side of node i's statement: an operand printed inside it (`inside`, by node) as its own expression,
// parenthesized where C++ would otherwise group it differently (a - (b + c), a * (b + c), a / (b * c), -(a * b): by
// the operation table's binding); any other operand by the name `name_of` gives it. C++ groups a + b + c as
// (a + b) + c, so the operations and their order are exactly those of one statement per node.
std::string statement_text(const ExpressionGraph& g, int i, const std::vector<char>& inside,
                           const std::function<std::string(int)>& name_of) {
  const Node& n = g.node(i);
  const Operation& op = operation(n.op);
  // Operand j, parenthesized when it binds no tighter than `needs`.
  const auto operand = [&](int j, int needs) {
    if (!inside[static_cast<std::size_t>(j)]) return name_of(j);
    const std::string text = statement_text(g, j, inside, name_of);
    return operation(g.node(j).op).binding <= needs ? "(" + text + ")" : text;
  };
  switch (op.notation) {
    case Notation::infix:
      return operand(n.a, op.binding - 1) + op.cpp + operand(n.b, op.binding);
    case Notation::prefix:
      return op.cpp + operand(n.a, op.binding);
    case Notation::call:
      return op.cpp + ("(" + operand(n.a, 0)) + (op.operands == 2 ? ", " + operand(n.b, 0) : std::string()) + ")";
    case Notation::none:
      break;
  }
  throw std::logic_error("statement_text: node " + std::to_string(i) + " is not an operation");
}

}  // namespace

std::string real_literal(double v) {
  if (std::isnan(v)) return "real(NAN)";
  if (std::isinf(v)) return v > 0 ? "real(HUGE_VAL)" : "real(-HUGE_VAL)";
  std::string s = shortest_decimal(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return "real(" + s + ")";
}

std::string stage_array(int stage) { return "s" + std::to_string(stage); }
std::string layout_array(int unit) { return "m" + std::to_string(unit); }
std::string value_array(const StageValue& at) {
  return at.layout >= 0 ? layout_array(at.layout) : stage_array(at.stage);
}

StatementPrinter::StatementPrinter(const ExpressionGraph& g, const StatementSchedule& schedule, const Kernel& kernel,
                                   const Destination& destination, const StageReads* reads)
    : g_(g), s_(schedule), k_(kernel), d_(destination), reads_(reads) {}

std::string StatementPrinter::print(const std::vector<Step>& steps, int part, Usage& usage) {
  std::string text;
  for (const Step& step : steps) {
    const int first = step.lane >= 0 ? step.lane : 0, end = step.lane >= 0 ? step.lane + 1 : d_.lanes;
    for (lane_ = first; lane_ < end; ++lane_) text += line(step, part, usage);
  }
  lane_ = 0;
  return text;
}

std::string StatementPrinter::line(const Step& step, int part, Usage& usage) const {
  const int i = step.node;
  switch (step.kind) {
    case Step::Kind::compute:
      return "  const real " + local(i) + " = " +
             statement_text(g_, i, s_.inside, [&](int j) { return name(j, part, usage); }) + ";\n";
    case Step::Kind::pass:
      usage.wrote.insert("v");
      return "  " + passed(i) + " = " + local(i) + ";\n";
    case Step::Kind::write:
      break;
  }
  const std::size_t o = step.output * static_cast<std::size_t>(d_.lanes) + static_cast<std::size_t>(lane_);
  const std::string to = d_.target(o);
  usage.wrote.insert(to.substr(0, to.find('[')));
  return "  " + to + " = " + name(i, part, usage) + ";  // " + k_.output_names[o] + "\n";
}

// Node i where function `part` reads it: a leaf in place, a statement of its own by its local, one of another part
// from v[].
std::string StatementPrinter::name(int i, int part, Usage& usage) const {
  if (s_.leaf[static_cast<std::size_t>(i)]) return leaf(i, usage);
  if (s_.part[static_cast<std::size_t>(i)] == part) return local(i);
  usage.wrote.insert("v");
  return passed(i);
}

// A leaf as the lane being printed reads it: the program's x[k] is x[k·lanes + lane].
std::string StatementPrinter::leaf(int i, Usage& usage) const {
  const Node& n = g_.node(i);
  if (reads_) {
    const auto given = reads_->value.find(i);
    if (given != reads_->value.end()) {
      usage.read.insert(value_array(given->second));
      return value_array(given->second) + "[" + std::to_string(given->second.position) + "]";
    }
  }
  if (n.op == Op::constant) return real_literal(n.value);
  usage.arguments[static_cast<int>(n.argument)] = true;
  if (n.argument == Argument::time) return "t";
  const int index = d_.lanes > 1 && n.argument == Argument::state ? n.index * d_.lanes + lane_ : n.index;
  return std::string(argument_name(n.argument)) + "[" + std::to_string(index) + "]";
}

std::string StatementPrinter::local(int i) const {
  return "w" + std::to_string(s_.local.at(i)) + (d_.lanes > 1 ? "_" + std::to_string(lane_) : std::string());
}

std::string StatementPrinter::passed(int i) const {
  return "v[" + std::to_string(s_.parts.slot.at(i) * d_.lanes + lane_) + "]";
}

}  // namespace hamel
