#include "algebra/intermediates.hpp"

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

std::vector<std::size_t> Intermediates::used_by(const ex& e) const {
  std::set<std::size_t> used;
  collect(e, position_, used);
  return {used.begin(), used.end()};
}

ex Intermediates::diff(const ex& e, const GiNaC::symbol& x) {
  ex out = e.diff(x);  // explicit dependence; intermediates are independent symbols to GiNaC
  std::set<std::size_t> used;
  collect(e, position_, used);
  for (std::size_t k : used) {
    const auto key = std::make_pair(k, ex(x));
    auto it = derivative_memo_.find(key);
    if (it == derivative_memo_.end()) {
      const ex value = definitions_[k].value;  // copy: define() below may grow the vector
      const ex d = define(diff(value, x));
      it = derivative_memo_.emplace(key, d).first;
    }
    if (it->second.is_zero()) continue;
    out += e.diff(definitions_[k].symbol) * it->second;
  }
  return out;
}

ex Intermediates::inline_all(const ex& e) const {
  for (std::size_t k = inlined_.size(); k < definitions_.size(); ++k) {
    GiNaC::exmap earlier;
    std::set<std::size_t> used;
    collect(definitions_[k].value, position_, used);
    for (std::size_t j : used) earlier[definitions_[j].symbol] = inlined_[j];
    inlined_.push_back(definitions_[k].value.subs(earlier));
  }
  std::set<std::size_t> used;
  collect(e, position_, used);
  GiNaC::exmap map;
  for (std::size_t j : used) map[definitions_[j].symbol] = inlined_[j];
  return e.subs(map);
}

GiNaC::exmap Intermediates::evaluate(const GiNaC::exmap& values) const {
  GiNaC::exmap out = values;
  for (const Definition& d : definitions_) out[d.symbol] = d.value.subs(out).evalf();
  return out;
}

}  // namespace hamel
