#include "emit/equations_of_motion.hpp"

#include "algebra/simplify.hpp"
#include "emit/linear_solve.hpp"
#include "model/input_error.hpp"
#include "rbd/aba.hpp"
#include "rbd/rnea.hpp"
#include "rbd/rnea_derivatives.hpp"

#include <functional>
#include <optional>

namespace hamel {

namespace {

// The tuned constants of the route, all here.

// Operations of rhs above which a model that is not a kinematic tree gets its Jacobian by forward mode only
// (trees differentiate their inverse dynamics analytically at any size).
constexpr int kSymbolicJacobianLimit = 8000;

// The jacobian's solves are printed as one function called on this many columns at a time, its lanes (Subroutine):
// with two, g++ -O2 computes both columns' copies of a statement in one SSE2 instruction (the 30-joint chain's
// jacobian 18 % faster than two columns printed one after the other, docs/benchmarks.md)...
const std::size_t kColumnLanes = 2;
// ... always with the articulated-body recursion, and with the LDLᵀ when its substitutions take at least this many
// operations.
const int kCalledSolveMinimum = 1000;

// A tree's Jacobian columns are solved by the articulated-body recursion when its program has at most this share
// of the operations of the LDLᵀ route: per operation it ran 5–13 % slower (docs/benchmarks.md, ab-bench:
// 0.95 of the operations took 1.03× the time for chain 12, 0.98 took 1.11× for the 30-body tree; 0.88 took
// 0.89× for chain 16, 0.67 took 0.73× for chain 30; measured before the inward forces).
constexpr double kRecursiveSolveShare = 0.9;

// u_I' = M⁻¹ f formed exactly at generation time when M is a matrix of numbers (parameters folded and M
// independent of q: the free rigid body, the satellites in the Lagrange–Poincaré form, the sleigh), with its
// monomials in the velocities collected: an LDLᵀ at run time would leave its rounding and the cancellation
// between the products M⁻¹_IJ f_J to double arithmetic (satellite_se3: 2.3e3 ulps, docs/accuracy.md).
bool constant_mass_matrix(const HamelEquations& eq) {
  const unsigned d = static_cast<unsigned>(eq.independent.size());
  if (d == 0) return false;
  for (unsigned i = 0; i < d; ++i)
    for (unsigned j = 0; j < d; ++j)
      if (!GiNaC::is_a<GiNaC::numeric>(eq.mass_matrix(i, j))) return false;
  return true;
}

std::vector<GiNaC::ex> exact_accelerations(const HamelEquations& eq, const HamelSystem& sys) {
  const unsigned d = static_cast<unsigned>(eq.independent.size());
  const GiNaC::matrix inverse = eq.mass_matrix.inverse();
  std::vector<GiNaC::ex> velocities;
  for (int I : eq.independent) velocities.push_back(sys.velocities[static_cast<std::size_t>(I)]);
  std::vector<GiNaC::ex> out(d);
  for (unsigned i = 0; i < d; ++i) {
    GiNaC::ex sum = 0;
    for (unsigned j = 0; j < d; ++j) sum += inverse(i, j) * eq.forcing[j];
    out[i] = simplify_quadratic_form(sum, velocities);
  }
  return out;
}

// M u̇ = f: u̇ by the LDLᵀ of M, or exactly when M is constant; the Jacobian by the chain rule through M and f.
class MassMatrixEquations : public EquationsOfMotion {
 public:
  MassMatrixEquations(const Derivation& derivation, KernelProgram program, std::vector<std::vector<int>> M,
                      std::vector<int> f, bool constant)
      : eq_(derivation.equations),
        sys_(derivation.system),
        p_(program),
        g_(program.graph),
        M_(std::move(M)),
        f_(std::move(f)),
        n_(static_cast<int>(sys_.coordinates.size())),
        d_(eq_.independent.size()) {
    if (constant) exact_ = exact_accelerations(eq_, sys_);
  }

  const Accelerations& accelerations() override {
    if (!formed_) {
      accel_ = form_accelerations();
      formed_ = true;
    }
    return accel_;
  }

  Jacobian jacobian(const std::vector<int>& rhs) override { return columns_by(state_symbols(), true, rhs); }
  Jacobian jacobian_by(const std::vector<GiNaC::ex>& by, const std::vector<int>& rhs) override {
    return columns_by(by, false, rhs);
  }

