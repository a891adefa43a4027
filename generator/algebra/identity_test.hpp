// Exact decisions on derived expressions that may use intermediate symbols (algebra/intermediates.hpp):
// "is this γ zero", "is T a quadratic form", "is A·B = I", "is L regular" — for expressions whose
// numerators and denominators contain parameters, without expanding the program into one formula.
//
// Schwartz–Zippel in the field Z/pZ, p = 2^61 − 1: after the trigonometric functions are read as
// points of the unit circle, every expression the generator builds is a rational function of the
// symbols. Each symbol gets a random residue, each angle θ a random point (cos θ, sin θ) =
// ((1 − τ²)/(1 + τ²), 2τ/(1 + τ²)) of the circle x² + y² = 1 over Z/pZ (1 + τ² ≠ 0 because p ≡ 3 mod 4),
// and sin/cos of an integer combination Σ k_i θ_i is the product of the points in the circle group, so
// sin² + cos² = 1 and the addition theorems hold exactly. Intermediates are evaluated through their
// definitions, once per point. A non-zero value proves "not identically zero"; zero at three independent
// points means zero with error probability below (D/p)³ for a rational function of total degree D.
// Square roots are algebraic elements (x^(j/2) = r^j for one root r of x). Expressions this cannot read
// (exp, a float, sin of a non-linear argument mixed with its expansion) answer `undecided`, and callers
// fall back to what they did before.
//
// The arithmetic is algebra/modular_arithmetic's Residue and its random points (RandomPoint, values drawn for the
// names of symbols and the printed text of angles, so a decision does not follow GiNaC's term order), the number
// type the IR's zero test (emit/zero_test, through emit/interpreter.hpp) computes in too. This test walks GiNaC
// expressions instead of the IR because it decides during the derivation, before any graph exists, on expressions
// whose coefficients are exact rationals (the graph holds doubles: 1/3 would not be 1/3), and because it must also
// answer "nonzero" soundly: a function it cannot relate to its argument makes it undecided, where the IR's test,
// which only ever answers "zero", reads it as a free variable.
#pragma once

#include "algebra/intermediates.hpp"

#include <ginac/ginac.h>

namespace hamel {

enum class Identity { zero, nonzero, undecided };

/// Is `e` identically zero as a function of the model's symbols (intermediates read through `program`)?
Identity identically_zero(const GiNaC::ex& e, const Intermediates& program);

/// Is det(m) identically zero? (Gaussian elimination modulo p at random points.)
Identity identically_singular(const GiNaC::matrix& m, const Intermediates& program);

/// True when det(m) is shown identically zero: by identically_singular() above, or where that cannot decide, by
/// is_zero_almost_surely (algebra/simplify.hpp) of the symbolic determinant (intermediates read as free symbols).
bool shown_singular(const GiNaC::matrix& m, const Intermediates& program);

/// True when `e` is shown identically zero: by identically_zero() above, or where that cannot decide,
/// by the normal form of simplify_bounded() (intermediates read as free symbols: "zero" is then still a
/// proof, "not zero" only means not shown).
bool shown_zero(const GiNaC::ex& e, const Intermediates& program);

}  // namespace hamel
