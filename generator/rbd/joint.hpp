// One-degree-of-freedom joints: the pose of a body relative to its parent, g = (rotation, offset) · exp(q S), with
// S = (axis, 0) for a revolute joint (rotation by q about the axis through the joint frame's origin, Rodrigues'
// formula) and S = (0, axis) for a prismatic one (translation by q along the axis); axis a unit vector in the joint
// frame, which is the body frame at q = 0.
#pragma once

#include "rbd/tree.hpp"

namespace hamel::rbd {

struct Joint {
  bool prismatic = false;
  Vec3<Ex> axis{0, 0, 0};
  Vec3<Ex> offset{0, 0, 0};             ///< the joint frame's origin in the parent's frame
  Mat3<Ex> rotation = identity3<Ex>();  ///< the joint frame in the parent's frame
};

/// S: the joint's motion per unit rate in the body's frame.
Vec6<Ex> joint_axis(const Joint& joint);

/// The body's pose in its parent's frame at coordinate q, every entry named (sin q and cos q once).
Link<Ex> joint_pose(const Joint& joint, const Ex& q, const Namer<Ex>& name);

}  // namespace hamel::rbd
