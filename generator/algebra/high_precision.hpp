// Numbers in high precision (50 digits for hamel accuracy's references): one of the number types hamel evaluates
// expressions in, with double (algebra/operations.hpp) and residues modulo a prime (algebra/modular_arithmetic.hpp).
// Values are CLN reals (cln::cl_R, what a real GiNaC::numeric holds), computed with the operations GiNaC::numeric
// calls for +, −, ×, /, integer powers and abs, so the results are those of GiNaC::numeric without its wrapping of
// every intermediate value; the precision is GiNaC::Digits when an operation runs.
//
// The IR's interpreter in this number type is numeric/graph_evaluator's HighPrecisionGraphEvaluator (the same
// operation rules, HighPrecision::operation). HighPrecisionExpressionEvaluator below evaluates GiNaC expressions
// instead, and must: it is the reference the graph is measured against (numeric/kernel_accuracy), so it may share
// the number type but not the graph — it reads the derivation's exact rationals and functions where the graph holds
// doubles and folded constants — and it serves the values `derive --at` prints, which are the expressions' own.
#pragma once

#include "algebra/intermediates.hpp"
#include "algebra/operations.hpp"

#include <cln/real.h>
#include <ginac/ginac.h>

#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

namespace hamel {

class StructuralOrder;

/// The value of a finite double as an exact GiNaC rational.
GiNaC::numeric exact_rational(double v);

/// A finite double as a CLN float with the current GiNaC::Digits (exact: doubles have 53 bits).
GiNaC::numeric high_precision(double v);

/// The operations of evaluate_in (algebra/operations.hpp) on cln::cl_R at the current GiNaC::Digits. A division by
/// zero, 0 to a negative power, a fractional power of a negative number and a function outside its real domain
/// throw std::domain_error.
struct HighPrecision {
  using Value = cln::cl_R;
  static Value of(const GiNaC::numeric& v);  ///< a real number (a complex one: std::logic_error)
  static GiNaC::numeric numeric_of(const Value& v);
  static Value constant(double v);  ///< exactly, as a float of the current precision
  static Value divide(const Value& a, const Value& b);
  /// base^exponent for an exact exponent (an integer power is exact repeated squaring).
  static Value power(const Value& base, const GiNaC::numeric& exponent);
  static Value power(const Value& base, const Value& exponent);
  /// An elementary function of the model language (algebra/operations.hpp).
  static Value function(Op f, const Value& x);
  static Value operation(Op op, const Value& a, const Value& b) {
    return evaluate_in<Value>(
        op, a, b, divide, [](const Value& x, const Value& y) { return power(x, y); }, function);
  }
};

/// Evaluates GiNaC expressions numerically with `digits` decimal digits at given symbol values. Understands
/// numbers, symbols, constants (Pi), sums, products, powers and the functions the emitter knows (sin … tanh,
/// abs, sqrt); throws std::domain_error at a pole and std::logic_error for anything else.
/// An expression is compiled once, when first asked for, into numbered nodes (one per distinct
/// subexpression, intermediates through their definitions); each set of values then evaluates every node it
/// needs once, by number, so repeated points cost arithmetic only, not hashing and comparing expressions.
/// The terms of a sum and the factors of a product are added and multiplied in structural order
/// (algebra/expression_text.hpp), not in GiNaC's, which follows hash values that include addresses: the rounded
/// results are the same in every run.
class HighPrecisionExpressionEvaluator {
 public:
  explicit HighPrecisionExpressionEvaluator(int digits = 50);
  ~HighPrecisionExpressionEvaluator();
  /// Sets symbol values (numbers converted to floats at the evaluator's precision); forgets computed values.
  void assign(const std::map<GiNaC::ex, GiNaC::numeric, GiNaC::ex_is_less>& values);
  /// Intermediate symbols (algebra/intermediates.hpp) are evaluated through their definitions.
  void define(const Intermediates& intermediates);
  GiNaC::numeric value(const GiNaC::ex& e);
  /// The expression evaluated with every sum taken over the absolute values of its terms (and products,
  /// positive powers and arguments of functions likewise; divisors and function values at their true
  /// values): the size of what is added, the scale below which a result is cancellation noise.
  GiNaC::numeric magnitude(const GiNaC::ex& e);

 private:
  enum class Kind { number, symbol, constant, add, mul, power, function };
  struct Node {
    Kind kind;
    std::vector<int> operands;  ///< node numbers (power: base, exponent)
    GiNaC::ex expression;       ///< number, symbol, constant, or the function (for its name)
    const Function* function = nullptr;
    cln::cl_R number;  ///< a number's exact value
  };
  int compile(const GiNaC::ex& e);
  const cln::cl_R& eval(int node, bool absolute);
  struct Hash {
    std::size_t operator()(const GiNaC::ex& e) const { return e.gethash(); }
  };
  int digits_;
  std::map<GiNaC::ex, cln::cl_R, GiNaC::ex_is_less> values_;
  std::map<GiNaC::ex, GiNaC::ex, GiNaC::ex_is_less> definitions_;
  std::unordered_map<GiNaC::ex, int, Hash, GiNaC::ex_is_equal> number_;  ///< compiled expressions
  std::vector<Node> nodes_;
  std::vector<cln::cl_R> computed_[2];  ///< per node: true value, magnitude
  std::vector<unsigned> stamp_[2];      ///< computed_ holds this set of values' result when == generation_
  unsigned generation_ = 1;
  std::unique_ptr<StructuralOrder> order_;
};

}  // namespace hamel
