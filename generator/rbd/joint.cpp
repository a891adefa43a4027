#include "rbd/joint.hpp"

#include "algebra/simplify.hpp"

namespace hamel::rbd {

Vec6<Ex> joint_axis(const Joint& j) { return j.prismatic ? join<Ex>({0, 0, 0}, j.axis) : join<Ex>(j.axis, {0, 0, 0}); }

Link<Ex> joint_pose(const Joint& joint, const Ex& q, const Namer<Ex>& name) {
  Link<Ex> l;
  Mat3<Ex> J = identity3<Ex>();  // the joint's own rotation
  if (!joint.prismatic) {
    // Rodrigues: 1 + sin q [a]× + (1 − cos q) [a]×², a unit.
    const Ex s = name(GiNaC::sin(q)), co = name(GiNaC::cos(q));
    const Mat3<Ex> K = skew(joint.axis);
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t c = 0; c < 3; ++c) {
        Ex k2 = 0;
        for (std::size_t j = 0; j < 3; ++j) k2 += K[r][j] * K[j][c];
        J[r][c] = expand_keeping_powers_of_sums((r == c ? 1 : 0) + s * K[r][c] +
                                                (1 - co) * expand_keeping_powers_of_sums(k2));
      }
  }
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      Ex e = 0;
      for (std::size_t j = 0; j < 3; ++j) e += joint.rotation[r][j] * J[j][c];
      l.R[r][c] = name(expand_keeping_powers_of_sums(e));
    }
    Ex shift = 0;
    if (joint.prismatic)
      for (std::size_t j = 0; j < 3; ++j) shift += joint.rotation[r][j] * joint.axis[j] * q;
    l.p[r] = name(expand_keeping_powers_of_sums(joint.offset[r] + shift));
  }
  return l;
}

}  // namespace hamel::rbd
