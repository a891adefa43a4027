#include "emit/linear_solve.hpp"

#include "derive/bundle_connection.hpp"

#include "rbd/ldlt.hpp"

#include <algorithm>
#include <array>
#include <map>

namespace hamel {

namespace {

using rbd::Vec6;

std::vector<GraphScalar> scalars(const std::vector<int>& nodes) {
  std::vector<GraphScalar> out;
  for (int n : nodes) out.push_back(GraphScalar::node(n));
  return out;
}
std::vector<std::vector<GraphScalar>> scalars(const std::vector<std::vector<int>>& nodes) {
  std::vector<std::vector<GraphScalar>> out;
  for (const std::vector<int>& row : nodes) out.push_back(scalars(row));
  return out;
}
std::vector<int> ids(const std::vector<GraphScalar>& values) {
  std::vector<int> out;
  for (const GraphScalar& v : values) out.push_back(v.id());
  return out;
}
std::vector<std::vector<int>> ids(const std::vector<std::vector<GraphScalar>>& values) {
  std::vector<std::vector<int>> out;
  for (const std::vector<GraphScalar>& v : values) out.push_back(ids(v));
  return out;
}

// The graph's LDLᵀ: every term of the elimination is (the numerator of L_ik) · L_jk, one multiplication.
rbd::LdltOptions<GraphScalar> graph_ldlt(bool last_first, bool reciprocal) {
  rbd::LdltOptions<GraphScalar> o;
  o.numerator_products = true;
  o.reciprocal = reciprocal ? rbd::LdltOptions<GraphScalar>::Reciprocal::substitution
                            : rbd::LdltOptions<GraphScalar>::Reciprocal::none;
  o.last_first = last_first;
  return o;
}

}  // namespace

std::vector<int> ldlt_solve(ExpressionGraph& g, const std::vector<std::vector<int>>& M, const std::vector<int>& f,
                            bool last_first, std::vector<int>* pivots) {
  const GraphScope scope(g);
  std::vector<GraphScalar> d;
  const std::vector<int> x =
      ids(rbd::ldlt_solve(scalars(M), {scalars(f)}, graph_ldlt(last_first, false), pivots ? &d : nullptr).front());
  if (pivots)
    for (const GraphScalar& p : d) pivots->push_back(p.id());
  return x;
}

std::vector<std::vector<int>> ldlt_solve_columns(ExpressionGraph& g, const std::vector<std::vector<int>>& M,
                                                 const std::vector<std::vector<int>>& columns, bool last_first) {
  const GraphScope scope(g);
  return ids(rbd::ldlt_solve(scalars(M), scalars(columns), graph_ldlt(last_first, true)));
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

ArticulatedNodes articulated_nodes(ExpressionGraph& g, const rbd::TreeDynamics& tree,
                                   const rbd::ArticulatedFactor& factor, ProgramConverter& node_of) {
  const std::size_t N = tree.model.size(), m = tree.model.base.size();
  const GraphScope scope(g);
  const auto nodes = [&](const Vec6<GiNaC::ex>& v) {
    Vec6<GraphScalar> out = rbd::zero6<GraphScalar>();
    for (std::size_t k = 0; k < 6; ++k) out[k] = GraphScalar::node(node_of(v[k]));
    return out;
  };
  ArticulatedNodes f;
  f.parent = tree.model.parent;
  f.s = f.U = f.W = std::vector<Vec6<GraphScalar>>(N, rbd::zero6<GraphScalar>());
  f.inverse_D = f.sigma = f.omega = std::vector<GraphScalar>(N, GraphScalar(0));
  f.base_inertia.assign(m, std::vector<GraphScalar>(m, GraphScalar(0)));
  for (std::size_t i = 1; i < N; ++i) {
    f.s[i] = nodes(tree.frame.axis[i]);
    f.U[i] = nodes(factor.U[i]);
    f.inverse_D[i] = GraphScalar::node(node_of(factor.inverse_D[i]));
    f.W[i] = nodes(factor.W[i]);
    const std::size_t l = static_cast<std::size_t>(tree.model.parent[i]);
    if (l == 0) continue;
    f.sigma[i] = rbd::paired_dot(f.s[l], f.U[i]);
    f.omega[i] = f.sigma[i] * f.inverse_D[i];
  }
  for (std::size_t alpha = 0; alpha < m; ++alpha) {
    f.e.push_back(nodes(tree.model.base[alpha]));
    for (std::size_t beta = 0; beta < m; ++beta)
      f.base_inertia[alpha][beta] = GraphScalar::node(node_of(factor.base_inertia[alpha][beta]));
  }
  return f;
}

std::vector<std::vector<int>> articulated_solve_columns(ExpressionGraph& g, const ArticulatedNodes& factor,
                                                        const std::vector<std::vector<int>>& columns,
                                                        const std::vector<InwardForce>& inward) {
  const GraphScope scope(g);
  std::vector<rbd::InwardForce<GraphScalar>> forces;
  for (const InwardForce& f : inward) {
    rbd::InwardForce<GraphScalar> force{f.body, rbd::zero6<GraphScalar>()};
    for (std::size_t k = 0; k < 6; ++k) force.force[k] = GraphScalar::node(f.force[k]);
    forces.push_back(force);
  }
  rbd::ArticulatedSolveOptions options;
  options.short_chains = true;
  return ids(rbd::articulated_solve(factor, scalars(columns), options, rbd::Namer<GraphScalar>::identity(), forces));
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
  const auto value = [&](const GraphScalar& x) { return GraphScalar::node(shared(x.id())); };
  const auto vectors = [&](const std::vector<Vec6<GraphScalar>>& v) {
    std::vector<Vec6<GraphScalar>> out = v;
    for (Vec6<GraphScalar>& w : out)
      for (GraphScalar& x : w) x = value(x);
    return out;
  };
  ArticulatedNodes local = factor;
  local.s = vectors(factor.s);
  local.U = vectors(factor.U);
  local.W = vectors(factor.W);
  local.e = vectors(factor.e);
  for (GraphScalar& x : local.inverse_D) x = value(x);
  for (GraphScalar& x : local.sigma) x = value(x);
  for (GraphScalar& x : local.omega) x = value(x);
  for (std::vector<GraphScalar>& row : local.base_inertia)
    for (GraphScalar& x : row) x = value(x);
  return local;
}

}  // namespace hamel
