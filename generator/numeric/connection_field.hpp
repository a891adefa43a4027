// The connection 𝒜(r) of a bundle model evaluated numerically (paper (KinConnect) / (mechConn)), with the locked
// inertia L(r) when the kinetic energy is a quadratic form, and on request its shape derivatives ∂𝒜^α_J/∂r^I,
// obtained by forward-mode differentiation of the derivation's expression graph (tangent()), not by differences.
// Shared by the phase (numeric/phase.cpp) and the gait designer (numeric/gait.cpp): one evaluation of 𝒜.
#pragma once

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "model/model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <memory>
#include <vector>

namespace hamel {

class ConnectionField {
 public:
  /// `derivation` must be the bundle model's (any form; trees solve L 𝒜 = K in the graph); `parameters` are the
  /// values of model.parameters. With `derivatives`, evaluate() also computes ∂𝒜/∂r.
  ConnectionField(const Model& model, const Derivation& derivation, const std::vector<double>& parameters,
                  bool derivatives = false);

  /// Evaluates at the shape r (n values).
  void evaluate(const double* r);

  double A(unsigned a, unsigned I) const { return out_[a * n_ + I]; }
  double L(unsigned a, unsigned b) const { return out_[m_ * n_ + a * m_ + b]; }
  /// ∂𝒜^a_J/∂r^I (only with derivatives).
  double dA(unsigned a, unsigned J, unsigned I) const { return out_[offset_dA_ + (I * m_ + a) * n_ + J]; }
  bool has_locked_inertia() const { return has_L_; }
  bool has_derivatives() const { return offset_dA_ != 0; }
  unsigned m() const { return m_; }
  unsigned n() const { return n_; }

 private:
  unsigned m_, n_;
  std::vector<double> p_, x_, out_;
  ExpressionGraph graph_;
  std::unique_ptr<GraphEvaluator> evaluator_;
  std::size_t offset_dA_ = 0;
  bool has_L_ = false;
};

}  // namespace hamel