 protected:
  // d(x')/dw for every w of `by`, the state's components when `of_state`.
  virtual Jacobian columns_by(const std::vector<GiNaC::ex>& by, bool of_state, const std::vector<int>& rhs) {
    // A large rhs program (the Whipple bicycle: 1.5e4 operations) is differentiated in forward mode only: the
    // symbolic route differentiates M and f through the derivation's program per state component, which costs
    // seconds of GiNaC work there, for a kernel of about the same size (1.25e5 against 1.32e5 operations).
    if (!eq_.tree && g_.count(g_.schedule(rhs)).total() > kSymbolicJacobianLimit)
      return {forward_columns(by, rhs), nullptr, "; forward mode through the rhs program"};
    return symbolic_jacobian(by, of_state);
  }

  virtual Accelerations form_accelerations() {
    if (exact_) {
      Accelerations a{{}, {}, " with u_I' = M^-1 f, M constant, inverted at generation time"};
      for (const GiNaC::ex& e : *exact_) a.values.push_back(p_.node_of(e));
      return a;
    }
    Accelerations a{{}, {}, " with M u_I' = f solved by unrolled LDL^T"};
    a.values = ldlt_solve(g_, M_, f_, eq_.factor_last_first, &a.pivots);
    return a;
  }

  // The right side of M du̇/dx_k = b_k for column k, x_k its symbol (a state component when `of_state`); the chain
  // rule through M and f by default.
  virtual std::vector<int> right_side(std::size_t /*k*/, const GiNaC::ex& x_k, const std::vector<int>& accel,
                                      bool /*of_state*/) {
    std::vector<int> b(d_);
    for (std::size_t i = 0; i < d_; ++i) {
      int r = p_.node_of(diff(eq_.forcing[i], x_k));
      for (std::size_t j = 0; j < d_; ++j) {
        const GiNaC::ex dM = diff(eq_.mass_matrix(static_cast<unsigned>(i), static_cast<unsigned>(j)), x_k);
        if (!dM.is_zero()) r = g_.binary(Op::sub, r, g_.binary(Op::mul, p_.node_of(dM), accel[j]));
      }
      b[i] = r;
    }
    return b;
  }

  // M y = b_k for every right side: the LDLᵀ's columns, printed as calls when the substitutions are long.
  virtual std::vector<std::vector<int>> solve_columns(const std::vector<std::vector<int>>& right_sides, Jacobian& out,
                                                      bool /*of_state*/) {
    std::vector<std::vector<int>> solved = ldlt_solve_columns(g_, M_, right_sides, eq_.factor_last_first);
    if (operations(solved) - operations(right_sides) >= kCalledSolveMinimum) call_columns(right_sides, by_ldlt(), out);
    return solved;
  }

  // The accelerations the Jacobian's columns are taken at (what u̇ stands for in them).
  virtual std::vector<int> accelerations_for_columns() { return accelerations().values; }
  // Work the right sides share, done once before them (those of the state's columns when `of_state`).
  virtual void before_right_sides(bool /*of_state*/) {}

  // d(x')/dw for every w of `by` (the state's components when `of_state`): the kinematics rows by differentiation,
  // the acceleration rows from M du̇/dw_k = b_k solved with one factorization (value numbering shares it between the
  // columns, and between the jacobian and the kernels by inputs and parameters), or by differentiating u̇ = M⁻¹ f when
  // M is constant.
  Jacobian symbolic_jacobian(const std::vector<GiNaC::ex>& by, bool of_state) {
    Jacobian out;
    const std::vector<int> accel = exact_ ? std::vector<int>{} : column_accelerations();
    for (std::size_t j = 0; j < eq_.acceleration_symbols.size() && !accel.empty(); ++j)
      p_.leaves[eq_.acceleration_symbols[j]] = accel[j];
    if (!exact_) before_right_sides(of_state);
    const std::size_t nx = by.size();
    out.columns.assign(nx, {});
    std::vector<std::vector<int>> right_sides;  // M du̇/dw_k = b_k, all solved with one factorization
    for (std::size_t k = 0; k < nx; ++k) {
      const GiNaC::ex& x_k = by[k];
      for (int a = 0; a < n_; ++a)
        out.columns[k].push_back(p_.node_of(diff(eq_.kinematics[static_cast<std::size_t>(a)], x_k)));
      if (exact_) {
        for (const GiNaC::ex& a : *exact_) out.columns[k].push_back(p_.node_of(diff(a, x_k)));
        continue;
      }
      right_sides.push_back(right_side(k, x_k, accel, of_state));
    }
    if (!exact_) {
      const std::vector<std::vector<int>> solved = solve_columns(right_sides, out, of_state);
      for (std::size_t k = 0; k < nx; ++k)
        out.columns[k].insert(out.columns[k].end(), solved[k].begin(), solved[k].end());
    }
    return out;
  }

