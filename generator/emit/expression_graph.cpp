#include "emit/expression_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;

namespace {

bool commutative(Op op) { return op == Op::add || op == Op::mul; }

Op function_op(const std::string& name) {
  const Function* f = function_named(name);
  if (!f) throw std::logic_error("expression graph: function '" + name + "' cannot be emitted");
  return f->op;
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {  // splitmix64's finalizer over h combined with v
  std::uint64_t z = h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t value_bits(double value) {
  std::uint64_t bits = 0;
  static_assert(sizeof bits == sizeof value, "double is 64 bits");
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

}  // namespace

int ExpressionGraph::intern(const Node& n) {
  const std::uint64_t bits = value_bits(n.value);
  const std::uint64_t ops = (static_cast<std::uint64_t>(n.op) << 56) | (static_cast<std::uint64_t>(n.argument) << 48) |
                            static_cast<std::uint64_t>(static_cast<std::uint32_t>(n.index));
  const std::uint64_t operands =
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(n.a)) << 32) | static_cast<std::uint32_t>(n.b);
  const Key key{{ops, operands, n.op == Op::constant ? bits : 0}};
  auto it = index_.find(key);
  if (it != index_.end()) return it->second;
  // The structural key: what the node computes, from its operands' keys (never their indices).
  std::uint64_t h = mix(0x68616d656cULL, static_cast<std::uint64_t>(n.op));
  if (n.op == Op::constant) h = mix(h, bits);
  if (n.op == Op::constant && n.index > 0) h = mix(h, static_cast<std::uint32_t>(n.index));  // unrepresentable
  if (n.op == Op::input) h = mix(mix(h, static_cast<std::uint64_t>(n.argument)), static_cast<std::uint32_t>(n.index));
  if (n.a >= 0) h = mix(h, this->key(n.a));
  if (n.b >= 0) h = mix(h, this->key(n.b));
  nodes_.push_back(n);
  keys_.push_back(h);
  const int id = static_cast<int>(nodes_.size()) - 1;
  index_.emplace(key, id);
  return id;
}

bool ExpressionGraph::structurally_less(int i, int j) const {
  // Distinct nodes differ in structure (value numbering): comparing operation, constant or input and then
  // the operands (recursively, only on equal keys) decides. Equal keys of distinct nodes are hash
  // collisions, so the recursion practically never goes deeper than one level.
  if (i == j) return false;
  if (key(i) != key(j)) return key(i) < key(j);
  const Node& x = node(i);
  const Node& y = node(j);
  if (x.op != y.op) return x.op < y.op;
  if (x.op == Op::constant)
    return std::make_pair(value_bits(x.value), x.index) < std::make_pair(value_bits(y.value), y.index);
  if (x.op == Op::input) return std::make_pair(x.argument, x.index) < std::make_pair(y.argument, y.index);
  if (x.a != y.a) return structurally_less(x.a, y.a);
  return structurally_less(x.b, y.b);
}

int ExpressionGraph::constant(double value) {
  if (value == 0.0) value = 0.0;  // one zero: -0.0 and 0.0 share a node
  Node n;
  n.op = Op::constant;
  n.value = value;
  return intern(n);
}

int ExpressionGraph::unrepresentable_constant(double value, const std::string& exact) {
  // index: 1 + the position of the exact value in unrepresentable_values_ (0 marks ordinary constants).
  auto at = std::find(unrepresentable_values_.begin(), unrepresentable_values_.end(), exact);
  if (at == unrepresentable_values_.end()) at = unrepresentable_values_.insert(at, exact);
  Node n;
  n.op = Op::constant;
  n.value = value;
  n.index = static_cast<int>(at - unrepresentable_values_.begin()) + 1;
  return intern(n);
}

int ExpressionGraph::exact_constant(const GiNaC::numeric& v) {
  const double d = v.to_double();
  if (std::isfinite(d) && (d != 0 || v.is_zero())) return constant(d);
  // About 6 significant digits of the exact value: GiNaC prints "1.0E400", "2.6199755966169518372E-507".
  std::ostringstream text;
  text << v.evalf();
  std::string s = text.str();
  const std::size_t e = s.find('E');
  std::string mantissa = s.substr(0, e), exponent = e == std::string::npos ? "" : s.substr(e + 1);
  const std::size_t point = mantissa.find('.');
  if (point != std::string::npos && mantissa.size() > point + 6) mantissa.resize(point + 6);
  while (point != std::string::npos && mantissa.size() > point + 2 && mantissa.back() == '0') mantissa.pop_back();
  return unrepresentable_constant(d, exponent.empty() ? mantissa : mantissa + "e" + exponent);
}

int ExpressionGraph::folded(Op op, double x, double y, double r) {
  const bool binary_op = operation(op).operands == 2;
  const bool overflow = !std::isfinite(r) && std::isfinite(x) && (!binary_op || std::isfinite(y));
  const bool underflow =
      r == 0 && x != 0 &&
      ((op == Op::mul && y != 0) || (op == Op::div && std::isfinite(y)) || (op == Op::pow && std::isfinite(y)));
  if (!overflow && !underflow) return constant(r);
  std::ostringstream text;
  text.precision(6);
  const char* symbol = op == Op::pow ? "^" : operation(op).cpp;
  if (binary_op)
    text << x << symbol << y;
  else
    text << "a function of " << x;
  return unrepresentable_constant(r, text.str());
}

std::pair<int, int> ExpressionGraph::first_unrepresentable(const std::vector<int>& outputs) const {
  if (unrepresentable_values_.empty()) return {-1, -1};
  for (std::size_t o = 0; o < outputs.size(); ++o)
    for (int i : schedule({outputs[o]}))
      if (is_unrepresentable(i)) return {static_cast<int>(o), i};
  return {-1, -1};
}

int ExpressionGraph::input(Argument argument, int index) {
  Node n;
  n.op = Op::input;
  n.argument = argument;
  n.index = index;
  return intern(n);
}

int ExpressionGraph::unary(Op op, int a) {
  const Node& x = node(a);
  if (x.op == Op::constant && x.index == 0) return folded(op, x.value, 0.0, evaluate(op, x.value, 0.0));
  if (op == Op::neg && x.op == Op::neg) return x.a;
  if (op == Op::neg && x.op == Op::sub) return binary(Op::sub, x.b, x.a);
  Node n;
  n.op = op;
  n.a = a;
  return intern(n);
}

int ExpressionGraph::binary(Op op, int a, int b) {
  // Operands of commutative operations in structural order before anything else, so that the rules below
  // and the node created see the same pair whichever order the caller passed.
  if (commutative(op) && structurally_less(b, a)) std::swap(a, b);
  const Node& x = node(a);
  const Node& y = node(b);
  if (x.op == Op::constant && y.op == Op::constant && x.index == 0 && y.index == 0)
    return folded(op, x.value, y.value, evaluate(op, x.value, y.value));
  switch (op) {
    case Op::add:
      if (is_constant(a, 0)) return b;
      if (is_constant(b, 0)) return a;
      if (y.op == Op::neg) return binary(Op::sub, a, y.a);
      if (x.op == Op::neg) return binary(Op::sub, b, x.a);
      break;
    case Op::sub:
      if (is_constant(b, 0)) return a;
      if (is_constant(a, 0)) return unary(Op::neg, b);
      if (a == b) return constant(0);
      if (y.op == Op::neg) return binary(Op::add, a, y.a);
      break;
    case Op::mul:
      if (is_constant(a, 0) || is_constant(b, 0)) return constant(0);
      if (is_constant(a, 1)) return b;
      if (is_constant(b, 1)) return a;
      if (is_constant(a, -1)) return unary(Op::neg, b);
      if (is_constant(b, -1)) return unary(Op::neg, a);
      break;
    case Op::div:
      if (is_constant(b, 1)) return a;
      if (is_constant(a, 0)) return constant(0);
      break;
    default:
      break;
  }
  Node n;
  n.op = op;
  n.a = a;
  n.b = b;
  return intern(n);
}

int ExpressionGraph::integer_power(int base, long exponent) {
  if (exponent == 0) return constant(1);
  if (exponent > 16) return binary(Op::pow, base, constant(static_cast<double>(exponent)));
  if (exponent == 1) return base;
  const int half = integer_power(base, exponent / 2);
  const int square = binary(Op::mul, half, half);
  return exponent % 2 ? binary(Op::mul, square, base) : square;
}

int ExpressionGraph::from_expression(const ex& e, const std::map<ex, int, GiNaC::ex_is_less>& leaves) {
  const auto [id, sign] = signed_expression(e, leaves);
  return sign < 0 ? unary(Op::neg, id) : id;
}

namespace {

// Orders (node, sign) pairs structurally: by node, then by sign.
struct Structural {
  const ExpressionGraph& g;
  bool operator()(const std::pair<int, int>& p, const std::pair<int, int>& q) const {
    if (p.first != q.first) return g.structurally_less(p.first, q.first);
    return p.second < q.second;
  }
};

}  // namespace

std::pair<int, int> ExpressionGraph::signed_expression(const ex& e,
                                                       const std::map<ex, int, GiNaC::ex_is_less>& leaves) {
  if (auto it = memo_.find(e); it != memo_.end()) return it->second;
  std::pair<int, int> result{-1, 1};  // node, sign
  if (is_a<GiNaC::numeric>(e)) {
    const GiNaC::numeric& v = ex_to<GiNaC::numeric>(e);
    if (!v.is_real())
      throw std::logic_error("expression graph: complex number " + std::to_string(v.real().to_double()));
    result = {exact_constant(abs(v)), v.is_negative() ? -1 : 1};
  } else if (is_a<GiNaC::constant>(e)) {
    result.first = constant(ex_to<GiNaC::numeric>(e.evalf()).to_double());
  } else if (is_a<GiNaC::symbol>(e)) {
    auto it = leaves.find(e);
    if (it == leaves.end())
      throw std::logic_error("expression graph: symbol '" + ex_to<GiNaC::symbol>(e).get_name() + "' is not an input");
    result.first = it->second;
  } else if (is_a<GiNaC::add>(e)) {
    result = signed_sum(e, leaves);
  } else if (is_a<GiNaC::mul>(e)) {
    result = signed_product(e, leaves);
  } else if (is_a<GiNaC::power>(e)) {
    result = signed_power(e, leaves);
  } else if (is_a<GiNaC::function>(e)) {
    const std::string name = ex_to<GiNaC::function>(e).get_name();
    if (e.nops() != 1) throw std::logic_error("expression graph: function '" + name + "' cannot be emitted");
    result.first = unary(function_op(name), from_expression(e.op(0), leaves));
  } else {
    throw std::logic_error("expression graph: unsupported expression type");
  }
  if (is_constant(result.first, 0)) result.second = 1;  // 0 has no sign to carry
  memo_.emplace(e, result);
  return result;
}

std::pair<int, int> ExpressionGraph::signed_sum(const ex& e, const std::map<ex, int, GiNaC::ex_is_less>& leaves) {
  // The terms in structural order (not GiNaC's address-dependent one), each added or subtracted by its
  // sign, so no constant -1 multiplies remain; the first term is added, the sum's sign returned apart.
  const Structural structural{*this};
  std::vector<std::pair<int, int>> terms;  // node, sign
  // Terms that are 0 in the graph (a factor is a constrained velocity) are left out: their sign, which
  // depends on how GiNaC wrote them, would otherwise decide the sign of the sum when they sort first.
  for (std::size_t i = 0; i < e.nops(); ++i) {
    const std::pair<int, int> term = signed_expression(e.op(i), leaves);
    if (!is_constant(term.first, 0)) terms.push_back(term);
  }
  std::sort(terms.begin(), terms.end(), structural);
  // Terms GiNaC keeps apart that are the same node (the same value written differently, which depends
  // on GiNaC's term order in earlier steps) are collected: x − x vanishes, x + x becomes 2·x.
  std::vector<std::pair<int, int>> collected;
  for (std::size_t i = 0; i < terms.size();) {
    std::size_t j = i;
    int count = 0;
    for (; j < terms.size() && terms[j].first == terms[i].first; ++j) count += terms[j].second;
    if (count == 1 || count == -1) collected.emplace_back(terms[i].first, count);
    if (count > 1 || count < -1)
      collected.emplace_back(binary(Op::mul, constant(std::abs(count)), terms[i].first), count > 0 ? 1 : -1);
    i = j;
  }
  if (collected.size() != terms.size()) std::sort(collected.begin(), collected.end(), structural);
  terms.swap(collected);
  int sign = 1;
  if (!terms.empty() && terms.front().second < 0) {
    sign = -1;
    for (auto& t : terms) t.second = -t.second;
  }
  int id = constant(0);
  for (const auto& [term, s] : terms) id = binary(s < 0 ? Op::sub : Op::add, id, term);
  return {id, sign};
}

std::pair<int, int> ExpressionGraph::signed_product(const ex& e, const std::map<ex, int, GiNaC::ex_is_less>& leaves) {
  // Numerator and denominator factors, each chained in structural order, their signs collected.
  std::vector<std::pair<int, int>> numerator, denominator;
  GiNaC::numeric coefficient = 1;
  for (std::size_t i = 0; i < e.nops(); ++i) {
    const ex factor = e.op(i);
    if (is_a<GiNaC::numeric>(factor)) {
      coefficient *= ex_to<GiNaC::numeric>(factor);
    } else if (is_a<GiNaC::power>(factor) && is_a<GiNaC::numeric>(factor.op(1)) &&
               ex_to<GiNaC::numeric>(factor.op(1)).is_negative()) {
      denominator.push_back(signed_expression(GiNaC::pow(factor.op(0), -factor.op(1)), leaves));
    } else {
      numerator.push_back(signed_expression(factor, leaves));
    }
  }
  int sign = 1;
  if (coefficient.is_negative()) {
    sign = -sign;
    coefficient = -coefficient;
  }
  const auto chain = [&](std::vector<std::pair<int, int>>& factors) {
    std::sort(factors.begin(), factors.end(), Structural{*this});
    int product = constant(1);
    for (const auto& [f, s] : factors) {
      product = binary(Op::mul, product, f);
      sign *= s;
    }
    return product;
  };
  const int num = chain(numerator);
  const int den = chain(denominator);
  const int c = exact_constant(coefficient);
  return {binary(Op::mul, c, binary(Op::div, num, den)), sign};
}

std::pair<int, int> ExpressionGraph::signed_power(const ex& e, const std::map<ex, int, GiNaC::ex_is_less>& leaves) {
  const ex base = e.op(0), exponent = e.op(1);
  if (is_a<GiNaC::numeric>(exponent) && ex_to<GiNaC::numeric>(exponent).is_integer()) {  // (s·b)^m = s^m · b^m
    const long m = ex_to<GiNaC::numeric>(exponent).to_long();
    const auto [b, s] = signed_expression(base, leaves);
    const int id = m >= 0 ? integer_power(b, m) : binary(Op::div, constant(1), integer_power(b, -m));
    return {id, (s < 0 && m % 2 != 0) ? -1 : 1};
  }
  const int b = from_expression(base, leaves);
  if (!is_a<GiNaC::numeric>(exponent)) return {binary(Op::pow, b, from_expression(exponent, leaves)), 1};
  const GiNaC::numeric k = ex_to<GiNaC::numeric>(exponent);
  if (!(2 * k).is_integer()) return {binary(Op::pow, b, constant(k.to_double())), 1};
  const long h = (2 * k).to_long();  // base^(h/2) = sqrt(base)^h
  const int root = unary(Op::sqrt, b);
  return {h >= 0 ? integer_power(root, h) : binary(Op::div, constant(1), integer_power(root, -h)), 1};
}

std::vector<int> ExpressionGraph::schedule(const std::vector<int>& outputs) const {
  return schedule(outputs, std::vector<char>());
}

std::vector<int> ExpressionGraph::schedule(const std::vector<int>& outputs, const std::vector<char>& boundary) const {
  // Depth first from the outputs in their order, first operand before second, each node after its
  // operands: a function of the structure reachable from the outputs only (commutative operands are in
  // structural order), not of node indices, and every value is computed close to where it is used.
  std::vector<char> seen(nodes_.size(), 0);
  std::vector<int> order;
  std::vector<std::pair<int, int>> stack;  // node, operands pushed so far
  for (int o : outputs) {
    if (seen[static_cast<std::size_t>(o)]) continue;
    seen[static_cast<std::size_t>(o)] = 1;
    stack.emplace_back(o, 0);
    while (!stack.empty()) {
      const int i = stack.back().first;
      const int k = stack.back().second++;
      const Node& n = node(i);
      const bool given = static_cast<std::size_t>(i) < boundary.size() && boundary[static_cast<std::size_t>(i)];
      const int operand = given ? -1 : k == 0 ? n.a : k == 1 ? n.b : -1;
      if (k < 2) {
        if (operand >= 0 && !seen[static_cast<std::size_t>(operand)]) {
          seen[static_cast<std::size_t>(operand)] = 1;
          stack.emplace_back(operand, 0);
        }
        continue;
      }
      order.push_back(i);
      stack.pop_back();
    }
  }
  return order;
}

OpCounts ExpressionGraph::count(const std::vector<int>& schedule) const {
  OpCounts c;
  for (int i : schedule) {
    switch (operation(node(i).op).cost) {
      case Cost::none:
        break;
      case Cost::add:
        ++c.add;
        break;
      case Cost::mul:
        ++c.mul;
        break;
      case Cost::div:
        ++c.div;
        break;
      case Cost::call:
        ++c.call;
        break;
    }
  }
  return c;
}

namespace {

// The program computing `outputs` rebuilt from its leaves up: `rule(i, a, b)` gives the image of node i from
// the images a and b of its operands (b = −1 for one operand or none), or −1 for the default, which is i itself
// when the operands are unchanged and the same operation on the images otherwise.
template <class Rule>
std::vector<int> rebuild(ExpressionGraph& g, const std::vector<int>& outputs, Rule rule) {
  std::vector<int> image(static_cast<std::size_t>(g.size()));
  for (int i = 0; i < g.size(); ++i) image[static_cast<std::size_t>(i)] = i;
  for (int i : g.schedule(outputs)) {
    const Node n = g.node(i);  // a copy: rebuilding grows the graph
    const int a = n.a >= 0 ? image[static_cast<std::size_t>(n.a)] : -1;
    const int b = n.b >= 0 ? image[static_cast<std::size_t>(n.b)] : -1;
    const int chosen = rule(i, a, b);
    if (chosen >= 0)
      image[static_cast<std::size_t>(i)] = chosen;
    else if (n.a >= 0 && (a != n.a || b != n.b))
      image[static_cast<std::size_t>(i)] = b >= 0 ? g.binary(n.op, a, b) : g.unary(n.op, a);
  }
  std::vector<int> out;
  for (int o : outputs) out.push_back(image[static_cast<std::size_t>(o)]);
  return out;
}

// varying[i]: node i (of `order`, a schedule) depends on t, x or in.
std::vector<char> varying_nodes(const ExpressionGraph& g, const std::vector<int>& order) {
  std::vector<char> varying(static_cast<std::size_t>(g.size()), 0);
  for (int i : order) {
    const Node& n = g.node(i);
    if (n.op == Op::input)
      varying[static_cast<std::size_t>(i)] = n.argument != Argument::parameter;
    else if (n.op != Op::constant)
      varying[static_cast<std::size_t>(i)] =
          varying[static_cast<std::size_t>(n.a)] || (n.b >= 0 && varying[static_cast<std::size_t>(n.b)]);
  }
  return varying;
}

}  // namespace

std::vector<int> substitute(ExpressionGraph& g, const std::vector<int>& outputs, const std::map<int, int>& replace) {
  return rebuild(g, outputs, [&](int i, int, int) {
    const auto it = replace.find(i);
    return it == replace.end() ? -1 : it->second;
  });
}

std::vector<int> group_invariants(ExpressionGraph& g, const std::vector<int>& outputs) {
  // varying(i) for every node, also those the rewrite creates.
  std::vector<char> known, varying;
  const std::function<bool(int)> is_varying = [&](int i) -> bool {
    if (static_cast<std::size_t>(i) >= known.size()) {
      known.resize(static_cast<std::size_t>(g.size()), 0);
      varying.resize(static_cast<std::size_t>(g.size()), 0);
    }
    if (!known[static_cast<std::size_t>(i)]) {
      const Node n = g.node(i);
      const bool v = n.op == Op::input      ? n.argument != Argument::parameter
                     : n.op == Op::constant ? false
                                            : is_varying(n.a) || (n.b >= 0 && is_varying(n.b));
      known[static_cast<std::size_t>(i)] = 1;
      varying[static_cast<std::size_t>(i)] = v;
    }
    return varying[static_cast<std::size_t>(i)];
  };
  // A varying factor v · k with k invariant, as (v, k); (x, −1) otherwise.
  const auto split = [&](int x) -> std::pair<int, int> {
    const Node& n = g.node(x);
    if (n.op == Op::mul && is_varying(n.a) != is_varying(n.b))
      return is_varying(n.a) ? std::pair<int, int>{n.a, n.b} : std::pair<int, int>{n.b, n.a};
    return {x, -1};
  };
  const int one = g.constant(1);
  return rebuild(g, outputs, [&](int i, int a, int b) {
    const Op op = g.node(i).op;
    if (op != Op::mul && op != Op::div) return -1;
    if (op == Op::div) {
      if (!is_varying(a) || is_varying(b) || g.node(b).op == Op::constant) return -1;
      b = g.binary(Op::div, one, b);  // a / k = a · (1/k)
    }
    if (is_varying(a) == is_varying(b) && !is_varying(a)) return -1;  // parameter-only: stays whole
    const auto [va, ka] = is_varying(a) ? split(a) : std::pair<int, int>{-1, a};
    const auto [vb, kb] = is_varying(b) ? split(b) : std::pair<int, int>{-1, b};
    if (ka < 0 && kb < 0) return op == Op::mul ? -1 : g.binary(Op::mul, a, b);
    const int v = va < 0 ? vb : vb < 0 ? va : g.binary(Op::mul, va, vb);
    const int k = ka < 0 ? kb : kb < 0 ? ka : g.binary(Op::mul, ka, kb);
    return g.binary(Op::mul, v, k);
  });
}

OpCounts run_time_operations(const ExpressionGraph& g, const std::vector<int>& outputs) {
  const std::vector<int> order = g.schedule(outputs);
  const std::vector<char> varying = varying_nodes(g, order);
  std::vector<int> run_time;
  for (int i : order)
    if (varying[static_cast<std::size_t>(i)]) run_time.push_back(i);
  return g.count(run_time);
}

std::vector<int> parameter_frontier(const ExpressionGraph& g, const std::vector<int>& outputs) {
  const std::vector<int> order = g.schedule(outputs);
  const std::vector<char> varying = varying_nodes(g, order);
  std::vector<char> hoist(static_cast<std::size_t>(g.size()), 0);
  const auto operation = [&](int i) { return g.node(i).op != Op::constant && g.node(i).op != Op::input; };
  for (int i : order) {
    const Node& n = g.node(i);
    if (!varying[static_cast<std::size_t>(i)] || n.op == Op::input) continue;
    const bool va = varying[static_cast<std::size_t>(n.a)];
    const bool vb = n.b >= 0 && varying[static_cast<std::size_t>(n.b)];
    if (!va && operation(n.a)) hoist[static_cast<std::size_t>(n.a)] = 1;
    if (n.b >= 0 && !vb && operation(n.b)) hoist[static_cast<std::size_t>(n.b)] = 1;
  }
  for (int o : outputs)
    if (!varying[static_cast<std::size_t>(o)] && operation(o)) hoist[static_cast<std::size_t>(o)] = 1;
  std::vector<int> frontier;
  for (int i : order)
    if (hoist[static_cast<std::size_t>(i)]) frontier.push_back(i);
  return frontier;
}

bool hoist_shared_work(ExpressionGraph& g, Subroutine& sub) {
  ExpressionGraph& s = sub.graph;
  const std::vector<int> frontier = parameter_frontier(s, sub.outputs);
  const std::vector<int> order = s.schedule(frontier);
  for (int i : order)
    if (s.is_unrepresentable(i)) return false;
  // The frontier's program rebuilt in g, reading the shared values where s reads p[k].
  std::vector<int> in_g(static_cast<std::size_t>(s.size()), -1);
  for (int i : order) {
    const Node& n = s.node(i);
    const auto at = [&](int j) { return in_g[static_cast<std::size_t>(j)]; };
    in_g[static_cast<std::size_t>(i)] = n.op == Op::constant ? g.constant(n.value)
                                        : n.op == Op::input  ? sub.shared.at(static_cast<std::size_t>(n.index))
                                        : n.b >= 0           ? g.binary(n.op, at(n.a), at(n.b))
                                                             : g.unary(n.op, at(n.a));
  }
  // The frontier read as p[P + j] (P: the shared values so far), then every p[k] still read renumbered from 0.
  const int P = static_cast<int>(sub.shared.size());
  std::vector<int> value_of = sub.shared;  // the value in g of p[k]
  std::map<int, int> replace;
  for (std::size_t j = 0; j < frontier.size(); ++j) {
    replace[frontier[j]] = s.input(Argument::parameter, P + static_cast<int>(j));
    value_of.push_back(in_g[static_cast<std::size_t>(frontier[j])]);
  }
  const std::vector<int> outputs = substitute(s, sub.outputs, replace);
  std::vector<int> read;
  for (int i : s.schedule(outputs))
    if (s.node(i).op == Op::input && s.node(i).argument == Argument::parameter) read.push_back(s.node(i).index);
  std::sort(read.begin(), read.end());
  replace.clear();
  sub.shared.clear();
  for (int k : read) {
    replace[s.input(Argument::parameter, k)] = s.input(Argument::parameter, static_cast<int>(sub.shared.size()));
    sub.shared.push_back(value_of[static_cast<std::size_t>(k)]);
  }
  sub.outputs = substitute(s, outputs, replace);
  return true;
}

namespace {

// The graph's node constructors, as the operation table's derivative rules build their results.
class GraphTerms final : public TermBuilder {
 public:
  explicit GraphTerms(ExpressionGraph& g) : g_(g) {}
  int constant(double value) override { return g_.constant(value); }
  int unary(Op op, int a) override { return g_.unary(op, a); }
  int binary(Op op, int a, int b) override { return g_.binary(op, a, b); }
  bool is_constant(int i, double& value) const override {
    if (g_.node(i).op != Op::constant) return false;
    value = g_.node(i).value;
    return true;
  }

