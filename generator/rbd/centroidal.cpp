#include "rbd/centroidal.hpp"

#include "rbd/rnea.hpp"

namespace hamel::rbd {

CentroidalMomentum centroidal_momentum(const TreeDynamics& tree, const Namer<Ex>& name) {
  const TreeModel& model = tree.model;
  const FrameView world(model, tree.frame, name);
  const Motion motion = rnea_motion(world, tree.base_velocity, tree.rates, {}, {}, name);
  CentroidalMomentum out{zero6<Ex>(), {Ex(0), Ex(0), Ex(0)}, Ex(0)};
  Vec3<Ex> first{Ex(0), Ex(0), Ex(0)};  // Σ m_i c_i
  for (std::size_t i = model.fixed_base() ? 1 : 0; i < model.size(); ++i) {
    const Inertia<Ex>& inertia = world.inertia(i);
    out.mass = out.mass + inertia.m;
    for (std::size_t k = 0; k < 3; ++k) first[k] = first[k] + inertia.h[k];
    out.momentum = out.momentum + motion.h[i];
  }
  out.mass = name(out.mass);
  const Ex inverse_mass = name(1 / out.mass);
  for (std::size_t k = 0; k < 3; ++k) out.com[k] = name(first[k] * inverse_mass);
  const Vec3<Ex> p = name(linear(out.momentum)), L_O = name(angular(out.momentum));
  const Vec3<Ex> c_x_p = cross(out.com, p);
  out.momentum = join(Vec3<Ex>{L_O[0] - c_x_p[0], L_O[1] - c_x_p[1], L_O[2] - c_x_p[2]}, p);
  return out;
}

}  // namespace hamel::rbd