  GiNaC::ex diff(const GiNaC::ex& e, const GiNaC::ex& x) { return p_.tape.diff(e, GiNaC::ex_to<GiNaC::symbol>(x)); }
  rbd::Namer<GiNaC::ex> namer() {
    return rbd::Namer<GiNaC::ex>([this](const GiNaC::ex& e) { return p_.tape.define(e); });
  }
  // The state's symbols x = (q, u_I), in the order of rhs's outputs.
  std::vector<GiNaC::ex> state_symbols() const {
    std::vector<GiNaC::ex> x(sys_.coordinates.begin(), sys_.coordinates.end());
    for (int I : eq_.independent) x.push_back(sys_.velocities[static_cast<std::size_t>(I)]);
    return x;
  }
  // Forward mode through the rhs program: d(rhs)/dw, one tangent pass per w of `by` (at its leaf).
  std::vector<std::vector<int>> forward_columns(const std::vector<GiNaC::ex>& by, const std::vector<int>& rhs) {
    std::vector<std::vector<int>> columns;
    for (const GiNaC::ex& w : by) columns.push_back(tangent(g_, rhs, {{p_.leaves.at(w), g_.constant(1)}}));
    return columns;
  }
  // accelerations_for_columns(), formed once for all the kernels that take columns.
  const std::vector<int>& column_accelerations() {
    if (!column_accelerations_) column_accelerations_ = accelerations_for_columns();
    return *column_accelerations_;
  }
  // Operations of the program computing `columns`.
  int operations(const std::vector<std::vector<int>>& columns) const {
    std::vector<int> all;
    for (const std::vector<int>& c : columns) all.insert(all.end(), c.begin(), c.end());
    return g_.count(g_.schedule(all)).total();
  }
  ColumnSolver by_ldlt() const {
    return [this](ExpressionGraph& s, const std::function<int(int)>& shared, const std::vector<std::vector<int>>& b) {
      std::vector<std::vector<int>> M = M_;
      for (std::vector<int>& row : M)
        for (int& entry : row) entry = shared(entry);
      return ldlt_solve_columns(s, M, b, eq_.factor_last_first);
    };
  }
  // The solves of M y = b for `right_sides` printed as one function called on kColumnLanes columns at a time (the
  // kernel row-major with one column per right side).
  void call_columns(const std::vector<std::vector<int>>& right_sides, const ColumnSolver& solve, Jacobian& out) {
    const std::size_t nx = right_sides.size();
    Subroutine calls = solve_subroutine(
        g_, right_sides, kColumnLanes,
        [&](std::size_t k, std::size_t i) {
          return static_cast<int>((static_cast<std::size_t>(n_) + i) * nx + k);  // row-major
        },
        solve);
    if (!calls.calls.empty()) out.calls = std::make_shared<const Subroutine>(std::move(calls));
  }

  const HamelEquations& eq_;
  const HamelSystem& sys_;
  KernelProgram p_;
  ExpressionGraph& g_;
  const std::vector<std::vector<int>> M_;
  const std::vector<int> f_;
  const int n_;                                  ///< coordinates
  const std::size_t d_;                          ///< independent quasi-velocities
  std::optional<std::vector<GiNaC::ex>> exact_;  ///< M⁻¹ f when M is constant

 private:
  Accelerations accel_;
  bool formed_ = false;
  std::optional<std::vector<int>> column_accelerations_;
};

// A kinematic tree: u̇ by the articulated-body algorithm or the LDLᵀ; the Jacobian by ∂ID/∂x.
class TreeEquations : public MassMatrixEquations {
 public:
  TreeEquations(const Derivation& derivation, KernelProgram program, std::vector<std::vector<int>> M,
                std::vector<int> f, bool constant, bool articulated, ColumnSolve column_solve)
      : MassMatrixEquations(derivation, program, std::move(M), std::move(f), constant),
        tree_(*eq_.tree),
        articulated_(articulated),
        column_solve_(column_solve) {}

  Jacobian columns_by(const std::vector<GiNaC::ex>& by, bool of_state, const std::vector<int>& rhs) override {
    Jacobian out = symbolic_jacobian(by, of_state);
    // With the articulated-body algorithm also forward-mode differentiation of the rhs program itself, one
    // tangent pass per column (size ~ program × columns, no M, no solve per column); the smaller of the two programs
    // is kept (docs/benchmarks.md: the tangent one is larger for the trees measured so far, because the articulated
    // inertias depend on every joint angle outboard of a body).
    if (articulated_) {
      std::vector<std::vector<int>> forward = forward_columns(by, rhs);
      if (operations(forward) < operations(out.columns))
        return {std::move(forward), nullptr, "; forward mode through the rhs program"};
    }
    return out;
  }

