#include "algebra/simplify.hpp"

#include "algebra/high_precision.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/modular_arithmetic.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <set>
#include <unordered_map>

#include <map>
#include <vector>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;

namespace {

struct SinCos {
  ex sin, cos;
};

// sin and cos of an angle, recursively split over sums and integer multiples.
SinCos sin_cos_of(const ex& angle) {
  if (is_a<GiNaC::add>(angle) && angle.nops() > 1) {
    const ex first = angle.op(0);
    const ex rest = angle - first;
    const SinCos a = sin_cos_of(first), b = sin_cos_of(rest);
    return {a.sin * b.cos + a.cos * b.sin, a.cos * b.cos - a.sin * b.sin};
  }
  if (is_a<GiNaC::mul>(angle)) {
    const ex coefficient = angle.op(angle.nops() - 1);  // GiNaC keeps the numeric factor last
    if (is_a<GiNaC::numeric>(coefficient)) {
      const GiNaC::numeric c = ex_to<GiNaC::numeric>(coefficient);
      const ex base = angle / coefficient;
      if (c.is_integer() && c != 1 && c != -1 && abs(c) <= 12) {
        // Multiple angles: sin((k)x) from sin((k-1)x) by the addition theorem.
        const SinCos one = sin_cos_of(base);
        SinCos acc = one;
        const long k = abs(c).to_long();
        for (long i = 1; i < k; ++i)
          acc = {acc.sin * one.cos + acc.cos * one.sin, acc.cos * one.cos - acc.sin * one.sin};
        if (c.is_negative()) acc.sin = -acc.sin;
        return acc;
      }
      if (c.is_negative()) {
        const SinCos pos = sin_cos_of(-angle);
        return {-pos.sin, pos.cos};
      }
    }
  }
  if (is_a<GiNaC::numeric>(angle) && angle.is_zero()) return {0, 1};
  return {GiNaC::sin(angle), GiNaC::cos(angle)};
}

struct ExpandTrig : GiNaC::map_function {
  ex operator()(const ex& e) override {
    if (is_a<GiNaC::function>(e)) {
      const std::string name = ex_to<GiNaC::function>(e).get_name();
      if (name == "sin" || name == "cos" || name == "tan") {
        const SinCos sc = sin_cos_of((*this)(e.op(0)).expand());
        if (name == "sin") return sc.sin;
        if (name == "cos") return sc.cos;
        return sc.sin / sc.cos;
      }
    }
    return e.map(*this);
  }
};

// Replaces sin(θ)/cos(θ) by symbols S_θ/C_θ and back.
class TrigSymbols {
 public:
  ex to_symbols(const ex& e) {
    struct Map : GiNaC::map_function {
      TrigSymbols* self;
      explicit Map(TrigSymbols* s) : self(s) {}
      ex operator()(const ex& x) override {
        if (is_a<GiNaC::function>(x)) {
          const std::string name = ex_to<GiNaC::function>(x).get_name();
          if (name == "sin") return self->symbol_for(x.op(0)).first;
          if (name == "cos") return self->symbol_for(x.op(0)).second;
        }
        return x.map(*this);
      }
    } map(this);
    return map(e);
  }
  ex from_symbols(const ex& e) const { return e.subs(back_); }
  const std::vector<std::pair<GiNaC::symbol, GiNaC::symbol>>& pairs() const { return pairs_; }

 private:
  std::pair<GiNaC::symbol, GiNaC::symbol> symbol_for(const ex& angle) {
    auto it = index_.find(angle);
    if (it != index_.end()) return pairs_[it->second];
    GiNaC::symbol s, c;
    index_.emplace(angle, pairs_.size());
    pairs_.emplace_back(s, c);
    back_.append(s == GiNaC::sin(angle));
    back_.append(c == GiNaC::cos(angle));
    return pairs_.back();
  }
  std::map<ex, std::size_t, GiNaC::ex_is_less> index_;
  std::vector<std::pair<GiNaC::symbol, GiNaC::symbol>> pairs_;
  GiNaC::lst back_;
};

// Remainder of a polynomial modulo S² + C² − 1 for every (S, C) pair. Parts that are no polynomial in
// S and C, such as sqrt(S) or S^x, stand in as fresh symbols meanwhile (found by tests/fuzz: degree()
// throws on them).
ex reduce_pythagoras(const ex& polynomial, const TrigSymbols& trig) {
  GiNaC::exmap opaque;
  ex p = polynomial.expand().to_polynomial(opaque);
  for (const auto& [s, c] : trig.pairs()) {
    if (!p.is_polynomial(GiNaC::lst{s, c})) continue;  // safety net; to_polynomial should leave none
    const int degree = p.degree(s);
    if (degree < 2) continue;
    ex reduced = 0;
    for (int k = 0; k <= degree; ++k) reduced += p.coeff(s, k) * GiNaC::pow(s, k % 2) * GiNaC::pow(1 - c * c, k / 2);
    p = reduced.expand();
  }
  return p.subs(opaque).expand();
}

}  // namespace

