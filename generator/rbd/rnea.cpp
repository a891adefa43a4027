#include "rbd/rnea.hpp"

namespace hamel::rbd {

Motion rnea_motion(const FrameView& view, const std::vector<Ex>& base_velocity, const std::vector<Ex>& rates,
                   const std::vector<Ex>& base_acceleration, const std::vector<Ex>& joint_acceleration,
                   const Namer<Ex>& name) {
  const TreeModel& model = view.model();
  const std::size_t N = view.size(), m = model.base.size();
  Motion out{std::vector<Vec6<Ex>>(N), std::vector<Vec6<Ex>>(N, zero6<Ex>()), std::vector<Vec6<Ex>>(N),
             std::vector<Vec6<Ex>>(N), std::vector<Vec6<Ex>>(N)};
  out.v[0] = zero6<Ex>();
  out.a[0] = model.root_acceleration;
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    out.v[0] = out.v[0] + model.base[alpha] * base_velocity[alpha];
    if (!base_acceleration.empty()) out.a[0] = out.a[0] + model.base[alpha] * base_acceleration[alpha];
  }
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(view.parent(i));
      const Vec6<Ex>& s = view.axis(i);
      const Vec6<Ex> seen = view.motion_from_parent(i, out.v[l]);  // the parent's twist in body i's frame
      out.v[i] = name(seen + s * rates[i - 1]);
      // ψ_i = v_i × S_i = (X_i v_λ) × S_i (S_i × S_i = 0): in the bodies' frames from v_i, whose entries are named
      // (a unit S_i picks them out); in the common frame from v_λ, named, so that ψ_i does not wait for v_i.
      out.psi[i] = view.convention() == Frame::local ? ad(out.v[i], s) : name(ad(seen, s));
      Vec6<Ex> a = view.motion_from_parent(i, out.a[l]);
      if (!joint_acceleration.empty()) a = a + s * joint_acceleration[i - 1];
      out.a[i] = name(a + out.psi[i] * rates[i - 1]);
    }
    const Inertia<Ex>& I = view.inertia(i);
    out.h[i] = name(I(out.v[i]));
    out.f[i] = I(out.a[i]) + coadjoint_term(out.v[i], out.h[i]);
  }
  return out;
}

std::vector<Vec6<Ex>> with_applied(const FrameView& view, std::vector<Vec6<Ex>> f) {
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!view.external(i)[0].is_zero() || !view.external(i)[1].is_zero() || !view.external(i)[2].is_zero() ||
        !view.external(i)[3].is_zero() || !view.external(i)[4].is_zero() || !view.external(i)[5].is_zero())
      f[i] = f[i] - view.external(i);
  return f;
}

std::vector<Vec6<Ex>> rnea_forces(const FrameView& view, std::vector<Vec6<Ex>> F, const Namer<Ex>& name) {
  for (std::size_t i = view.size(); i-- > 0;) {  // children come after their parents
    if (i == 0 && view.model().fixed_base()) break;
    F[i] = name(F[i]);
    if (i == 0) break;
    const std::size_t l = static_cast<std::size_t>(view.parent(i));
    F[l] = F[l] + view.force_to_parent(i, F[i]);
  }
  return F;
}

std::vector<Ex> forcing(const FrameView& view, const std::vector<Vec6<Ex>>& F, const std::vector<Ex>& joint_force) {
  const TreeModel& model = view.model();
  const std::size_t N = view.size(), m = model.base.size();
  std::vector<Ex> f(m + N - 1);
  for (std::size_t alpha = 0; alpha < m; ++alpha) f[alpha] = -dot(model.base[alpha], F[0]);
  for (std::size_t i = 1; i < N; ++i) f[m + i - 1] = joint_force[i - 1] - dot(view.axis(i), F[i]);
  return f;
}

std::vector<Ex> applied_generalized_forces(const FrameView& view, const Namer<Ex>& name) {
  const TreeModel& model = view.model();
  const std::size_t N = view.size(), m = model.base.size();
  std::vector<Vec6<Ex>> F(N);
  for (std::size_t i = 0; i < N; ++i) F[i] = view.external(i);
  F = rnea_forces(view, F, name);
  std::vector<Ex> Q(m + N - 1);
  for (std::size_t alpha = 0; alpha < m; ++alpha) Q[alpha] = dot(model.base[alpha], F[0]);
  for (std::size_t i = 1; i < N; ++i) Q[m + i - 1] = dot(view.axis(i), F[i]);
  return Q;
}

namespace {

// −ID(r, u, u̇) + τ in the common frame with base accelerations ξ̇ and joint accelerations r̈ (both empty: zero).
std::vector<Ex> forcing_at(const TreeDynamics& tree, const std::vector<Ex>& base_acceleration,
                           const std::vector<Ex>& joint_acceleration, const Namer<Ex>& name) {
  const FrameView view(tree.model, tree.frame, name);
  const Motion motion = rnea_motion(view, tree.base_velocity, tree.rates, base_acceleration, joint_acceleration, name);
  std::vector<Ex> f = forcing(view, rnea_forces(view, with_applied(view, motion.f), name), tree.joint_force);
  const std::size_t m = tree.model.base.size();
  for (std::size_t i = 0; i < joint_acceleration.size(); ++i)
    f[m + i] -= tree.model.armature[i + 1] * joint_acceleration[i];
  return f;
}

}  // namespace

std::vector<Ex> bias_forcing(const TreeDynamics& tree, const Namer<Ex>& name) { return forcing_at(tree, {}, {}, name); }

std::vector<Ex> residual_forcing(const TreeDynamics& tree, const Namer<Ex>& name) {
  const auto split = tree.accelerations.begin() + static_cast<long>(tree.model.base.size());
  return forcing_at(tree, {tree.accelerations.begin(), split}, {split, tree.accelerations.end()}, name);
}

}  // namespace hamel::rbd