 protected:
  Accelerations form_accelerations() override {
    if (!articulated_) return MassMatrixEquations::form_accelerations();
    Accelerations a{{}, {}, " with u_I' by the articulated-body algorithm (O(n), no M)"};
    const rbd::ForwardDynamics fd = rbd::forward_dynamics(tree_, namer());
    for (const GiNaC::ex& e : fd.accelerations) a.values.push_back(p_.node_of(e));
    for (const GiNaC::ex& e : fd.pivots) a.pivots.push_back(p_.node_of(e));
    return a;
  }

  // Where rhs runs the articulated-body algorithm in the bodies' frames, the Jacobian solves M u̇ = f once more
  // with the factor in the common frame that its columns use (f from the common frame too): about a third of the
  // operations of calling rhs's recursion (the 30-joint chain: 13.5 k).
  std::vector<int> accelerations_for_columns() override {
    if (!articulated_ || column_solve_ == ColumnSolve::ldlt) return accelerations().values;
    std::vector<int> f;
    for (const GiNaC::ex& e : rbd::bias_forcing(tree_, namer())) f.push_back(p_.node_of(e));
    return articulated_solve_columns(g_, factor(), {f}).front();
  }

  // ∂ID/∂x analytically (rbd/rnea_derivatives.hpp): the right sides are −∂ID/∂x (P, V and Δ negated once per column
  // instead of every row). By inputs and parameters, −ID = f − M u̇ at the acceleration symbols (rbd::residual_forcing,
  // O(n)) differentiated through its program: inputs reach it through the generalized forces, parameters through
  // the inertias, offsets, axes, gravity, armatures and joint forces.
  void before_right_sides(bool of_state) override {
    if (of_state && !id_) {
      id_ = rbd::rnea_derivatives(tree_, p_.tape);
      minus_id_ = id_->negated(p_.tape);
      id_columns_ = minus_id_->dense(tree_);
    }
    if (!of_state && minus_inverse_dynamics_.empty()) minus_inverse_dynamics_ = rbd::residual_forcing(tree_, namer());
  }

  std::vector<int> right_side(std::size_t k, const GiNaC::ex& w, const std::vector<int>&, bool of_state) override {
    std::vector<int> b(d_);
    for (std::size_t i = 0; i < d_; ++i)
      b[i] = p_.node_of(of_state ? id_columns_[k][i] : diff(minus_inverse_dynamics_[i], w));
    return b;
  }

  // M y = b_k: the LDLᵀ of M or the articulated-body recursion, as asked, or the recursion when it is clearly the
  // smaller program.
  std::vector<std::vector<int>> solve_columns(const std::vector<std::vector<int>>& right_sides, Jacobian& out,
                                              bool of_state) override {
    std::vector<std::vector<int>> solved;
    if (column_solve_ != ColumnSolve::articulated)
      solved = ldlt_solve_columns(g_, M_, right_sides, eq_.factor_last_first);
    // The LDLᵀ's columns, printed as calls when the substitutions are long (the factorization goes to the stage).
    const auto by_ldlt_kept = [&] {
      if (operations(solved) - operations(right_sides) >= kCalledSolveMinimum)
        call_columns(right_sides, by_ldlt(), out);
      return solved;
    };
    if (column_solve_ == ColumnSolve::ldlt) return by_ldlt_kept();
    // The recursion takes what a joint's subtree passes to its ancestors' rows as one inward force (InwardForce: Δ,
    // whose rows are −⟨s_I, Δ⟩); the columns by inputs and parameters as they are.
    std::vector<std::vector<int>> own_rows = of_state ? std::vector<std::vector<int>>{} : right_sides;
    std::vector<InwardForce> inward;
    for (std::size_t k = 0; k < right_sides.size() && of_state; ++k) {
      own_rows.emplace_back();
      for (const GiNaC::ex& r : minus_id_->rows(tree_, k)) own_rows.back().push_back(p_.node_of(r));
      InwardForce f{id_->columns[k].body, {}};
      for (std::size_t c = 0; c < 6; ++c) f.force[c] = p_.node_of(id_->inward(k)[c]);
      inward.push_back(f);
    }
    const ArticulatedNodes& articulated = factor();
    std::vector<std::vector<int>> recursive = articulated_solve_columns(g_, articulated, own_rows, inward);
    if (!solved.empty() && operations(recursive) > kRecursiveSolveShare * operations(solved)) return by_ldlt_kept();
    out.how = "; M^-1 b by the articulated-body recursion";
    // Printed as calls, on the dense columns (a call cannot know at which body a column's inward force enters).
    call_columns(
        right_sides,
        [&](ExpressionGraph& s, const std::function<int(int)>& shared, const std::vector<std::vector<int>>& b) {
          return articulated_solve_columns(s, shared_factor(articulated, shared), b);
        },
        out);
    return recursive;
  }

