#include "emit/zero_test.hpp"

#include "algebra/modular_arithmetic.hpp"

#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <unordered_map>

namespace hamel {

namespace {

using modular::add_mod;
using modular::Circle;
using modular::inverse_of_nonzero;
using modular::mul_mod;
using modular::pow_mod;
using modular::prime;
using modular::sub_mod;
using modular::u64;

// An integer-valued constant of moderate size, the factor of an angle (2θ).
std::optional<long> small_integer(const Node& n) {
  if (n.op != Op::constant || n.index != 0 || n.value != std::round(n.value) || std::fabs(n.value) > 1e6)
    return std::nullopt;
  return static_cast<long>(n.value);
}

}  // namespace

// Residues of the nodes of a graph at one random point; nullopt where a division meets a residue 0 or a constant
// is not a finite double.
class GraphResidues {
 public:
  GraphResidues(const ExpressionGraph& g, u64 seed) : g_(g), rng_(seed) {}

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
      bool ready = true;
      if (n.op != Op::constant && n.op != Op::input)
        for (int operand : {n.a, n.b})
          if (operand >= 0 && !memo_.count(operand)) {
            stack.push_back(operand);
            ready = false;
          }
      if (!ready) continue;
      stack.pop_back();
      memo_[i] = evaluate(i, n);
    }
    return memo_.at(root);
  }

 private:
  u64 random_residue() { return std::uniform_int_distribution<u64>(1, prime - 1)(rng_); }

  // A free variable standing for node i (an argument, or a function the test does not relate to its operand).
  u64 free_variable(int i) {
    auto [it, fresh] = free_.try_emplace(i, 0);
    if (fresh) it->second = random_residue();
    return it->second;
  }

  // The circle point of an angle: Σ k_j θ_j over the integer combination of nodes θ_j the angle is.
  Circle circle(int angle) {
    std::map<int, long> form;
    linear_form(angle, 1, form);
    Circle z;
    for (const auto& [node, k] : form) {
      if (k == 0) continue;
      auto [it, fresh] = points_.try_emplace(node);
      if (fresh) it->second = Circle::at(random_residue());
      z = z * it->second.power(k);
    }
    return z;
  }

  void linear_form(int i, long k, std::map<int, long>& form) const {
    const Node& n = g_.node(i);
    switch (n.op) {
      case Op::add:
      case Op::sub:
        linear_form(n.a, k, form);
        linear_form(n.b, n.op == Op::add ? k : -k, form);
        return;
      case Op::neg:
        linear_form(n.a, -k, form);
        return;
      case Op::mul:
        if (const auto m = small_integer(g_.node(n.a))) return linear_form(n.b, k * *m, form);
        if (const auto m = small_integer(g_.node(n.b))) return linear_form(n.a, k * *m, form);
        break;
      default:
        break;
    }
    form[i] += k;
  }

  // One operation on the residues of its operands (already in memo_).
  std::optional<u64> evaluate(int i, const Node& n) {
    std::optional<u64> v;
    const auto operand = [&](int j) { return memo_.at(j); };
    switch (n.op) {
      case Op::constant:
        if (n.index == 0 && std::isfinite(n.value)) v = modular::residue_of_double(n.value);
        break;
      case Op::input:
        v = free_variable(i);
        break;
      case Op::add:
      case Op::sub:
      case Op::mul:
      case Op::div: {
        const auto a = operand(n.a), b = operand(n.b);
        if (!a || !b) break;
        if (n.op == Op::add) v = add_mod(*a, *b);
        if (n.op == Op::sub) v = sub_mod(*a, *b);
        if (n.op == Op::mul) v = mul_mod(*a, *b);
        if (n.op == Op::div && *b != 0) v = mul_mod(*a, inverse_of_nonzero(*b));
        break;
      }
      case Op::neg:
        if (const auto a = operand(n.a)) v = sub_mod(0, *a);
        break;
      case Op::sin:
      case Op::cos:
      case Op::tan: {
        const Circle z = circle(n.a);
        if (n.op == Op::sin) v = z.s;
        if (n.op == Op::cos) v = z.c;
        if (n.op == Op::tan && z.c != 0) v = mul_mod(z.s, inverse_of_nonzero(z.c));
        break;
      }
      case Op::pow: {
        const auto a = operand(n.a);
        const std::optional<long> e = small_integer(g_.node(n.b));
        if (!e) {
          v = free_variable(i);
          break;
        }
        if (!a) break;
        const u64 p = pow_mod(*a, static_cast<u64>(std::labs(*e)));
        if (*e >= 0)
          v = p;
        else if (p != 0)
          v = inverse_of_nonzero(p);
        break;
      }
      default:  // sqrt, exp, log, the inverse and hyperbolic functions, abs
        v = free_variable(i);
        break;
    }
    return v;
  }

  const ExpressionGraph& g_;
  std::mt19937_64 rng_;
  std::unordered_map<int, u64> free_;
  std::map<int, Circle> points_;
  std::unordered_map<int, std::optional<u64>> memo_;
};

ZeroTest::ZeroTest(const ExpressionGraph& g)
    : points_{std::make_unique<GraphResidues>(g, 0x9e3779b97f4a7c15ULL),
              std::make_unique<GraphResidues>(g, 0xc2b2ae3d27d4eb4fULL),
              std::make_unique<GraphResidues>(g, 0x165667b19e3779f9ULL)} {}
ZeroTest::~ZeroTest() = default;

bool ZeroTest::operator()(int node) {
  for (const auto& point : points_) {
    const std::optional<u64> v = point->value(node);
    if (!v || *v != 0) return false;
  }
  return true;
}

std::vector<int> without_identical_zeros(ExpressionGraph& g, const std::vector<int>& outputs) {
  ZeroTest vanishes(g);
  const int zero = g.constant(0);
  std::map<int, int> replace;
  for (int i : g.schedule(outputs)) {
    const Op op = g.node(i).op;
    if (op != Op::constant && op != Op::input && vanishes(i)) replace[i] = zero;
  }
  return replace.empty() ? outputs : substitute(g, outputs, replace);
}

}  // namespace hamel
