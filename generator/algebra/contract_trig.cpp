#include "algebra/contract_trig.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/simplify.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <vector>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;

namespace {

constexpr std::size_t unlimited = std::numeric_limits<std::size_t>::max() / 2;
// A trigonometric monomial is linearized only up to this degree and this many modes: beyond, its term stays as
// it is (keeps printing cheap for the large expressions of big models; contraction pays off for small degrees).
constexpr int max_degree = 8;
constexpr std::size_t max_modes = 64;

// The angles of one sum, as integer combinations of its base angles (the arguments of its sin and cos factors):
// products of modes then only add and subtract integer vectors.
class Angles {
 public:
  std::size_t index(const ex& base) {
    auto [it, inserted] = index_.emplace(base, bases_.size());
    if (inserted) bases_.push_back(base);
    return it->second;
  }
  ex as_ex(const std::vector<int>& k) const {
    ex out = 0;
    for (std::size_t i = 0; i < k.size(); ++i) out += k[i] * bases_[i];
    return out;
  }

 private:
  std::map<ex, std::size_t, GiNaC::ex_is_less> index_;
  std::vector<ex> bases_;
};

// A Fourier mode: the constant 1, cos(k·θ) or sin(k·θ) for an integer vector k (no trailing zeros) whose first
// non-zero entry is positive.
enum class Kind { one, cos, sin };
struct Mode {
  Kind kind;
  std::vector<int> angle;
  bool operator<(const Mode& o) const { return kind != o.kind ? kind < o.kind : angle < o.angle; }
};
// A trigonometric polynomial in linear form: Σ coefficient · mode.
using Fourier = std::map<Mode, ex>;

// out += coefficient · mode(kind, angle), with cos(−x) = cos x, sin(−x) = −sin x, cos 0 = 1, sin 0 = 0.
void add_mode(Fourier& out, Kind kind, std::vector<int> angle, const ex& coefficient) {
  while (!angle.empty() && angle.back() == 0) angle.pop_back();
  ex c = coefficient;
  if (kind == Kind::one || angle.empty()) {
    if (kind == Kind::sin) return;
    kind = Kind::one;
    angle.clear();
  } else if (*std::find_if(angle.begin(), angle.end(), [](int k) { return k != 0; }) < 0) {
    for (int& k : angle) k = -k;
    if (kind == Kind::sin) c = -c;
  }
  auto [it, inserted] = out.emplace(Mode{kind, std::move(angle)}, c);
  if (!inserted) it->second += c;
}

std::vector<int> combine(const std::vector<int>& a, const std::vector<int>& b, int sign) {
  std::vector<int> out(std::max(a.size(), b.size()), 0);
  for (std::size_t i = 0; i < a.size(); ++i) out[i] += a[i];
  for (std::size_t i = 0; i < b.size(); ++i) out[i] += sign * b[i];
  return out;
}

// f · (cos or sin)(b) by the product-to-sum identities.
Fourier times(const Fourier& f, Kind kind, const std::vector<int>& b) {
  Fourier out;
  for (const auto& [m, c] : f) {
    if (m.kind == Kind::one) {
      add_mode(out, kind, b, c);
      continue;
    }
    const std::vector<int>& a = m.angle;
    const ex half = c / 2;
    if (m.kind == Kind::cos && kind == Kind::cos) {  // cos a cos b = (cos(a−b) + cos(a+b)) / 2
      add_mode(out, Kind::cos, combine(a, b, -1), half);
      add_mode(out, Kind::cos, combine(a, b, 1), half);
    } else if (m.kind == Kind::sin && kind == Kind::sin) {  // sin a sin b = (cos(a−b) − cos(a+b)) / 2
      add_mode(out, Kind::cos, combine(a, b, -1), half);
      add_mode(out, Kind::cos, combine(a, b, 1), -half);
    } else if (m.kind == Kind::sin) {  // sin a cos b = (sin(a+b) + sin(a−b)) / 2
      add_mode(out, Kind::sin, combine(a, b, 1), half);
      add_mode(out, Kind::sin, combine(a, b, -1), half);
    } else {  // cos a sin b = (sin(a+b) − sin(a−b)) / 2
      add_mode(out, Kind::sin, combine(a, b, 1), half);
      add_mode(out, Kind::sin, combine(a, b, -1), -half);
    }
  }
  for (auto it = out.begin(); it != out.end();) it = it->second.is_zero() ? out.erase(it) : std::next(it);
  return out;
}

// True when `a` is the negative of the spelling of an angle to print: the sign of its leading term (GiNaC orders
// the terms of a sum by everything but their numeric coefficient, so `a` and `−a` agree on which term leads).
bool negative_angle(const ex& a) {
  if (is_a<GiNaC::numeric>(a)) return ex_to<GiNaC::numeric>(a).is_negative();
  if (is_a<GiNaC::mul>(a)) {
    const ex c = a.op(a.nops() - 1);
    return is_a<GiNaC::numeric>(c) && ex_to<GiNaC::numeric>(c).is_negative();
  }
  if (is_a<GiNaC::add>(a))
    for (std::size_t i = 0; i < a.nops(); ++i)
      if (!is_a<GiNaC::numeric>(a.op(i))) return negative_angle(a.op(i));
  return false;
}

bool has_symbol(const ex& e) {
  if (is_a<GiNaC::symbol>(e)) return true;
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (has_symbol(e.op(i))) return true;
  return false;
}

// sin or cos of an angle that depends on a symbol (sin(1) is a number, not a trigonometric factor).
std::optional<Kind> trig_kind(const ex& x) {
  if (!is_a<GiNaC::function>(x)) return std::nullopt;
  const std::string name = ex_to<GiNaC::function>(x).get_name();
  if (name != "sin" && name != "cos") return std::nullopt;
  if (!has_symbol(x.op(0))) return std::nullopt;
  return name == "sin" ? Kind::sin : Kind::cos;
}

// The degree of a product's trigonometric monomial: its sin and cos factors counted with their powers.
long trig_degree(const ex& term) {
  const auto degree = [](const ex& x) -> long {
    if (trig_kind(x)) return 1;
    if (is_a<GiNaC::power>(x) && trig_kind(x.op(0)) && is_a<GiNaC::numeric>(x.op(1)) &&
        ex_to<GiNaC::numeric>(x.op(1)).is_pos_integer())
      return ex_to<GiNaC::numeric>(x.op(1)).to_long();
    return 0;
  };
  if (!is_a<GiNaC::mul>(term)) return degree(term);
  long n = 0;
  for (std::size_t i = 0; i < term.nops(); ++i) n += degree(term.op(i));
  return n;
}

// A term of a sum as coefficient · trigonometric monomial, the monomial linearized; the base angles it depends on
// name its group. Empty when the term has no trigonometric factor or one beyond the bounds above.
struct LinearTerm {
  ex coefficient, monomial;  // the term is coefficient · monomial
  Fourier linear;            // the term linearized
  std::vector<std::size_t> bases;
};

std::optional<LinearTerm> linearize_term(const ex& term, Angles& angles) {
  std::vector<ex> factors;
  if (is_a<GiNaC::mul>(term))
    for (std::size_t i = 0; i < term.nops(); ++i) factors.push_back(term.op(i));
  else
    factors.push_back(term);
  ex coefficient = 1, monomial = 1;
  Fourier f{{Mode{Kind::one, {}}, 1}};
  std::set<std::size_t> bases;
  int degree = 0;
  for (const ex& x : factors) {
    ex base = x;
    long power = 1;
    if (is_a<GiNaC::power>(x) && is_a<GiNaC::numeric>(x.op(1)) && ex_to<GiNaC::numeric>(x.op(1)).is_pos_integer()) {
      base = x.op(0);
      power = ex_to<GiNaC::numeric>(x.op(1)).to_long();
    }
    const std::optional<Kind> kind = trig_kind(base);
    if (!kind) {
      coefficient *= x;
      continue;
    }
    monomial *= x;
    degree += static_cast<int>(power);
    if (degree > max_degree) return std::nullopt;
    const std::size_t i = angles.index(base.op(0));
    bases.insert(i);
    std::vector<int> angle(i + 1, 0);
    angle[i] = 1;
    for (long k = 0; k < power; ++k) f = times(f, *kind, angle);
    if (f.size() > max_modes) return std::nullopt;
  }
  if (degree == 0) return std::nullopt;
  LinearTerm out;
  out.coefficient = coefficient;
  out.monomial = monomial;
  for (auto& [m, c] : f) out.linear.emplace(m, c * coefficient);
  out.bases.assign(bases.begin(), bases.end());
  return out;
}

// Coefficients collected exactly where that is cheap (terms that cancel only once expanded).
void tidy(Fourier& f) {
  for (auto it = f.begin(); it != f.end();) {
    if (node_count(it->second, 200) <= 200) it->second = it->second.expand();
    it = it->second.is_zero() ? f.erase(it) : std::next(it);
  }
}

ex as_ex(const Fourier& f, const Angles& angles) {
  ex out = 0;
  for (const auto& [m, c] : f) {
    if (m.kind == Kind::one) {
      out += c;
      continue;
    }
    const ex angle = angles.as_ex(m.angle);
    if (m.kind == Kind::cos) {
      out += c * GiNaC::cos(negative_angle(angle) ? -angle : angle);
      continue;
    }
    // c sin(a), or −c sin(−a) for an angle whose leading term is negative (how it prints, algebra/expression_text).
    out += negative_angle(angle) ? -c * GiNaC::sin(-angle) : c * GiNaC::sin(angle);
  }
  return out;
}

// The terms of a sum (or the one term).
std::vector<ex> terms_of(const ex& e) {
  std::vector<ex> terms;
  if (is_a<GiNaC::add>(e))
    for (std::size_t i = 0; i < e.nops(); ++i) terms.push_back(e.op(i));
  else
    terms.push_back(e);
  return terms;
}

// False in the common case where nothing can contract: terms of degree at most 1 with distinct trigonometric
// factors.
bool may_contract(const std::vector<ex>& terms) {
  std::set<ex, GiNaC::ex_is_less> factors;
  for (const ex& t : terms) {
    const long degree = trig_degree(t);
    if (degree >= 2) return true;
    if (degree == 0) continue;
    ex factor = t;
    if (is_a<GiNaC::mul>(t))
      for (std::size_t i = 0; i < t.nops(); ++i)
        if (trig_kind(t.op(i))) factor = t.op(i);
    if (!factors.insert(factor).second) return true;
  }
  return false;
}

// The nodes of a sum are 1 + those of its terms: the nodes its terms add to another sum.
std::size_t terms_size(const ex& x) {
  if (x.is_zero()) return 0;
  const std::size_t n = node_count(x, unlimited);
  return is_a<GiNaC::add>(x) ? n - 1 : n;
}

// One sum's terms grouped by the angle symbols of their trigonometric factors, and the search for the form of
// each group (contract_sum).
class SumContraction {
 public:
  explicit SumContraction(const std::vector<ex>& terms);
  /// False when no group can change: every monomial of degree 1 (they linearize to themselves) and none repeated.
  bool may_change() const { return may_change_; }
  /// The shortest form found, or e (the sum of the terms) when none is shorter.
  ex best(const ex& e);

