#include "rbd/joint.hpp"

#include "algebra/simplify.hpp"

namespace hamel::rbd {

Vec6<Ex> joint_axis(const Joint& j) { return j.prismatic ? join<Ex>({0, 0, 0}, j.axis) : join<Ex>(j.axis, {0, 0, 0}); }

namespace {

// k when R turns about e_k (Link::about): row and column k are e_k, and with i, j the axes after k,
// R_jj = R_ii = a, R_ij = −R_ji = −b ≠ 0 and a² + b² = 1 exactly (`circle`: sin² q → 1 − cos² q); −1 otherwise
// (a joint frame's rotation written in decimals is orthonormal only to rounding: the double angle would not be
// the same rotation).
int rotation_axis(const Mat3<Ex>& R, const GiNaC::exmap& circle) {
  const auto same = [&](const Ex& x, const Ex& y) {
    return expand_keeping_powers_of_sums(expand_keeping_powers_of_sums(x - y).subs(circle)).is_zero();
  };
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t i = (k + 1) % 3, j = (k + 2) % 3;
    if (!same(R[k][k], 1) || !R[k][i].is_zero() || !R[k][j].is_zero() || !R[i][k].is_zero() || !R[j][k].is_zero())
      continue;
    if (same(R[i][i], R[j][j]) && same(R[i][j], -R[j][i]) && !R[j][i].is_zero() &&
        same(R[i][i] * R[i][i] + R[j][i] * R[j][i], 1))
      return static_cast<int>(k);
  }
  return -1;
}

}  // namespace

Link<Ex> joint_pose(const Joint& joint, const Ex& q, const Namer<Ex>& name) {
  Link<Ex> l;
  Mat3<Ex> J = identity3<Ex>();  // the joint's own rotation
  GiNaC::exmap circle;
  if (!joint.prismatic) {
    // Rodrigues: 1 + sin q [a]× + (1 − cos q) [a]×², a unit.
    const Ex s = name(GiNaC::sin(q)), co = name(GiNaC::cos(q));
    circle[GiNaC::pow(s, 2)] = 1 - GiNaC::pow(co, 2);
    const Mat3<Ex> K = skew(joint.axis);
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) {
        Ex k2 = 0;
        for (std::size_t j = 0; j < 3; ++j) k2 += K[r][j] * K[j][c];
        J[r][c] = expand_keeping_powers_of_sums((r == c ? 1 : 0) + s * K[r][c] +
                                                (1 - co) * expand_keeping_powers_of_sums(k2));
      }
  }
  Mat3<Ex> R;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) {
      Ex e = 0;
      for (std::size_t j = 0; j < 3; ++j) e += joint.rotation[r][j] * J[j][c];
      R[r][c] = expand_keeping_powers_of_sums(e);
    }
  l.about = joint.prismatic ? -1 : rotation_axis(R, circle);  // a prismatic joint's fixed rotation is free as it is
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) l.R[r][c] = name(R[r][c]);
    Ex shift = 0;
    if (joint.prismatic)
      for (std::size_t j = 0; j < 3; ++j) shift += joint.rotation[r][j] * joint.axis[j] * q;
    l.p[r] = name(expand_keeping_powers_of_sums(joint.offset[r] + shift));
  }
  return l;
}

}  // namespace hamel::rbd
