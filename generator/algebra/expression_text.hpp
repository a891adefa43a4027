// Expressions as text for reports (derive output, error messages), in an order that depends only on the
// mathematics.
//
// GiNaC keeps the terms of a sum and the factors of a product sorted by hash values that include addresses (of its
// type-information strings, in the library and in the executable), and prints them in that order; it also leaves
// the sign of a sum to the algorithm that built it (normal() writes N/D or (−N)/(−D) by its term order). Printed by
// GiNaC, the same expression can read differently from run to run. These printers walk the expression themselves:
// - terms and factors are sorted by a structural key (kind, names, numbers and the keys of their operands, never a
//   hash), factors by their base first (l1^2*m2), terms by their monomials;
// - a sum that is a factor of a product, the base of an integer power or the argument of sin, cos or tan is written
//   with its first term positive, the sign moved out (sin(−x) = −sin x, cos(−x) = cos x, (−s)^n = (−1)^n s^n);
// - everything else is GiNaC's own notation: numbers, symbols, constants and function names are printed by GiNaC,
//   sums, products and powers with its operators, precedences and parentheses, so the text still reads back with
//   GiNaC's parser and the LaTeX is what GiNaC's print_latex writes.
#pragma once

#include <ginac/ginac.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>

namespace hamel {

/// GiNaC's default (parsable) notation of `e`, in the structural order above.
std::string to_text(const GiNaC::ex& e);

/// GiNaC's LaTeX notation of `e` (print_latex), in the structural order above; symbols are spelled by
/// `symbol_tex(name)`.
std::string to_latex(const GiNaC::ex& e, const std::function<std::string(const std::string&)>& symbol_tex);

/// The order of the printers above: true when `a` comes before `b` (never by a hash value, so the same in every
/// run). Expressions that print alike are equivalent; for algorithms whose result depends on the order in which
/// they visit expressions (the angles of algebra/contract_trig).
bool structurally_less(const GiNaC::ex& a, const GiNaC::ex& b);

/// structurally_less for many comparisons: keeps the canonical form of every expression it has compared.
class StructuralOrder {
 public:
  StructuralOrder();
  ~StructuralOrder();
  bool operator()(const GiNaC::ex& a, const GiNaC::ex& b);

 private:
  struct Forms;
  std::unique_ptr<Forms> forms_;
};

/// The shortest decimal spelling (15 to 17 significant digits) that reads back as exactly `value`.
inline std::string shortest_decimal(double value) {
  char buf[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

}  // namespace hamel