 private:
  enum Form { original, collected, linearized };
  struct Group {
    ex original = 0, collected = 0;
    std::size_t terms = 0;
    long degree = 0;                                    // the highest degree of its monomials
    std::size_t original_size = 0, collected_size = 0;  // nodes of its terms
    bool linearizable = false;
    std::map<ex, ex, GiNaC::ex_is_less> by_monomial;
    Fourier linear;
  };
  /// Each group's collected and linear forms, formed once the sum may change.
  void complete_groups();
  /// The fixed terms plus the linearized groups' modes, merged.
  ex linear_part(const std::vector<Form>& form);
  /// The estimated nodes of the sum in `form` (merges of the linear part with the fixed terms aside).
  std::size_t size_of(const std::vector<Form>& form);
  /// Each group's shortest form on its own.
  std::vector<Form> locally_best();
  /// The best estimate among: the local choice, all groups collected, all linearizable groups linearized, and
  /// for a few groups, changes of one group at a time.
  std::vector<Form> search(const std::vector<Form>& local);
  ex built(const std::vector<Form>& form);

  ex fixed_ = 0;  // terms that do not linearize
  std::size_t fixed_size_ = 0;
  Angles angles_;
  std::map<std::vector<std::size_t>, Group> by_atoms_;
  std::vector<Group> groups_;
  bool may_change_ = false;
  std::map<std::vector<bool>, std::size_t> linear_sizes_;  // by the set of linearized groups
};

SumContraction::SumContraction(const std::vector<ex>& terms) {
  // The angles are numbered in structural order, not in GiNaC's term order (which follows hash values that include
  // addresses): the numbering orders the groups, and ties between equally short forms go to the first group.
  std::vector<ex> bases;
  for (const ex& t : terms)
    for (std::size_t i = 0; i < (is_a<GiNaC::mul>(t) ? t.nops() : 1); ++i) {
      const ex x = is_a<GiNaC::mul>(t) ? t.op(i) : t;
      const ex base = is_a<GiNaC::power>(x) ? x.op(0) : x;
      if (trig_kind(base)) bases.push_back(base.op(0));
    }
  std::sort(bases.begin(), bases.end(), structurally_less);
  for (const ex& b : bases) angles_.index(b);
  for (const ex& t : terms) {
    std::optional<LinearTerm> l = linearize_term(t, angles_);
    if (!l) {
      fixed_ += t;
      fixed_size_ += node_count(t, unlimited);
      continue;
    }
    Group& g = by_atoms_[l->bases];
    g.original += t;
    g.original_size += node_count(t, unlimited);
    ++g.terms;
    g.degree = std::max(g.degree, trig_degree(l->monomial));
    g.by_monomial[l->monomial] += l->coefficient;
    for (auto& [m, c] : l->linear) add_mode(g.linear, m.kind, m.angle, c);
  }
  for (const auto& [bases, g] : by_atoms_) may_change_ = may_change_ || g.degree >= 2 || g.by_monomial.size() < g.terms;
}

void SumContraction::complete_groups() {
  for (auto& [bases, g] : by_atoms_) {
    tidy(g.linear);
    // Linearizing pays off only when modes cancel: a linear form with more modes than the group has monomials
    // (plus the constant) is longer in practice (cos²a cos²b has 5), and is not tried. Groups of degree 1 are
    // their own linear form: linearized, they merge with the modes of other linearized groups.
    g.linearizable = g.linear.size() <= g.by_monomial.size() + 1;
    for (const auto& [monomial, c] : g.by_monomial) {
      const ex term = (node_count(c, 200) <= 200 ? c.expand() : c) * monomial;
      g.collected += term;
      g.collected_size += node_count(term, unlimited);
    }
    groups_.push_back(std::move(g));
  }
  by_atoms_.clear();
}

ex SumContraction::linear_part(const std::vector<Form>& form) {
  Fourier pool;
  std::map<Mode, int> contributions;
  for (std::size_t i = 0; i < groups_.size(); ++i)
    if (form[i] == linearized)
      for (const auto& [m, c] : groups_[i].linear) {
        add_mode(pool, m.kind, m.angle, c);
        ++contributions[m];
      }
  // Each group's coefficients are collected already: only modes shared by groups need it again.
  for (auto it = pool.begin(); it != pool.end();) {
    if (contributions[it->first] > 1 && node_count(it->second, 200) <= 200) it->second = it->second.expand();
    it = it->second.is_zero() ? pool.erase(it) : std::next(it);
  }
  return fixed_ + as_ex(pool, angles_);
}

// Terms of different groups have different monomials and do not merge; linearized groups are merged with each
// other and the fixed terms. (The size of the chosen form is checked on the built expression at the end.)
std::size_t SumContraction::size_of(const std::vector<Form>& form) {
  std::size_t n = 1;
  std::vector<bool> linear(groups_.size(), false);
  for (std::size_t i = 0; i < groups_.size(); ++i) {
    if (form[i] == original) n += groups_[i].original_size;
    if (form[i] == collected) n += groups_[i].collected_size;
    linear[i] = form[i] == linearized;
  }
  if (std::none_of(linear.begin(), linear.end(), [](bool b) { return b; })) return n + fixed_size_;
  auto it = linear_sizes_.find(linear);
  if (it == linear_sizes_.end()) it = linear_sizes_.emplace(linear, terms_size(linear_part(form))).first;
  return n + it->second;
}

std::vector<SumContraction::Form> SumContraction::locally_best() {
  std::vector<Form> local(groups_.size(), original);
  for (std::size_t i = 0; i < groups_.size(); ++i) {
    std::size_t size = groups_[i].original_size;
    if (groups_[i].collected_size < size) local[i] = collected, size = groups_[i].collected_size;
    if (groups_[i].linearizable && terms_size(as_ex(groups_[i].linear, angles_)) < size) local[i] = linearized;
  }
  return local;
}

std::vector<SumContraction::Form> SumContraction::search(const std::vector<Form>& local) {
  std::vector<Form> choice(groups_.size(), original);
  std::size_t best_size = size_of(choice);
  const auto consider = [&](const std::vector<Form>& c) {
    const std::size_t size = size_of(c);
    if (size >= best_size) return false;
    best_size = size;
    choice = c;
    return true;
  };
  consider(local);
  consider(std::vector<Form>(groups_.size(), collected));
  // All linearized together: constants and modes cancel across linearized groups.
  std::vector<Form> all_linear = local;
  for (std::size_t i = 0; i < groups_.size(); ++i)
    if (groups_[i].linearizable) all_linear[i] = linearized;
  consider(all_linear);
  constexpr std::size_t few = 6;
  for (int pass = 0; pass < 2 && groups_.size() <= few; ++pass) {
    bool improved = false;
    for (std::size_t i = 0; i < groups_.size(); ++i)
      for (Form f : {original, collected, linearized}) {
        if (f == choice[i] || (f == collected && groups_[i].by_monomial.size() == groups_[i].terms) ||
            (f == linearized && !groups_[i].linearizable))
          continue;
        std::vector<Form> c = choice;
        c[i] = f;
        improved = consider(c) || improved;
      }
    if (!improved) break;
  }
  return choice;
}

ex SumContraction::built(const std::vector<Form>& form) {
  ex out = linear_part(form);
  for (std::size_t i = 0; i < groups_.size(); ++i) {
    if (form[i] == original) out += groups_[i].original;
    if (form[i] == collected) out += groups_[i].collected;
  }
  return out;
}

ex SumContraction::best(const ex& e) {
  complete_groups();
  const std::vector<Form> local = locally_best();
  const std::vector<Form> choice = search(local);
  // The estimate ignores merges of the linear part with the fixed terms: the choice and each group's own best are
  // built and counted.
  ex best = e;
  std::size_t size = node_count(e, unlimited);
  for (const std::vector<Form>& form : {choice, local}) {
    if (std::all_of(form.begin(), form.end(), [](Form f) { return f == original; })) continue;
    const ex x = built(form);
    const std::size_t n = node_count(x, size);
    if (n < size) best = x, size = n;
  }
  return best;
}

// A sum (or one term): each group of terms (same angle symbols) written as it is, with the coefficients of equal
// monomials collected (m cos²θ − n cos²θ → (m − n) cos²θ), or linearized, whichever choice gives the fewest nodes;
// linearized groups are collected together with the terms free of trigonometric factors, so that their constants
// and shared modes cancel.
ex contract_sum(const ex& e) {
  const std::vector<ex> terms = terms_of(e);
  if (!may_contract(terms)) return e;
  SumContraction contraction(terms);
  return contraction.may_change() ? contraction.best(e) : e;
}

struct Contract : GiNaC::map_function {
  ex operator()(const ex& e) override {
    if (is_a<GiNaC::symbol>(e) || is_a<GiNaC::numeric>(e)) return e;
    ex mapped = e.map(*this);
    if (mapped.is_equal(e)) mapped = e;  // keep the object (and its spelling) when nothing changed
    if (is_a<GiNaC::add>(mapped)) return contract_sum(mapped);
    // A single term only changes when its monomial is of degree 2 or more (2 sin t cos t → sin 2t).
    if ((is_a<GiNaC::mul>(mapped) || is_a<GiNaC::power>(mapped)) && trig_degree(mapped) >= 2)
      return contract_sum(mapped);
    return mapped;
  }
};

}  // namespace

ex contract_trig(const ex& e) {
  Contract contract;
  return contract(e);
}

}  // namespace hamel
