#include "emit/expression_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <stdexcept>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;

namespace {

bool commutative(Op op) { return op == Op::add || op == Op::mul; }

double apply(Op op, double a, double b) {
  switch (op) {
    case Op::add:
      return a + b;
    case Op::sub:
      return a - b;
    case Op::mul:
      return a * b;
    case Op::div:
      return a / b;
    case Op::neg:
      return -a;
    case Op::sqrt:
      return std::sqrt(a);
    case Op::sin:
      return std::sin(a);
    case Op::cos:
      return std::cos(a);
    case Op::tan:
      return std::tan(a);
    case Op::exp:
      return std::exp(a);
    case Op::log:
      return std::log(a);
    case Op::asin:
      return std::asin(a);
    case Op::acos:
      return std::acos(a);
    case Op::atan:
      return std::atan(a);
    case Op::sinh:
      return std::sinh(a);
    case Op::cosh:
      return std::cosh(a);
    case Op::tanh:
      return std::tanh(a);
    case Op::abs:
      return std::fabs(a);
    case Op::pow:
      return std::pow(a, b);
    case Op::constant:
    case Op::input:
      break;
  }
  throw std::logic_error("expression graph: not an operation");
}

Op function_op(const std::string& name) {
  static const std::map<std::string, Op> table = {
      {"sin", Op::sin},   {"cos", Op::cos},   {"tan", Op::tan},   {"exp", Op::exp},   {"log", Op::log},
      {"asin", Op::asin}, {"acos", Op::acos}, {"atan", Op::atan}, {"sinh", Op::sinh}, {"cosh", Op::cosh},
      {"tanh", Op::tanh}, {"abs", Op::abs},   {"sqrt", Op::sqrt}};
  auto it = table.find(name);
  if (it == table.end()) throw std::logic_error("expression graph: function '" + name + "' cannot be emitted");
  return it->second;
}

}  // namespace

int ExpressionGraph::intern(const Node& n) {
  std::uint64_t bits = 0;
  static_assert(sizeof bits == sizeof n.value, "double is 64 bits");
  std::memcpy(&bits, &n.value, sizeof bits);
  const std::uint64_t ops = (static_cast<std::uint64_t>(n.op) << 56) | (static_cast<std::uint64_t>(n.argument) << 48) |
                            static_cast<std::uint64_t>(static_cast<std::uint32_t>(n.index));
  const std::uint64_t operands =
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(n.a)) << 32) | static_cast<std::uint32_t>(n.b);
  const Key key{{ops, operands, n.op == Op::constant ? bits : 0}};
  auto it = index_.find(key);
  if (it != index_.end()) return it->second;
  nodes_.push_back(n);
  const int id = static_cast<int>(nodes_.size()) - 1;
  index_.emplace(key, id);
  return id;
}

int ExpressionGraph::constant(double value) {
  if (value == 0.0) value = 0.0;  // one zero: -0.0 and 0.0 share a node
  Node n;
  n.op = Op::constant;
  n.value = value;
  return intern(n);
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
  if (x.op == Op::constant) return constant(apply(op, x.value, 0.0));
  if (op == Op::neg && x.op == Op::neg) return x.a;
  if (op == Op::neg && x.op == Op::sub) return binary(Op::sub, x.b, x.a);
  Node n;
  n.op = op;
  n.a = a;
  return intern(n);
}

