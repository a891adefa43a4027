#include "emit/polynomial_form.hpp"

#include "algebra/modular_arithmetic.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <unordered_map>
#include <utility>

namespace hamel {

namespace {

using modular::add_mod;
using modular::inverse_of_nonzero;
using modular::mul_mod;
using modular::pow_mod;
using modular::prime;
using modular::sub_mod;
using modular::u64;

}  // namespace

// Residues of the nodes of a parameter-only program at one random point of the parameters; nullopt where the
// program leaves the rational functions (sqrt, sin, …) or divides by a residue 0.
class ModularPoint {
 public:
  ModularPoint(const ExpressionGraph& g, u64 seed) : g_(g), rng_(seed) {}

  /// The residue of node i, evaluating what it needs (iteratively: sums are long chains).
  std::optional<u64> value(int root) {
    std::vector<int> stack{root};
    while (!stack.empty()) {
      const int i = stack.back();
      if (memo_.count(i)) {
        stack.pop_back();
        continue;
      }
      const Node n = g_.node(i);
      const bool binary = n.op != Op::constant && n.op != Op::input && n.b >= 0;
      const bool unary = n.op != Op::constant && n.op != Op::input && n.b < 0;
      bool ready = true;
      for (int operand : {binary || unary ? n.a : -1, binary ? n.b : -1})
        if (operand >= 0 && !memo_.count(operand)) {
          stack.push_back(operand);
          ready = false;
        }
      if (!ready) continue;
      stack.pop_back();
      memo_[i] = evaluate(n);
    }
    return memo_.at(root);
  }

 private:
  // One operation on the residues of its operands (already in memo_).
  std::optional<u64> evaluate(const Node& n) {
    std::optional<u64> v;
    switch (n.op) {
      case Op::constant:
        if (std::isfinite(n.value)) v = modular::residue_of_double(n.value);
        break;
      case Op::input:
        if (n.argument == Argument::parameter) {
          auto [it, fresh] = parameters_.try_emplace(n.index, 0);
          if (fresh) it->second = std::uniform_int_distribution<u64>(1, prime - 1)(rng_);
          v = it->second;
        }
        break;
      case Op::add:
      case Op::sub:
      case Op::mul:
      case Op::div: {
        const auto a = memo_.at(n.a), b = memo_.at(n.b);
        if (!a || !b) break;
        if (n.op == Op::add) v = add_mod(*a, *b);
        if (n.op == Op::sub) v = add_mod(*a, sub_mod(0, *b));
        if (n.op == Op::mul) v = mul_mod(*a, *b);
        if (n.op == Op::div && *b != 0) v = mul_mod(*a, inverse_of_nonzero(*b));
        break;
      }
      case Op::neg:
        if (const auto a = memo_.at(n.a)) v = sub_mod(0, *a);
        break;
      case Op::pow: {
        const Node& e = g_.node(n.b);
        const auto a = memo_.at(n.a);
        if (!a || e.op != Op::constant || e.value != std::round(e.value) || std::fabs(e.value) > 1e6) break;
        const u64 p = pow_mod(*a, static_cast<u64>(std::fabs(e.value)));
        if (e.value >= 0)
          v = p;
        else if (p != 0)
          v = inverse_of_nonzero(p);
        break;
      }
      default:
        break;
    }
    return v;
  }

  const ExpressionGraph& g_;
  std::mt19937_64 rng_;
  std::map<int, u64> parameters_;
  std::unordered_map<int, std::optional<u64>> memo_;
};

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

ParameterZeroTest::ParameterZeroTest(const ExpressionGraph& g)
    : points_{std::make_unique<ModularPoint>(g, 0x9e3779b97f4a7c15ULL),
              std::make_unique<ModularPoint>(g, 0xc2b2ae3d27d4eb4fULL)} {}
ParameterZeroTest::~ParameterZeroTest() = default;

bool ParameterZeroTest::operator()(int node) {
  for (const auto& point : points_) {
    const std::optional<u64> v = point->value(node);
    if (!v || *v != 0) return false;
  }
  return true;
}

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
  ParameterZeroTest vanishes(g);
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
