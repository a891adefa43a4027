// SPDX-License-Identifier: MIT
// The direct product SO(3) x R^3: rotation and translation that do not interact.
#pragma once

#include <array>
#include <cstddef>

#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/so3.hpp"

namespace hamel::runtime::lie {

/// SO(3) x R^3 as a group policy: an element {R, p} composes as
/// (R1, p1)(R2, p2) = (R1 R2, p1 + p2), and algebra elements are (w, v),
/// angular before linear. Unlike SE(3), the rotation does not act on the
/// translation, so every map is block diagonal: the SO(3) map on w and the
/// identity (or zero, for ad) on v. With the left trivialization the linear
/// velocity is therefore p' itself, the spatial velocity of the reference
/// point, while the angular velocity is the body one R^T R'.
struct SO3xR3 {
  static constexpr std::size_t dim = 6;
  using Vector = Vec6;
  using Matrix = Mat6;
  struct Element {
    Mat3 R;
    Vec3 p;
  };

  static Element identity() { return {identity_matrix<3>(), {0.0, 0.0, 0.0}}; }

  static Element exp(const Vec6& x) { return {SO3::exp(angular(x)), linear(x)}; }
  static Vec6 log(const Element& g) { return join(SO3::log(g.R), g.p); }
  static Matrix dexp(const Vec6& x) { return block_diagonal(SO3::dexp(angular(x)), identity_matrix<3>()); }
  static Matrix dexpinv(const Vec6& x) { return block_diagonal(SO3::dexpinv(angular(x)), identity_matrix<3>()); }
  static Matrix ad(const Vec6& x) { return block_diagonal(SO3::hat(angular(x)), Mat3{}); }
  static Matrix Ad(const Element& g) { return block_diagonal(g.R, identity_matrix<3>()); }
  static Element compose(const Element& a, const Element& b) { return {a.R * b.R, a.p + b.p}; }
  static Element inverse(const Element& g) { return {transpose<3>(g.R), -1.0 * g.p}; }
  static bool is_finite(const Element& g) { return all_finite(g.R) && all_finite(g.p); }

  static Vec3 angular(const Vec6& x) { return {x[0], x[1], x[2]}; }
  static Vec3 linear(const Vec6& x) { return {x[3], x[4], x[5]}; }
  static Vec6 join(const Vec3& w, const Vec3& v) { return {w[0], w[1], w[2], v[0], v[1], v[2]}; }

  static Mat6 block_diagonal(const Mat3& a, const Mat3& b) {
    Mat6 m{};
    set_block<6>(m, 0, 0, a);
    set_block<6>(m, 3, 3, b);
    return m;
  }
};

}  // namespace hamel::runtime::lie
