#include "rbd/aba.hpp"

#include "rbd/rnea.hpp"

namespace hamel::rbd {

ArticulatedFactor articulated_factor(const FrameView& view, const Namer<Ex>& name) {
  const TreeModel& model = view.model();
  const std::size_t N = view.size(), m = model.base.size();
  const bool local = view.convention() == Frame::local;
  std::vector<Mat6<Ex>> IA(N);
  std::vector<bool> inner(N, false);  // has children: its 𝕀ᴬ is a sum, named
  for (std::size_t i = 0; i < N; ++i) {
    IA[i] = view.inertia(i).matrix();
    if (i > 0) inner[static_cast<std::size_t>(model.parent[i])] = true;
  }
  ArticulatedFactor f;
  f.U.assign(N, zero6<Ex>());
  f.W.assign(N, zero6<Ex>());
  f.D.assign(N, Ex(0));
  f.inverse_D.assign(N, Ex(0));
  if (local) f.passed.resize(N);
  for (std::size_t i = N; i-- > 1;) {
    if (inner[i]) IA[i] = name.symmetric(IA[i]);
    const Vec6<Ex>& s = view.axis(i);
    const Vec6<Ex> U = f.U[i] = name(times(IA[i], s));
    f.D[i] = name(dot(s, U) + model.armature[i]);
    const Ex inverse_D = f.inverse_D[i] = name(1 / f.D[i]);
    f.W[i] = name(U * inverse_D);
    const std::size_t l = static_cast<std::size_t>(model.parent[i]);
    if (l == 0 && m == 0) continue;  // a fixed base takes nothing
    const Mat6<Ex> passed = articulated_remainder(IA[i], U, f.W[i]);
    if (local) {
      f.passed[i] = name.symmetric(passed);
      IA[l] = IA[l] + inertia_to_parent(model.link[i], f.passed[i], name);
    } else {
      IA[l] = IA[l] + passed;
    }
  }
  if (m > 0) {
    f.base = IA[0] = name.symmetric(IA[0]);
    f.base_inertia.assign(m, std::vector<Ex>(m));
    for (std::size_t alpha = 0; alpha < m; ++alpha)
      for (std::size_t beta = 0; beta < m; ++beta)
        f.base_inertia[alpha][beta] = dot(model.base[alpha], times(IA[0], model.base[beta]));
  }
  return f;
}

ForwardDynamics forward_dynamics(const TreeDynamics& tree, const Namer<Ex>& name) {
  const TreeModel& t = tree.model;
  const FrameView local(t);
  const std::size_t N = t.size(), m = t.base.size();
  const ArticulatedFactor factor = articulated_factor(local, name);
  ArticulatedSystem<Ex> sys{t.parent,
                            t.axis,
                            factor.U,
                            factor.W,
                            factor.inverse_D,
                            t.base,
                            factor.base_inertia,
                            [&t](std::size_t i, const Vec6<Ex>& v) { return t.link[i].to_child(v); },
                            [&t](std::size_t i, const Vec6<Ex>& f) { return t.link[i].to_parent(f); },
                            {},
                            {}};
  ArticulatedBias<Ex> bias;
  for (std::size_t i = 0; i < N; ++i) bias.force.push_back(coadjoint_term(tree.local_twist[i], tree.local_momentum[i]));
  bias.force = with_applied(local, bias.force);
  for (std::size_t i = 0; i < N; ++i)
    bias.acceleration.push_back(i == 0 ? zero6<Ex>() : name(tree.local_axis_rate[i] * tree.rates[i - 1]));
  bias.passed = factor.passed;
  bool gravity = false;
  for (const Ex& g : t.root_acceleration) gravity = gravity || !g.is_zero();
  if (gravity) bias.root = {t.root_acceleration};
  if (gravity && m > 0) bias.root_inertia = {factor.base};
  std::vector<Ex> b(m, Ex(0));
  b.insert(b.end(), tree.joint_force.begin(), tree.joint_force.end());
  ForwardDynamics out;
  for (std::size_t i = N; i-- > 1;) out.pivots.push_back(factor.D[i]);
  out.accelerations = articulated_solve(sys, {b}, {}, name, {}, bias, &out.pivots).front();
  return out;
}

}  // namespace hamel::rbd
