#include "rbd/rnea_derivatives.hpp"

#include "rbd/rnea.hpp"

namespace hamel::rbd {

namespace {

// Q + Qᵀ for Q = [v ×*] 𝕀 (column k of Q is v ×* (𝕀 e_k)): symmetric, and all the derivatives need of Q.
Mat6<Ex> velocity_times_inertia_symmetrized(const Vec6<Ex>& v, const Inertia<Ex>& I) {
  Mat6<Ex> Q;
  for (int k = 0; k < 6; ++k) {
    const Vec6<Ex> column = coadjoint_term(v, I(unit6<Ex>(k)));
    for (std::size_t r = 0; r < 6; ++r) Q[r][static_cast<std::size_t>(k)] = column[r];
  }
  Mat6<Ex> S;
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t k = r; k < 6; ++k) S[r][k] = S[k][r] = Q[r][k] + Q[k][r];
  return S;
}

bool in_subtree(const TreeModel& t, std::size_t i, std::size_t k) {  // i = k or a descendant of k
  for (int j = static_cast<int>(i); j >= 0; j = t.parent[static_cast<std::size_t>(j)])
    if (static_cast<std::size_t>(j) == k) return true;
  return false;
}

}  // namespace

bool InverseDynamicsJacobian::inside(const TreeModel& t, std::size_t i, std::size_t k) const {
  return in_subtree(t, i, columns[k].body);
}

std::vector<Ex> InverseDynamicsJacobian::rows(const TreeDynamics& t, std::size_t k) const {
  const std::size_t m = t.model.base.size(), N = t.model.size();
  const Column& c = columns[k];
  std::vector<Ex> column(m + N - 1, Ex(0));
  for (std::size_t beta = 0; beta < m; ++beta) {
    if (c.body == 0) column[beta] = dot(t.model.base[beta], c.Delta);
    column[beta] -= c.force[beta];
  }
  for (std::size_t i = 1; i < N; ++i) {
    if (inside(t.model, i, k)) column[m + i - 1] = dot(u[i], c.P) + dot(b[i], c.V);
    column[m + i - 1] -= c.force[m + i - 1];
  }
  return column;
}

std::vector<std::vector<Ex>> InverseDynamicsJacobian::dense(const TreeDynamics& t) const {
  const std::size_t m = t.model.base.size();
  std::vector<std::vector<Ex>> out;
  for (std::size_t k = 0; k < columns.size(); ++k) {
    out.push_back(rows(t, k));
    const std::size_t K = columns[k].body;
    if (K == 0) continue;
    for (std::size_t beta = 0; beta < m; ++beta) out[k][beta] += dot(t.model.base[beta], inward(k));
    for (int i = t.model.parent[K]; i > 0; i = t.model.parent[static_cast<std::size_t>(i)])
      out[k][m + static_cast<std::size_t>(i) - 1] += dot(t.frame.axis[static_cast<std::size_t>(i)], inward(k));
  }
  return out;
}

InverseDynamicsJacobian InverseDynamicsJacobian::negated(Intermediates& tape) const {
  const Namer<Ex> name([&tape](const Ex& e) { return tape.define(e); });
  InverseDynamicsJacobian out{u, b, {}};
  for (const Column& c : columns) {
    Column minus{c.body, name(c.P * Ex(-1)), name(c.V * Ex(-1)), name(c.Delta * Ex(-1)), {}};
    for (const Ex& f : c.force) minus.force.push_back(-f);
    out.columns.push_back(minus);
  }
  return out;
}

