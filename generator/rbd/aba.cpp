#include "rbd/aba.hpp"

#include "rbd/rnea.hpp"

namespace hamel::rbd {

namespace {

// k when s = c e_k (one nonzero entry, a number), else −1.
int coordinate_axis(const Vec6<Ex>& s) {
  int k = -1;
  for (std::size_t j = 0; j < 6; ++j) {
    if (s[j].is_zero()) continue;
    if (k >= 0 || !GiNaC::is_a<GiNaC::numeric>(s[j])) return -1;
    k = static_cast<int>(j);
  }
  return k;
}

// v ×* 𝕀 v, the velocity-product wrench of a rigid body at twist V = (ω, v), from its data about the centre of mass
// c: with p = m (v + ω × c) and f = ω × p it is (ω × Θ ω + c × f, f) about the frame's origin (𝕀 V = (Θ ω + c × p,
// p), and ω × (c × p) + v × p = c × (ω × p) by Jacobi's identity, v × p being −(ω × c) × p). Fewer operations than
// through 𝕀 about the origin (coadjoint_term of the momentum).
Vec6<Ex> velocity_product_wrench(const BodyInertia& b, const Vec6<Ex>& V, const Namer<Ex>& name) {
  const Vec3<Ex> w = angular(V), v = linear(V), c = b.com;
  const Vec3<Ex> wc = cross(w, c);
  const Vec3<Ex> p = name(Vec3<Ex>{b.mass * (v[0] + wc[0]), b.mass * (v[1] + wc[1]), b.mass * (v[2] + wc[2])});
  const Vec3<Ex> f = name(cross(w, p));
  return join(cross(w, name(b.rotational * w)) + cross(c, f), f);
}

}  // namespace

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
    // s = c e_k without armature: W_k = 1/c and 𝕀ᵃ's row and column k vanish (𝕀ᵃ s = U − U ⟨W, s⟩ = 0), exactly
    // rather than as U_k (1/D) − 1 in the program.
    const int k = model.armature[i].is_zero() ? coordinate_axis(s) : -1;
    if (k >= 0) f.W[i][static_cast<std::size_t>(k)] = 1 / s[static_cast<std::size_t>(k)];
    const std::size_t l = static_cast<std::size_t>(model.parent[i]);
    if (l == 0 && m == 0) continue;  // a fixed base takes nothing
    Mat6<Ex> passed = articulated_remainder(IA[i], U, f.W[i]);
    if (k >= 0)
      for (std::size_t j = 0; j < 6; ++j)
        passed[j][static_cast<std::size_t>(k)] = passed[static_cast<std::size_t>(k)][j] = 0;
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
  for (std::size_t i = 0; i < N; ++i)
    bias.force.push_back(velocity_product_wrench(t.body[i], tree.local_twist[i], name));
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
