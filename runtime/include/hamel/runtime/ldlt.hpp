// SPDX-License-Identifier: MIT
// Allocation-free LDL^T solve for the small dense mass matrices of generated models.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <utility>

#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Solves M x = b in place for a symmetric positive definite M.
///
/// M is n x n, row-major; only its lower triangle (including the diagonal) is
/// read. M is overwritten by the factors of P M P^T = L D L^T (unit lower L
/// below the diagonal, D on it, the pivot order in the strict upper triangle),
/// and b by x. Returns singular_mass_matrix, with M and b unspecified, when a
/// pivot d_k is non-finite or not above relative_pivot_tolerance * max_i |M_ii|:
/// a mass matrix must be positive definite, so a tiny or negative pivot means a
/// modelling error (a massless coordinate, a redundant joint).
///
/// Pivoting is symmetric and always takes the largest remaining diagonal entry.
/// Positive definite matrices need no pivoting for stability, but without it a
/// singular matrix whose leading block is merely ill-conditioned can leave a
/// rounding-sized last pivot amplified far above the threshold; with it the
/// rank deficiency shows up as a pivot at rounding level.
/// Real: the scalar type (Real, or float for a float package).
template <class Real>
Status ldlt_solve(Real* M, Real* b, int n, std::common_type_t<Real> relative_pivot_tolerance = Real(1e-13)) {
  if (n <= 0) {
    return Status::ok;  // The empty system is trivially solved.
  }
  const auto N = static_cast<std::size_t>(n);
  auto A = [M, N](std::size_t i, std::size_t j) -> Real& { return M[i * N + j]; };

  // The threshold scales with the matrix so that models in any unit system
  // (grams or tonnes) are judged alike.
  Real max_diagonal = Real(0.0);
  for (std::size_t i = 0; i < N; ++i) {
    const Real d = std::fabs(A(i, i));
    if (!std::isfinite(d)) {
      return Status::singular_mass_matrix;
    }
    max_diagonal = std::fmax(max_diagonal, d);
  }
  const Real threshold = relative_pivot_tolerance * max_diagonal;

  // Right-looking factorisation: after step j the trailing lower triangle holds
  // the Schur complement, whose diagonal is what pivoting chooses from.
  for (std::size_t j = 0; j < N; ++j) {
    std::size_t p = j;
    for (std::size_t i = j; i < N; ++i) {
      if (!std::isfinite(A(i, i))) {
        return Status::singular_mass_matrix;
      }
      if (A(i, i) > A(p, p)) {
        p = i;
      }
    }
    const Real d = A(p, p);
    if (!(d > threshold)) {
      return Status::singular_mass_matrix;
    }

    if (p != j) {
      // Symmetric interchange of rows and columns j and p, touching only the
      // lower triangle: rows of L computed so far, then the trailing block.
      for (std::size_t k = 0; k < j; ++k) std::swap(A(j, k), A(p, k));
      std::swap(A(j, j), A(p, p));
      for (std::size_t i = j + 1; i < p; ++i) std::swap(A(i, j), A(p, i));
      for (std::size_t i = p + 1; i < N; ++i) std::swap(A(i, j), A(i, p));
    }
    if (j + 1 < N) {
      A(j, j + 1) = static_cast<Real>(p);  // unused upper triangle: record the pivot
    }

    for (std::size_t i = j + 1; i < N; ++i) {
      const Real c = A(i, j) / d;
      for (std::size_t l = j + 1; l <= i; ++l) {
        A(i, l) -= c * A(l, j);
      }
    }
    for (std::size_t i = j + 1; i < N; ++i) {
      A(i, j) /= d;
    }
  }

  // P M P^T (P x) = P b: permute b, solve with L D L^T, undo the permutation.
  for (std::size_t j = 0; j + 1 < N; ++j) {
    std::swap(b[j], b[static_cast<std::size_t>(A(j, j + 1))]);
  }
  for (std::size_t i = 0; i < N; ++i) {
    Real s = b[i];
    for (std::size_t k = 0; k < i; ++k) {
      s -= A(i, k) * b[k];
    }
    b[i] = s;
  }
  for (std::size_t i = 0; i < N; ++i) {
    b[i] /= A(i, i);
  }
  // L^T x = z, reading L by columns to avoid a transposed copy.
  for (std::size_t i = N; i-- > 0;) {
    Real s = b[i];
    for (std::size_t k = i + 1; k < N; ++k) {
      s -= A(k, i) * b[k];
    }
    b[i] = s;
  }
  for (std::size_t j = N - 1; j-- > 0;) {
    std::swap(b[j], b[static_cast<std::size_t>(A(j, j + 1))]);
  }
  return Status::ok;
}

/// The double form (also for a null system of size 0, which names no scalar type).
inline Status ldlt_solve(double* M, double* b, int n, double relative_pivot_tolerance = 1e-13) {
  return ldlt_solve<double>(M, b, n, relative_pivot_tolerance);
}

/// Fixed-size convenience overload of ldlt_solve for generated code that knows n at compile time.
template <std::size_t N>
Status ldlt_solve(std::array<double, N * N>& M, std::array<double, N>& b, double relative_pivot_tolerance = 1e-13) {
  static_assert(N <= static_cast<std::size_t>(std::numeric_limits<int>::max()), "matrix dimension must fit in int");
  return ldlt_solve(M.data(), b.data(), static_cast<int>(N), relative_pivot_tolerance);
}

}  // namespace hamel::runtime