ex expand_trig(const ex& e) {
  ExpandTrig expander;
  return expander(e);
}

namespace {

// Powers of sums b^n (n an integer, |n| >= 2) stand in as powers of fresh symbols z_b^n while a fraction is
// formed, so that normal() does not multiply them out. Each base is brought to its own (chosen) form
// first, recursively, numerator and denominator separately, so a base that is no sum once simplified
// ((sin² + cos²)^3) does not stay opaque.
class PowersOfSums : public GiNaC::map_function {
 public:
  ex operator()(const ex& e) override {
    if (is_a<GiNaC::power>(e) && is_a<GiNaC::numeric>(e.op(1))) {
      const GiNaC::numeric n = ex_to<GiNaC::numeric>(e.op(1));
      if (n.is_integer() && GiNaC::abs(n) >= 2 && is_a<GiNaC::add>(e.op(0))) {
        const ex nd = simplify(e.op(0)).numer_denom();
        return GiNaC::pow(atom(nd.op(0)), n) / GiNaC::pow(atom(nd.op(1)), n);
      }
    }
    return e.map(*this);
  }
  const GiNaC::exmap& back() const { return back_; }

 private:
  ex atom(const ex& base) {
    if (!is_a<GiNaC::add>(base)) return base;
    auto it = index_.find(base);
    if (it != index_.end()) return it->second;
    const GiNaC::symbol z;
    index_.emplace(base, z);
    back_[z] = base;
    return z;
  }
  std::map<ex, ex, GiNaC::ex_is_less> index_;
  GiNaC::exmap back_;
};

// One fraction of `e` (sin/cos already expanded), numerator and denominator reduced modulo sin² + cos² = 1;
// with `powers`, the powers of sums stay whole. Returns 0 when the numerator reduces to 0.
ex fraction(const ex& e, TrigSymbols& trig, PowersOfSums* powers) {
  ex x = trig.to_symbols(powers ? (*powers)(e) : e);
  // Two rounds: the reduction can expose common factors that normal() then cancels.
  for (int round = 0; round < 2; ++round) {
    const ex nd = x.normal().numer_denom();
    const ex num = reduce_pythagoras(nd.op(0), trig);
    if (num.is_zero()) return 0;
    const ex den = reduce_pythagoras(nd.op(1), trig);
    x = num / den;
  }
  x = trig.from_symbols(x.normal());
  return powers ? x.subs(powers->back()) : x;
}

bool has_power_of_sum(const ex& e) {
  if (is_a<GiNaC::power>(e) && is_a<GiNaC::add>(e.op(0)) && is_a<GiNaC::numeric>(e.op(1))) {
    const GiNaC::numeric n = ex_to<GiNaC::numeric>(e.op(1));
    if (n.is_integer() && GiNaC::abs(n) >= 2) return true;
  }
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (has_power_of_sum(e.op(i))) return true;
  return false;
}

}  // namespace

// The normal form multiplies out every power of a sum. That is what makes cancellations exact
// ((v sin θ + a ω cos θ)² + (a ω sin θ − v cos θ)² is v² + a²ω²), but where nothing cancels it only
// costs size and accuracy: (x+1)^199 becomes 200 monomials whose sum in doubles at x = −0.9 is −3e38
// instead of −1e−199; in general an expanded b^n loses u·(Σ|monomials|)/|b^n| near a
// root of b, where b^n evaluated whole loses only n times b's own relative error. So both forms are made,
// the normal form and the one with powers of sums kept whole, and the smaller (in expression nodes) is
// returned, the normal form on a tie: a cancellation shows as a smaller normal form, a mere expansion as a
// larger one. Zero detection stays exact: the normal form is canonical, and 0 is the smallest of all.
ex simplify(const ex& e) {
  const ex expanded = expand_trig(e);
  TrigSymbols trig;
  const ex normal = fraction(expanded, trig, nullptr);
  if (normal.is_zero() || !has_power_of_sum(expanded)) return normal;
  // A normal form no larger than the expression as given has not grown by expansion: keep it without
  // making the other (which costs time, and GiNaC symbols whose serial numbers shift the term order of
  // everything derived afterwards).
  const std::size_t normal_size = node_count(normal, std::numeric_limits<std::size_t>::max() / 2);
  if (normal_size <= node_count(expanded, normal_size)) return normal;
  PowersOfSums powers;
  const ex whole = fraction(expanded, trig, &powers);
  return node_count(whole, normal_size) < normal_size ? whole : normal;
}

