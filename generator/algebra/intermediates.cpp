#include "algebra/intermediates.hpp"

#include "algebra/simplify.hpp"

#include <set>

namespace hamel {

using GiNaC::ex;

namespace {

// The intermediates an expression uses directly (not through other intermediates).
void collect(const ex& e, const std::map<ex, std::size_t, GiNaC::ex_is_less>& position, std::set<std::size_t>& out) {
  if (GiNaC::is_a<GiNaC::symbol>(e)) {
    const auto it = position.find(e);
    if (it != position.end()) out.insert(it->second);
    return;
  }
  for (std::size_t i = 0; i < e.nops(); ++i) collect(e.op(i), position, out);
}

}  // namespace

ex Intermediates::define(const ex& value) {
  if (GiNaC::is_a<GiNaC::numeric>(value) || GiNaC::is_a<GiNaC::symbol>(value)) return value;
  GiNaC::realsymbol s("_" + std::to_string(definitions_.size() + 1));
  position_[s] = definitions_.size();
  definitions_.push_back({s, value});
  return s;
}

GiNaC::realsymbol Intermediates::define_named(const std::string& name, const ex& value) {
  GiNaC::realsymbol s(name);
  position_[s] = definitions_.size();
  definitions_.push_back({s, value});
  return s;
}

void Intermediates::substitute_in_definitions(const GiNaC::exmap& map) {
  for (Definition& d : definitions_) d.value = d.value.subs(map);
  derivative_memo_.clear();
  partials_.clear();
  inlined_.clear();
  small_inlined_.clear();
  small_limit_.clear();
}

ex Intermediates::keep(const ex& value, std::size_t inline_size) {
  const ex simplified = simplify_bounded(value);
  if (node_count(simplified, inline_size) <= inline_size) return simplified;
  return define(simplified);
}

std::optional<ex> Intermediates::closed_form(const ex& e, std::size_t inlined, std::size_t kept) const {
  const std::optional<ex> whole = inline_bounded(e, inlined);
  if (!whole) return std::nullopt;
  const std::size_t size = node_count(*whole, inlined);
  const ex simplified = simplify(*whole);
  const ex& smaller = node_count(simplified, size) <= size ? simplified : *whole;
  if (node_count(smaller, kept) > kept) return std::nullopt;
  return smaller;
}

std::optional<ex> Intermediates::definition_of(const ex& e) const {
  if (!GiNaC::is_a<GiNaC::symbol>(e)) return std::nullopt;
  const auto it = position_.find(e);
  if (it == position_.end()) return std::nullopt;
  return definitions_[it->second].value;
}

std::vector<std::size_t> Intermediates::used_by(const ex& e) const {
  std::set<std::size_t> used;
  collect(e, position_, used);
  return {used.begin(), used.end()};
}

Intermediates::Partials Intermediates::partials_of(const ex& e) const {
  Partials out;
  std::set<std::size_t> used;
  collect(e, position_, used);
  if (!GiNaC::is_a<GiNaC::add>(e) || used.size() < 2) {
    for (std::size_t k : used) out.emplace_back(k, e.diff(definitions_[k].symbol));
    return out;
  }
  // A sum, term by term: each term is differentiated only by the intermediates it uses. e.diff(s_k) for every k
  // would differentiate every term by every intermediate of the sum, time n^2 for a Lagrangian that sums n bodies'
  // energies (100 bodies on 2 coordinates: 40 s).
  std::map<std::size_t, GiNaC::exvector> terms;
  for (std::size_t i = 0; i < e.nops(); ++i) {
    std::set<std::size_t> in_term;
    collect(e.op(i), position_, in_term);
    for (std::size_t k : in_term) terms[k].push_back(e.op(i).diff(definitions_[k].symbol));
  }
  for (std::size_t k : used) out.emplace_back(k, GiNaC::add(terms[k]));
  return out;
}

ex Intermediates::chain_rule(const ex& explicit_part, const Partials& partials, const GiNaC::symbol& x) {
  GiNaC::exvector terms{explicit_part};
  for (const auto& [k, partial] : partials) {
    const auto key = std::make_pair(k, ex(x));
    auto it = derivative_memo_.find(key);
    if (it == derivative_memo_.end()) {
      if (partials_.size() <= k) partials_.resize(k + 1);
      if (!partials_[k]) partials_[k] = partials_of(definitions_[k].value);
      const Partials inner = *partials_[k];  // copies: the recursion below may grow both vectors
      const ex value = definitions_[k].value;
      const ex d = define(chain_rule(value.diff(x), inner, x));
      it = derivative_memo_.emplace(key, d).first;
    }
    if (!it->second.is_zero()) terms.push_back(partial * it->second);
  }
  return GiNaC::add(terms);
}

ex Intermediates::diff(const ex& e, const GiNaC::symbol& x) { return chain_rule(e.diff(x), partials_of(e), x); }

std::vector<ex> Intermediates::diff(const ex& e, const std::vector<GiNaC::symbol>& xs) {
  const Partials partials = partials_of(e);
  std::vector<ex> out;
  out.reserve(xs.size());
  for (const GiNaC::symbol& x : xs) out.push_back(chain_rule(e.diff(x), partials, x));
  return out;
}

ex Intermediates::substitute(const ex& e, const GiNaC::exmap& map, SubstitutionMemo& memo) {
  // Depth first through the definitions e uses, with an explicit stack (a chain of 10 000 definitions needed
  // 10 000 frames of recursion): each definition is replaced after the ones it uses, in the order the recursion
  // visited them (uses ascending), so the new intermediates are numbered as before.
  constexpr std::size_t kTop = static_cast<std::size_t>(-1);
  struct Frame {
    std::size_t k;                  // the definition being replaced, kTop for e itself
    std::vector<std::size_t> used;  // the intermediates its value uses directly, ascending
    std::size_t next = 0;           // the first of `used` not yet replaced
  };
  const auto uses = [this](const ex& value) {
    std::set<std::size_t> used;
    collect(value, position_, used);
    return std::vector<std::size_t>(used.begin(), used.end());
  };
  std::vector<Frame> stack;
  stack.push_back({kTop, uses(e)});
  for (;;) {
    Frame& top = stack.back();
    bool descended = false;
    while (top.next < top.used.size()) {
      const std::size_t k = top.used[top.next];
      if (memo.replaced.size() <= k) memo.replaced.resize(k + 1);
      if (!memo.replaced[k]) {
        stack.push_back({k, uses(definitions_[k].value)});  // invalidates `top`
        descended = true;
        break;
      }
      ++top.next;
    }
    if (descended) continue;
    const Frame done = std::move(stack.back());
    stack.pop_back();
    const ex value = done.k == kTop ? e : definitions_[done.k].value;  // copy: define() below may grow the vector
    GiNaC::exmap with = map;
    for (std::size_t k : done.used)
      if (!memo.replaced[k]->is_equal(definitions_[k].symbol)) with[definitions_[k].symbol] = *memo.replaced[k];
    const ex replaced = value.subs(with);
    if (done.k == kTop) return replaced;
    memo.replaced[done.k] = replaced.is_equal(value) ? ex(definitions_[done.k].symbol) : define(replaced);
    ++stack.back().next;
  }
}

std::optional<ex> Intermediates::inline_bounded(const ex& e, std::size_t limit) const {
  std::set<std::size_t> used;
  collect(e, position_, used);
  GiNaC::exmap map;
  for (std::size_t k : used) {
    if (small_inlined_.size() <= k) small_inlined_.resize(k + 1), small_limit_.resize(k + 1, 0);
    if (small_limit_[k] < limit && !(small_limit_[k] > 0 && small_inlined_[k])) {
      small_inlined_[k] = inline_bounded(definitions_[k].value, limit);
      small_limit_[k] = limit;
    }
    if (!small_inlined_[k] || node_count(*small_inlined_[k], limit) > limit) return std::nullopt;
    map[definitions_[k].symbol] = *small_inlined_[k];
  }
  const ex out = map.empty() ? e : e.subs(map);
  if (node_count(out, limit) > limit) return std::nullopt;
  return out;
}

ex Intermediates::inline_all(const ex& e) const {
  // Only the definitions `e` needs, directly or through others (iteratively: programs may be deep).
  if (inlined_.size() < definitions_.size()) inlined_.resize(definitions_.size());
  std::set<std::size_t> top;
  collect(e, position_, top);
  std::vector<std::pair<std::size_t, bool>> stack;  // (position, its dependencies are done)
  for (std::size_t k : top) stack.emplace_back(k, false);
  while (!stack.empty()) {
    const auto [k, ready] = stack.back();
    stack.pop_back();
    if (inlined_[k]) continue;
    std::set<std::size_t> used;
    collect(definitions_[k].value, position_, used);
    if (!ready) {
      stack.emplace_back(k, true);
      for (std::size_t j : used)
        if (!inlined_[j]) stack.emplace_back(j, false);
      continue;
    }
    GiNaC::exmap earlier;
    for (std::size_t j : used) earlier[definitions_[j].symbol] = *inlined_[j];
    inlined_[k] = definitions_[k].value.subs(earlier);
  }
  GiNaC::exmap map;
  for (std::size_t j : top) map[definitions_[j].symbol] = *inlined_[j];
  return map.empty() ? e : e.subs(map);
}

ex Intermediates::value_at(const ex& e, const GiNaC::exmap& values, ValueMemo& memo) const {
  if (memo.value.size() < definitions_.size()) memo.value.resize(definitions_.size());
  GiNaC::exmap floats;  // exact values would make exact arithmetic: d = d^2 + d doubles its digits per definition
  for (const auto& [symbol, v] : values) floats[symbol] = v.evalf();
  std::set<std::size_t> top;
  collect(e, position_, top);
  std::vector<std::pair<std::size_t, bool>> stack;  // (position, its dependencies are done)
  for (std::size_t k : top) stack.emplace_back(k, false);
  while (!stack.empty()) {
    const auto [k, ready] = stack.back();
    stack.pop_back();
    if (memo.value[k]) continue;
    std::set<std::size_t> used;
    collect(definitions_[k].value, position_, used);
    if (!ready) {
      stack.emplace_back(k, true);
      for (std::size_t j : used)
        if (!memo.value[j]) stack.emplace_back(j, false);
      continue;
    }
    GiNaC::exmap at = floats;
    for (std::size_t j : used) at[definitions_[j].symbol] = *memo.value[j];
    const ex v = definitions_[k].value.subs(at).evalf();
    memo.value[k] = GiNaC::is_a<GiNaC::numeric>(v) ? v : ex(definitions_[k].symbol);
  }
  GiNaC::exmap at = floats;
  for (std::size_t j : top) at[definitions_[j].symbol] = *memo.value[j];
  return e.subs(at).evalf();
}

GiNaC::exmap Intermediates::evaluate(const GiNaC::exmap& values) const {
  GiNaC::exmap out = values;
  for (const Definition& d : definitions_) out[d.symbol] = d.value.subs(out).evalf();
  return out;
}

}  // namespace hamel
