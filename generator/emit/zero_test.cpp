#include "emit/zero_test.hpp"

#include "algebra/modular_arithmetic.hpp"
#include "emit/interpreter.hpp"

#include <cmath>
#include <map>
#include <optional>

namespace hamel {

namespace {

using modular::Circle;
using modular::inverse_of_nonzero;
using modular::mul_mod;
using modular::u64;

// An integer-valued constant of moderate size, the factor of an angle (2θ).
std::optional<long> small_integer(const Node& n) {
  if (n.op != Op::constant || n.index != 0 || n.value != std::round(n.value) || std::fabs(n.value) > 1e6)
    return std::nullopt;
  return static_cast<long>(n.value);
}

}  // namespace

// The IR in residues at one random point (emit/interpreter.hpp's arithmetic for ZeroTest). Arguments, and functions
// the test does not relate to their operands, are free variables, each drawn for its structural key (the same in
// every run, whatever order nodes are evaluated in); sin, cos and tan read the circle point of their angle; +, −, ×,
// / and integer powers are residue arithmetic. No value (nullopt): a division by 0, a constant that is not a finite
// double, and everything computed from those.
class ResidueArithmetic {
 public:
  using Value = std::optional<modular::Residue>;
  explicit ResidueArithmetic(u64 seed) : point_(seed) {}

  Value constant(const ExpressionGraph& g, int i) const {
    const Node& n = g.node(i);
    if (n.index != 0 || !std::isfinite(n.value)) return std::nullopt;
    return modular::Residue{modular::residue_of_double(n.value)};
  }

  Value argument(Argument argument, int index) const {
    return point_.residue(modular::key_of("argument") ^ (static_cast<u64>(argument) << 40) ^
                          static_cast<u64>(static_cast<unsigned>(index)));
  }

  Value operation(const ExpressionGraph& g, int i, Op op, const Value& a, const Value& b) {
    const Node& n = g.node(i);
    switch (op) {
      case Op::add:
      case Op::sub:
      case Op::mul:
      case Op::div:
      case Op::neg:
        if (!a || !b) return std::nullopt;
        try {
          return modular::arithmetic(op, *a, *b);
        } catch (const modular::Pole&) {
          return std::nullopt;
        }
      case Op::sin:
      case Op::cos:
      case Op::tan: {
        const Circle z = circle(g, n.a);
        if (op == Op::sin) return modular::Residue{z.s};
        if (op == Op::cos) return modular::Residue{z.c};
        if (z.c == 0) return std::nullopt;
        return modular::Residue{mul_mod(z.s, inverse_of_nonzero(z.c))};
      }
      case Op::pow: {
        const std::optional<long> k = small_integer(g.node(n.b));
        if (!k) return point_.residue(g.key(i));
        if (!a) return std::nullopt;
        try {
          return modular::power(*a, *k);
        } catch (const modular::Pole&) {
          return std::nullopt;
        }
      }
      default:  // sqrt, exp, log, the inverse and hyperbolic functions, abs: free variables
        return point_.residue(g.key(i));
    }
  }

 private:
  // The circle point of an angle: Σ k_j θ_j over the integer combination of nodes θ_j the angle is.
  Circle circle(const ExpressionGraph& g, int angle) {
    std::map<int, long> form;
    linear_form(g, angle, 1, form);
    Circle z;
    for (const auto& [node, k] : form) {
      if (k == 0) continue;
      auto [it, fresh] = points_.try_emplace(node);
      if (fresh) it->second = point_.circle(g.key(node));
      z = z * it->second.power(k);
    }
    return z;
  }

  static void linear_form(const ExpressionGraph& g, int i, long k, std::map<int, long>& form) {
    const Node& n = g.node(i);
    switch (n.op) {
      case Op::add:
      case Op::sub:
        linear_form(g, n.a, k, form);
        linear_form(g, n.b, n.op == Op::add ? k : -k, form);
        return;
      case Op::neg:
        linear_form(g, n.a, -k, form);
        return;
      case Op::mul:
        if (const auto m = small_integer(g.node(n.a))) return linear_form(g, n.b, k * *m, form);
        if (const auto m = small_integer(g.node(n.b))) return linear_form(g, n.a, k * *m, form);
        break;
      default:
        break;
    }
    form[i] += k;
  }

  modular::RandomPoint point_;
  std::map<int, Circle> points_;  ///< circle points of the angles' nodes, drawn once
};

ZeroTest::ZeroTest(const ExpressionGraph& g) {
  const u64 seeds[3] = {0x9e3779b97f4a7c15ULL, 0xc2b2ae3d27d4eb4fULL, 0x165667b19e3779f9ULL};
  for (std::size_t k = 0; k < points_.size(); ++k)
    points_[k] = std::make_unique<Interpreter<ResidueArithmetic>>(g, ResidueArithmetic(seeds[k]));
}
ZeroTest::~ZeroTest() = default;

bool ZeroTest::operator()(int node) {
  for (const auto& point : points_) {
    const auto mark = point->mark();
    const int slot = point->compile({node}).front();
    point->run([&](Argument argument, int index) { return point->arithmetic().argument(argument, index); }, mark);
    const std::optional<modular::Residue>& v = point->value(slot);
    if (!v || !v->is_zero()) return false;
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
