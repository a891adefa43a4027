// SPDX-License-Identifier: MIT
// Allocation-free dense LU factorisation with partial pivoting, for the Newton
// iteration matrices of the implicit integrators (radau5.hpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>

namespace hamel::runtime {

/// Factors the n x n row-major matrix A in place as P A = L U.
///
/// On return the strict lower triangle of A holds L (whose unit diagonal is not
/// stored) and the upper triangle U; pivots[k] is the row that was swapped with
/// row k at elimination step k (LAPACK's ipiv, zero-based), so the swaps must
/// be replayed in order k = 0, 1, ... to apply P.
///
/// Partial pivoting (the largest |entry| of the column becomes the pivot) keeps
/// every multiplier within [-1, 1]; that is enough for stability on the Newton
/// matrices I - h (A (x) J) of the integrators, which unlike mass matrices are
/// neither symmetric nor definite, so ldlt.hpp does not apply.
///
/// Returns false, with A and pivots unspecified, when an entry of A is
/// non-finite or a pivot is not above relative_pivot_tolerance * max_ij |A_ij|
/// (the largest entry of the matrix as given). A pivot that small means the
/// matrix is singular to working precision (condition number beyond about
/// 1 / tolerance), where a solve would return mostly amplified rounding
/// errors; relative_pivot_tolerance = 0 rejects only exactly zero pivots. The
/// threshold scales with the matrix so that the unit system does not matter.
/// Real: the scalar type (double, or float for a float package).
template <class Real>
bool lu_factor(Real* A, int* pivots, int n, std::common_type_t<Real> relative_pivot_tolerance = Real(1e-14)) {
  if (n <= 0) {
    return true;  // The empty matrix is trivially factored.
  }
  const auto N = static_cast<std::size_t>(n);
  Real max_entry = Real(0.0);
  for (std::size_t i = 0; i < N * N; ++i) {
    const Real a = std::fabs(A[i]);
    if (!std::isfinite(a)) {
      return false;
    }
    max_entry = std::fmax(max_entry, a);
  }
  const Real threshold = relative_pivot_tolerance * max_entry;

  // Right-looking elimination, row-major friendly: the update of the trailing
  // block runs along rows.
  for (std::size_t k = 0; k < N; ++k) {
    std::size_t p = k;
    Real best = std::fabs(A[k * N + k]);
    for (std::size_t i = k + 1; i < N; ++i) {
      const Real a = std::fabs(A[i * N + k]);
      if (a > best) {
        best = a;
        p = i;
      }
    }
    // Written so that a NaN pivot (from overflow in the trailing block) also fails.
    if (!(best > threshold) || !std::isfinite(best)) {
      return false;
    }
    pivots[k] = static_cast<int>(p);
    if (p != k) {
      for (std::size_t j = 0; j < N; ++j) std::swap(A[k * N + j], A[p * N + j]);
    }
    const Real inv_pivot = Real(1.0) / A[k * N + k];
    for (std::size_t i = k + 1; i < N; ++i) {
      Real* row = A + i * N;
      const Real l = row[k] * inv_pivot;
      row[k] = l;
      if (l != Real(0.0)) {  // sparse Jacobians give many zero multipliers
        const Real* pivot_row = A + k * N;
        for (std::size_t j = k + 1; j < N; ++j) row[j] -= l * pivot_row[j];
      }
    }
  }
  return true;
}

/// Solves A x = b in place (b becomes x) with the factors from a successful
/// lu_factor. The factors are only read, so one factorisation serves any
/// number of right-hand sides.
template <class Real>
void lu_solve(const Real* LU, const int* pivots, Real* b, int n) {
  if (n <= 0) {
    return;
  }
  const auto N = static_cast<std::size_t>(n);
  // P b, then L y = P b (unit diagonal), then U x = y.
  for (std::size_t k = 0; k < N; ++k) {
    const auto p = static_cast<std::size_t>(pivots[k]);
    if (p != k) std::swap(b[k], b[p]);
  }
  for (std::size_t i = 1; i < N; ++i) {
    Real s = b[i];
    const Real* row = LU + i * N;
    for (std::size_t j = 0; j < i; ++j) s -= row[j] * b[j];
    b[i] = s;
  }
  for (std::size_t i = N; i-- > 0;) {
    Real s = b[i];
    const Real* row = LU + i * N;
    for (std::size_t j = i + 1; j < N; ++j) s -= row[j] * b[j];
    b[i] = s / row[i];
  }
}

/// The double forms (also for a null matrix of size 0, which names no scalar type).
inline bool lu_factor(double* A, int* pivots, int n, double relative_pivot_tolerance = 1e-14) {
  return lu_factor<double>(A, pivots, n, relative_pivot_tolerance);
}
inline void lu_solve(const double* LU, const int* pivots, double* b, int n) { lu_solve<double>(LU, pivots, b, n); }

}  // namespace hamel::runtime
