#include "algebra/identity_test.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/modular_arithmetic.hpp"
#include "algebra/simplify.hpp"

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;

namespace {

using modular::Circle;
using modular::inverse_of_nonzero;
using modular::mul_mod;
using modular::Pole;
using modular::prime;
using modular::Residue;
using modular::sub_mod;
using modular::u64;

struct Undecidable {};  // the expression is not a rational function of symbols and circle points

Residue residue(const GiNaC::numeric& n) {
  if (!n.is_rational()) throw Undecidable{};
  static const GiNaC::numeric p(static_cast<long>(prime));
  const u64 num = static_cast<u64>(GiNaC::mod(n.numer(), p).to_long());
  const u64 den = static_cast<u64>(GiNaC::mod(n.denom(), p).to_long());
  return modular::divide({num}, {den});
}

struct ExHash {
  std::size_t operator()(const ex& e) const { return e.gethash(); }
};

// One random point: residues for symbols and constants, circle points for angles, and every intermediate through its
// definition (memoized). The values are drawn for names (a symbol's, a constant's, an angle's as printed,
// algebra/expression_text), not in the order this walk meets them, which follows GiNaC's term order.
class ModularPoint {
 public:
  ModularPoint(const Intermediates& program, u64 seed) : program_(program), point_(seed) {}

  u64 value(const ex& e) {
    if (auto it = memo_.find(e); it != memo_.end()) return it->second;
    const u64 v = compute(e);
    memo_.emplace(e, v);
    return v;
  }

 private:
  u64 compute(const ex& e) {
    if (is_a<GiNaC::numeric>(e)) return residue(ex_to<GiNaC::numeric>(e)).value;
    if (is_a<GiNaC::symbol>(e)) {
      if (const std::optional<ex> def = program_.definition_of(e)) return value(*def);
      return free_value(e);
    }
    if (is_a<GiNaC::constant>(e)) return free_value(e);  // π, e: transcendental, so independent
    if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e)) {
      const bool sum = is_a<GiNaC::add>(e);
      Residue s{sum ? 0U : 1U};
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const Residue x{value(e.op(i))};
        s = sum ? s + x : s * x;
      }
      return s.value;
    }
    if (is_a<GiNaC::power>(e)) {
      const ex k = e.op(1);
      if (!is_a<GiNaC::numeric>(k) || !ex_to<GiNaC::numeric>(k).is_rational()) throw Undecidable{};
      GiNaC::numeric kk = ex_to<GiNaC::numeric>(k);
      Residue base{value(e.op(0))};
      if (!kk.is_integer()) {  // x^(j/2): the canonical square root of x, read as one algebraic element
        if (kk.denom() != 2) throw Undecidable{};
        base = modular::square_root(base);
        kk = kk * 2;
      }
      if (base.is_zero()) {
        if (kk.is_negative()) throw Pole{};
        return 0;
      }
      const long magnitude = GiNaC::mod(GiNaC::abs(kk), GiNaC::numeric(static_cast<long>(prime - 1))).to_long();
      return modular::power(base, kk.is_negative() ? -magnitude : magnitude).value;
    }
    if (is_a<GiNaC::function>(e)) {
      const std::string name = ex_to<GiNaC::function>(e).get_name();
      if (name == "sin" || name == "cos" || name == "tan") {
        const Circle z = angle(e.op(0));
        if (name == "sin") return z.s;
        if (name == "cos") return z.c;
        return modular::divide({z.s}, {z.c}).value;
      }
    }
    throw Undecidable{};
  }

  // The residue of a free symbol or constant, drawn for its name; distinct symbols that share a name (never in a
  // model, whose names are unique) are told apart by the order they are met in.
  u64 free_value(const ex& s) {
    auto it = free_.find(s);
    if (it == free_.end()) it = free_.emplace(s, point_.residue(key(s, free_names_)).value).first;
    return it->second;
  }

  Circle circle_for(const ex& angle) {
    auto it = circles_.find(angle);
    if (it == circles_.end()) it = circles_.emplace(angle, point_.circle(key(angle, circle_names_))).first;
    return it->second;
  }

  // The key of `e`'s value: its text, and how many distinct expressions of that text came before it.
  static u64 key(const ex& e, std::map<std::string, u64>& seen) {
    const std::string text = to_text(e);
    return modular::key_of(text) + seen[text]++;
  }

  // e^{iθ} for θ = Σ k_i x_i + rest: integer multiples of symbols (read through linear definitions)
  // multiply their circle points; any other part is one angle of its own.
  Circle angle(const ex& theta) {
    std::map<ex, long, GiNaC::ex_is_less> multiples;
    ex rest = 0;
    split_angle(theta, 1, multiples, rest);
    Circle z;
    for (const auto& [x, k] : multiples)
      if (k != 0) z = z * circle_for(x).power(k);
    if (!rest.is_zero()) z = z * circle_for(rest.expand());
    return z;
  }

  void split_angle(const ex& e, long factor, std::map<ex, long, GiNaC::ex_is_less>& multiples, ex& rest) {
    if (is_a<GiNaC::add>(e)) {
      for (std::size_t i = 0; i < e.nops(); ++i) split_angle(e.op(i), factor, multiples, rest);
      return;
    }
    if (is_a<GiNaC::symbol>(e)) {
      if (const std::optional<ex> def = program_.definition_of(e)) return split_angle(*def, factor, multiples, rest);
      multiples[e] += factor;
      return;
    }
    if (is_a<GiNaC::mul>(e) && e.nops() == 2 && is_a<GiNaC::numeric>(e.op(1)) &&
        ex_to<GiNaC::numeric>(e.op(1)).is_integer() && GiNaC::abs(ex_to<GiNaC::numeric>(e.op(1))) <= 64) {
      split_angle(e.op(0), factor * ex_to<GiNaC::numeric>(e.op(1)).to_long(), multiples, rest);
      return;
    }
    if (is_a<GiNaC::numeric>(e)) {  // a constant angle (a folded parameter): no program to read
      if (!e.is_zero()) rest += factor * e;
      return;
    }
    rest += factor * program_.inline_all(e);
  }

  const Intermediates& program_;
  modular::RandomPoint point_;
  std::unordered_map<ex, u64, ExHash, GiNaC::ex_is_equal> memo_;
  std::map<ex, u64, GiNaC::ex_is_less> free_;
  std::map<ex, Circle, GiNaC::ex_is_less> circles_;
  std::map<std::string, u64> free_names_, circle_names_;  ///< distinct expressions met per text
};

