// Linear systems solved as straight-line code in the expression graph (no loops or branches reach the
// emitted kernel): the LDLᵀ of a symmetric positive definite matrix for one or many right-hand sides, the
// connection A = L⁻¹K of a tree, and a tree's mass matrix by the articulated-body recursion. The algorithms are
// rbd/ldlt.hpp and rbd/aba.hpp, run on graph nodes (emit/graph_scalar.hpp); this file adapts node indices to them.
#pragma once

#include "emit/expression_graph.hpp"
#include "emit/graph_scalar.hpp"
#include "rbd/aba.hpp"

#include <array>
#include <functional>
#include <vector>

namespace hamel {

struct BundleGeometry;  // derive/bundle_connection.hpp: only the connection below reads it

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

/// A kinematic tree's articulated factor as graph nodes (rbd::ArticulatedFactor converted, or the inputs of a column
/// program), in the common frame: per body i ≥ 1 the joint axis s_i, U_i, W_i = U_i / D_i and 1 / D_i, the base's
/// directions e_α and its m × m articulated inertia; with a parent joint λ (λ ≥ 1): σ_i = ⟨s_λ, U_i⟩ and
/// ω_i = σ_i / D_i = ⟨W_i, s_λ⟩ (zero below the base), which shorten the solve's chains of dependent operations
/// (rbd::ArticulatedSolveOptions::short_chains).
using ArticulatedNodes = rbd::ArticulatedSystem<GraphScalar>;

/// The factor and the tree's axes and base directions converted through `node_of`.
ArticulatedNodes articulated_nodes(ExpressionGraph& g, const rbd::TreeDynamics& tree,
                                   const rbd::ArticulatedFactor& factor, ProgramConverter& node_of);

/// M y = b for each column b (m + n rows: base directions, then joints) of a kinematic tree's mass matrix, with
/// the articulated-body solve in the common frame (rbd::articulated_solve with short chains, the factor as nodes).
/// About 55 operations per body and column against about 2·nnz(L) for the substitutions of an LDLᵀ of M: fewer for
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