int ExpressionGraph::binary(Op op, int a, int b) {
  const Node& x = node(a);
  const Node& y = node(b);
  if (x.op == Op::constant && y.op == Op::constant) return constant(apply(op, x.value, y.value));
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
  if (commutative(op) && n.b < n.a) std::swap(n.a, n.b);
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
  if (auto it = memo_.find(e); it != memo_.end()) return it->second;
  int id = -1;
  if (is_a<GiNaC::numeric>(e)) {
    const GiNaC::numeric& v = ex_to<GiNaC::numeric>(e);
    if (!v.is_real())
      throw std::logic_error("expression graph: complex number " + std::to_string(v.real().to_double()));
    id = constant(v.to_double());
  } else if (is_a<GiNaC::constant>(e)) {
    id = constant(ex_to<GiNaC::numeric>(e.evalf()).to_double());
  } else if (is_a<GiNaC::symbol>(e)) {
    auto it = leaves.find(e);
    if (it == leaves.end())
      throw std::logic_error("expression graph: symbol '" + ex_to<GiNaC::symbol>(e).get_name() + "' is not an input");
    id = it->second;
  } else if (is_a<GiNaC::add>(e)) {
    // Terms with a negative numeric factor become subtractions, so no constant -1 multiplies remain.
    id = constant(0);
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex term = e.op(i);
      bool negative = false;
      if (is_a<GiNaC::numeric>(term)) negative = ex_to<GiNaC::numeric>(term).is_negative();
      if (is_a<GiNaC::mul>(term)) {
        const ex last = term.op(term.nops() - 1);
        negative = is_a<GiNaC::numeric>(last) && ex_to<GiNaC::numeric>(last).is_negative();
      }
      id = negative ? binary(Op::sub, id, from_expression(-term, leaves))
                    : binary(Op::add, id, from_expression(term, leaves));
    }
  } else if (is_a<GiNaC::mul>(e)) {
    int numerator = constant(1), denominator = constant(1);
    double coefficient = 1.0;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex factor = e.op(i);
      if (is_a<GiNaC::numeric>(factor)) {
        coefficient *= ex_to<GiNaC::numeric>(factor).to_double();
      } else if (is_a<GiNaC::power>(factor) && is_a<GiNaC::numeric>(factor.op(1)) &&
                 ex_to<GiNaC::numeric>(factor.op(1)).is_negative()) {
        denominator = binary(Op::mul, denominator, from_expression(GiNaC::pow(factor.op(0), -factor.op(1)), leaves));
      } else {
        numerator = binary(Op::mul, numerator, from_expression(factor, leaves));
      }
    }
    const int c = constant(coefficient);  // first: the order of evaluating two arguments is unspecified
    id = binary(Op::mul, c, binary(Op::div, numerator, denominator));
  } else if (is_a<GiNaC::power>(e)) {
    const ex base = e.op(0), exponent = e.op(1);
    const int b = from_expression(base, leaves);
    if (is_a<GiNaC::numeric>(exponent)) {
      const GiNaC::numeric k = ex_to<GiNaC::numeric>(exponent);
      if (k.is_integer()) {
        const long m = k.to_long();
        id = m >= 0 ? integer_power(b, m) : binary(Op::div, constant(1), integer_power(b, -m));
      } else if ((2 * k).is_integer()) {
        const long m = (2 * k).to_long();  // base^(m/2) = sqrt(base)^m
        const int root = unary(Op::sqrt, b);
        id = m >= 0 ? integer_power(root, m) : binary(Op::div, constant(1), integer_power(root, -m));
      } else {
        id = binary(Op::pow, b, constant(k.to_double()));
      }
    } else {
      id = binary(Op::pow, b, from_expression(exponent, leaves));
    }
  } else if (is_a<GiNaC::function>(e)) {
    const std::string name = ex_to<GiNaC::function>(e).get_name();
    if (e.nops() != 1) throw std::logic_error("expression graph: function '" + name + "' cannot be emitted");
    id = unary(function_op(name), from_expression(e.op(0), leaves));
  } else {
    throw std::logic_error("expression graph: unsupported expression type");
  }
  memo_.emplace(e, id);
  return id;
}

std::vector<int> ExpressionGraph::schedule(const std::vector<int>& outputs) const {
  std::vector<char> needed(nodes_.size(), 0);
  for (int o : outputs) needed[static_cast<std::size_t>(o)] = 1;
  // Operands always have smaller indices than their users: one backward sweep marks everything.
  for (int i = size() - 1; i >= 0; --i) {
    if (!needed[static_cast<std::size_t>(i)]) continue;
    const Node& n = node(i);
    if (n.a >= 0) needed[static_cast<std::size_t>(n.a)] = 1;
    if (n.b >= 0) needed[static_cast<std::size_t>(n.b)] = 1;
  }
  std::vector<int> order;
  for (int i = 0; i < size(); ++i)
    if (needed[static_cast<std::size_t>(i)]) order.push_back(i);
  return order;
}

