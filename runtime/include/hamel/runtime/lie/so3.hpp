// SPDX-License-Identifier: MIT
// The rotation group SO(3): exp, log, dexp, dexp^-1, ad, Ad on rotation vectors.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "hamel/runtime/lie/coefficients.hpp"
#include "hamel/runtime/lie/matrix.hpp"

namespace hamel::runtime::lie {

/// SO(3) as a group policy: elements are rotation matrices R (Mat3, row-major),
/// algebra elements are rotation vectors w with hat(w) v = w x v.
///
/// Conventions shared by all groups of this runtime:
///  - dexp(x) = sum_k ad_x^k/(k+1)! is the right-trivialized differential of
///    exp: d/dt exp(x(t)) exp(x(t))^-1 = hat(dexp(x) x'). The left-trivialized
///    one, exp(-x) d/dt exp(x), is dexp(-x).
///  - Ad(g) xi = vee(g hat(xi) g^-1), ad(x) y = vee([hat x, hat y]).
///  - log returns the principal logarithm, |w| <= pi.
/// On SO(3), ad(w) = hat(w) and Ad(R) = R.
struct SO3 {
  static constexpr std::size_t dim = 3;
  using Vector = Vec3;
  using Matrix = Mat3;  // linear maps of the algebra
  using Element = Mat3;

  static Element identity() { return identity_matrix<3>(); }

  /// The skew matrix with hat(w) v = w x v.
  static Mat3 hat(const Vec3& w) { return {0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0}; }

  /// Inverse of hat, applied to the skew-symmetric part (m - m^T)/2, so that a
  /// matrix that is skew only up to rounding gives the nearest rotation vector.
  static Vec3 vee(const Mat3& m) { return {0.5 * (m[7] - m[5]), 0.5 * (m[2] - m[6]), 0.5 * (m[3] - m[1])}; }

  /// R = I + a W + b W^2 (Rodrigues) with a = sin(theta)/theta and
  /// b = (1 - cos theta)/theta^2 from coefficients.hpp, accurate at every angle.
  /// W^2 = w w^T - theta^2 I is expanded so that no matrix product is formed.
  static Element exp(const Vec3& w) {
    const double theta = norm(w);
    const double a = coefficients::sinc(theta);
    const double b = coefficients::versine_ratio(theta);
    return quadratic_in_hat(w, a, b);
  }

  /// Principal logarithm: the rotation vector w with |w| <= pi and exp(w) = R.
  ///
  /// With c = (tr R - 1)/2 = cos theta and v = vee(R) = sin(theta) n, the angle
  /// is theta = atan2(|v|, c), accurate to about an ulp at every angle (unlike
  /// acos(c) near 0 or asin(|v|) near pi/2 and pi).
  ///
  /// The axis: away from pi, w = v/a(theta). Near pi, v = sin(theta) n shrinks
  /// to rounding level while its absolute error does not, so v/a(theta) would
  /// lose log10(1/(pi - theta)) digits; there the axis comes from the symmetric
  /// part instead, (R + R^T)/2 - c I = (1 - c) n n^T, whose largest diagonal
  /// entry is at least (1 - c)/3 and whose column through that entry is
  /// parallel to n with a relative error of about sqrt(3) u/(1 - c). The sign of
  /// n, which the symmetric part cannot see, is that of v (sin theta >= 0 on
  /// [0, pi]); at theta = pi exactly both signs are valid logarithms.
  /// The skew route has relative error about u/sin(theta), the symmetric one
  /// about sqrt(3) u/(1 - cos theta); they are equal at theta = 2pi/3, c = -1/2,
  /// which is where the switch is.
  ///
  /// R should be a rotation; a matrix that is orthogonal only up to rounding
  /// gives the logarithm of a rotation within rounding of it.
  static Vec3 log(const Element& R) {
    const double c = 0.5 * (R[0] + R[4] + R[8] - 1.0);
    const Vec3 v = vee(R);
    const double s = norm(v);
    const double theta = std::atan2(s, c);
    if (c > -0.5) return (1.0 / coefficients::sinc(theta)) * v;

    std::size_t i = 0;
    if (R[4] > R[i * 4]) i = 1;
    if (R[8] > R[i * 4]) i = 2;
    Vec3 col;
    for (std::size_t j = 0; j < 3; ++j) col[j] = 0.5 * (R[i * 3 + j] + R[j * 3 + i]);
    col[i] -= c;
    const double len = norm(col);
    const double scale = (dot(col, v) < 0.0 ? -theta : theta) / len;
    return scale * col;
  }

  /// dexp(w) = I + b W + c W^2, b = (1 - cos theta)/theta^2,
  /// c = (theta - sin theta)/theta^3 (equal to sum_k W^k/(k+1)!).
  static Matrix dexp(const Vec3& w) {
    const double theta = norm(w);
    return quadratic_in_hat(w, coefficients::versine_ratio(theta), coefficients::sin_defect_ratio(theta));
  }

  /// dexp(w)^-1 = I - W/2 + eta W^2, eta = (1 - (theta/2) cot(theta/2))/theta^2.
  /// Singular at |w| = 2 pi; finite and well conditioned for |w| <= pi and beyond.
  static Matrix dexpinv(const Vec3& w) {
    const double theta = norm(w);
    return quadratic_in_hat(w, -0.5, coefficients::dexpinv_ratio(theta));
  }

  static Matrix ad(const Vec3& w) { return hat(w); }
  static Matrix Ad(const Element& R) { return R; }
  static Element compose(const Element& a, const Element& b) { return a * b; }
  static Element inverse(const Element& R) { return transpose<3>(R); }
  static bool is_finite(const Element& R) { return all_finite(R); }

  /// I + p W + q W^2 with W = hat(w), using W^2 = w w^T - |w|^2 I; the
  /// diagonal 1 - q (w_j^2 + w_k^2) is formed without subtracting w_i^2 from |w|^2.
  static Mat3 quadratic_in_hat(const Vec3& w, double p, double q) {
    const double x2 = w[0] * w[0], y2 = w[1] * w[1], z2 = w[2] * w[2];
    const double pw0 = p * w[0], pw1 = p * w[1], pw2 = p * w[2];
    const double q01 = q * w[0] * w[1], q02 = q * w[0] * w[2], q12 = q * w[1] * w[2];
    return {1.0 - q * (y2 + z2), q01 - pw2, q02 + pw1, q01 + pw2,          1.0 - q * (x2 + z2),
            q12 - pw0,           q02 - pw1, q12 + pw0, 1.0 - q * (x2 + y2)};
  }
};

}  // namespace hamel::runtime::lie
