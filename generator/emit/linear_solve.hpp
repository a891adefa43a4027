// Linear systems solved as straight-line code in the expression graph (no loops or branches reach the
// emitted kernel): the LDLᵀ of a symmetric positive definite matrix for one or many right-hand sides, the
// connection A = L⁻¹K of a tree, and a tree's mass matrix by the articulated-body recursion.
#pragma once

#include "derive/derivation.hpp"
#include "derive/tree_derivatives.hpp"
#include "emit/expression_graph.hpp"

#include <array>
#include <functional>
#include <vector>

namespace hamel {

/// Solves M y = f for symmetric positive definite M as straight-line code in the graph (LDLᵀ without
/// pivoting or square roots): no loops or branches in the emitted kernel. M by rows of node indices.
/// `last_first` eliminates from the last index down (M = LᵀDL): for the mass matrix of a kinematic tree,
/// whose bodies come after their parents, that creates no fill-in, so structural zeros (bodies on
/// different branches) stay zero and cost nothing.
/// `pivots` (if given) receives the d_k, all positive iff M is positive definite.
std::vector<int> ldlt_solve(ExpressionGraph& g, const std::vector<std::vector<int>>& M, const std::vector<int>& f,
                            bool last_first = false, std::vector<int>* pivots = nullptr);

/// M Y = F for the columns of F with one factorization (as ldlt_solve): the substitutions multiply by the
/// reciprocal pivots, one division per pivot instead of one per pivot and column. For the Jacobian's
/// columns and the connection A = L⁻¹K.
std::vector<std::vector<int>> ldlt_solve_columns(ExpressionGraph& g, const std::vector<std::vector<int>>& M,
                                                 const std::vector<std::vector<int>>& columns, bool last_first = false);

/// The connection A = L⁻¹K of a bundle whose connection is not formed symbolically (kinematic trees): L and K
/// (blocks of the mass matrix) converted through `node_of`, every column solved with one LDLᵀ of L.
/// A[α][I] as graph nodes.
std::vector<std::vector<int>> solved_connection(ExpressionGraph& g, const BundleGeometry& geo,
                                                ProgramConverter& node_of);

/// A force a right-hand side passes inward from a body (InverseDynamicsJacobian::inward): beyond its listed
/// rows, b holds −⟨s_I, force⟩ on the rows of the body's strict ancestors I and −⟨e_α, force⟩ on the base's.
/// body 0: none.
struct InwardForce {
  std::size_t body = 0;
  std::array<int, 6> force{};
};

/// A kinematic tree's articulated factor as graph nodes (ArticulatedFactor converted, or the inputs of a column
/// program): per body i ≥ 1 the joint axis s_i, U_i, W_i = U_i / D_i and 1 / D_i in the common frame, the base's
/// directions e_α and its m × m articulated inertia; `parent` the tree's parent indices. With a parent joint λ
/// (λ ≥ 1): σ_i = ⟨s_λ, U_i⟩ and ω_i = σ_i / D_i = ⟨W_i, s_λ⟩ (zero below the base), which shorten the solve's
/// chains of dependent operations (articulated_solve_columns).
struct ArticulatedNodes {
  using Vec = std::array<int, 6>;
  std::vector<int> parent;
  std::vector<Vec> s, U, W, e;
  std::vector<int> inverse_D;
  std::vector<std::vector<int>> base_inertia;
  std::vector<int> sigma, omega;
};

/// ArticulatedFactor and the tree's axes and base directions converted through `node_of`.
ArticulatedNodes articulated_nodes(ExpressionGraph& g, const TreeRecursion& tree, const ArticulatedFactor& factor,
                                   ProgramConverter& node_of);

/// M y = b for each column b (m + n rows: base directions, then joints) of a kinematic tree's mass matrix, with
/// the articulated-body recursion in the common frame (derive/tree_derivatives.hpp, the factor as nodes). Per
/// column, from the leaves in: μ_i = (b_i − ⟨s_i, p_i⟩) / D_i and p_λ += p_i + U_i μ_i; the base's m × m block
/// solved for all columns with one LDLᵀ; then outward: ÿ_i = μ_i − ⟨W_i, a_λ⟩, a_i = a_λ + s_i ÿ_i. The two
/// products are formed one level early, ⟨s_i, p_i⟩ = Σ_c (⟨s_i, p_c⟩ + σ_c μ_c) over i's children c and
/// ⟨W_i, a_λ⟩ = ⟨W_i, a_λλ⟩ + ω_i ÿ_λ, so that μ and ÿ pass from body to body through one multiply-add
/// instead of a whole dot product: the solve is a long chain of dependent operations, and this halves it. About
/// 55 operations per body and column against about 2·nnz(L) for the substitutions of an LDLᵀ of M: fewer for
/// long chains, where L is dense. A column's `inward` force (if given, one per column) starts p at the body's parent:
/// its ancestors' rows cost nothing.
std::vector<std::vector<int>> articulated_solve_columns(ExpressionGraph& g, const ArticulatedNodes& factor,
                                                        const std::vector<std::vector<int>>& columns,
                                                        const std::vector<InwardForce>& inward = {});

/// Builds, in a subroutine's graph `s`, the solutions of the columns `b` (nodes of s), reading any node of the kernel's
/// graph through `shared(node)`: e.g. ldlt_solve_columns or articulated_solve_columns on the factor read that way.
using ColumnSolver = std::function<std::vector<std::vector<int>>(
    ExpressionGraph& s, const std::function<int(int)>& shared, const std::vector<std::vector<int>>& b)>;

/// A solve repeated over `columns` (nodes of g, all of one length) as a Subroutine (emit/expression_graph.hpp): the
/// solve of one column, called on `lanes` consecutive columns at a time (its lanes); the solution's row r of a call's
/// lane l is placed at result_of(column, r) in the kernel's outputs. Shared values are nodes of g (a constant is
/// copied into the subroutine's graph instead, where it folds); the work on them alone (a factorization) is hoisted
/// into g (hoist_shared_work). A last call with fewer columns left takes the last `lanes` columns (some solved
/// twice). Empty (no calls) when that work reaches a constant that is not a finite double.
Subroutine solve_subroutine(ExpressionGraph& g, const std::vector<std::vector<int>>& columns, std::size_t lanes,
                            const std::function<int(std::size_t, std::size_t)>& result_of, const ColumnSolver& solve);

/// `factor` with every node read through `shared` (for a ColumnSolver).
ArticulatedNodes shared_factor(const ArticulatedNodes& factor, const std::function<int(int)>& shared);

}  // namespace hamel
