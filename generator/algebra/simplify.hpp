// Exact simplification and zero testing of expressions built from rational functions of symbols and of
// sin/cos of their integer combinations. GiNaC's normal() does not know sin² + cos² = 1; we rewrite
// sin/cos of sums and integer multiples into those of single angles, name sin(θ) = S and cos(θ) = C,
// bring the expression to one fraction, and reduce numerator and denominator modulo S² + C² − 1
// (each S^k with k ≥ 2 becomes S^(k mod 2) (1 − C²)^(k div 2)). With the S < C order this is a normal
// form, so a numerator that reduces to 0 proves the expression zero: zero detection is exact.
#pragma once

#include <ginac/ginac.h>

namespace hamel {

/// sin, cos and tan of a sum or an integer multiple rewritten in sin and cos of the summands/angle.
GiNaC::ex expand_trig(const GiNaC::ex& e);

/// Normal form of `e`: one fraction, trigonometric polynomials reduced with sin² + cos² = 1.
GiNaC::ex simplify(const GiNaC::ex& e);

/// Exact test: true iff `e` simplifies to 0 (not a numerical test).
bool is_zero_exactly(const GiNaC::ex& e);

/// Applies simplify() to every entry.
GiNaC::matrix simplify(const GiNaC::matrix& m);

}  // namespace hamel
