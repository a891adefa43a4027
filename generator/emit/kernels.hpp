// The kernels of a model, built on one shared expression graph (so CSE spans all of them):
// kinematics (qadot), mass_matrix and forcing (BHconstr), hamel_coefficients (gamma), rhs (state
// derivative with an unrolled LDLᵀ solve of M u̇ = f), energy and constraint_residual (monitors); on request
// only, riemann_linearization (the covariant linearization of the Riemannian view, derive/riemann.hpp).
#pragma once

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "model/model.hpp"

#include <set>
#include <string>
#include <vector>

namespace hamel {

struct KernelSet {
  ExpressionGraph graph;
  std::vector<Kernel> kernels;
  /// The pivots of rhs's solve (articulated inertias D_i and the base's d_k, or the LDLᵀ's d_k of M; none
  /// when M is inverted at generation time): all positive iff M is positive definite. For the emitted
  /// status-returning rhs (rhs_status); empty when rhs is not built.
  std::vector<int> rhs_pivots;
  const Kernel& get(const std::string& name) const;
};

/// Kernel ABI: every kernel is `void name(real t, const real* x, const real* p, const real* in, real* out)`
/// with the state x = (q^1..q^n, u^I...), parameters p in file order and inputs in file order.
/// `only` (if not empty) selects kernels by name; the others are not built (the Jacobian's derivatives are
/// not even formed), so nothing of them reaches the emitted code. Built only when `only` names them:
/// `linearization` (A and B of the linearized state equations, forward mode through rhs) and
/// `riemann_linearization` (only for unconstrained models in general coordinates with L = ½ g q̇q̇ − V).
KernelSet build_kernels(const Model& model, const Derivation& derivation, const std::set<std::string>& only = {});

}  // namespace hamel
