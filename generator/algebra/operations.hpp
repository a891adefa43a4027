// The operations of hamel's expressions, in one table (after CasADi's calculus.hpp): one entry per operation of the
// expression graph (emit/expression_graph.hpp) with how emitted C++ spells it and how tightly that binds, what an
// operation count counts it as, its derivative rule (the graph's forward-mode pass, `tangent`, reads it), and, for
// the elementary functions of the model language, their name in model files, their double evaluation
// (GraphEvaluator, constant folding) and their 50-digit evaluation (hamel accuracy's references). The parser, the
// graph, its passes, the printer and the accuracy module all read it, so an operation is added in one place.
#pragma once

#include <ginac/ginac.h>

#include <cstdint>
#include <string>
#include <vector>

namespace hamel {

enum class Op : std::uint8_t {
  constant,
  input,  // argument `array`, element `index`
  add,
  sub,
  mul,
  div,
  neg,
  sqrt,
  sin,
  cos,
  tan,
  exp,
  log,
  asin,
  acos,
  atan,
  sinh,
  cosh,
  tanh,
  abs,
  pow,
};

/// How a derivative rule forms its result: the node constructors of the graph being differentiated, behind an
/// interface so that the table does not depend on the graph (emit/expression_graph.cpp implements it). Terms are
/// the graph's node numbers.
class TermBuilder {
 public:
  virtual int constant(double value) = 0;
  virtual int unary(Op op, int a) = 0;
  virtual int binary(Op op, int a, int b) = 0;
  /// True, with its value as a double, when term `i` is a constant.
  virtual bool is_constant(int i, double& value) const = 0;

  int add(int a, int b) { return binary(Op::add, a, b); }
  int sub(int a, int b) { return binary(Op::sub, a, b); }
  int mul(int a, int b) { return binary(Op::mul, a, b); }
  int div(int a, int b) { return binary(Op::div, a, b); }
  int neg(int a) { return unary(Op::neg, a); }

 protected:
  ~TermBuilder() = default;
};

/// One operation y = op(a, b) under forward-mode differentiation: its operands, its result, and the tangents of its
/// operands (for an operation of one operand, b is -1 and db the term 0).
struct TangentOf {
  int a, b, y, da, db;
};

/// How an operation is written in emitted C++: between its operands (a + b), before its one operand (-a), or as a
/// call (std::sin(a), std::pow(a, b)).
enum class Notation : std::uint8_t { none, infix, prefix, call };

/// What an operation count (OpCounts, in every kernel's comment) counts an operation as.
enum class Cost : std::uint8_t { none, add, mul, div, call };

/// One operation of the expression graph.
struct Operation {
  Op op;
  int operands;       ///< 0 (constant, input), 1 or 2
  Notation notation;  ///< none for constant and input, which the printer names
  /// The operator as printed (" + ", "-" for negation), or the function called ("std::sin", "std::pow").
  const char* cpp;
  /// How tightly its printed expression binds: sums 1, products and quotients 2, a negation 3, a call 4 (names and
  /// literals bind like calls). The printer parenthesizes an operand that binds less tightly than the operation
  /// (a right operand also one that binds as tightly: C++ groups a - b - c as (a - b) - c).
  int binding;
  Cost cost;
  /// The tangent of y = op(a, b) from the operands' tangents, built through `terms`; nullptr for constant and input.
  int (*derivative)(TermBuilder& terms, const TangentOf& x);
  /// An elementary function of the model language: its name in model files (and GiNaC); nullptr for the others.
  const char* name;
  /// An elementary function's double evaluation (the arithmetic operations are evaluate_in's); nullptr otherwise.
  double (*evaluate)(double);
  /// An elementary function at the current GiNaC precision (Digits); throws std::domain_error outside the real
  /// domain (log of a non-positive number, asin/acos outside [−1, 1]). nullptr for the others.
  GiNaC::numeric (*evaluate_exactly)(const GiNaC::numeric&);
};

/// The entry of operation `op` (every Op has one).
const Operation& operation(Op op);

/// An elementary function of one argument: the table entry of an operation with a name in the model language.
using Function = Operation;

/// The elementary functions of the model language, in the order of Op.
const std::vector<Function>& functions();

/// The function named `name` (model-file spelling), or nullptr.
const Function* function_named(const std::string& name);

/// The function of operation `op`, or nullptr for an operation that is not one (add, pow, …).
const Function* function_of(Op op);

/// op(a, b) in the number type T: +, − and × (and negation) as T's operators, a / b as divide(a, b), a^b as
/// power(a, b) and any other operation (an elementary function of a; b unused) as function(op, a). The double
/// interpreter and the 50-digit one (numeric/kernel_accuracy) differ only in these three rules.
template <class T, class Divide, class Power, class ElementaryFunction>
T evaluate_in(Op op, const T& a, const T& b, Divide divide, Power power, ElementaryFunction function) {
  switch (op) {
    case Op::add:
      return a + b;
    case Op::sub:
      return a - b;
    case Op::mul:
      return a * b;
    case Op::neg:
      return -a;
    case Op::div:
      return divide(a, b);
    case Op::pow:
      return power(a, b);
    default:
      return function(op, a);
  }
}

/// op(a, b) in double: an arithmetic operation, pow, or an elementary function of a (b unused); throws
/// std::logic_error for constant and input, which are not operations.
double evaluate(Op op, double a, double b);

}  // namespace hamel
