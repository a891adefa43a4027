#include "derive/tree_derivatives.hpp"

namespace hamel {

using GiNaC::ex;
using namespace spatial;

namespace {

// The body's inertia in the common frame, the body at pose (R, p): centre of mass c = p + R c_b, rotational
// inertia about it R Θ Rᵀ, about the origin J = R Θ Rᵀ − m [c]×².
Inertia common_frame_inertia(const RigidBody& b, const Mat3& R, const Vec3& p, Namer& name) {
  const Vec3 c = name(p + R * Vec3{b.com[0], b.com[1], b.com[2]});
  Mat3 RT;  // R Θ
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k)
      RT[r][k] = R[r][0] * b.inertia[0][k] + R[r][1] * b.inertia[1][k] + R[r][2] * b.inertia[2][k];
  Inertia I;
  I.m = b.mass;
  for (std::size_t r = 0; r < 3; ++r) I.h[r] = b.mass * c[r];
  const ex cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = r; k < 3; ++k) {
      const ex rotational = RT[r][0] * R[k][0] + RT[r][1] * R[k][1] + RT[r][2] * R[k][2];
      I.J[r][k] = I.J[k][r] = rotational + b.mass * ((r == k ? cc : ex(0)) - c[r] * c[k]);
    }
  return name(I);
}

// Q + Qᵀ for Q = [v ×*] 𝕀 (column k of Q is v ×* (𝕀 e_k)): symmetric, and all the derivatives need of Q.
Mat6 velocity_times_inertia_symmetrized(const Vec6& v, const Inertia& I) {
  Mat6 Q;
  for (int k = 0; k < 6; ++k) {
    const Vec6 column = coadjoint_term(v, I(unit6(k)));
    for (std::size_t r = 0; r < 6; ++r) Q[r][static_cast<std::size_t>(k)] = column[r];
  }
  Mat6 S;
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t k = r; k < 6; ++k) S[r][k] = S[k][r] = Q[r][k] + Q[k][r];
  return S;
}

}  // namespace

CommonFrame common_frame(const TreeRecursion& t, Intermediates& tape) {
  Namer name(tape);
  const std::size_t N = t.parent.size();
  CommonFrame cf;
  cf.R.resize(N);
  cf.p.resize(N);
  cf.axis.assign(N, zero6());
  cf.inertia.resize(N);
  cf.R[0] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  cf.p[0] = {0, 0, 0};
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(t.parent[i]);
      const Link& link = t.link[i];
      Mat3 R;
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t k = 0; k < 3; ++k)
          R[r][k] = cf.R[l][r][0] * link.R[0][k] + cf.R[l][r][1] * link.R[1][k] + cf.R[l][r][2] * link.R[2][k];
      cf.R[i] = name(R);
      cf.p[i] = name(cf.p[l] + cf.R[l] * link.p);
      cf.axis[i] = name(Link{cf.R[i], cf.p[i]}.motion_to_parent(t.axis[i]));
    }
    cf.inertia[i] = common_frame_inertia(t.bodies[i], cf.R[i], cf.p[i], name);
  }
  // Composites from the leaves in (children come after their parents); a fixed base's is not needed.
  cf.composite = cf.inertia;
  for (std::size_t i = N; i-- > 0;) {
    if (i == 0 && t.base.empty()) break;
    cf.composite[i] = name(cf.composite[i]);
    if (i > 0) cf.composite[static_cast<std::size_t>(t.parent[i])].add(cf.composite[i]);
  }
  return cf;
}

