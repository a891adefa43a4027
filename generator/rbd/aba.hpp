// The articulated-body algorithm (Featherstone, Rigid Body Dynamics Algorithms, 2008, §7.3 and Table 7.1), in two
// halves:
//  - articulated_factor: from the leaves in, 𝕀ᴬ_i = 𝕀_i + Σ_children X_cᵀ 𝕀ᵃ_c X_c with U_i = 𝕀ᴬ_i S_i,
//    D_i = ⟨S_i, U_i⟩ + a_i (the armature), W_i = U_i / D_i and 𝕀ᵃ_i = 𝕀ᴬ_i − U_i W_iᵀ, and the floating base's block
//    ⟨e_α, 𝕀ᴬ_0 e_β⟩: a factorization of the mass matrix (GiNaC expressions, named);
//  - articulated_solve: for a right-hand side b (generalized forces, m + n rows) and optional velocity-product
//    terms, from the leaves in μ_i = (b_i − ⟨S_i, p_i⟩) / D_i and p_λ += X_iᵀ (p_i + 𝕀ᵃ_i c_i + U_i μ_i); the base's
//    m × m system by LDLᵀ; then outward a_i = X_i a_λ + c_i + S_i r̈_i with r̈_i = μ_i − ⟨W_i, X_i a_λ + c_i⟩.
//    Generic in the scalar: u̇ of rhs in the bodies' frames (expressions, with the bias terms p_i = v_i ×* 𝕀_i v_i
//    − f_ext,i and c_i = ψ_i ṙ_i of rbd/rnea.hpp, gravity as the base's upward acceleration), and M⁻¹ b for the
//    many columns of the Jacobian in the common frame (graph nodes, emit/graph_scalar.hpp).
// O(n) per solve; M is never formed.
#pragma once

#include "rbd/ldlt.hpp"
#include "rbd/tree.hpp"

#include <functional>
#include <vector>

