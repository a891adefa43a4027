// The operations of hamel's expressions, in one table: the scalar operations of the expression graph
// (emit/expression_graph.hpp) and, for the elementary functions of the model language, their name in model
// files, their C++ spelling in emitted code, their double evaluation (GraphEvaluator, constant folding) and
// their 50-digit evaluation (hamel accuracy's references). The parser, the graph, the printer and the
// accuracy module all read it, so a function is added in one place.
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

/// An elementary function of one argument.
struct Function {
  const char* name;  ///< in model files (and GiNaC)
  Op op;
  const char* cpp;  ///< in emitted code (<cmath>)
  double (*evaluate)(double);
  /// At the current GiNaC precision (Digits); throws std::domain_error outside the real domain (log of a
  /// non-positive number, asin/acos outside [−1, 1]).
  GiNaC::numeric (*evaluate_exactly)(const GiNaC::numeric&);
};

/// The elementary functions of the model language, in a fixed order.
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
