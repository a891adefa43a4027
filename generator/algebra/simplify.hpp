// Exact simplification and zero testing of expressions built from rational functions of symbols and of
// sin/cos of their integer combinations. GiNaC's normal() does not know sin² + cos² = 1; we rewrite
// sin/cos of sums and integer multiples into those of single angles, name sin(θ) = S and cos(θ) = C,
// bring the expression to one fraction, and reduce numerator and denominator modulo S² + C² − 1
// (each S^k with k ≥ 2 becomes S^(k mod 2) (1 − C²)^(k div 2)). With the S < C order this is a normal
// form, so a numerator that reduces to 0 proves the expression zero: zero detection is exact.
#pragma once

#include <ginac/ginac.h>

#include <vector>

namespace hamel {

/// sin, cos and tan of a sum or an integer multiple rewritten in sin and cos of the summands/angle.
GiNaC::ex expand_trig(const GiNaC::ex& e);

/// Normal form of `e`: one fraction, trigonometric polynomials reduced with sin² + cos² = 1. Where `e` holds a
/// power of a sum (b^n, |n| >= 2) and its normal form grew beyond `e`, the fraction with those powers kept whole
/// is made too and the smaller of the two (in nodes) returned, the normal form on a tie: an expanded power loses
/// accuracy near a root of its base. Zero is always found (the normal form is canonical up to sign).
/// The sign is GiNaC's: normal() writes N/D or (−N)/(−D), and a product keeps a sum S or −S, by its term order,
/// which follows hash values that include addresses. No GiNaC object can pin it (a product re-chooses the sign of
/// a sum factor when it is built), so nothing that reads the result may depend on it: node_count (the size tests)
/// does not count signs, the IR (emit/expression_graph) and the printers (algebra/expression_text) place them
/// structurally, and the evaluators compute −(−x) exactly.
GiNaC::ex simplify(const GiNaC::ex& e);

/// e.expand(), except where `e` holds a power of a sum (b^n, |n| >= 2) and its expansion grew beyond `e`: then
/// the expansion with those powers kept whole is made too and the smaller (in nodes) returned, the full expansion
/// on a tie. simplify()'s rule, for the same reason (an expanded b^n loses accuracy near a root of b), where an
/// expansion, not a normal form, is wanted: the kinematic tree's products of the bodies' mass, centre of mass,
/// inertia, offsets and rotations and its inlined kinetic energy (a body mass "(m+1)^20" became 21 monomials).
GiNaC::ex expand_keeping_powers_of_sums(const GiNaC::ex& e);

/// Zero test without a program of intermediates, exact except for a negligible chance of a wrong "zero": a
/// 50-digit evaluation at two fixed points first answers "not zero" when the value is clearly away from 0
/// (numerically_nonzero); otherwise the modular identity test (algebra/identity_test.hpp, identically_zero with no
/// intermediates) decides, and where it cannot (functions other than sin, cos, tan and square roots), the normal
/// form of simplify(), which does not see every identity of such functions.
bool is_zero_almost_surely(const GiNaC::ex& e);

/// True when a 50-digit evaluation (algebra/high_precision.hpp) at one of two fixed points is clearly non-zero
/// (|v| > 1e-25): then e is certainly not identically zero. False says nothing. Each symbol's value at a point is a
/// function of its name.
bool numerically_nonzero(const GiNaC::ex& e);

/// The number of nodes of e's expression tree, counted up to a little past `limit`, without its signs: a factor −1
/// and the product −x it leaves are not counted. The derivation's size thresholds and the printed forms
/// contract_trig chooses between use this count, so they do not depend on where GiNaC puts a sign (N/D or
/// (−N)/(−D), −x·y or (−x)·y, a sum factor or its negative), which follows its term order and so the address
/// layout.
std::size_t node_count(const GiNaC::ex& e, std::size_t limit);

/// simplify(e) when e is small (at most `limit` nodes); a large e that the modular identity test shows zero becomes
/// 0; other large expressions are left as derived: their normal form costs more than it saves (the emitted code
/// shares subexpressions anyway).
GiNaC::ex simplify_bounded(const GiNaC::ex& e, std::size_t limit = 400);

/// `e` as a polynomial of degree at most 2 in `variables` (the velocities of an equation of motion), written
/// as Σ c_m · m over the monomials m, found by distributing sums over products (velocity-free parts stay
/// whole), each coefficient c_m passed through simplify_bounded(c_m, limit / 8). Collecting the monomials
/// in exact arithmetic removes the cancellation a large unsimplified expression leaves to double
/// arithmetic (products of sums whose expansion cancels: up to 4e4 ulps in the shipped models, see
/// docs/accuracy.md). Normal forms of larger coefficients cost derivation time and bought no accuracy on
/// the planar space robot, so those are only tested for zero. If `e` is not such a polynomial (a velocity
/// in a divisor or a function), simplify_bounded(e, limit).
GiNaC::ex simplify_quadratic_form(const GiNaC::ex& e, const std::vector<GiNaC::ex>& variables, std::size_t limit = 400);

/// Applies simplify() to every entry.
GiNaC::matrix simplify(const GiNaC::matrix& m);

}  // namespace hamel
