// SPDX-License-Identifier: MIT
// Fixed-size vectors and row-major matrices for the Lie-group runtime.
//
// Everything is a std::array<double, n>, so values live on the stack, copy
// cheaply and never touch the heap. A k x k matrix is std::array<double, k*k>
// stored row by row: entry (i, j) is m[i * k + j]. The size of a square matrix
// cannot be deduced from k*k, so the generic helpers take k explicitly
// (mat_vec<6>(m, x)); the common 3 x 3 operations have operator overloads.
// Those operators take std::array arguments, so argument-dependent lookup does
// not find them outside this namespace: callers elsewhere write
// `using hamel::runtime::lie::operator*;` (or use mat_mul/mat_vec).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace hamel::runtime::lie {

using Vec3 = std::array<double, 3>;
using Vec6 = std::array<double, 6>;
using Mat3 = std::array<double, 9>;   // 3 x 3, row-major
using Mat4 = std::array<double, 16>;  // 4 x 4, row-major (homogeneous se(3) matrices)
using Mat6 = std::array<double, 36>;  // 6 x 6, row-major

/// k x k row-major matrix.
template <std::size_t K>
using SquareMatrix = std::array<double, K * K>;

/// The k x k identity.
template <std::size_t K>
constexpr SquareMatrix<K> identity_matrix() {
  SquareMatrix<K> m{};
  for (std::size_t i = 0; i < K; ++i) m[i * K + i] = 1.0;
  return m;
}

/// Product of two k x k matrices.
template <std::size_t K>
SquareMatrix<K> mat_mul(const SquareMatrix<K>& a, const SquareMatrix<K>& b) {
  SquareMatrix<K> c{};
  for (std::size_t i = 0; i < K; ++i) {
    for (std::size_t l = 0; l < K; ++l) {
      const double a_il = a[i * K + l];
      for (std::size_t j = 0; j < K; ++j) c[i * K + j] += a_il * b[l * K + j];
    }
  }
  return c;
}

/// Matrix-vector product m x for a k x k matrix.
template <std::size_t K>
std::array<double, K> mat_vec(const SquareMatrix<K>& m, const std::array<double, K>& x) {
  std::array<double, K> y{};
  for (std::size_t i = 0; i < K; ++i) {
    double s = 0.0;
    for (std::size_t j = 0; j < K; ++j) s += m[i * K + j] * x[j];
    y[i] = s;
  }
  return y;
}

/// Transpose of a k x k matrix.
template <std::size_t K>
SquareMatrix<K> transpose(const SquareMatrix<K>& m) {
  SquareMatrix<K> t{};
  for (std::size_t i = 0; i < K; ++i) {
    for (std::size_t j = 0; j < K; ++j) t[j * K + i] = m[i * K + j];
  }
  return t;
}

/// Writes the 3 x 3 block b into the k x k matrix m with its top-left entry at (row, col).
template <std::size_t K>
void set_block(SquareMatrix<K>& m, std::size_t row, std::size_t col, const Mat3& b) {
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) m[(row + i) * K + col + j] = b[i * 3 + j];
  }
}

/// Whether every entry is finite (neither NaN nor infinite).
template <std::size_t N>
bool all_finite(const std::array<double, N>& a) {
  for (double v : a) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

inline Mat3 operator*(const Mat3& a, const Mat3& b) { return mat_mul<3>(a, b); }
inline Vec3 operator*(const Mat3& m, const Vec3& x) { return mat_vec<3>(m, x); }

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }

inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// Euclidean norm without overflow or underflow for any finite input.
///
/// The plain sqrt(x . x) squares the entries, which underflows to 0 below about
/// 1e-154 and overflows above 1e154. Rotation vectors are never that small or
/// large in practice, so the scaled path is taken only when the plain sum of
/// squares left the safe range.
inline double norm(const Vec3& a) {
  const double s = dot(a, a);
  if (s > 1e-290 && s < 1e290) return std::sqrt(s);
  const double m = std::fmax(std::fabs(a[0]), std::fmax(std::fabs(a[1]), std::fabs(a[2])));
  if (!(m > 0.0) || !std::isfinite(m)) return s == 0.0 ? 0.0 : std::sqrt(s);  // zero, NaN or infinite
  const Vec3 b = (1.0 / m) * a;
  return m * std::sqrt(dot(b, b));
}

}  // namespace hamel::runtime::lie
