#include "rbd/forward_kinematics.hpp"

namespace hamel::rbd {

namespace {

// The body's inertia in the common frame, the body at pose (R, p).
Inertia<Ex> common_frame_inertia(const BodyInertia& b, const Mat3<Ex>& R, const Vec3<Ex>& p, const Namer<Ex>& name) {
  const Vec3<Ex> c = name(p + R * b.com);
  Mat3<Ex> RT;  // R Θ
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k)
      RT[r][k] = R[r][0] * b.rotational[0][k] + R[r][1] * b.rotational[1][k] + R[r][2] * b.rotational[2][k];
  Inertia<Ex> I;
  I.m = b.mass;
  for (std::size_t r = 0; r < 3; ++r) I.h[r] = b.mass * c[r];
  const Ex cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = r; k < 3; ++k) {
      const Ex rotational = RT[r][0] * R[k][0] + RT[r][1] * R[k][1] + RT[r][2] * R[k][2];
      I.J[r][k] = I.J[k][r] = rotational + b.mass * ((r == k ? cc : Ex(0)) - c[r] * c[k]);
    }
  return name(I);
}

}  // namespace

CommonFrame forward_kinematics(const TreeModel& model, const Namer<Ex>& name) {
  const std::size_t N = model.size();
  CommonFrame cf;
  cf.R.resize(N);
  cf.p.resize(N);
  cf.axis.assign(N, zero6<Ex>());
  cf.inertia.resize(N);
  cf.R[0] = identity3<Ex>();
  cf.p[0] = {0, 0, 0};
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(model.parent[i]);
      const Link<Ex>& link = model.link[i];
      cf.R[i] = name(cf.R[l] * link.R);
      cf.p[i] = name(cf.p[l] + cf.R[l] * link.p);
      cf.axis[i] = name(Link<Ex>{cf.R[i], cf.p[i]}.motion_to_parent(model.axis[i]));
    }
    cf.inertia[i] = common_frame_inertia(model.body[i], cf.R[i], cf.p[i], name);
  }
  return cf;
}

}  // namespace hamel::rbd
