// M X = B for a symmetric positive definite M by M = L D Lᵀ (unit lower L) without pivoting or square roots
// (Golub & Van Loan, Algorithm 4.1.2), generic in the scalar: straight-line code, no loops or branches reach an
// emitted kernel. The one LDLᵀ of the generator: the mass matrix's solve in the kernels (graph nodes), the
// connection 𝒜 = L⁻¹K of eq. (mechConn) and the Christoffel symbols of the Riemannian view in the derivation
// (GiNaC expressions through intermediates), and the floating base's block of the articulated-body algorithm.
#pragma once

#include "rbd/spatial.hpp"

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

namespace hamel::rbd {

/// How the factorization and the substitutions name and arrange what they compute.
template <class S>
struct LdltOptions {
  /// Names the pivots d_j, the factors L_ij, the forward substitution's y_i and the solution's x_i (identity for
  /// graph nodes; Intermediates::keep or define for expressions).
  Namer<S> pivot = Namer<S>::identity(), factor = Namer<S>::identity(), forward = Namer<S>::identity(),
           solution = Namer<S>::identity();
  /// Each term of the elimination, L_ik d_k L_jk, as (the numerator of L_ik) · L_jk: one multiplication when the
  /// numerator is a value of its own (graph nodes). Otherwise L_ik · d_k · L_jk (named factors and pivots).
  bool numerator_products = false;
  /// Where 1/d_j is formed and multiplied by instead of dividing by d_j: nowhere, in the back substitution (one
  /// division per pivot for many right-hand sides), or also in the factorization (named with the pivot).
  enum class Reciprocal { none, substitution, everywhere } reciprocal = Reciprocal::none;
  /// Eliminates from the last index down (M = LᵀDL): for the mass matrix of a kinematic tree, whose bodies come
  /// after their parents, that creates no fill-in, so bodies on different branches stay zero and cost nothing.
  bool last_first = false;
};

template <class S>
struct LdltFactor {
  std::vector<std::vector<S>> L;  ///< unit lower triangle (below the diagonal)
  std::vector<S> d;               ///< the pivots: all positive iff M is positive definite
  std::vector<S> inverse_d;       ///< 1/d_i unless Reciprocal::none
};

/// The factor of M (natural order; last_first is applied by ldlt_solve).
template <class S>
LdltFactor<S> ldlt_factor(const std::vector<std::vector<S>>& M, const LdltOptions<S>& o) {
  const std::size_t n = M.size();
  LdltFactor<S> F{std::vector<std::vector<S>>(n, std::vector<S>(n, S(0))), std::vector<S>(n, S(0)), {}};
  std::vector<std::vector<S>> P(n, std::vector<S>(n, S(0)));  // P_ik = L_ik d_k, the elimination's left factor
  for (std::size_t j = 0; j < n; ++j) {
    S dj = M[j][j];
    for (std::size_t k = 0; k < j; ++k)
      if (!is_zero(F.L[j][k])) dj = dj - P[j][k] * F.L[j][k];
    F.d[j] = o.pivot(dj);
    if (o.reciprocal == LdltOptions<S>::Reciprocal::everywhere) F.inverse_d.push_back(o.pivot(S(1) / F.d[j]));
    for (std::size_t i = j + 1; i < n; ++i) {
      S s = M[i][j];
      for (std::size_t k = 0; k < j; ++k)
        if (!is_zero(F.L[i][k]) && !is_zero(F.L[j][k])) s = s - P[i][k] * F.L[j][k];
      if (is_zero(s)) continue;
      F.L[i][j] = o.factor(o.reciprocal == LdltOptions<S>::Reciprocal::everywhere ? s * F.inverse_d[j] : s / F.d[j]);
      P[i][j] = o.numerator_products ? s : F.L[i][j] * F.d[j];
    }
  }
  if (o.reciprocal == LdltOptions<S>::Reciprocal::substitution)
    for (const S& d : F.d) F.inverse_d.push_back(S(1) / d);
  return F;
}

/// x with L D Lᵀ x = b: y = L⁻¹ b, then x = D⁻¹ y − Lᵀ x from the last row up.
template <class S>
std::vector<S> ldlt_substitute(const LdltFactor<S>& F, const std::vector<S>& b, const LdltOptions<S>& o) {
  const std::size_t n = b.size();
  std::vector<S> y(n, S(0)), x(n, S(0));
  for (std::size_t i = 0; i < n; ++i) {
    S s = b[i];
    for (std::size_t k = 0; k < i; ++k)
      if (!is_zero(F.L[i][k])) s = s - F.L[i][k] * y[k];
    y[i] = o.forward(s);
  }
  for (std::size_t i = n; i-- > 0;) {
    S s = o.reciprocal == LdltOptions<S>::Reciprocal::none ? y[i] / F.d[i] : y[i] * F.inverse_d[i];
    for (std::size_t k = i + 1; k < n; ++k)
      if (!is_zero(F.L[k][i])) s = s - F.L[k][i] * x[k];
    x[i] = o.solution(s);
  }
  return x;
}

/// The solutions of M x = b for every column b of `columns`, with one factorization; the pivots d_i (in the
/// order eliminated) go to `pivots` if given.
template <class S>
std::vector<std::vector<S>> ldlt_solve(const std::vector<std::vector<S>>& M, const std::vector<std::vector<S>>& columns,
                                       const LdltOptions<S>& o, std::vector<S>* pivots = nullptr) {
  const std::size_t n = M.size();
  if (o.last_first) {  // P M Pᵀ (P x) = P b with P the exchange matrix
    std::vector<std::vector<S>> R(n, std::vector<S>(n, S(0)));
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) R[i][j] = M[n - 1 - i][n - 1 - j];
    std::vector<std::vector<S>> flipped;
    for (std::vector<S> b : columns) {
      std::reverse(b.begin(), b.end());
      flipped.push_back(b);
    }
    LdltOptions<S> natural = o;
    natural.last_first = false;
    std::vector<std::vector<S>> out = ldlt_solve(R, flipped, natural, pivots);
    for (std::vector<S>& x : out) std::reverse(x.begin(), x.end());
    return out;
  }
  const LdltFactor<S> F = ldlt_factor(M, o);
  if (pivots) pivots->insert(pivots->end(), F.d.begin(), F.d.end());
  std::vector<std::vector<S>> out;
  for (const std::vector<S>& b : columns) out.push_back(ldlt_substitute(F, b, o));
  return out;
}

}  // namespace hamel::rbd
