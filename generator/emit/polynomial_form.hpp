// Outputs that are polynomials of degree ≤ 2 in the run-time arguments (t, x, in) with coefficients that depend
// on the parameters alone — the accelerations of a system whose mass matrix is constant, quadratic in the
// velocities — rewritten as Σ coefficient · monomial, dropping the coefficients that vanish identically. With
// the coefficients prepared once per parameter set (KernelSet::Prepared), what is left per call is what a
// generation-time inversion of a numeric mass matrix leaves: a product per non-zero coefficient.
#pragma once

#include "emit/expression_graph.hpp"

#include <array>
#include <memory>
#include <vector>

namespace hamel {

class ModularPoint;

/// "Is this parameter-only program identically zero?", decided exactly with high probability: its value
/// modulo the prime 2^61 − 1 at two random points of the parameters is 0 at both (Schwartz–Zippel; a non-zero
/// rational function of degree d vanishes at a random point with probability ≤ d / 2^61). Constants are the
/// doubles of the graph, read as the rationals they are. A program outside the rational functions (sqrt,
/// sin, …, a power with a non-integer exponent) or a division by a residue 0 counts as non-zero. Shares the
/// evaluations between calls.
class ParameterZeroTest {
 public:
  explicit ParameterZeroTest(const ExpressionGraph& g);
  ~ParameterZeroTest();
  bool operator()(int node);

 private:
  std::array<std::unique_ptr<ModularPoint>, 2> points_;
};

/// Each output that is a polynomial of degree ≤ 2 in the inputs t, x and in (sums, products, negations and
/// divisions by parameter-only values) as Σ c_m · m over its monomials m with c_m not identically zero
/// (ParameterZeroTest); other outputs unchanged.
std::vector<int> polynomial_form(ExpressionGraph& g, const std::vector<int>& outputs);

}  // namespace hamel
