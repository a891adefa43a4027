// The kernels of a model, built on one shared expression graph (so CSE spans all of them):
// kinematics (qadot), mass_matrix and forcing (BHconstr), hamel_coefficients (gamma), rhs (state
// derivative; u̇ and the jacobian's columns as emit/equations_of_motion.hpp forms them), energy and constraint_residual
// (monitors); for systems with position constraints g(q) = 0 (HamelSystem::position_constraints) constraint_position
// and its Jacobian, for the runtime's projector; on request only, riemann_linearization (the covariant linearization of
// the Riemannian view, derive/riemann.hpp).
#pragma once

#include "derive/derivation.hpp"
#include "emit/equations_of_motion.hpp"
#include "emit/expression_graph.hpp"
#include "model/model.hpp"

#include <optional>
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
  /// Prepared parameters: rhs (and jacobian) with their parameter-only work done once per parameter set.
  /// `prepare` maps p to P = (p, then the values of parameter_frontier), written into out; the kernels
  /// (rhs_prepared, jacobian_prepared) read P where the originals read p, and equal them. Per call they do
  /// what depends on t, x or in: parameter-only factors gathered (group_invariants), or, when that is
  /// fewer operations, polynomial outputs as Σ coefficient · monomial (polynomial_form). Built by default
  /// when rhs_prepared saves at least a tenth of rhs's operations per call (symbolic parameters in a constant
  /// mass matrix: the satellites), or when `only` names rhs_prepared or jacobian_prepared.
  struct Prepared {
    Kernel prepare;
    std::vector<Kernel> kernels;
    OpCounts rhs;           ///< operations of rhs
    OpCounts rhs_prepared;  ///< operations of rhs_prepared (per call)
    OpCounts once;          ///< operations of prepare (once per parameter set)
  };
  std::optional<Prepared> prepared;
  const Kernel& get(const std::string& name) const;
};

/// Kernel ABI: every kernel is `void name(real t, const real* x, const real* p, const real* in, real* out)`
/// with the state x = (q^1..q^n, u^I...), parameters p in file order and inputs in file order.
/// `only` (if not empty) selects kernels by name (emit/kernel_registry.hpp); the others are left out of the
/// set, so nothing of them reaches the emitted code. The cheap ones rhs is made from (kinematics, mass_matrix,
/// forcing) are formed anyway; the costly ones are not formed at all when not selected (the Jacobian's
/// derivatives, the linearizations, the tree connection's solves, the prepared kernels). Built only when
/// `only` names them (the registry's on-request kernels): `linearization` (A and B of the linearized state
/// equations, forward mode through rhs), `input_jacobian` and `parameter_jacobian` (d(x')/d(in) and d(x')/dp by the
/// parameters not folded, as EquationsOfMotion::jacobian_by forms them; an InputError when the model has no inputs,
/// or no parameter left symbolic) and `riemann_linearization` (only for unconstrained models in general
/// coordinates with L = ½ g q̇q̇ − V). `dynamics`: how u̇ and the Jacobian's columns are computed (--dynamics,
/// --jacobian-solve; emit/equations_of_motion.hpp chooses the route).
KernelSet build_kernels(const Model& model, const Derivation& derivation, const std::set<std::string>& only = {},
                        const DynamicsOptions& dynamics = {});

/// Kernels that would compute with a constant whose exact value is not a finite double (beyond ±1.8e308, or
/// nonzero and below the smallest double, so it would be printed as HUGE_VAL or 0.0: the mass matrix of
/// A = diag(1e200, 1e-200) has 1e400 and 1e-400), counting rhs's pivots with rhs and the prepared kernels with
/// prepare_parameters. When `named` (the caller asked for these kernels: `emit --kernels`, a scene, simulate) the
/// first such kernel is an InputError that names it, its output and the constant. Otherwise (the default set)
/// they are removed from `set` (the prepared kernels as a whole) and the returned notes say which and why; an
/// InputError still when none would be left. Returns no notes when every kernel is representable. Messages
/// begin with `model_path`.
std::vector<std::string> drop_unrepresentable(KernelSet& set, bool named, const std::string& model_path);

}  // namespace hamel