ArticulatedFactor articulated_factor(const TreeRecursion& t, Intermediates& tape) {
  Namer name(tape);
  const std::size_t N = t.parent.size(), m = t.base.size();
  const std::vector<Vec6>& s = t.frame.axis;
  std::vector<Mat6> IA(N);
  std::vector<bool> inner(N, false);  // has children: its 𝕀ᴬ is a sum, named
  for (std::size_t i = 0; i < N; ++i) {
    IA[i] = t.frame.inertia[i].matrix();
    if (i > 0) inner[static_cast<std::size_t>(t.parent[i])] = true;
  }
  ArticulatedFactor f;
  f.U.assign(N, zero6());
  f.W.assign(N, zero6());
  f.inverse_pivot.assign(N, ex(0));
  for (std::size_t i = N; i-- > 1;) {
    if (inner[i]) IA[i] = name.symmetric(IA[i]);
    const Vec6 U = f.U[i] = name(times(IA[i], s[i]));
    const ex inverse_D = f.inverse_pivot[i] = name(1 / name(dot(s[i], U) + t.armature[i - 1]));
    const std::size_t l = static_cast<std::size_t>(t.parent[i]);
    f.W[i] = name(U * inverse_D);
    if (l == 0 && m == 0) continue;  // a fixed base takes nothing
    IA[l] = IA[l] + articulated_remainder(IA[i], U, f.W[i]);
  }
  if (m > 0) {
    IA[0] = name.symmetric(IA[0]);
    f.base_inertia.assign(m, std::vector<ex>(m));
    for (std::size_t alpha = 0; alpha < m; ++alpha)
      for (std::size_t beta = 0; beta < m; ++beta)
        f.base_inertia[alpha][beta] = dot(t.base[alpha], times(IA[0], t.base[beta]));
  }
  return f;
}

namespace {

// The motion in the common frame at u̇ = `accelerations` (m + n: base directions, then joints): twists
// v_i = v_λ + s_i ṙ_i, ψ_i = v_λ × s_i (= v_i × s_i, the rate of s_i), accelerations a_i = a_λ + s_i u̇_i + ψ_i ṙ_i
// from the base's Σ e_α u̇_α + (0, −g), momenta h_i = 𝕀_i v_i and wrenches f_i = 𝕀_i a_i + v_i ×* h_i (not named).
struct CommonFrameMotion {
  std::vector<Vec6> v, a, psi, h, f;
};

CommonFrameMotion common_frame_motion(const TreeRecursion& t, const std::vector<ex>& accelerations, Namer& name) {
  const std::size_t N = t.parent.size(), m = t.base.size();
  const std::vector<Vec6>& s = t.frame.axis;
  const std::vector<Inertia>& I = t.frame.inertia;
  CommonFrameMotion out{std::vector<Vec6>(N), std::vector<Vec6>(N), std::vector<Vec6>(N), std::vector<Vec6>(N),
                        std::vector<Vec6>(N)};
  std::vector<Vec6>&v = out.v, &a = out.a, &psi = out.psi;
  v[0] = zero6();
  a[0] = t.base_acceleration;
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    v[0] = v[0] + t.base[alpha] * t.base_velocity[alpha];
    a[0] = a[0] + t.base[alpha] * accelerations[alpha];
  }
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(t.parent[i]);
      psi[i] = name(ad(v[l], s[i]));
      v[i] = name(v[l] + s[i] * t.rates[i - 1]);
      a[i] = name(a[l] + s[i] * accelerations[m + i - 1] + psi[i] * t.rates[i - 1]);
    }
    out.h[i] = name(I[i](v[i]));
    out.f[i] = I[i](a[i]) + coadjoint_term(v[i], out.h[i]);
  }
  return out;
}

bool in_subtree(const TreeRecursion& t, std::size_t i, std::size_t k) {  // i = k or a descendant of k
  for (int j = static_cast<int>(i); j >= 0; j = t.parent[static_cast<std::size_t>(j)])
    if (static_cast<std::size_t>(j) == k) return true;
  return false;
}

}  // namespace

bool InverseDynamicsJacobian::inside(const TreeRecursion& t, std::size_t i, std::size_t k) const {
  return in_subtree(t, i, columns[k].body);
}

