#include "derive/articulated_body.hpp"

#include <cstddef>

namespace hamel {

using GiNaC::ex;
using namespace spatial;

namespace {

// A x = b for a small symmetric positive definite A (the floating base's articulated inertia on its
// directions) by LDLᵀ without pivoting, every factor named; the pivots d_k go to `pivots`.
std::vector<ex> solve_symmetric(Namer& name, const std::vector<std::vector<ex>>& A, const std::vector<ex>& b,
                                std::vector<ex>& pivots) {
  const std::size_t k = b.size();
  std::vector<std::vector<ex>> L(k, std::vector<ex>(k, ex(0)));
  std::vector<ex> d(k), inverse(k), y(k), x(k);
  for (std::size_t j = 0; j < k; ++j) {
    ex dj = A[j][j];
    for (std::size_t l = 0; l < j; ++l) dj -= L[j][l] * L[j][l] * d[l];
    d[j] = name(dj);
    pivots.push_back(d[j]);
    inverse[j] = name(1 / d[j]);
    for (std::size_t i = j + 1; i < k; ++i) {
      ex s = A[i][j];
      for (std::size_t l = 0; l < j; ++l) s -= L[i][l] * L[j][l] * d[l];
      L[i][j] = name(s * inverse[j]);
    }
  }
  for (std::size_t i = 0; i < k; ++i) {
    ex s = b[i];
    for (std::size_t l = 0; l < i; ++l) s -= L[i][l] * y[l];
    y[i] = name(s);
  }
  for (std::size_t i = k; i-- > 0;) {
    ex s = y[i] * inverse[i];
    for (std::size_t l = i + 1; l < k; ++l) s -= L[l][i] * x[l];
    x[i] = name(s);
  }
  return x;
}

}  // namespace

void articulated_body(Namer& name, const BodyFrames& b, const std::vector<Vec6>& base, const Vec6& root_acceleration,
                      const std::vector<GiNaC::realsymbol>& rates, const std::vector<ex>& joint_force,
                      const std::vector<ex>& armature, HamelEquations& eq) {
  const std::size_t N = b.parent.size(), m = base.size();
  std::vector<Mat6> IA = b.inertia;  // articulated inertias, summed inward
  std::vector<Vec6> pA(N), c(N), U(N);
  std::vector<ex> inverse_D(N), u(N);
  for (std::size_t i = 0; i < N; ++i) {
    pA[i] = coadjoint_term(b.V[i], b.h[i]);
    if (i > 0) c[i] = name(ad(b.V[i], b.axis[i] * rates[i - 1]));
  }
  for (std::size_t i = N; i-- > 1;) {
    IA[i] = name.symmetric(IA[i]);
    pA[i] = name(pA[i]);
    U[i] = name(times(IA[i], b.axis[i]));
    // D_i = S_iᵀ 𝕀ᴬ_i S_i + armature_i (the rotor's inertia about the joint axis, as in M's diagonal).
    const ex D = name(dot(b.axis[i], U[i]) + armature[i]);
    eq.recursive_pivots.push_back(D);
    inverse_D[i] = name(1 / D);
    u[i] = name(joint_force[i] - dot(b.axis[i], pA[i]));
    const std::size_t p = static_cast<std::size_t>(b.parent[i]);
    if (p == 0 && m == 0) continue;  // a fixed base takes no articulated inertia: nothing solves for it
    // 𝕀ᵃ = 𝕀ᴬ − U Wᵀ with W = U / D (symmetric), pᵃ = pᴬ + 𝕀ᵃ c + W u, moved to the parent's frame.
    const Vec6 W = name(U[i] * inverse_D[i]);
    const Mat6 Ia = name.symmetric(articulated_remainder(IA[i], U[i], W));
    const Vec6 pa = name(pA[i] + times(Ia, c[i]) + W * u[i]);
    IA[p] = IA[p] + inertia_to_parent(b.link[i], Ia, name);
    pA[p] = pA[p] + b.link[i].to_parent(pa);
  }
  if (m > 0) {
    IA[0] = name.symmetric(IA[0]);
    pA[0] = name(pA[0]);
  }
  std::vector<std::vector<ex>> A(m, std::vector<ex>(m));
  std::vector<ex> rhs(m);
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    rhs[alpha] = -dot(base[alpha], pA[0]);
    for (std::size_t beta = 0; beta < m; ++beta) A[alpha][beta] = dot(base[alpha], times(IA[0], base[beta]));
  }
  const std::vector<ex> base_rate = solve_symmetric(name, A, rhs, eq.recursive_pivots);
  std::vector<Vec6> acc(N);
  acc[0] = root_acceleration;  // −g on a fixed base; zero on a floating one (the loader refuses gravity)
  for (std::size_t alpha = 0; alpha < m; ++alpha) acc[0] = acc[0] + base[alpha] * base_rate[alpha];
  eq.recursive_accelerations = base_rate;
  for (std::size_t i = 1; i < N; ++i) {
    const Vec6 ap = name(b.link[i].to_child(acc[static_cast<std::size_t>(b.parent[i])]) + c[i]);
    const ex rate = name((u[i] - dot(U[i], ap)) * inverse_D[i]);
    eq.recursive_accelerations.push_back(rate);
    acc[i] = name(ap + b.axis[i] * rate);
  }
}

}  // namespace hamel