InverseDynamicsJacobian rnea_derivatives(const TreeDynamics& t, Intermediates& tape) {
  const Namer<Ex> name([&tape](const Ex& e) { return tape.define(e); });
  const TreeModel& model = t.model;
  const std::size_t N = model.size(), m = model.base.size();

  // Forward, in the common frame, at u̇ = accelerations; also c_i = a_λ × s_i + v_λ × ψ_i and Q_i + Q_iᵀ.
  const FrameView view(model, t.frame, name);
  const std::vector<Vec6<Ex>>& s = t.frame.axis;
  const std::vector<Inertia<Ex>>& I = t.frame.inertia;
  const std::vector<Inertia<Ex>>& Ic = t.frame.composite;
  const std::vector<Ex> base_acceleration(t.accelerations.begin(), t.accelerations.begin() + static_cast<long>(m));
  const std::vector<Ex> joint_acceleration(t.accelerations.begin() + static_cast<long>(m), t.accelerations.end());
  const Motion motion = rnea_motion(view, t.base_velocity, t.rates, base_acceleration, joint_acceleration, name);
  const std::vector<Vec6<Ex>>&v = motion.v, &a = motion.a, &psi = motion.psi, &h = motion.h, &f = motion.f;
  std::vector<Vec6<Ex>> c(N);
  std::vector<Mat6<Ex>> S(N);  // Q_i + Q_iᵀ
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t l = static_cast<std::size_t>(model.parent[i]);
      c[i] = name(ad(a[l], s[i]) + ad(v[l], psi[i]));
    }
    S[i] = velocity_times_inertia_symmetrized(v[i], I[i]);
  }

  // Backward: composite wrenches, momenta and Q + Qᵀ over each subtree (plain sums), named once per body.
  std::vector<Vec6<Ex>> Fc = f, Hc = h;
  std::vector<Mat6<Ex>> Sc = S;
  for (std::size_t i = N; i-- > 0;) {
    if (i == 0 && m == 0) break;  // a fixed base's composites are not used
    Fc[i] = name(Fc[i]);
    Hc[i] = name(Hc[i]);
    Sc[i] = name.symmetric(Sc[i]);
    if (i == 0) break;
    const std::size_t l = static_cast<std::size_t>(model.parent[i]);
    Fc[l] = Fc[l] + Fc[i];
    Hc[l] = Hc[l] + Hc[i];
    Sc[l] = Sc[l] + Sc[i];
  }
  // Bᶜ_i x = (Qᶜ + Qᶜᵀ) x + x ×* hᶜ.
  const auto B = [&](std::size_t i, const Vec6<Ex>& x) { return times(Sc[i], x) + coadjoint_term(x, Hc[i]); };

  // Per joint: u = 𝕀ᶜ s, b = Bᶜᵀ s = Qᶜ s + Qᶜᵀ s − s ×* hᶜ, and what an ancestor's row sees of the subtree:
  // Δ (for r_i) and Δ' (for ṙ_i).
  InverseDynamicsJacobian out;
  out.u.assign(N, zero6<Ex>());
  out.b.assign(N, zero6<Ex>());
  std::vector<Vec6<Ex>> delta(N), delta_rate(N), twice_psi(N);
  for (std::size_t i = 1; i < N; ++i) {
    twice_psi[i] = name(psi[i] * Ex(2));  // named, so that 2 is not multiplied into every product that reads it
    out.u[i] = name(Ic[i](s[i]));
    const Vec6<Ex> Qs = name(times(Sc[i], s[i]));
    const Vec6<Ex> sh = name(coadjoint_term(s[i], Hc[i]));
    out.b[i] = name(Qs - sh);
    delta[i] = name(coadjoint_term(s[i], Fc[i]) + Ic[i](c[i]) + B(i, psi[i]));
    delta_rate[i] = name(Ic[i](twice_psi[i]) + Qs + sh);
  }

  // Joint K's angle: rows in K's subtree ⟨u_I, c_K⟩ + ⟨b_I, ψ_K⟩, the others see Δ_K. A base velocity: every body
  // moves with the base, rows I see 𝕀ᶜ_I ψ + Bᶜ_I e with ψ = v_0 × e (no bias on the base itself). Joint K's rate:
  // 2⟨u_I, ψ_K⟩ + ⟨b_I, s_K⟩ inside, Δ'_K outside.
  std::vector<Ex> state;
  for (std::size_t K = 1; K < N; ++K) {
    out.columns.push_back({K, c[K], psi[K], delta[K], {}});
    state.push_back(t.coordinates[K - 1]);
  }
  // Γ_k (gravity in the base's frame, in the state after r): it moves every body's acceleration by
  // ∂a_0/∂Γ_k = (0, −e_k), so rows I see 𝕀ᶜ_I (0, −e_k) and the base 𝕀ᶜ_0 (0, −e_k).
  for (std::size_t k = 0; k < t.gravity_state.size(); ++k) {
    Vec6<Ex> P = zero6<Ex>();
    P[3 + k] = -1;
    out.columns.push_back({0, P, zero6<Ex>(), name(Ic[0](P)), {}});
    state.push_back(t.gravity_state[k]);
  }
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    const Vec6<Ex>& e = model.base[alpha];
    const Vec6<Ex> psi0 = name(ad(v[0], e));
    out.columns.push_back({0, psi0, e, Ic[0](psi0) + B(0, e), {}});
    state.push_back(t.base_velocity[alpha]);
  }
  for (std::size_t K = 1; K < N; ++K) {
    out.columns.push_back({K, twice_psi[K], s[K], delta_rate[K], {}});
    state.push_back(t.rates[K - 1]);
  }

  // The generalized forces: ID = … − Q.
  for (std::size_t k = 0; k < out.columns.size(); ++k) {
    const GiNaC::symbol& x = GiNaC::ex_to<GiNaC::symbol>(state[k]);
    for (const Ex& q : t.generalized_force) out.columns[k].force.push_back(tape.diff(q, x));
  }
  return out;
}

}  // namespace hamel::rbd
