#include "emit/polynomial_form.hpp"

#include "emit/zero_test.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <utility>

namespace hamel {

namespace {

// ---- Polynomials over parameter-only coefficients -------------------------------------------------------

// A monomial of degree ≤ 2: the input nodes of its variables, (−1, −1) for 1, (−1, v) for v, (u, v) for u·v
// with u ≤ v.
using Monomial = std::pair<int, int>;
using Polynomial = std::map<Monomial, int>;  // monomial → coefficient node (parameter-only)

std::optional<Monomial> times(const Monomial& a, const Monomial& b) {
  int vars[4] = {a.first, a.second, b.first, b.second};
  std::sort(vars, vars + 4);
  if (vars[0] >= 0 || vars[1] >= 0) return std::nullopt;  // degree > 2
  return Monomial{vars[2], vars[3]};
}

constexpr std::size_t kMaxTerms = 256;

}  // namespace

std::vector<int> polynomial_form(ExpressionGraph& g, const std::vector<int>& outputs) {
  const std::vector<int> order = g.schedule(outputs);
  const std::size_t size = static_cast<std::size_t>(g.size());
  std::vector<char> varying(size, 0);
  std::vector<std::optional<Polynomial>> poly(size);
  const int zero = g.constant(0), one = g.constant(1);
  const auto constant_poly = [&](int i) { return Polynomial{{Monomial{-1, -1}, i}}; };
  const auto of = [&](int i) -> std::optional<Polynomial> {
    return varying[static_cast<std::size_t>(i)] ? poly[static_cast<std::size_t>(i)] : constant_poly(i);
  };
  const auto combine = [&](const Polynomial& a, const Polynomial& b, Op op) {
    Polynomial r = a;
    for (const auto& [m, c] : b) {
      auto it = r.find(m);
      const int base = it == r.end() ? zero : it->second;
      r[m] = g.binary(op, base, c);
    }
    return r;
  };
  for (int i : order) {
    const Node n = g.node(i);  // a copy: building coefficients grows the graph
    const std::size_t k = static_cast<std::size_t>(i);
    if (n.op == Op::input) {
      varying[k] = n.argument != Argument::parameter;
      if (varying[k]) poly[k] = Polynomial{{Monomial{-1, i}, one}};
      continue;
    }
    if (n.op == Op::constant) continue;
    varying[k] = varying[static_cast<std::size_t>(n.a)] || (n.b >= 0 && varying[static_cast<std::size_t>(n.b)]);
    if (!varying[k]) continue;
    const std::optional<Polynomial> a = of(n.a);
    const std::optional<Polynomial> b = n.b >= 0 ? of(n.b) : std::nullopt;
    if (!a || (n.b >= 0 && !b)) continue;  // not a polynomial: stays nullopt
    std::optional<Polynomial> r;
    switch (n.op) {
      case Op::add:
      case Op::sub:
        r = combine(*a, *b, n.op);
        break;
      case Op::neg:
        r = combine(Polynomial{}, *a, Op::sub);
        break;
      case Op::mul: {
        Polynomial p;
        bool ok = true;
        for (const auto& [ma, ca] : *a)
          for (const auto& [mb, cb] : *b) {
            const std::optional<Monomial> m = times(ma, mb);
            if (!m) {
              ok = false;
              break;
            }
            const int c = g.binary(Op::mul, ca, cb);
            auto it = p.find(*m);
            p[*m] = it == p.end() ? c : g.binary(Op::add, it->second, c);
          }
        if (ok) r = std::move(p);
        break;
      }
      case Op::div:
        if (!varying[static_cast<std::size_t>(n.b)]) {
          const int reciprocal = g.binary(Op::div, one, n.b);
          Polynomial p;
          for (const auto& [m, c] : *a) p[m] = g.binary(Op::mul, c, reciprocal);
          r = std::move(p);
        }
        break;
      default:
        break;
    }
    if (r && r->size() <= kMaxTerms) poly[k] = std::move(r);
  }

  // Outputs as Σ coefficient · monomial over the coefficients that do not vanish identically.
  std::map<Monomial, int> monomial_node;
  const auto monomial = [&](const Monomial& m) {
    auto [it, fresh] = monomial_node.try_emplace(m, one);
    if (fresh && m.second >= 0) it->second = m.first < 0 ? m.second : g.binary(Op::mul, m.first, m.second);
    return it->second;
  };
  ZeroTest vanishes(g);
  std::vector<int> result;
  for (int o : outputs) {
    const std::size_t k = static_cast<std::size_t>(o);
    if (!varying[k] || !poly[k]) {
      result.push_back(o);
      continue;
    }
    int sum = zero;
    for (const auto& [m, c] : *poly[k]) {
      if (c == zero || vanishes(c)) continue;
      sum = g.binary(Op::add, sum, g.binary(Op::mul, monomial(m), c));
    }
    result.push_back(sum);
  }
  return result;
}

}  // namespace hamel
