#include "emit/linear_solve.hpp"

#include <algorithm>
#include <array>
#include <map>

namespace hamel {

namespace {

// M = L D Lᵀ (unit lower L) as graph nodes, M in natural order. The entries before their division by the pivot,
// S = L D, are kept as well, so that every term of the elimination, S_ik L_jk = L_ik d_k L_jk, costs one
// multiplication (Golub & Van Loan, Algorithm 4.1.2).
struct LdltFactors {
  std::vector<std::vector<int>> L;
  std::vector<int> d;
};

LdltFactors ldlt_factor(ExpressionGraph& g, const std::vector<std::vector<int>>& M, std::vector<int>* pivots) {
  const std::size_t n = M.size();
  const int zero = g.constant(0);
  LdltFactors F{std::vector<std::vector<int>>(n, std::vector<int>(n, zero)), std::vector<int>(n)};
  std::vector<std::vector<int>> S(n, std::vector<int>(n, zero));  // S_ik = L_ik d_k
  for (std::size_t j = 0; j < n; ++j) {
    int dj = M[j][j];
    for (std::size_t k = 0; k < j; ++k) dj = g.binary(Op::sub, dj, g.binary(Op::mul, S[j][k], F.L[j][k]));
    F.d[j] = dj;
    if (pivots) pivots->push_back(dj);
    for (std::size_t i = j + 1; i < n; ++i) {
      int s = M[i][j];
      for (std::size_t k = 0; k < j; ++k) s = g.binary(Op::sub, s, g.binary(Op::mul, S[i][k], F.L[j][k]));
      S[i][j] = s;
      F.L[i][j] = g.binary(Op::div, s, dj);
    }
  }
  return F;
}

// y = L⁻¹ f, then x = D⁻¹ y − Lᵀ x from the last row up: dividing by d, or multiplying by `inverse` (1/d)
// when given.
std::vector<int> ldlt_substitute(ExpressionGraph& g, const LdltFactors& F, const std::vector<int>& f,
                                 const std::vector<int>* inverse) {
  const std::size_t n = f.size();
  std::vector<int> y(n);
  for (std::size_t i = 0; i < n; ++i) {
    int s = f[i];
    for (std::size_t k = 0; k < i; ++k) s = g.binary(Op::sub, s, g.binary(Op::mul, F.L[i][k], y[k]));
    y[i] = s;
  }
  std::vector<int> x(n);
  for (std::size_t i = n; i-- > 0;) {
    int s = inverse ? g.binary(Op::mul, y[i], (*inverse)[i]) : g.binary(Op::div, y[i], F.d[i]);
    for (std::size_t k = i + 1; k < n; ++k) s = g.binary(Op::sub, s, g.binary(Op::mul, F.L[k][i], x[k]));
    x[i] = s;
  }
  return x;
}

// P v: v reversed (P the exchange matrix), and P M Pᵀ.
std::vector<int> reversed(std::vector<int> v) {
  std::reverse(v.begin(), v.end());
  return v;
}
std::vector<std::vector<int>> reversed(const std::vector<std::vector<int>>& M) {
  const std::size_t n = M.size();
  std::vector<std::vector<int>> R(n, std::vector<int>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) R[i][j] = M[n - 1 - i][n - 1 - j];
  return R;
}

// ⟨a, b⟩ of two 6-vectors of nodes, summed in pairs: shorter chains of dependent additions.
int paired_dot(ExpressionGraph& g, const std::array<int, 6>& a, const std::array<int, 6>& b) {
  int pair[3];
  for (std::size_t k = 0; k < 3; ++k)
    pair[k] = g.binary(Op::add, g.binary(Op::mul, a[2 * k], b[2 * k]), g.binary(Op::mul, a[2 * k + 1], b[2 * k + 1]));
  return g.binary(Op::add, g.binary(Op::add, pair[0], pair[1]), pair[2]);
}

}  // namespace

// Solves M y = f for symmetric positive definite M as straight-line code (LDLᵀ, no pivoting, no
// square roots): no loops or branches are left in the emitted kernel. With `last_first`, the same
// factorization of the reversed system, P M Pᵀ (P y) = P f.
std::vector<int> ldlt_solve(ExpressionGraph& g, const std::vector<std::vector<int>>& M, const std::vector<int>& f,
                            bool last_first, std::vector<int>* pivots) {
  if (last_first) return reversed(ldlt_solve(g, reversed(M), reversed(f), false, pivots));
  return ldlt_substitute(g, ldlt_factor(g, M, pivots), f, nullptr);
}

std::vector<std::vector<int>> ldlt_solve_columns(ExpressionGraph& g, const std::vector<std::vector<int>>& M,
                                                 const std::vector<std::vector<int>>& columns, bool last_first) {
  if (last_first) {
    std::vector<std::vector<int>> flipped;
    for (const std::vector<int>& f : columns) flipped.push_back(reversed(f));
    std::vector<std::vector<int>> out = ldlt_solve_columns(g, reversed(M), flipped, false);
    for (std::vector<int>& x : out) x = reversed(x);
    return out;
  }
  const LdltFactors F = ldlt_factor(g, M, nullptr);
  std::vector<int> inverse;
  for (int d : F.d) inverse.push_back(g.binary(Op::div, g.constant(1), d));
  std::vector<std::vector<int>> out;
  for (const std::vector<int>& f : columns) out.push_back(ldlt_substitute(g, F, f, &inverse));
  return out;
}

std::vector<std::vector<int>> solved_connection(ExpressionGraph& g, const BundleGeometry& geo,
                                                ProgramConverter& node_of) {
  const unsigned m = geo.L.rows(), n = geo.K.cols();
  std::vector<std::vector<int>> L(m, std::vector<int>(m)), K(n, std::vector<int>(m));
  for (unsigned a = 0; a < m; ++a)
    for (unsigned c = 0; c < m; ++c) L[a][c] = node_of(geo.L(a, c));
  for (unsigned I = 0; I < n; ++I)
    for (unsigned a = 0; a < m; ++a) K[I][a] = node_of(geo.K(a, I));
  const std::vector<std::vector<int>> columns = ldlt_solve_columns(g, L, K);
  std::vector<std::vector<int>> A(m, std::vector<int>(n));
  for (unsigned a = 0; a < m; ++a)
    for (unsigned I = 0; I < n; ++I) A[a][I] = columns[I][a];
  return A;
}

ArticulatedNodes articulated_nodes(ExpressionGraph& g, const TreeRecursion& tree, const ArticulatedFactor& factor,
                                   ProgramConverter& node_of) {
  using Vec = ArticulatedNodes::Vec;
  const std::size_t N = tree.parent.size(), m = tree.base.size();
  const int zero = g.constant(0);
  const auto nodes = [&](const spatial::Vec6& v) {
    Vec out;
    for (std::size_t k = 0; k < 6; ++k) out[k] = node_of(v[k]);
    return out;
  };
  const Vec none = {zero, zero, zero, zero, zero, zero};
  ArticulatedNodes f{tree.parent,
                     std::vector<Vec>(N, none),
                     std::vector<Vec>(N, none),
                     std::vector<Vec>(N, none),
                     {},
                     std::vector<int>(N, zero),
                     std::vector<std::vector<int>>(m, std::vector<int>(m)),
                     std::vector<int>(N, zero),
                     std::vector<int>(N, zero)};
  for (std::size_t i = 1; i < N; ++i) {
    f.s[i] = nodes(tree.frame.axis[i]);
    f.U[i] = nodes(factor.U[i]);
    f.inverse_D[i] = node_of(factor.inverse_pivot[i]);
    f.W[i] = nodes(factor.W[i]);
    const std::size_t l = static_cast<std::size_t>(tree.parent[i]);
    if (l == 0) continue;
    f.sigma[i] = paired_dot(g, f.s[l], f.U[i]);
    f.omega[i] = g.binary(Op::mul, f.sigma[i], f.inverse_D[i]);
  }
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    f.e.push_back(nodes(tree.base[alpha]));
    for (std::size_t beta = 0; beta < m; ++beta)
      f.base_inertia[alpha][beta] = node_of(factor.base_inertia[alpha][beta]);
  }
  return f;
}