namespace hamel::rbd {

/// The factor of a tree's mass matrix in the view's frame convention (expressions, named).
struct ArticulatedFactor {
  std::vector<Vec6<Ex>> U, W;    ///< per body i ≥ 1 (index 0 unused)
  std::vector<Ex> D, inverse_D;  ///< pivots D_i and 1 / D_i (index 0 unused)
  std::vector<Mat6<Ex>> passed;  ///< 𝕀ᵃ_i, what body i passes to its parent (Frame::local: named; else empty)
  Mat6<Ex> base;                 ///< 𝕀ᴬ_0 (floating base)
  std::vector<std::vector<Ex>> base_inertia;  ///< m × m: ⟨e_α, 𝕀ᴬ_0 e_β⟩
};

/// The factor of `view`'s tree. Articulated inertias of bodies with children are named once summed; in the bodies'
/// frames 𝕀ᵃ_i is named and moved to the parent's frame (inertia_to_parent), in the common frame it is added as it is.
ArticulatedFactor articulated_factor(const FrameView& view, const Namer<Ex>& name);

/// What articulated_solve reads: the factor and the tree's structure, as scalars of type S.
template <class S>
struct ArticulatedSystem {
  std::vector<int> parent;
  std::vector<Vec6<S>> s, U, W;  ///< joint axes in the convention's frame, U_i, W_i (index 0 unused)
  std::vector<S> inverse_D;
  std::vector<Vec6<S>> e;                    ///< the base's directions (empty: fixed base)
  std::vector<std::vector<S>> base_inertia;  ///< m × m
  /// Twists from the parent's frame into body i's, wrenches back; empty: the identity (Frame::world).
  std::function<Vec6<S>(std::size_t, const Vec6<S>&)> motion_from_parent, force_to_parent;
  /// Frame::world only, for short chains: σ_i = ⟨s_λ, U_i⟩ and ω_i = σ_i / D_i for a body whose parent λ is a joint.
  std::vector<S> sigma, omega;
};

/// The velocity-product and applied terms of a forward-dynamics solve (all optional).
template <class S>
struct ArticulatedBias {
  std::vector<Vec6<S>> force;         ///< p_i at the start: v_i ×* 𝕀_i v_i − f_ext,i (per body; empty: none)
  std::vector<Vec6<S>> acceleration;  ///< c_i = ψ_i ṙ_i (per body; empty: none)
  std::vector<Mat6<S>> passed;        ///< 𝕀ᵃ_i, which carries c_i inward (needed with `acceleration`)
  /// One element, or none: the base's acceleration at zero ξ̇ (gravity), and 𝕀ᴬ_0, which carries it into a
  /// floating base's equation (none on a fixed base).
  std::vector<Vec6<S>> root;
  std::vector<Mat6<S>> root_inertia;
};

/// A right-hand side that is a force entering at a body's parent (InverseDynamicsJacobian's Δ): beyond its listed
/// rows, b has −⟨s_I, force⟩ on the rows of the body's strict ancestors and −⟨e_α, force⟩ on the base's. Body 0: none.
template <class S>
struct InwardForce {
  std::size_t body = 0;
  Vec6<S> force;
};

struct ArticulatedSolveOptions {
  /// Frame::world without bias: ⟨s_i, p_i⟩ formed one level early, as ⟨s_i, q_i⟩ + Σ_c σ_c μ_c with q_i the
  /// children's p without their U_c μ_c, and ⟨W_i, a_λ⟩ as ⟨W_i, a_λλ⟩ + ω_i r̈_λ: μ and r̈ pass from body to body
  /// through one multiply-add instead of a whole dot product. The solve is a long chain of dependent operations,
  /// and this halves it (the Jacobian's columns); it costs a few additions per body.
  bool short_chains = false;
};

/// M y = b for every column b of `columns` (m + n rows: base directions, then joints), with `inward` forces (one per
/// column, or none) and `bias` (for u̇ itself: b the joint forces τ); `name` names μ_i, p_i, the accelerations and the
/// base's solve; the base's LDLᵀ pivots go to `pivots` when given.
template <class S>
std::vector<std::vector<S>> articulated_solve(const ArticulatedSystem<S>& sys,
                                              const std::vector<std::vector<S>>& columns,
                                              const ArticulatedSolveOptions& options, const Namer<S>& name,
                                              const std::vector<InwardForce<S>>& inward = {},
                                              const ArticulatedBias<S>& bias = {}, std::vector<S>* pivots = nullptr) {
  const std::size_t N = sys.parent.size(), m = sys.e.size();
  const auto from_parent = [&](std::size_t i, const Vec6<S>& v) {
    return sys.motion_from_parent ? sys.motion_from_parent(i, v) : v;
  };
  const auto to_parent = [&](std::size_t i, const Vec6<S>& f) {
    return sys.force_to_parent ? sys.force_to_parent(i, f) : f;
  };
  const bool short_chains = options.short_chains;
  const bool has_root = !bias.root.empty();

  // Inward, per column: μ_i and the base's right-hand side.
  std::vector<std::vector<S>> mu(columns.size(), std::vector<S>(N, S(0))), base_rhs(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const std::vector<S>& b = columns[c];
    std::vector<Vec6<S>> p = bias.force.empty() ? std::vector<Vec6<S>>(N, zero6<S>()) : bias.force;
    std::vector<Vec6<S>> q = p;   // short chains: p without the children's U_c μ_c
    std::vector<S> s_p(N, S(0));  // short chains: Σ_c σ_c μ_c
    if (!inward.empty() && inward[c].body > 0) {
      const std::size_t entry = static_cast<std::size_t>(sys.parent[inward[c].body]);
      p[entry] = q[entry] = inward[c].force;
    }
    for (std::size_t i = N; i-- > 1;) {
      p[i] = name(p[i]);  // read twice: by ⟨S_i, p_i⟩ and in what passes to the parent
      const S s_pi = short_chains ? paired_dot(sys.s[i], q[i]) + s_p[i] : paired_dot(sys.s[i], p[i]);
      mu[c][i] = name((b[m + i - 1] - s_pi) * sys.inverse_D[i]);
      const std::size_t l = static_cast<std::size_t>(sys.parent[i]);
      if (l == 0 && m == 0) continue;  // a fixed base takes nothing
      Vec6<S> pa = p[i];
      for (std::size_t k = 0; k < 6; ++k) pa[k] = pa[k] + sys.U[i][k] * mu[c][i];
      if (!bias.acceleration.empty()) pa = pa + times(bias.passed[i], bias.acceleration[i]);
      pa = to_parent(i, name(pa));
      for (std::size_t k = 0; k < 6; ++k) p[l][k] = p[l][k] + pa[k];
      if (!short_chains) continue;
      for (std::size_t k = 0; k < 6; ++k) q[l][k] = q[l][k] + p[i][k];
      s_p[l] = s_p[l] + sys.sigma[i] * mu[c][i];
    }
    if (m == 0) continue;
    Vec6<S> p0 = p[0];
    if (has_root) p0 = p0 + times(bias.root_inertia.front(), bias.root.front());
    p0 = name(p0);
    for (std::size_t alpha = 0; alpha < m; ++alpha) base_rhs[c].push_back(b[alpha] - paired_dot(sys.e[alpha], p0));
  }
  std::vector<std::vector<S>> base_rate(columns.size());
  if (m > 0) {
    LdltOptions<S> o;
    o.pivot = o.factor = o.forward = o.solution = name;
    o.numerator_products = short_chains;
    // Graph columns share one factor and divide in it; a derivation names 1/d with the pivot and only multiplies.
    o.reciprocal = short_chains ? LdltOptions<S>::Reciprocal::substitution : LdltOptions<S>::Reciprocal::everywhere;
    base_rate = ldlt_solve(sys.base_inertia, base_rhs, o, pivots);
  }

  // Outward: the base's acceleration (gravity, then its directions), then the joints'.
  std::vector<std::vector<S>> out(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    std::vector<Vec6<S>> a(N, zero6<S>());
    if (has_root) a[0] = bias.root.front();
    for (std::size_t alpha = 0; alpha < m; ++alpha)
      for (std::size_t k = 0; k < 6; ++k) a[0][k] = a[0][k] + sys.e[alpha][k] * base_rate[c][alpha];
    out[c] = base_rate[c];
    for (std::size_t i = 1; i < N; ++i) {
      const std::size_t l = static_cast<std::size_t>(sys.parent[i]);
      Vec6<S> ap = from_parent(i, a[l]);
      if (!bias.acceleration.empty()) ap = name(ap + bias.acceleration[i]);
      const S W_a = short_chains && l != 0 ? paired_dot(sys.W[i], a[static_cast<std::size_t>(sys.parent[l])]) +
                                                 sys.omega[i] * out[c][m + l - 1]
                                           : paired_dot(sys.W[i], ap);
      const S rate = name(mu[c][i] - W_a);
      out[c].push_back(rate);
      Vec6<S> ai = ap;
      for (std::size_t k = 0; k < 6; ++k) ai[k] = ai[k] + sys.s[i][k] * rate;
      a[i] = name(ai);
    }
  }
  return out;
}

/// u̇ of `tree` (m + n: base directions, then joints) by the articulated-body algorithm in the bodies' frames: the
/// factor, then one solve with the velocity-product terms of the tree's local motion, gravity, applied wrenches and
/// the joint forces τ; O(n), M never formed. `pivots` (positive iff M is positive definite): the D_i from the last
/// body in, then the base's LDLᵀ pivots.
struct ForwardDynamics {
  std::vector<Ex> accelerations;
  std::vector<Ex> pivots;
};
ForwardDynamics forward_dynamics(const TreeDynamics& tree, const Namer<Ex>& name);

}  // namespace hamel::rbd