ex expand_keeping_powers_of_sums(const ex& e) {
  const ex full = e.expand();
  if (!has_power_of_sum(e)) return full;
  const std::size_t full_size = node_count(full, std::numeric_limits<std::size_t>::max() / 2);
  if (full_size <= node_count(e, full_size)) return full;
  PowersOfSums powers;
  const ex whole = powers(e).expand().subs(powers.back());
  return node_count(whole, full_size) < full_size ? whole : full;
}

namespace {

void collect_symbols(const ex& e, std::set<ex, GiNaC::ex_is_less>& out) {
  if (is_a<GiNaC::symbol>(e)) {
    out.insert(e);
    return;
  }
  for (std::size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), out);
}

}  // namespace

std::size_t node_count(const ex& e, std::size_t limit) {
  if (is_a<GiNaC::mul>(e)) {  // a factor −1 is not counted, nor the product −x it leaves
    std::size_t n = 0, kept = 0;
    for (std::size_t i = 0; i < e.nops() && n <= limit; ++i) {
      if (is_a<GiNaC::numeric>(e.op(i)) && e.op(i).is_equal(GiNaC::ex(-1))) continue;
      n += node_count(e.op(i), limit - n);
      ++kept;
    }
    return kept == 1 ? n : n + 1;
  }
  std::size_t n = 1;
  for (std::size_t i = 0; i < e.nops() && n <= limit; ++i) n += node_count(e.op(i), limit - n);
  return n;
}

bool numerically_nonzero(const ex& e) {
  std::set<ex, GiNaC::ex_is_less> symbols;
  collect_symbols(e, symbols);
  HighPrecisionExpressionEvaluator evaluator(50);
  // Two fixed pseudo-random points in [0.31, 1.3]: deterministic, and away from the integers and zero. Each symbol's
  // value is a function of its name and the point, not of the order GiNaC keeps the symbols in.
  for (int point = 0; point < 2; ++point) {
    std::map<ex, GiNaC::numeric, GiNaC::ex_is_less> values;
    for (const ex& s : symbols) {
      const modular::u64 h = modular::RandomPoint(0x2545f4914f6cdd1dULL + static_cast<modular::u64>(point))
                                 .residue(modular::key_of(ex_to<GiNaC::symbol>(s).get_name()))
                                 .value;
      values[s] = GiNaC::numeric(31 + static_cast<int>(h % 1000u), 100);
    }
    evaluator.assign(values);
    try {
      if (GiNaC::abs(evaluator.value(e)) > GiNaC::pow(GiNaC::numeric(10), -25)) return true;
    } catch (const std::exception&) {
      // a pole, a value off the real line or a function the evaluator does not know: this point says nothing
    }
  }
  return false;
}

bool is_zero_almost_surely(const ex& e) {
  if (numerically_nonzero(e)) return false;
  return identically_zero(e, Intermediates{}) == Identity::zero || simplify(e).is_zero();
}

ex simplify_bounded(const ex& e, std::size_t limit) {
  if (node_count(e, limit) <= limit) return simplify(e);
  // modular evaluation: cheap for large e; where it cannot decide, e is left as derived
  return identically_zero(e, Intermediates{}) == Identity::zero ? ex(0) : e;
}

namespace {

// A polynomial of degree ≤ 2 in velocities v_0 … v_{d−1}: monomial → coefficient (free of the velocities).
// Keys (a, b), a ≤ b, index the velocities of the monomial, −1 for none: (−1, −1) is the constant term,
// (−1, j) the term in v_j, (j, k) the term in v_j v_k.
using Monomial = std::pair<int, int>;
using QuadraticPolynomial = std::map<Monomial, ex>;

class QuadraticSplitter {
 public:
  explicit QuadraticSplitter(const std::vector<ex>& variables) {
    for (std::size_t j = 0; j < variables.size(); ++j) index_.emplace(variables[j], static_cast<int>(j));
  }

  // The monomial coefficients of e, built by distributing sums over products only (an identity, so nothing
  // needs checking afterwards); std::nullopt when e is not a polynomial of degree ≤ 2 in the variables.
  std::optional<QuadraticPolynomial> split(const ex& e) {
    if (auto it = memo_.find(e); it != memo_.end()) return it->second;
    std::optional<QuadraticPolynomial> out = compute(e);
    memo_.emplace(e, out);
    return out;
  }

