// SPDX-License-Identifier: MIT
// The planar rigid-body group SE(2): exp, log, dexp, dexp^-1, ad, Ad on (w, vx, vy).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "hamel/runtime/lie/coefficients.hpp"
#include "hamel/runtime/lie/matrix.hpp"

namespace hamel::runtime::lie {

/// SE(2) as a group policy. An element {theta, x, y} is the homogeneous matrix
/// [[cos theta, -sin theta, x], [sin theta, cos theta, y], [0, 0, 1]]; algebra
/// elements are (w, vx, vy) with hat = [[0, -w, vx], [w, 0, vy], [0, 0, 0]].
/// Conventions as documented at SO3.
///
/// The angle is stored, not a rotation matrix: an angle cannot drift off the
/// group, and compose adds angles without reducing them, so theta counts whole
/// turns (a wheel or a heading can be read off unwrapped). Only log reduces it,
/// to the principal value in [-pi, pi]. Two elements whose angles differ by
/// 2 pi are the same group element.
///
/// With J = [[0, -1], [1, 0]] and u = (vy, -vx) = -J v, ad(w, v) = [[0, 0], [u, w J]];
/// its powers give, with a = sin(w)/w, b = (1 - cos w)/w^2, c = (w - sin w)/w^3,
///   dexp    = [[1, 0], [(b I + c w J) u, a I + b w J]]
///   dexp^-1 = [[1, 0], [-u/2 + eta w J u, p I - (w/2) J]],  p = (w/2) cot(w/2),
/// using (a I + b w J)^-1 = (a I - b w J)/(2b) and a/(2b) = p = 1 - eta w^2.
struct SE2 {
  static constexpr std::size_t dim = 3;
  using Vector = Vec3;
  using Matrix = Mat3;
  struct Element {
    double theta;
    double x;
    double y;
  };

  static Element identity() { return {0.0, 0.0, 0.0}; }

  static Mat3 hat(const Vec3& xi) { return {0.0, -xi[0], xi[1], xi[0], 0.0, xi[2], 0.0, 0.0, 0.0}; }

  /// Inverse of hat; w is read from the skew part of the upper-left block.
  static Vec3 vee(const Mat3& m) { return {0.5 * (m[3] - m[1]), m[2], m[5]}; }

  /// The homogeneous 3 x 3 matrix of g.
  static Mat3 matrix(const Element& g) {
    const double c = std::cos(g.theta), s = std::sin(g.theta);
    return {c, -s, g.x, s, c, g.y, 0.0, 0.0, 1.0};
  }

  /// exp(w, v) = {w, (a I + b w J) v}; theta is w itself, not reduced.
  static Element exp(const Vec3& xi) {
    const double w = xi[0], t = std::fabs(w);
    const double a = coefficients::sinc(t), bw = coefficients::versine_ratio(t) * w;
    return {w, a * xi[1] - bw * xi[2], bw * xi[1] + a * xi[2]};
  }

  /// Principal logarithm, w in [-pi, pi]. The angle is reduced as
  /// atan2(sin theta, cos theta), which inherits libm's exact argument reduction
  /// (subtracting multiples of the rounded 2 pi would be off by 2.4e-16 per turn).
  /// Then v = (p I - (w/2) J) (x, y) with p = cos(w/2)/a(w/2), accurate up to pi.
  static Vec3 log(const Element& g) {
    const double w = std::atan2(std::sin(g.theta), std::cos(g.theta));
    const double p = half_cot(w), h = 0.5 * w;
    return {w, p * g.x + h * g.y, -h * g.x + p * g.y};
  }

  static Matrix dexp(const Vec3& xi) {
    const double w = xi[0], t = std::fabs(w);
    const double a = coefficients::sinc(t), b = coefficients::versine_ratio(t);
    const double cw = coefficients::sin_defect_ratio(t) * w, bw = b * w;
    const double ux = xi[2], uy = -xi[1];  // u = (vy, -vx); J u = (vx, vy)
    return {1.0, 0.0, 0.0, b * ux - cw * uy, a, -bw, b * uy + cw * ux, bw, a};
  }

  /// Singular at |w| = 2 pi.
  static Matrix dexpinv(const Vec3& xi) {
    const double w = xi[0];
    const double ew = coefficients::dexpinv_ratio(std::fabs(w)) * w, p = half_cot(w), h = 0.5 * w;
    return {1.0, 0.0, 0.0, -0.5 * xi[2] + ew * xi[1], p, h, 0.5 * xi[1] + ew * xi[2], -h, p};
  }

  static Matrix ad(const Vec3& xi) { return {0.0, 0.0, 0.0, xi[2], 0.0, -xi[0], -xi[1], xi[0], 0.0}; }

  /// Ad(theta, x, y) = [[1, 0, 0], [y, cos, -sin], [-x, sin, cos]].
  static Matrix Ad(const Element& g) {
    const double c = std::cos(g.theta), s = std::sin(g.theta);
    return {1.0, 0.0, 0.0, g.y, c, -s, -g.x, s, c};
  }

  static Element compose(const Element& a, const Element& b) {
    const double c = std::cos(a.theta), s = std::sin(a.theta);
    return {a.theta + b.theta, a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y};
  }

  static Element inverse(const Element& g) {
    const double c = std::cos(g.theta), s = std::sin(g.theta);
    return {-g.theta, -(c * g.x + s * g.y), s * g.x - c * g.y};
  }

  static bool is_finite(const Element& g) { return std::isfinite(g.theta) && std::isfinite(g.x) && std::isfinite(g.y); }

  /// (w/2) cot(w/2) = cos(w/2)/a(w/2): a quotient of accurate factors, no cancellation.
  static double half_cot(double w) {
    const double h = 0.5 * w;
    return std::cos(h) / coefficients::sinc(std::fabs(h));
  }
};

}  // namespace hamel::runtime::lie