 private:
  // The tree's articulated factor in the common frame as nodes, built on first use.
  const ArticulatedNodes& factor() {
    if (!factor_) {
      const rbd::FrameView world(tree_.model, tree_.frame, namer());
      factor_ = articulated_nodes(g_, tree_, rbd::articulated_factor(world, namer()), p_.node_of);
    }
    return *factor_;
  }

  const rbd::TreeDynamics& tree_;
  const bool articulated_;
  const ColumnSolve column_solve_;
  std::optional<ArticulatedNodes> factor_;
  std::optional<rbd::InverseDynamicsJacobian> id_, minus_id_;
  std::vector<std::vector<GiNaC::ex>> id_columns_;
  std::vector<GiNaC::ex> minus_inverse_dynamics_;  ///< f − M u̇ at the acceleration symbols, for jacobian_by
};

}  // namespace

// One body: the 7×7 (SE3) LDLᵀ of M is as cheap as the recursion (rhs 1.0–1.3× faster with ldlt, 690 against
// 619 operations for the scaling chain); from two bodies on the articulated-body algorithm is faster and its
// advantage grows with n (docs/benchmarks.md). On a fixed base M is only n×n (no 6×6 base block to factor)
// and the recursion saves less: rhs operations of fixed chains under gravity with armature and damping
// (aba/ldlt) 1.22 (n = 2), 1.16 (3), 1.08 (4), 1.00 (5), 0.94 (6), 0.88 (7), 0.86 (8), so aba from 5 bodies.
std::string tree_dynamics_default(std::size_t bodies, bool fixed_base) {
  return bodies >= (fixed_base ? 5u : 2u) ? "aba" : "ldlt";
}

AccelerationRoute acceleration_route(const Model& model, const Derivation& derivation, const std::string& dynamics) {
  if (!dynamics.empty() && dynamics != "aba" && dynamics != "ldlt")
    throw InputError("--dynamics: expected aba or ldlt, got '" + dynamics + "'");
  if (!dynamics.empty() && model.locations.count("loops"))
    throw InputError("--dynamics applies to the recursive derivation of kinematic trees; '" + model.source_path +
                     "' is a tree with closed loops (key loops), derived as holonomic constraints on its joints "
                     "(docs/model-format.md, Closed loops); expected no --dynamics");
  const bool tree = derivation.equations.tree != nullptr;
  if (dynamics == "aba" && !tree)
    throw InputError(
        "--dynamics aba applies to kinematic tree models (key 'tree'; on a floating base in the ep "
        "form); '" +
        model.source_path + "' is " + (model.bundle && model.bundle->tree ? "not in the ep form" : "not a tree"));
  if (tree) {
    const bool fixed = model.tree.has_value();
    const std::size_t bodies = fixed ? model.tree->bodies.size() : model.bundle->tree->bodies.size();
    if ((dynamics.empty() ? tree_dynamics_default(bodies, fixed) : dynamics) == "aba")
      return AccelerationRoute::articulated;
  }
  return constant_mass_matrix(derivation.equations) ? AccelerationRoute::constant_inverse : AccelerationRoute::ldlt;
}

std::unique_ptr<EquationsOfMotion> equations_of_motion(const Model& model, const Derivation& derivation,
                                                       const DynamicsOptions& options, KernelProgram program,
                                                       std::vector<std::vector<int>> M, std::vector<int> f) {
  const AccelerationRoute route = acceleration_route(model, derivation, options.accelerations);
  const bool constant = constant_mass_matrix(derivation.equations);
  if (derivation.equations.tree)
    return std::make_unique<TreeEquations>(derivation, program, std::move(M), std::move(f), constant,
                                           route == AccelerationRoute::articulated, options.column_solve);
  return std::make_unique<MassMatrixEquations>(derivation, program, std::move(M), std::move(f), constant);
}

}  // namespace hamel