 private:
  std::optional<QuadraticPolynomial> compute(const ex& e) {
    if (is_a<GiNaC::symbol>(e)) {
      auto it = index_.find(e);
      if (it != index_.end()) return QuadraticPolynomial{{{-1, it->second}, 1}};
      return QuadraticPolynomial{{{-1, -1}, e}};
    }
    if (is_a<GiNaC::add>(e)) {
      QuadraticPolynomial sum;
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const auto term = split(e.op(i));
        if (!term) return std::nullopt;
        for (const auto& [m, c] : *term) sum[m] += c;
      }
      return sum;
    }
    if (is_a<GiNaC::mul>(e)) {
      QuadraticPolynomial product{{{-1, -1}, 1}};
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const auto factor = split(e.op(i));
        if (!factor) return std::nullopt;
        product = multiply(product, *factor);
        if (product.empty()) return std::nullopt;
      }
      return product;
    }
    if (!has_variable(e)) return QuadraticPolynomial{{{-1, -1}, e}};
    if (is_a<GiNaC::power>(e) && is_a<GiNaC::numeric>(e.op(1)) && ex_to<GiNaC::numeric>(e.op(1)).is_pos_integer()) {
      const auto base = split(e.op(0));
      if (!base) return std::nullopt;
      QuadraticPolynomial product{{{-1, -1}, 1}};
      for (long k = ex_to<GiNaC::numeric>(e.op(1)).to_long(); k > 0; --k) {
        product = multiply(product, *base);
        if (product.empty()) return std::nullopt;
      }
      return product;
    }
    return std::nullopt;  // a velocity inside a function, a divisor or a fractional power
  }

  bool has_variable(const ex& e) const {
    for (const auto& [v, j] : index_)
      if (e.has(v)) return true;
    return false;
  }

  // The product, or an empty map when its degree exceeds 2.
  static QuadraticPolynomial multiply(const QuadraticPolynomial& a, const QuadraticPolynomial& b) {
    QuadraticPolynomial out;
    for (const auto& [ma, ca] : a)
      for (const auto& [mb, cb] : b) {
        std::vector<int> v;
        for (int j : {ma.first, ma.second, mb.first, mb.second})
          if (j >= 0) v.push_back(j);
        if (v.size() > 2) return {};
        std::sort(v.begin(), v.end());
        const Monomial m = v.empty() ? Monomial{-1, -1} : v.size() == 1 ? Monomial{-1, v[0]} : Monomial{v[0], v[1]};
        out[m] += ca * cb;
      }
    return out;
  }

  struct Hash {
    std::size_t operator()(const ex& e) const { return e.gethash(); }
  };
  std::map<ex, int, GiNaC::ex_is_less> index_;
  std::unordered_map<ex, std::optional<QuadraticPolynomial>, Hash, GiNaC::ex_is_equal> memo_;
};

}  // namespace

namespace {

// `simplified` unless it has more nodes than `e` (a normal form that multiplied out products of sums).
ex smaller_of(const ex& e, const ex& simplified) {
  const std::size_t size = node_count(e, std::numeric_limits<std::size_t>::max() / 2);
  return node_count(simplified, size) <= size ? simplified : e;
}

}  // namespace

ex simplify_quadratic_form(const ex& e, const std::vector<ex>& variables, std::size_t limit) {
  QuadraticSplitter splitter(variables);
  const std::optional<QuadraticPolynomial> poly = splitter.split(e);
  if (!poly) return simplify_bounded(e, limit);
  ex form = 0;
  for (const auto& [m, c] : *poly) {
    ex monomial = 1;
    if (m.first >= 0) monomial *= variables[static_cast<std::size_t>(m.first)];
    if (m.second >= 0) monomial *= variables[static_cast<std::size_t>(m.second)];
    // Small coefficients in their normal form; larger ones where that is no larger than the coefficient as derived.
    const ex simplified = simplify_bounded(c, limit);
    form += (node_count(c, limit / 8) <= limit / 8 ? simplified : smaller_of(c, simplified)) * monomial;
  }
  return form;
}

GiNaC::matrix simplify(const GiNaC::matrix& m) {
  GiNaC::matrix out(m.rows(), m.cols());
  for (unsigned i = 0; i < m.rows(); ++i)
    for (unsigned j = 0; j < m.cols(); ++j) out(i, j) = simplify(m(i, j));
  return out;
}

}  // namespace hamel