u64 determinant_mod(std::vector<std::vector<u64>> a) {
  const std::size_t n = a.size();
  u64 det = 1;
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t pivot = c;
    while (pivot < n && a[pivot][c] == 0) ++pivot;
    if (pivot == n) return 0;
    if (pivot != c) std::swap(a[pivot], a[c]), det = sub_mod(0, det);
    det = mul_mod(det, a[c][c]);
    const u64 inv = inverse_of_nonzero(a[c][c]);
    for (std::size_t r = c + 1; r < n; ++r) {
      const u64 f = mul_mod(a[r][c], inv);
      if (f == 0) continue;
      for (std::size_t j = c; j < n; ++j) a[r][j] = sub_mod(a[r][j], mul_mod(f, a[c][j]));
    }
  }
  return det;
}

// `is_zero_at(point)` → true/false; poles (and square roots of non-squares) draw a new point. Zero at three
// points: zero.
template <class IsZeroAt>
Identity decide(IsZeroAt is_zero_at) {
  int zeros = 0;
  for (u64 attempt = 0; attempt < 40 && zeros < 3; ++attempt) {
    try {
      if (!is_zero_at(0x9e3779b97f4a7c15ULL * (attempt + 1))) return Identity::nonzero;
      ++zeros;
    } catch (const Pole&) {
    } catch (const Undecidable&) {
      return Identity::undecided;
    }
  }
  return zeros == 3 ? Identity::zero : Identity::undecided;
}

}  // namespace

Identity identically_zero(const ex& e, const Intermediates& program) {
  if (is_a<GiNaC::numeric>(e)) return e.is_zero() ? Identity::zero : Identity::nonzero;
  return decide([&](u64 seed) { return ModularPoint(program, seed).value(e) == 0; });
}

Identity identically_singular(const GiNaC::matrix& m, const Intermediates& program) {
  return decide([&](u64 seed) {
    ModularPoint point(program, seed);
    std::vector<std::vector<u64>> a(m.rows(), std::vector<u64>(m.cols()));
    for (unsigned i = 0; i < m.rows(); ++i)
      for (unsigned j = 0; j < m.cols(); ++j) a[i][j] = point.value(m(i, j));
    return determinant_mod(std::move(a)) == 0;
  });
}

bool shown_singular(const GiNaC::matrix& m, const Intermediates& program) {
  switch (identically_singular(m, program)) {
    case Identity::zero:
      return true;
    case Identity::nonzero:
      return false;
    case Identity::undecided:
      break;
  }
  return is_zero_almost_surely(m.determinant());
}

bool shown_zero(const ex& e, const Intermediates& program) {
  if (e.is_zero()) return true;
  switch (identically_zero(e, program)) {
    case Identity::zero:
      return true;
    case Identity::nonzero:
      return false;
    case Identity::undecided:
      break;
  }
  return simplify_bounded(e).is_zero();
}

}  // namespace hamel