OpCounts ExpressionGraph::count(const std::vector<int>& schedule) const {
  OpCounts c;
  for (int i : schedule) {
    switch (node(i).op) {
      case Op::constant:
      case Op::input:
        break;
      case Op::add:
      case Op::sub:
      case Op::neg:
        ++c.add;
        break;
      case Op::mul:
        ++c.mul;
        break;
      case Op::div:
        ++c.div;
        break;
      default:
        ++c.call;
        break;
    }
  }
  return c;
}

GraphEvaluator::GraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs)
    : graph_(graph),
      outputs_(std::move(outputs)),
      schedule_(graph.schedule(outputs_)),
      values_(static_cast<std::size_t>(graph.size()), 0.0) {}

void GraphEvaluator::evaluate(double t, const double* x, const double* p, const double* in, double* out) {
  for (int i : schedule_) {
    const Node& n = graph_.node(i);
    double& v = values_[static_cast<std::size_t>(i)];
    switch (n.op) {
      case Op::constant:
        v = n.value;
        break;
      case Op::input:
        switch (n.argument) {
          case Argument::time:
            v = t;
            break;
          case Argument::state:
            v = x[n.index];
            break;
          case Argument::parameter:
            v = p[n.index];
            break;
          case Argument::input:
            v = in[n.index];
            break;
        }
        break;
      default:
        v = apply(n.op, values_[static_cast<std::size_t>(n.a)],
                  n.b >= 0 ? values_[static_cast<std::size_t>(n.b)] : 0.0);
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) out[k] = values_[static_cast<std::size_t>(outputs_[k])];
}

// Solves M y = f for symmetric positive definite M as straight-line code (LDLᵀ, no pivoting, no
// square roots): no loops or branches are left in the emitted kernel.
std::vector<int> ldlt_solve(ExpressionGraph& g, const std::vector<std::vector<int>>& M, const std::vector<int>& f,
                            bool last_first, std::vector<int>* pivots) {
  const std::size_t n = f.size();
  if (last_first) {  // the same factorization of the reversed system, P M Pᵀ (P y) = P f
    std::vector<std::vector<int>> R(n, std::vector<int>(n));
    std::vector<int> r(n);
    for (std::size_t i = 0; i < n; ++i) {
      r[i] = f[n - 1 - i];
      for (std::size_t j = 0; j < n; ++j) R[i][j] = M[n - 1 - i][n - 1 - j];
    }
    std::vector<int> y = ldlt_solve(g, R, r, false, pivots);
    std::reverse(y.begin(), y.end());
    return y;
  }
  std::vector<std::vector<int>> L(n, std::vector<int>(n, g.constant(0)));
  std::vector<int> d(n);
  for (std::size_t j = 0; j < n; ++j) {
    int dj = M[j][j];
    for (std::size_t k = 0; k < j; ++k)
      dj = g.binary(Op::sub, dj, g.binary(Op::mul, g.binary(Op::mul, L[j][k], L[j][k]), d[k]));
    d[j] = dj;
    if (pivots) pivots->push_back(dj);
    for (std::size_t i = j + 1; i < n; ++i) {
      int s = M[i][j];
      for (std::size_t k = 0; k < j; ++k)
        s = g.binary(Op::sub, s, g.binary(Op::mul, g.binary(Op::mul, L[i][k], L[j][k]), d[k]));
      L[i][j] = g.binary(Op::div, s, dj);
    }
  }
  std::vector<int> y(n);
  for (std::size_t i = 0; i < n; ++i) {
    int s = f[i];
    for (std::size_t k = 0; k < i; ++k) s = g.binary(Op::sub, s, g.binary(Op::mul, L[i][k], y[k]));
    y[i] = s;
  }
  std::vector<int> x(n);
  for (std::size_t i = n; i-- > 0;) {
    int s = g.binary(Op::div, y[i], d[i]);
    for (std::size_t k = i + 1; k < n; ++k) s = g.binary(Op::sub, s, g.binary(Op::mul, L[k][i], x[k]));
    x[i] = s;
  }
  return x;
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
      const bool v = n.op == Op::input ? n.argument != Argument::parameter
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

std::vector<int> tangent(ExpressionGraph& g, const std::vector<int>& outputs, const std::map<int, int>& seed) {
  const std::vector<int> order = g.schedule(outputs);
  const int zero = g.constant(0), one = g.constant(1);
  std::vector<int> dot(static_cast<std::size_t>(g.size()), zero);
  const auto mul = [&](int x, int y) { return g.binary(Op::mul, x, y); };
  for (int i : order) {
    const Node n = g.node(i);  // a copy: the rules below grow the graph
    int t = zero;
    if (n.op == Op::input) {
      const auto it = seed.find(i);
      if (it != seed.end()) t = it->second;
      dot[static_cast<std::size_t>(i)] = t;
      continue;
    }
    if (n.op == Op::constant) continue;
    const int da = dot[static_cast<std::size_t>(n.a)];
    const int db = n.b >= 0 ? dot[static_cast<std::size_t>(n.b)] : zero;
    if (da == zero && db == zero) continue;
    switch (n.op) {
      case Op::add:
        t = g.binary(Op::add, da, db);
        break;
      case Op::sub:
        t = g.binary(Op::sub, da, db);
        break;
      case Op::mul:
        t = g.binary(Op::add, mul(da, n.b), mul(n.a, db));
        break;
      case Op::div:  // (a/b)' = (a' − (a/b) b') / b
        t = g.binary(Op::div, g.binary(Op::sub, da, mul(i, db)), n.b);
        break;
      case Op::neg:
        t = g.unary(Op::neg, da);
        break;
      case Op::sqrt:
        t = g.binary(Op::div, da, mul(g.constant(2), i));
        break;
      case Op::sin:
        t = mul(g.unary(Op::cos, n.a), da);
        break;
      case Op::cos:
        t = g.unary(Op::neg, mul(g.unary(Op::sin, n.a), da));
        break;
      case Op::tan:
        t = mul(g.binary(Op::add, one, mul(i, i)), da);
        break;
      case Op::exp:
        t = mul(i, da);
        break;
      case Op::log:
        t = g.binary(Op::div, da, n.a);
        break;
      case Op::asin:
        t = g.binary(Op::div, da, g.unary(Op::sqrt, g.binary(Op::sub, one, mul(n.a, n.a))));
        break;
      case Op::acos:
        t = g.unary(Op::neg, g.binary(Op::div, da, g.unary(Op::sqrt, g.binary(Op::sub, one, mul(n.a, n.a)))));
        break;
      case Op::atan:
        t = g.binary(Op::div, da, g.binary(Op::add, one, mul(n.a, n.a)));
        break;
      case Op::sinh:
        t = mul(g.unary(Op::cosh, n.a), da);
        break;
      case Op::cosh:
        t = mul(g.unary(Op::sinh, n.a), da);
        break;
      case Op::tanh:
        t = mul(g.binary(Op::sub, one, mul(i, i)), da);
        break;
      case Op::abs:  // sign(a) a' as a / |a|: branch-free, undefined at a = 0 like the derivative
        t = mul(g.binary(Op::div, n.a, i), da);
        break;
      case Op::pow:
        if (g.node(n.b).op == Op::constant) {
          const double k = g.node(n.b).value;
          t = mul(mul(g.constant(k), g.binary(Op::pow, n.a, g.constant(k - 1))), da);
        } else {  // (a^b)' = a^b (b' log a + b a' / a)
          t = mul(i, g.binary(Op::add, mul(db, g.unary(Op::log, n.a)), g.binary(Op::div, mul(n.b, da), n.a)));
        }
        break;
      case Op::constant:
      case Op::input:
        break;
    }
    dot[static_cast<std::size_t>(i)] = t;
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
