// Printing expressions: the normal form of simplify() writes sin/cos of multiple and sum angles in sin and cos of
// single angles (sin(3t) = 4 sin t cos² t − sin t, cos(2ψ) = 2 cos² ψ − 1) because that makes cancellations exact
// for the derivation and the emitted kernels. For the reader, contract_trig() rewrites the trigonometric
// polynomials of an expression back into multiple and sum angles where that is shorter.
#pragma once

#include <ginac/ginac.h>

namespace hamel {

/// `e` with its trigonometric polynomials contracted to multiple and sum angles where the result has fewer nodes
/// (node_count, which does not count signs). In every sum the terms are grouped by the angles of their sin/cos factors,
/// and each group is written as it is, with the coefficients of equal monomials collected, or linearized
/// (product-to-sum: Σ c_k cos(k·θ) + s_k sin(k·θ) over integer combinations k·θ of the angles, collected with the terms
/// free of sin/cos, so that sin²ψ + cos²ψ − 1 becomes 0), whichever gives the shortest sum; a single product only when
/// its monomial has degree ≥ 2 (2 sin t cos t → sin(2t)). Every step is a trigonometric identity: the result equals `e`
/// exactly. An expression with nothing shorter to offer is returned unchanged (the same GiNaC object). For display
/// only: the derivation and the emitted code keep the normal form of simplify().
GiNaC::ex contract_trig(const GiNaC::ex& e);

}  // namespace hamel
