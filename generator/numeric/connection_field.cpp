#include "numeric/connection_field.hpp"

#include "emit/linear_solve.hpp"

#include <map>

namespace hamel {

ConnectionField::ConnectionField(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                                 bool derivatives)
    : m_(d.bundle->algebra.dim()), n_(static_cast<unsigned>(model.coordinates.size())), p_(parameters) {
  std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves;
  leaves[model.time] = graph_.input(Argument::time, 0);
  std::vector<int> shape;
  for (unsigned I = 0; I < n_; ++I) {
    shape.push_back(graph_.input(Argument::state, static_cast<int>(I)));
    leaves[model.coordinates[I]] = shape.back();
    leaves[model.rates[I]] = graph_.input(Argument::state, static_cast<int>(n_ + I));
  }
  for (std::size_t k = 0; k < model.parameters.size(); ++k)
    leaves[model.parameters[k].symbol] = graph_.input(Argument::parameter, static_cast<int>(k));
  // Kinematic trees (ep form): L and K are blocks of the mass matrix, written with intermediate symbols
  // (converted as they are needed: those of L and K depend on r only); 𝒜 solves L 𝒜 = K in the graph.
  ProgramConverter node_of(graph_, leaves, d.equations.intermediates);
  const BundleGeometry& geo = *d.bundle;
  std::vector<int> connection, outputs;
  if (geo.connection_derived) {
    for (unsigned a = 0; a < m_; ++a)
      for (unsigned I = 0; I < n_; ++I) connection.push_back(node_of(geo.connection(a, I)));
  } else {
    for (const std::vector<int>& row : solved_connection(graph_, geo, node_of))
      connection.insert(connection.end(), row.begin(), row.end());
  }
  outputs = connection;
  has_L_ = geo.quadratic;
  for (unsigned a = 0; a < m_ && has_L_; ++a)
    for (unsigned b = 0; b < m_; ++b) outputs.push_back(node_of(geo.L(a, b)));
  if (derivatives) {
    offset_dA_ = outputs.size();
    for (unsigned I = 0; I < n_; ++I) {
      const std::vector<int> d_dI = tangent(graph_, connection, {{shape[I], graph_.constant(1.0)}});
      outputs.insert(outputs.end(), d_dI.begin(), d_dI.end());
    }
  }
  evaluator_ = std::make_unique<GraphEvaluator>(graph_, outputs);
  x_.assign(2 * n_, 0.0);
  out_.resize(outputs.size());
}

void ConnectionField::evaluate(const double* r) {
  for (unsigned I = 0; I < n_; ++I) x_[I] = r[I];
  evaluator_->evaluate(0.0, x_.data(), p_.data(), nullptr, out_.data());
}

}  // namespace hamel