std::vector<ex> InverseDynamicsJacobian::rows(const TreeRecursion& t, std::size_t k) const {
  const std::size_t m = t.base.size(), N = t.parent.size();
  const Column& c = columns[k];
  std::vector<ex> column(m + N - 1, ex(0));
  if (c.body == 0)
    for (std::size_t beta = 0; beta < m; ++beta) column[beta] = dot(t.base[beta], c.Delta);
  for (std::size_t i = 1; i < N; ++i) {
    if (inside(t, i, k)) column[m + i - 1] = dot(u[i], c.P) + dot(b[i], c.V);
    column[m + i - 1] -= c.force[i - 1];
  }
  return column;
}

std::vector<std::vector<ex>> InverseDynamicsJacobian::dense(const TreeRecursion& t) const {
  const std::size_t m = t.base.size();
  std::vector<std::vector<ex>> out;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    out.push_back(rows(t, k));
    const std::size_t K = columns[k].body;
    if (K == 0) continue;
    for (std::size_t beta = 0; beta < m; ++beta) out[k][beta] += dot(t.base[beta], inward(k));
    for (int i = t.parent[K]; i > 0; i = t.parent[static_cast<std::size_t>(i)])
      out[k][m + static_cast<std::size_t>(i) - 1] += dot(t.frame.axis[static_cast<std::size_t>(i)], inward(k));
  }
  return out;
}

InverseDynamicsJacobian InverseDynamicsJacobian::negated(Intermediates& tape) const {
  Namer name(tape);
  InverseDynamicsJacobian out{u, b, {}};
  for (const Column& c : columns) {
    Column minus{c.body, name(c.P * -1), name(c.V * -1), name(c.Delta * -1), {}};
    for (const ex& f : c.force) minus.force.push_back(-f);
    out.columns.push_back(minus);
  }
  return out;
}