 private:
  ExpressionGraph& g_;
};

}  // namespace

std::vector<int> tangent(ExpressionGraph& g, const std::vector<int>& outputs, const std::map<int, int>& seed) {
  const std::vector<int> order = g.schedule(outputs);
  const int zero = g.constant(0);
  std::vector<int> dot(static_cast<std::size_t>(g.size()), zero);
  GraphTerms terms(g);
  for (int i : order) {
    const Node n = g.node(i);  // a copy: the rules grow the graph
    if (n.op == Op::input) {
      const auto it = seed.find(i);
      dot[static_cast<std::size_t>(i)] = it != seed.end() ? it->second : zero;
      continue;
    }
    if (n.op == Op::constant) continue;
    const int da = dot[static_cast<std::size_t>(n.a)];
    const int db = n.b >= 0 ? dot[static_cast<std::size_t>(n.b)] : zero;
    if (da == zero && db == zero) continue;
    dot[static_cast<std::size_t>(i)] = operation(n.op).derivative(terms, TangentOf{n.a, n.b, i, da, db});
  }
  std::vector<int> out;
  for (int o : outputs) out.push_back(dot[static_cast<std::size_t>(o)]);
  return out;
}

void ProgramConverter::convert_used(const GiNaC::ex& e) {
  converted_.resize(tape_.size(), false);
  for (std::size_t k : tape_.used_by(e)) {
    if (converted_[k]) continue;
    const GiNaC::ex value = tape_.definitions()[k].value;
    convert_used(value);
    leaves_[tape_.definitions()[k].symbol] = graph_.from_expression(value, leaves_);
    converted_[k] = true;
  }
}

int ProgramConverter::operator()(const GiNaC::ex& e) {
  convert_used(e);
  return graph_.from_expression(e, leaves_);
}

}  // namespace hamel
