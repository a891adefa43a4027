// The equations of motion as the kernels compute them: u̇_I (rhs), d(x')/dx (jacobian) and d(x')/dw by inputs and
// parameters (input_jacobian, parameter_jacobian, with the jacobian's columns), on the kernels' graph.
// This is the one place where the route is chosen (equations_of_motion(), with every tuned constant in the .cpp).
//
// Every derivation gives M(q) u̇_I = f (BHconstr); a kinematic tree also gives the tree itself (rbd::TreeDynamics,
// HamelEquations::tree). Two families offer the same two things:
//  - MassMatrixEquations: u̇ by an unrolled LDLᵀ of M at run time, or M⁻¹ f formed exactly at generation time when M
//    is a matrix of numbers; the Jacobian by the chain rule through the programs of M and f
//    (M du̇/dx_k = df/dx_k − (dM/dx_k) u̇, every column solved with the one factorization), by differentiating the exact
//    M⁻¹ f, or by forward mode through the rhs program when that program is large;
//  - TreeEquations (a MassMatrixEquations): u̇ by the articulated-body algorithm in the bodies' frames (rbd/aba.hpp,
//    O(n), no M) or by the LDLᵀ of M, as --dynamics says; the Jacobian by the analytical derivatives of the inverse
//    dynamics (rbd/rnea_derivatives.hpp), M du̇/dx_k = −∂ID/∂x_k, its columns solved with the LDLᵀ of M or the
//    articulated-body recursion (--jacobian-solve), or forward mode through rhs where that is the smaller program.
#pragma once

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "model/model.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hamel {

/// How a kinematic tree's Jacobian solves M y = b for its columns: with the LDLᵀ of M (about 2·nnz(L) operations
/// per column, few for bushy trees), with the articulated-body recursion (articulated_solve_columns, about 50
/// per body and column, fewer for long chains), or (the default) the recursion when its program has at most 0.9
/// of the other's operations (per operation it runs slower). Other models always use the LDLᵀ.
enum class ColumnSolve { smaller, ldlt, articulated };

/// The command line's say in the route (--dynamics, --jacobian-solve), the same for every verb.
struct DynamicsOptions {
  std::string accelerations;                        ///< --dynamics: "aba", "ldlt", or "" for tree_dynamics_default
  ColumnSolve column_solve = ColumnSolve::smaller;  ///< --jacobian-solve
};

/// The default of --dynamics for a kinematic tree of `bodies` bodies, floating or on a fixed base (measured in
/// docs/benchmarks.md): aba from 2 bodies on a floating base, from 5 on a fixed one.
std::string tree_dynamics_default(std::size_t bodies, bool fixed_base);

/// How rhs computes u̇: the articulated-body algorithm (trees, --dynamics aba or its default), M⁻¹ f exactly (M a
/// matrix of numbers), or an unrolled LDLᵀ of M.
enum class AccelerationRoute { articulated, constant_inverse, ldlt };

/// The route for `derivation` of `model` under --dynamics `dynamics`. Throws InputError when `dynamics` is not aba,
/// ldlt or empty, or does not apply (aba on a model that is not a tree in the ep form, any value on a tree with
/// closed loops).
AccelerationRoute acceleration_route(const Model& model, const Derivation& derivation, const std::string& dynamics);

/// The kernels' graph and program as the equations of motion build on them (emit/kernels.cpp owns them): `leaves`
/// maps the state's and the parameters' symbols to their inputs, `node_of` converts expressions of `tape` (a copy of
/// the derivation's program that may grow) to nodes.
struct KernelProgram {
  ExpressionGraph& graph;
  Intermediates& tape;
  ProgramConverter& node_of;
  std::map<GiNaC::ex, int, GiNaC::ex_is_less>& leaves;
};

class EquationsOfMotion {
 public:
  struct Accelerations {
    std::vector<int> values;  ///< u̇_I, in the order of HamelEquations::independent
    std::vector<int> pivots;  ///< of the solve (D_i, d_k): all positive iff M is positive definite; none for M⁻¹ f
    std::string how;          ///< for rhs's summary, e.g. " with u_I' by the articulated-body algorithm (O(n), no M)"
  };
  struct Jacobian {
    std::vector<std::vector<int>> columns;    ///< columns[k][row] = d(x'_row)/dx_k, x' = rhs's outputs
    std::shared_ptr<const Subroutine> calls;  ///< the columns' solves as one function (jacobian row-major), or none
    std::string how;                          ///< for the jacobian's summary
  };

  virtual ~EquationsOfMotion() = default;
  /// rhs's u̇_I (formed on the first call).
  virtual const Accelerations& accelerations() = 0;
  /// d(x')/dx for x' = `rhs` (the kinematics' nodes, then accelerations().values), every state component x_k.
  virtual Jacobian jacobian(const std::vector<int>& rhs) = 0;
  /// d(x')/dw for symbols w that are not the state (the inputs, the parameters not folded; each with its leaf in the
  /// program), by the jacobian's machinery: the kinematics rows by differentiation, the acceleration rows from
  /// M du̇/dw = −∂ID/∂w at fixed u̇ (trees: the inverse dynamics' program differentiated by w; other models
  /// ∂f/∂w − (∂M/∂w) u̇), every column solved as the jacobian's are; or forward mode through rhs where the jacobian
  /// takes it. Jacobian::calls are row-major n_state x by.size().
  virtual Jacobian jacobian_by(const std::vector<GiNaC::ex>& by, const std::vector<int>& rhs) = 0;
};

/// The equations of motion of `derivation` on `program`, with the mass matrix's and the forcing's nodes `M`, `f`
/// already formed there: the family and its routes chosen by the derivation, `options` and the programs' sizes.
std::unique_ptr<EquationsOfMotion> equations_of_motion(const Model& model, const Derivation& derivation,
                                                       const DynamicsOptions& options, KernelProgram program,
                                                       std::vector<std::vector<int>> M, std::vector<int> f);

}  // namespace hamel