InverseDynamicsJacobian inverse_dynamics_jacobian(const TreeRecursion& t, Intermediates& tape) {
  Namer name(tape);
  const std::size_t N = t.parent.size(), m = t.base.size(), n = N - 1;

  // Forward, in the common frame (t.frame: poses, axes s_i, inertias), at u̇ = accelerations; also
  // c_i = a_λ × s_i + v_λ × ψ_i and Q_i + Q_iᵀ.
  const std::vector<Vec6>& s = t.frame.axis;
  const std::vector<Inertia>& I = t.frame.inertia;
  const std::vector<Inertia>& Ic = t.frame.composite;
  const CommonFrameMotion motion = common_frame_motion(t, t.accelerations, name);
  const std::vector<Vec6>&v = motion.v, &a = motion.a, &psi = motion.psi, &h = motion.h, &f = motion.f;
  std::vector<Vec6> c(N);
  std::vector<Mat6> S(N);  // Q_i + Q_iᵀ
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(t.parent[i]);
      c[i] = name(ad(a[l], s[i]) + ad(v[l], psi[i]));
    }
    S[i] = velocity_times_inertia_symmetrized(v[i], I[i]);
  }

  // Backward: composite wrenches, momenta and Q + Qᵀ over each subtree (plain sums), named once per body.
  std::vector<Vec6> Fc = f, Hc = h;
  std::vector<Mat6> Sc = S;
  for (std::size_t i = N; i-- > 0;) {
    if (i == 0 && m == 0) break;  // a fixed base's composites are not used
    Fc[i] = name(Fc[i]);
    Hc[i] = name(Hc[i]);
    Sc[i] = name.symmetric(Sc[i]);
    if (i == 0) break;
    const std::size_t l = static_cast<std::size_t>(t.parent[i]);
    Fc[l] = Fc[l] + Fc[i];
    Hc[l] = Hc[l] + Hc[i];
    Sc[l] = Sc[l] + Sc[i];
  }
  // Bᶜ_i x = (Qᶜ + Qᶜᵀ) x + x ×* hᶜ.
  const auto B = [&](std::size_t i, const Vec6& x) { return times(Sc[i], x) + coadjoint_term(x, Hc[i]); };

  // Per joint: u = 𝕀ᶜ s, b = Bᶜᵀ s = Qᶜ s + Qᶜᵀ s − s ×* hᶜ, and what an ancestor's row sees of the subtree:
  // Δ (for r_i) and Δ' (for ṙ_i).
  InverseDynamicsJacobian out;
  out.u.assign(N, zero6());
  out.b.assign(N, zero6());
  std::vector<Vec6> delta(N), delta_rate(N), twice_psi(N);
  for (std::size_t i = 1; i < N; ++i) {
    twice_psi[i] = name(psi[i] * 2);  // named, so that 2 is not multiplied into every product that reads it
    out.u[i] = name(Ic[i](s[i]));
    const Vec6 Qs = name(times(Sc[i], s[i]));
    const Vec6 sh = name(coadjoint_term(s[i], Hc[i]));
    out.b[i] = name(Qs - sh);
    delta[i] = name(coadjoint_term(s[i], Fc[i]) + Ic[i](c[i]) + B(i, psi[i]));
    delta_rate[i] = name(Ic[i](twice_psi[i]) + Qs + sh);
  }

  // Joint K's angle: rows in K's subtree ⟨u_I, c_K⟩ + ⟨b_I, ψ_K⟩, the others see Δ_K. A base velocity: every body
  // moves with the base, rows I see 𝕀ᶜ_I ψ + Bᶜ_I e with ψ = v_0 × e (no bias on the base itself). Joint K's rate:
  // 2⟨u_I, ψ_K⟩ + ⟨b_I, s_K⟩ inside, Δ'_K outside.
  std::vector<ex> state;
  for (std::size_t K = 1; K < N; ++K) {
    out.columns.push_back({K, c[K], psi[K], delta[K], {}});
    state.push_back(t.coordinates[K - 1]);
  }
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    const Vec6& e = t.base[alpha];
    const Vec6 psi0 = name(ad(v[0], e));
    out.columns.push_back({0, psi0, e, Ic[0](psi0) + B(0, e), {}});
    state.push_back(t.base_velocity[alpha]);
  }
  for (std::size_t K = 1; K < N; ++K) {
    out.columns.push_back({K, twice_psi[K], s[K], delta_rate[K], {}});
    state.push_back(t.rates[K - 1]);
  }

  // The joint forces: ID_I = ⟨s_I, Fᶜ_I⟩ + armature_I u̇_I − τ_I.
  for (std::size_t k = 0; k < out.columns.size(); ++k) {
    const GiNaC::symbol& x = GiNaC::ex_to<GiNaC::symbol>(state[k]);
    for (std::size_t i = 0; i < n; ++i) out.columns[k].force.push_back(tape.diff(t.joint_force[i], x));
  }
  return out;
}

std::vector<ex> bias_forcing(const TreeRecursion& t, Intermediates& tape) {
  Namer name(tape);
  const std::size_t N = t.parent.size(), m = t.base.size();
  const std::vector<Vec6>& s = t.frame.axis;
  std::vector<Vec6> F = common_frame_motion(t, std::vector<ex>(m + N - 1, ex(0)), name).f;
  for (std::size_t i = N; i-- > 0;) {
    if (i == 0 && m == 0) break;
    F[i] = name(F[i]);
    if (i > 0) F[static_cast<std::size_t>(t.parent[i])] = F[static_cast<std::size_t>(t.parent[i])] + F[i];
  }
  std::vector<ex> f(m + N - 1);
  for (std::size_t alpha = 0; alpha < m; ++alpha) f[alpha] = -dot(t.base[alpha], F[0]);
  for (std::size_t i = 1; i < N; ++i) f[m + i - 1] = t.joint_force[i - 1] - dot(s[i], F[i]);
  return f;
}

}  // namespace hamel