std::vector<std::vector<int>> articulated_solve_columns(ExpressionGraph& g, const ArticulatedNodes& factor,
                                                        const std::vector<std::vector<int>>& columns,
                                                        const std::vector<InwardForce>& inward) {
  using Vec = ArticulatedNodes::Vec;
  const std::size_t N = factor.parent.size(), m = factor.e.size();
  const int zero = g.constant(0);
  const auto dot = [&](const Vec& a, const Vec& b) { return paired_dot(g, a, b); };
  // y + a x, of numbers and of 6-vectors
  const auto multiply_add = [&](int y, int a, int x) { return g.binary(Op::add, y, g.binary(Op::mul, a, x)); };
  const auto axpy = [&](const Vec& y, const Vec& a, int x) {
    Vec out;
    for (std::size_t k = 0; k < 6; ++k) out[k] = multiply_add(y[k], a[k], x);
    return out;
  };
  const std::vector<Vec>&s = factor.s, &U = factor.U, &W = factor.W, &e = factor.e;
  const std::vector<int>& inverse_D = factor.inverse_D;
  const std::vector<int>& parent = factor.parent;
  const Vec none = {zero, zero, zero, zero, zero, zero};

  // Inward, per column: μ_i and the base's right-hand side. q_i is p_i without its children's U_c μ_c, which
  // reach ⟨s_i, p_i⟩ as σ_c μ_c in `s_p`.
  std::vector<std::vector<int>> mu(columns.size(), std::vector<int>(N, zero)), base_rhs(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const std::vector<int>& b = columns[c];
    std::vector<Vec> p(N, none), q(N, none);
    std::vector<int> s_p(N, zero);
    // b_I = −⟨s_I, F⟩ on the ancestors of the force's body: μ_I = (b_I − ⟨s_I, p_I⟩) / D_I with p_I + F in place
    // of p_I, and F passes inward with p unchanged.
    if (!inward.empty() && inward[c].body > 0) {
      const std::size_t entry = static_cast<std::size_t>(parent[inward[c].body]);
      p[entry] = q[entry] = inward[c].force;
    }
    for (std::size_t i = N; i-- > 1;) {
      const int s_pi = g.binary(Op::add, dot(s[i], q[i]), s_p[i]);  // ⟨s_i, p_i⟩
      mu[c][i] = g.binary(Op::mul, g.binary(Op::sub, b[m + i - 1], s_pi), inverse_D[i]);
      const std::size_t l = static_cast<std::size_t>(parent[i]);
      if (l == 0 && m == 0) continue;
      const Vec pi = axpy(p[i], U[i], mu[c][i]);
      for (std::size_t k = 0; k < 6; ++k) {
        p[l][k] = g.binary(Op::add, p[l][k], pi[k]);
        q[l][k] = g.binary(Op::add, q[l][k], p[i][k]);
      }
      s_p[l] = multiply_add(s_p[l], factor.sigma[i], mu[c][i]);
    }
    for (std::size_t alpha = 0; alpha < m; ++alpha)
      base_rhs[c].push_back(g.binary(Op::sub, b[alpha], dot(e[alpha], p[0])));
  }
  std::vector<std::vector<int>> base_rate(columns.size());
  if (m > 0) base_rate = ldlt_solve_columns(g, factor.base_inertia, base_rhs);

  // Outward: the base's acceleration (zero on a fixed base: M carries no gravity), then the joints'.
  std::vector<std::vector<int>> out(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) {
    std::vector<Vec> a(N, none);
    for (std::size_t alpha = 0; alpha < m; ++alpha) a[0] = axpy(a[0], e[alpha], base_rate[c][alpha]);
    out[c] = base_rate[c];
    for (std::size_t i = 1; i < N; ++i) {
      const std::size_t l = static_cast<std::size_t>(parent[i]);
      // ⟨W_i, a_λ⟩ = ⟨W_i, a_λλ⟩ + ω_i ÿ_λ below a joint λ.
      const int W_a =
          l == 0 ? dot(W[i], a[0])
                 : multiply_add(dot(W[i], a[static_cast<std::size_t>(parent[l])]), factor.omega[i], out[c][m + l - 1]);
      const int rate = g.binary(Op::sub, mu[c][i], W_a);
      out[c].push_back(rate);
      a[i] = axpy(a[l], s[i], rate);
    }
  }
  return out;
}

