#include "algebra/simplify.hpp"

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

ex simplify(const ex& e) {
  TrigSymbols trig;
  ex x = trig.to_symbols(expand_trig(e));
  // Two rounds: the reduction can expose common factors that normal() then cancels.
  for (int round = 0; round < 2; ++round) {
    const ex nd = x.normal().numer_denom();
    const ex num = reduce_pythagoras(nd.op(0), trig);
    if (num.is_zero()) return 0;
    const ex den = reduce_pythagoras(nd.op(1), trig);
    x = num / den;
  }
  return trig.from_symbols(x.normal());
}

bool is_zero_exactly(const ex& e) { return simplify(e).is_zero(); }

GiNaC::matrix simplify(const GiNaC::matrix& m) {
  GiNaC::matrix out(m.rows(), m.cols());
  for (unsigned i = 0; i < m.rows(); ++i)
    for (unsigned j = 0; j < m.cols(); ++j) out(i, j) = simplify(m(i, j));
  return out;
}

}  // namespace hamel
