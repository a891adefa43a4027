// Outputs that are polynomials of degree ≤ 2 in the run-time arguments (t, x, in) with coefficients that depend
// on the parameters alone — the accelerations of a system whose mass matrix is constant, quadratic in the
// velocities — rewritten as Σ coefficient · monomial, dropping the coefficients that vanish identically. With
// the coefficients prepared once per parameter set (KernelSet::Prepared), what is left per call is what a
// generation-time inversion of a numeric mass matrix leaves: a product per non-zero coefficient.
#pragma once

#include "emit/expression_graph.hpp"

#include <vector>

namespace hamel {

/// Each output that is a polynomial of degree ≤ 2 in the inputs t, x and in (sums, products, negations and
/// divisions by parameter-only values) as Σ c_m · m over its monomials m with c_m not identically zero
/// (ZeroTest, emit/zero_test.hpp); other outputs unchanged.
std::vector<int> polynomial_form(ExpressionGraph& g, const std::vector<int>& outputs);

}  // namespace hamel
