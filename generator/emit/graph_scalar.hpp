// A node of an expression graph as a scalar, so that the generic rigid-body algorithms of rbd/ (spatial algebra,
// LDLᵀ, the articulated-body solve) build graph programs with the same code that builds GiNaC programs in the
// derivation. Arithmetic adds nodes to the graph of the innermost GraphScope (constants folded and trivial
// identities removed by ExpressionGraph::binary, so zeros of a structure cost nothing).
#pragma once

#include "emit/expression_graph.hpp"

#include <stdexcept>

namespace hamel {

class GraphScalar {
 public:
  /// No value yet (as an uninitialized double: assign before use).
  GraphScalar() = default;
  /// The constant `value` in the current scope's graph.
  GraphScalar(int value) : node_(graph().constant(static_cast<double>(value))) {}  // NOLINT: 0 and 1 in formulas
  /// An existing node (of the current scope's graph).
  static GraphScalar node(int id) { return GraphScalar(id, Tag{}); }
  int id() const { return node_; }

  friend GraphScalar operator+(const GraphScalar& a, const GraphScalar& b) { return a.binary(Op::add, b); }
  friend GraphScalar operator-(const GraphScalar& a, const GraphScalar& b) { return a.binary(Op::sub, b); }
  friend GraphScalar operator*(const GraphScalar& a, const GraphScalar& b) { return a.binary(Op::mul, b); }
  friend GraphScalar operator/(const GraphScalar& a, const GraphScalar& b) { return a.binary(Op::div, b); }
  friend GraphScalar operator-(const GraphScalar& a) { return node(graph().unary(Op::neg, a.node_)); }
  friend bool is_zero(const GraphScalar& a) { return graph().is_constant(a.node_, 0); }

  /// The graph arithmetic writes to; a GraphScope must be open.
  static ExpressionGraph& graph() {
    if (!current()) throw std::logic_error("GraphScalar used outside a GraphScope");
    return *current();
  }

 private:
  friend class GraphScope;
  struct Tag {};
  GraphScalar(int id, Tag) : node_(id) {}
  GraphScalar binary(Op op, const GraphScalar& b) const { return node(graph().binary(op, node_, b.node_)); }
  static ExpressionGraph*& current() {
    static thread_local ExpressionGraph* graph = nullptr;
    return graph;
  }
  int node_ = -1;
};

/// Makes `g` the graph GraphScalar arithmetic writes to, until the scope closes (scopes nest).
class GraphScope {
 public:
  explicit GraphScope(ExpressionGraph& g) : previous_(GraphScalar::current()) { GraphScalar::current() = &g; }
  ~GraphScope() { GraphScalar::current() = previous_; }
  GraphScope(const GraphScope&) = delete;
  GraphScope& operator=(const GraphScope&) = delete;

 private:
  ExpressionGraph* previous_;
};

}  // namespace hamel
