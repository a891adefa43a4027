// SPDX-License-Identifier: MIT
// The rigid-body group SE(3): exp, log, dexp, dexp^-1, ad, Ad on twists (w, v).
#pragma once

#include <array>
#include <cstddef>

#include "hamel/runtime/lie/coefficients.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/so3.hpp"

namespace hamel::runtime::lie {

/// SE(3) as a group policy. An element {R, p} is the homogeneous matrix
/// [[R, p], [0, 1]]; a twist is (w, v), angular before linear, with
/// hat(w, v) = [[hat w, v], [0, 0]]. Conventions as documented at SO3.
///
/// In this basis ad(w, v) = [[W, 0], [V, W]] (W = hat w, V = hat v), a block
/// lower-triangular matrix with equal diagonal blocks. For any power series f,
/// f of such a matrix is [[f(W), 0], [Df(W)[V], f(W)]], where Df(W)[V] is the
/// derivative of f at W in the direction V. Hence dexp and dexp^-1 on SE(3)
/// consist of their SO(3) counterparts on the diagonal and, below it, the
/// directional derivative of I + p(theta) W + q(theta) W^2 along w -> w + s v:
///     p V + q (W V + V W) + (w . v) (p_d W + q_d W^2),
/// with p_d = (1/theta) dp/dtheta (d theta/ds = w . v/theta). The p_d, q_d are
/// the "_d" coefficients of coefficients.hpp, accurate at every angle.
struct SE3 {
  static constexpr std::size_t dim = 6;
  using Vector = Vec6;
  using Matrix = Mat6;
  struct Element {
    Mat3 R;
    Vec3 p;
  };

  static Element identity() { return {identity_matrix<3>(), {0.0, 0.0, 0.0}}; }

  static Mat4 hat(const Vec6& x) {
    return {0.0, -x[2], x[1], x[3], x[2], 0.0, -x[0], x[4], -x[1], x[0], 0.0, x[5], 0.0, 0.0, 0.0, 0.0};
  }

  /// Inverse of hat; the rotational part is read from the skew-symmetric part of
  /// the upper-left block (see SO3::vee) and the bottom row is ignored.
  static Vec6 vee(const Mat4& m) {
    return {0.5 * (m[9] - m[6]), 0.5 * (m[2] - m[8]), 0.5 * (m[4] - m[1]), m[3], m[7], m[11]};
  }

  /// The homogeneous 4 x 4 matrix of g.
  static Mat4 matrix(const Element& g) {
    const Mat3& R = g.R;
    return {R[0], R[1], R[2], g.p[0], R[3], R[4], R[5], g.p[1], R[6], R[7], R[8], g.p[2], 0.0, 0.0, 0.0, 1.0};
  }

  /// exp(w, v) = {exp(w), dexp_SO3(w) v}: the translation is V v with
  /// V = I + b W + c W^2, evaluated with cross products.
  static Element exp(const Vec6& x) {
    const Vec3 w = angular(x), v = linear(x);
    const double theta = norm(w);
    const Vec3 wv = cross(w, v);
    Element g;
    g.R = SO3::quadratic_in_hat(w, coefficients::sinc(theta), coefficients::versine_ratio(theta));
    g.p = v + coefficients::versine_ratio(theta) * wv + coefficients::sin_defect_ratio(theta) * cross(w, wv);
    return g;
  }

  /// Principal logarithm: w = SO3::log(R) (|w| <= pi, accurate near pi), then
  /// v = dexp_SO3(w)^-1 p, which is well conditioned for |w| <= pi.
  static Vec6 log(const Element& g) {
    const Vec3 w = SO3::log(g.R);
    const double eta = coefficients::dexpinv_ratio(norm(w));
    const Vec3 wp = cross(w, g.p);
    return join(w, g.p - 0.5 * wp + eta * cross(w, wp));
  }

