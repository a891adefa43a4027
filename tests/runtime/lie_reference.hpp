// SPDX-License-Identifier: MIT
// High-precision (CLN long-float) reference arithmetic for the Lie-group tests.
//
// Everything here is deliberately naive and independent of the runtime code it
// checks: matrices are dense, the exponential and dexp are the defining power
// series summed until the terms vanish at the working precision, inverses come
// from Gauss-Jordan elimination, and the rotation logarithm uses the textbook
// formula theta/(2 sin theta) (R - R^T), which is harmless at 50 digits.
#pragma once

#include <cln/dfloat.h>
#include <cln/float.h>
#include <cln/integer.h>
#include <cln/lfloat.h>
#include <cln/rational.h>
#include <cln/real.h>

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace lie_ref {

using Real = cln::cl_F;

/// Working precision, in decimal digits, of every value made by num().
inline int& digits() {
  static int d = 50;
  return d;
}
inline cln::float_format_t format() { return cln::float_format(digits()); }
inline void set_digits(int d) { digits() = d; }

/// The double x, exactly, at the working precision.
inline Real num(double x) { return cln::cl_float(cln::cl_DF(x), format()); }
/// The rational p/q at the working precision.
inline Real ratio(long p, long q) { return cln::cl_float(cln::cl_I(p) / cln::cl_I(q), format()); }
inline double to_double(const Real& x) { return cln::double_approx(x); }
inline Real pi() { return cln::pi(format()); }

struct Mat {
  std::size_t rows = 0, cols = 0;
  std::vector<Real> a;
  Mat(std::size_t r, std::size_t c) : rows(r), cols(c), a(r * c, num(0.0)) {}
  Real& operator()(std::size_t i, std::size_t j) { return a[i * cols + j]; }
  const Real& operator()(std::size_t i, std::size_t j) const { return a[i * cols + j]; }
};

inline Mat identity(std::size_t n) {
  Mat m(n, n);
  for (std::size_t i = 0; i < n; ++i) m(i, i) = num(1.0);
  return m;
}

/// A row-major r x c matrix of doubles, exactly.
inline Mat from_doubles(const double* p, std::size_t r, std::size_t c) {
  Mat m(r, c);
  for (std::size_t i = 0; i < r * c; ++i) m.a[i] = num(p[i]);
  return m;
}

/// Entry-wise rounding to the nearest doubles.
inline std::vector<double> round(const Mat& m) {
  std::vector<double> d(m.a.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = to_double(m.a[i]);
  return d;
}

inline Mat operator*(const Mat& x, const Mat& y) {
  Mat z(x.rows, y.cols);
  for (std::size_t i = 0; i < x.rows; ++i) {
    for (std::size_t j = 0; j < y.cols; ++j) {
      Real s = num(0.0);
      for (std::size_t l = 0; l < x.cols; ++l) s = s + x(i, l) * y(l, j);
      z(i, j) = s;
    }
  }
  return z;
}
inline Mat operator+(Mat x, const Mat& y) {
  for (std::size_t i = 0; i < x.a.size(); ++i) x.a[i] = x.a[i] + y.a[i];
  return x;
}
inline Mat operator-(Mat x, const Mat& y) {
  for (std::size_t i = 0; i < x.a.size(); ++i) x.a[i] = x.a[i] - y.a[i];
  return x;
}
inline Mat operator*(const Real& s, Mat x) {
  for (Real& v : x.a) v = s * v;
  return x;
}
inline Mat transpose(const Mat& x) {
  Mat t(x.cols, x.rows);
  for (std::size_t i = 0; i < x.rows; ++i) {
    for (std::size_t j = 0; j < x.cols; ++j) t(j, i) = x(i, j);
  }
  return t;
}

inline Real frobenius(const Mat& x) {
  Real s = num(0.0);
  for (const Real& v : x.a) s = s + v * v;
  return cln::sqrt(s);
}

/// ||computed - ref||_F / ||ref||_F, evaluated at the working precision, for a
/// row-major array of doubles of the same shape as ref.
inline double relative_error(const double* computed, const Mat& ref) {
  const Mat diff = from_doubles(computed, ref.rows, ref.cols) - ref;
  return to_double(frobenius(diff) / frobenius(ref));
}

/// sum_k coef(k) A^k, summed until two consecutive terms are below
/// 10^-(digits + 5) of the sum (the coefficients used here decrease
/// monotonically, and the terms of a non-nilpotent A vanish only in the limit).
template <class Coefficient>
Mat power_series(const Mat& A, Coefficient coef) {
  const Real tiny = cln::cl_float(cln::expt(cln::cl_RA(10), -(digits() + 5)), format());
  Mat power = identity(A.rows);
  Mat sum = coef(0) * power;
  int small = 0;
  for (long k = 1; k < 2000; ++k) {
    power = power * A;
    const Mat term = coef(k) * power;
    sum = sum + term;
    small = frobenius(term) < tiny * frobenius(sum) ? small + 1 : 0;
    if (small == 2) return sum;
  }
  throw std::runtime_error("power series did not converge");
}

/// 1/k! at the working precision.
inline Real inverse_factorial(long k) { return cln::cl_float(cln::cl_RA(1) / cln::factorial(k), format()); }

/// exp(X) = sum X^k/k!.
inline Mat exp(const Mat& X) { return power_series(X, inverse_factorial); }
/// dexp for the adjoint matrix A = ad_x: sum A^k/(k+1)!.
inline Mat dexp(const Mat& A) {
  return power_series(A, [](long k) { return inverse_factorial(k + 1); });
}

/// Inverse by Gauss-Jordan elimination with partial pivoting.
inline Mat inverse(Mat A) {
  const std::size_t n = A.rows;
  Mat B = identity(n);
  for (std::size_t j = 0; j < n; ++j) {
    std::size_t p = j;
    for (std::size_t i = j + 1; i < n; ++i) {
      if (cln::abs(A(i, j)) > cln::abs(A(p, j))) p = i;
    }
    if (cln::zerop(A(p, j))) throw std::runtime_error("singular matrix");
    for (std::size_t l = 0; l < n; ++l) {
      std::swap(A(j, l), A(p, l));
      std::swap(B(j, l), B(p, l));
    }
    const Real d = A(j, j);
    for (std::size_t l = 0; l < n; ++l) {
      A(j, l) = A(j, l) / d;
      B(j, l) = B(j, l) / d;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (i == j) continue;
      const Real f = A(i, j);
      for (std::size_t l = 0; l < n; ++l) {
        A(i, l) = A(i, l) - f * A(j, l);
        B(i, l) = B(i, l) - f * B(j, l);
      }
    }
  }
  return B;
}

/// The orthogonal polar factor of a nearly orthogonal matrix (the nearest
/// orthogonal matrix in the Frobenius norm), by Newton's iteration
/// Q <- (Q + Q^-T)/2, which converges quadratically.
inline Mat polar(const Mat& R) {
  Mat Q = R;
  for (int i = 0; i < 12; ++i) Q = ratio(1, 2) * (Q + transpose(inverse(Q)));
  return Q;
}

/// Column vector (n x 1) from exact doubles.
inline Mat vec(const std::vector<double>& v) { return from_doubles(v.data(), v.size(), 1); }

/// Logarithm of an exact rotation matrix: theta = atan2(|v|, (tr R - 1)/2),
/// w = theta v/|v| with v = vee((R - R^T)/2). Dividing by |v| = sin theta is fine
/// at 50 digits for the angles tested (|v| >= 1e-12 costs 12 of 50 digits).
inline Mat log_rotation(const Mat& R) {
  Mat v(3, 1);
  v(0, 0) = ratio(1, 2) * (R(2, 1) - R(1, 2));
  v(1, 0) = ratio(1, 2) * (R(0, 2) - R(2, 0));
  v(2, 0) = ratio(1, 2) * (R(1, 0) - R(0, 1));
  const Real c = ratio(1, 2) * (R(0, 0) + R(1, 1) + R(2, 2) - num(1.0));
  const Real s = frobenius(v);
  if (cln::zerop(s)) return v;
  const Real theta = The(cln::cl_F)(cln::atan(c, s));
  return (theta / s) * v;
}

/// hat of so(3): w -> [[0, -w3, w2], [w3, 0, -w1], [-w2, w1, 0]].
inline Mat hat_so3(const Mat& w) {
  Mat m(3, 3);
  m(0, 1) = -w(2, 0);
  m(0, 2) = w(1, 0);
  m(1, 0) = w(2, 0);
  m(1, 2) = -w(0, 0);
  m(2, 0) = -w(1, 0);
  m(2, 1) = w(0, 0);
  return m;
}

}  // namespace lie_ref