Subroutine solve_subroutine(ExpressionGraph& g, const std::vector<std::vector<int>>& columns, std::size_t lanes,
                            const std::function<int(std::size_t, std::size_t)>& result_of, const ColumnSolver& solve) {
  Subroutine sub;
  if (columns.empty()) return sub;
  ExpressionGraph& s = sub.graph;
  std::map<int, int> input_of;  // node of g -> the subroutine's p[k] reading it
  const std::function<int(int)> shared = [&](int node) {
    const Node& n = g.node(node);
    if (n.op == Op::constant && n.index == 0) return s.constant(n.value);
    const auto it = input_of.find(node);
    if (it != input_of.end()) return it->second;
    const int in = s.input(Argument::parameter, static_cast<int>(sub.shared.size()));
    sub.shared.push_back(node);
    return input_of[node] = in;
  };
  const std::size_t rows = columns.front().size();
  std::vector<int> b;
  for (std::size_t k = 0; k < rows; ++k) b.push_back(s.input(Argument::state, static_cast<int>(k)));
  sub.outputs = solve(s, shared, {b}).front();
  if (!hoist_shared_work(g, sub)) return {};
  // Calls of `lanes` consecutive columns; a last call with fewer left takes the `lanes` last columns, so that every
  // call has the same shape (it writes some results a second time, the same values).
  sub.lanes = std::max<std::size_t>(1, std::min(lanes, columns.size()));
  for (std::size_t start = 0; start < columns.size(); start += sub.lanes) {
    const std::size_t first = std::min(start, columns.size() - sub.lanes);
    Subroutine::Call call;
    for (std::size_t k = 0; k < rows; ++k)
      for (std::size_t l = 0; l < sub.lanes; ++l) call.arguments.push_back(columns[first + l][k]);
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t l = 0; l < sub.lanes; ++l) call.results.push_back(result_of(first + l, r));
    sub.calls.push_back(std::move(call));
  }
  return sub;
}

ArticulatedNodes shared_factor(const ArticulatedNodes& factor, const std::function<int(int)>& shared) {
  using Vec = ArticulatedNodes::Vec;
  const auto vectors = [&](const std::vector<Vec>& v) {
    std::vector<Vec> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      for (std::size_t k = 0; k < 6; ++k) out[i][k] = shared(v[i][k]);
    return out;
  };
  ArticulatedNodes local{factor.parent,
                         vectors(factor.s),
                         vectors(factor.U),
                         vectors(factor.W),
                         vectors(factor.e),
                         {},
                         factor.base_inertia,
                         {},
                         {}};
  for (int d : factor.inverse_D) local.inverse_D.push_back(shared(d));
  for (int x : factor.sigma) local.sigma.push_back(shared(x));
  for (int x : factor.omega) local.omega.push_back(shared(x));
  for (std::vector<int>& row : local.base_inertia)
    for (int& entry : row) entry = shared(entry);
  return local;
}

}  // namespace hamel