  /// dexp(w, v) = [[A, 0], [B, A]], A = I + b W + c W^2,
  /// B = b V + c (W V + V W) + (w . v) (b_d W + c_d W^2).
  static Matrix dexp(const Vec6& x) {
    const Vec3 w = angular(x), v = linear(x);
    const double theta = norm(w);
    const double b = coefficients::versine_ratio(theta);
    const double c = coefficients::sin_defect_ratio(theta);
    const double wv = dot(w, v);
    return lower_block_form(w, v, b, c, wv * coefficients::versine_ratio_d(theta),
                            wv * coefficients::sin_defect_ratio_d(theta));
  }

  /// dexp(w, v)^-1 = [[A^-1, 0], [C, A^-1]], A^-1 = I - W/2 + eta W^2,
  /// C = -V/2 + eta (W V + V W) + (w . v) eta_d W^2 (= -A^-1 B A^-1).
  /// Singular at |w| = 2 pi.
  static Matrix dexpinv(const Vec6& x) {
    const Vec3 w = angular(x), v = linear(x);
    const double theta = norm(w);
    return lower_block_form(w, v, -0.5, coefficients::dexpinv_ratio(theta), 0.0,
                            dot(w, v) * coefficients::dexpinv_ratio_d(theta));
  }

  /// ad(w, v) = [[W, 0], [V, W]].
  static Matrix ad(const Vec6& x) {
    Mat6 m{};
    const Mat3 W = SO3::hat(angular(x));
    set_block<6>(m, 0, 0, W);
    set_block<6>(m, 3, 0, SO3::hat(linear(x)));
    set_block<6>(m, 3, 3, W);
    return m;
  }

  /// Ad(R, p) = [[R, 0], [hat(p) R, R]].
  static Matrix Ad(const Element& g) {
    Mat6 m{};
    set_block<6>(m, 0, 0, g.R);
    set_block<6>(m, 3, 0, SO3::hat(g.p) * g.R);
    set_block<6>(m, 3, 3, g.R);
    return m;
  }

  static Element compose(const Element& a, const Element& b) { return {a.R * b.R, a.R * b.p + a.p}; }

  static Element inverse(const Element& g) {
    const Mat3 Rt = transpose<3>(g.R);
    return {Rt, -1.0 * (Rt * g.p)};
  }

  static bool is_finite(const Element& g) { return all_finite(g.R) && all_finite(g.p); }

  static Vec3 angular(const Vec6& x) { return {x[0], x[1], x[2]}; }
  static Vec3 linear(const Vec6& x) { return {x[3], x[4], x[5]}; }
  static Vec6 join(const Vec3& w, const Vec3& v) { return {w[0], w[1], w[2], v[0], v[1], v[2]}; }

  /// [[D, 0], [L, D]] with D = I + p W + q W^2 and
  /// L = p V + q (W V + V W) + r W + s W^2, using W V = v w^T - (w . v) I. As in
  /// SO3::quadratic_in_hat, the diagonals of W V + V W and W^2 are formed from the two
  /// other components, -2 (w_j v_j + w_k v_k) and -(w_j^2 + w_k^2), without subtracting
  /// 2 w_i v_i from 2 w . v or w_i^2 from |w|^2.
  static Mat6 lower_block_form(const Vec3& w, const Vec3& v, double p, double q, double r, double s) {
    const Mat3 D = SO3::quadratic_in_hat(w, p, q);
    const Mat3 W = SO3::hat(w), V = SO3::hat(v);
    Mat3 L;
    for (std::size_t i = 0; i < 3; ++i) {
      const std::size_t j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      for (std::size_t j = 0; j < 3; ++j) {
        const double sym = i == j ? -2.0 * (w[j1] * v[j1] + w[j2] * v[j2]) : v[i] * w[j] + w[i] * v[j];  // W V + V W
        const double w2 = i == j ? -(w[j1] * w[j1] + w[j2] * w[j2]) : w[i] * w[j];                       // W^2
        L[i * 3 + j] = p * V[i * 3 + j] + q * sym + r * W[i * 3 + j] + s * w2;
      }
    }
    Mat6 m{};
    set_block<6>(m, 0, 0, D);
    set_block<6>(m, 3, 0, L);
    set_block<6>(m, 3, 3, D);
    return m;
  }
};

}  // namespace hamel::runtime::lie
