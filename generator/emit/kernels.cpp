#include "emit/kernels.hpp"

#include "algebra/simplify.hpp"
#include "derive/riemann.hpp"
#include "derive/tree_derivatives.hpp"
#include "emit/kernel_registry.hpp"
#include "emit/linear_solve.hpp"
#include "emit/polynomial_form.hpp"
#include "model/input_error.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

namespace hamel {

const Kernel& KernelSet::get(const std::string& name) const {
  for (const Kernel& k : kernels)
    if (k.name == name) return k;
  throw std::logic_error("no kernel named " + name);
}

namespace {

// Prepared parameters are built by default when rhs_prepared has at most this share of rhs's operations.
constexpr double kPreparedShare = 0.9;

// Operations of rhs above which a model that is not a kinematic tree gets its Jacobian by forward mode only
// (trees differentiate their inverse dynamics analytically at any size).
constexpr int kSymbolicJacobianLimit = 8000;

// A tree's Jacobian columns are solved by the articulated-body recursion when its program has at most this share
// of the operations of the LDLᵀ route: per operation it ran 5–13 % slower (docs/benchmarks.md, ab-bench:
// 0.95 of the operations took 1.03× the time for chain 12, 0.98 took 1.11× for the 30-body tree; 0.88 took
// 0.89× for chain 16, 0.67 took 0.73× for chain 30; measured before the inward forces).
constexpr double kRecursiveSolveShare = 0.9;

// u_I' = M⁻¹ f formed exactly at generation time when M is a matrix of numbers (parameters folded and M
// independent of q: the free rigid body, the satellites in the Lagrange–Poincaré form, the sleigh), with its
// monomials in the velocities collected: an LDLᵀ at run time would leave its rounding and the cancellation
// between the products M⁻¹_IJ f_J to double arithmetic (satellite_se3: 2.3e3 ulps, docs/accuracy.md).
std::optional<std::vector<GiNaC::ex>> exact_accelerations(const HamelEquations& eq, const HamelSystem& sys) {
  const unsigned d = static_cast<unsigned>(eq.independent.size());
  if (d == 0) return std::nullopt;
  for (unsigned i = 0; i < d; ++i)
    for (unsigned j = 0; j < d; ++j)
      if (!GiNaC::is_a<GiNaC::numeric>(eq.mass_matrix(i, j))) return std::nullopt;
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

// An empty kernel with its registered name and summary, and `how` appended to the summary.
Kernel registered(const char* name, const std::string& how = "") {
  const KernelSpec& spec = kernel_spec(name);
  return {spec.name, spec.summary + how, {}, {}};
}

}  // namespace

KernelSet build_kernels(const Model& model, const Derivation& derivation, const std::set<std::string>& only,
                        ColumnSolve column_solve) {
  // A kernel is built when named, or, when none is named, if the registry builds it by default.
  const auto want = [&](const char* name) { return only.empty() ? kernel_spec(name).by_default : only.count(name) > 0; };
  KernelSet set;
  ExpressionGraph& g = set.graph;
  const HamelEquations& eq = derivation.equations;
  const HamelSystem& sys = derivation.system;
  const int n = static_cast<int>(sys.coordinates.size());

  std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves;
  leaves[model.time] = g.input(Argument::time, 0);
  for (int a = 0; a < n; ++a) leaves[sys.coordinates[static_cast<std::size_t>(a)]] = g.input(Argument::state, a);
  for (std::size_t i = 0; i < eq.independent.size(); ++i)
    leaves[sys.velocities[static_cast<std::size_t>(eq.independent[i])]] =
        g.input(Argument::state, n + static_cast<int>(i));
  for (int alpha : sys.constrained) leaves[sys.velocities[static_cast<std::size_t>(alpha)]] = g.constant(0);
  for (std::size_t k = 0; k < model.parameters.size(); ++k)
    leaves[model.parameters[k].symbol] = g.input(Argument::parameter, static_cast<int>(k));
  for (std::size_t k = 0; k < model.inputs.size(); ++k)
    leaves[model.inputs[k]] = g.input(Argument::input, static_cast<int>(k));

  // Intermediate symbols become the nodes of their definitions when an expression first needs them
  // (definitions before their users); differentiation (the Jacobian) may add definitions to this copy.
  // Some definitions use symbols that get their nodes late (the acceleration symbols of a tree's recursion).
  Intermediates tape = eq.intermediates;
  ProgramConverter node_of(g, leaves, tape);
  const auto diff = [&](const GiNaC::ex& e, const GiNaC::ex& x) { return tape.diff(e, GiNaC::ex_to<GiNaC::symbol>(x)); };
  const auto name_of = [&](int a) { return sys.velocities[static_cast<std::size_t>(a)].get_name(); };

  Kernel kinematics = registered("kinematics");
  for (int a = 0; a < n; ++a) {
    kinematics.outputs.push_back(node_of(eq.kinematics[static_cast<std::size_t>(a)]));
    kinematics.output_names.push_back(sys.coordinates[static_cast<std::size_t>(a)].get_name() + "_dot");
  }

  const std::size_t d = eq.independent.size();
  Kernel mass = registered("mass_matrix");
  std::vector<std::vector<int>> M(d, std::vector<int>(d));
  for (std::size_t i = 0; i < d; ++i)
    for (std::size_t j = 0; j < d; ++j) {
      M[i][j] = node_of(eq.mass_matrix(static_cast<unsigned>(i), static_cast<unsigned>(j)));
      mass.outputs.push_back(M[i][j]);
      mass.output_names.push_back("M[" + name_of(eq.independent[i]) + "][" + name_of(eq.independent[j]) + "]");
    }

  Kernel forcing = registered("forcing");
  for (std::size_t i = 0; i < d; ++i) {
    forcing.outputs.push_back(node_of(eq.forcing[i]));
    forcing.output_names.push_back("f[" + name_of(eq.independent[i]) + "]");
  }

  Kernel gamma = registered("hamel_coefficients");
  for (const HamelCoefficient& h : sys.gamma) {
    gamma.outputs.push_back(node_of(h.value));
    gamma.output_names.push_back("gamma^" + name_of(h.upper) + "_" + name_of(h.lower_a) + "," + name_of(h.lower_b));
  }

  const std::optional<std::vector<GiNaC::ex>> exact_accel = exact_accelerations(eq, sys);
  const bool articulated = !eq.recursive_accelerations.empty();
  Kernel rhs = registered("rhs", articulated   ? " with u_I' by the articulated-body algorithm (O(n), no M)"
                                 : exact_accel ? " with u_I' = M^-1 f, M constant, inverted at generation time"
                                               : " with M u_I' = f solved by unrolled LDL^T");
  rhs.outputs = kinematics.outputs;
  rhs.output_names = kinematics.output_names;
  std::vector<int> accel;
  if (articulated) {
    for (const GiNaC::ex& a : eq.recursive_accelerations) accel.push_back(node_of(a));
    for (const GiNaC::ex& d : eq.recursive_pivots) set.rhs_pivots.push_back(node_of(d));
  } else if (exact_accel) {
    for (const GiNaC::ex& a : *exact_accel) accel.push_back(node_of(a));
  } else {
    accel = ldlt_solve(g, M, forcing.outputs, eq.factor_last_first, &set.rhs_pivots);
  }
  for (std::size_t i = 0; i < d; ++i) {
    rhs.outputs.push_back(accel[i]);
    rhs.output_names.push_back(name_of(eq.independent[i]) + "_rate");
  }

  // d(x')/dx for implicit integrators: the kinematics rows by differentiation; the acceleration rows from
  // M u' = f as M d(u')/dx_k = df/dx_k − (dM/dx_k) u', solved with the same LDLᵀ (value numbering shares
  // the factorization between the columns), or by differentiating u' = M⁻¹ f when M is constant.
  Kernel jacobian = registered("jacobian");
  // A large rhs program (the Whipple bicycle: 1.5e4 operations) is differentiated in forward mode only: the
  // symbolic route below differentiates M and f through the derivation's program per state component, which
  // costs seconds of GiNaC work there, for a kernel of about the same size (1.25e5 against 1.32e5 operations).
  // Forward mode through the rhs program: d(rhs)/d(argument k) for k < count, one tangent pass each.
  const auto forward_columns = [&](Argument argument, int count) {
    std::vector<std::vector<int>> columns;
    for (int k = 0; k < count; ++k) columns.push_back(tangent(g, rhs.outputs, {{g.input(argument, k), g.constant(1)}}));
    return columns;
  };
  const auto state_name = [&](int k) {
    return k < n ? sys.coordinates[static_cast<std::size_t>(k)].get_name()
                 : name_of(eq.independent[static_cast<std::size_t>(k - n)]);
  };
  const bool build_jacobian = want("jacobian") || only.count("jacobian_prepared") > 0;  // its variant needs it
  // The linearization's A is the Jacobian: a tree's analytical columns are shared with it.
  const bool build_columns = build_jacobian || (want("linearization") && eq.tree);
  const bool forward_only = build_columns && !articulated && !eq.tree &&
                            g.count(g.schedule(rhs.outputs)).total() > kSymbolicJacobianLimit;
  std::vector<std::vector<int>> column;  // column[k][row] = d(x'_row)/dx_k
  const auto operations = [&](const std::vector<std::vector<int>>& columns) {  // of the program computing them
    std::vector<int> all;
    for (const std::vector<int>& c : columns) all.insert(all.end(), c.begin(), c.end());
    return g.count(g.schedule(all)).total();
  };
  if (forward_only) {
    column = forward_columns(Argument::state, static_cast<int>(rhs.outputs.size()));
    jacobian.summary += "; forward mode through the rhs program";
  } else if (build_columns) {
    std::string route;  // how the columns were formed, for the summary
    // The acceleration symbols of a tree's recursion stand for the solved u'.
    for (std::size_t j = 0; j < eq.acceleration_symbols.size(); ++j) leaves[eq.acceleration_symbols[j]] = accel[j];
    std::vector<GiNaC::ex> state_symbols(sys.coordinates.begin(), sys.coordinates.end());
    for (int I : eq.independent) state_symbols.push_back(sys.velocities[static_cast<std::size_t>(I)]);
    const std::size_t nx = state_symbols.size();
    column.resize(nx);
    // Trees: ∂ID/∂x analytically (derive/tree_derivatives.hpp), M d(u')/dx_k = −∂ID/∂x_k. Otherwise (and for
    // trees whose eq.tree a test clears, to compare) the chain rule through the programs of M and f below.
    std::optional<InverseDynamicsJacobian> id;
    if (eq.tree && !exact_accel) id = inverse_dynamics_jacobian(*eq.tree, tape);
    const std::vector<std::vector<GiNaC::ex>> id_columns = id ? id->dense(*eq.tree) : std::vector<std::vector<GiNaC::ex>>{};
    std::vector<std::vector<int>> right_sides;  // M d(u')/dx_k = b_k, all solved with one factorization
    for (std::size_t k = 0; k < nx; ++k) {
      const GiNaC::ex& x_k = state_symbols[k];
      for (int a = 0; a < n; ++a)
        column[k].push_back(node_of(diff(eq.kinematics[static_cast<std::size_t>(a)], x_k)));
      if (exact_accel) {
        for (const GiNaC::ex& a : *exact_accel) column[k].push_back(node_of(diff(a, x_k)));
        continue;
      }
      std::vector<int> b(d);
      for (std::size_t i = 0; i < d; ++i) {
        if (!id_columns.empty()) {
          b[i] = node_of(-id_columns[k][i]);
          continue;
        }
        int r = node_of(diff(eq.forcing[i], x_k));
        for (std::size_t j = 0; j < d; ++j) {
          const GiNaC::ex dM = diff(eq.mass_matrix(static_cast<unsigned>(i), static_cast<unsigned>(j)), x_k);
          if (!dM.is_zero()) r = g.binary(Op::sub, r, g.binary(Op::mul, node_of(dM), accel[j]));
        }
        b[i] = r;
      }
      right_sides.push_back(b);
    }
    if (!exact_accel) {
      // The LDLᵀ of M or (trees) the articulated-body recursion: as asked, or the recursion when it is clearly
      // the smaller program.
      std::vector<std::vector<int>> solved;
      if (id_columns.empty() || column_solve != ColumnSolve::articulated)
        solved = ldlt_solve_columns(g, M, right_sides, eq.factor_last_first);
      if (!id_columns.empty() && column_solve != ColumnSolve::ldlt) {
        // The recursion takes what a joint's subtree passes to its ancestors' rows as one inward force.
        std::vector<std::vector<int>> own_rows;
        std::vector<InwardForce> inward;
        for (std::size_t k = 0; k < nx; ++k) {
          own_rows.emplace_back();
          for (const GiNaC::ex& r : id->rows[k]) own_rows.back().push_back(node_of(-r));
          InwardForce f{id->inward_body[k], {}};
          for (std::size_t c = 0; c < 6; ++c) f.force[c] = node_of(id->inward[k][c]);
          inward.push_back(f);
        }
        std::vector<std::vector<int>> recursive =
            articulated_solve_columns(g, *eq.tree, articulated_factor(*eq.tree, tape), node_of, own_rows, inward);
        if (solved.empty() || operations(recursive) <= kRecursiveSolveShare * operations(solved)) {
          solved = std::move(recursive);
          route = "; M^-1 b by the articulated-body recursion";
        }
      }
      for (std::size_t k = 0; k < nx; ++k) column[k].insert(column[k].end(), solved[k].begin(), solved[k].end());
    }
    // With the articulated-body algorithm also forward-mode differentiation of the rhs program itself, one
    // tangent pass per state component (size ~ program × state dimension, no M, no solve per column); the
    // smaller of the two programs is kept (docs/benchmarks.md: the tangent one is larger for the trees
    // measured so far, because the articulated inertias depend on every joint angle outboard of a body).
    if (articulated) {
      const std::vector<std::vector<int>> forward = forward_columns(Argument::state, static_cast<int>(nx));
      if (operations(forward) < operations(column)) {
        column = forward;
        route = "; forward mode through the rhs program";
      }
    }
    jacobian.summary += route;
  }
  if (build_jacobian) {
    const std::size_t nx = column.size();
    for (std::size_t row = 0; row < nx; ++row)
      for (std::size_t k = 0; k < nx; ++k) {
        jacobian.outputs.push_back(column[k][row]);
        jacobian.output_names.push_back("d" + rhs.output_names[row] + "/d" + state_name(static_cast<int>(k)));
      }
  }

  // A = d(x')/dx and B = d(x')/d(in) along any state: A is the Jacobian's columns when they are built (for
  // trees always: analytical), otherwise forward mode through the rhs program like B (one tangent pass per
  // state or input component). Built only when asked for by name.
  Kernel linearization = registered("linearization");
  if (want("linearization")) {
    const int nx = static_cast<int>(rhs.outputs.size());
    const int ni = static_cast<int>(model.inputs.size());
    const std::vector<std::vector<int>> a_columns = column.empty() ? forward_columns(Argument::state, nx) : column;
    const std::vector<std::vector<int>> b_columns = forward_columns(Argument::input, ni);
    for (int row = 0; row < nx; ++row)
      for (int k = 0; k < nx; ++k) {
        linearization.outputs.push_back(a_columns[static_cast<std::size_t>(k)][static_cast<std::size_t>(row)]);
        linearization.output_names.push_back("A[" + rhs.output_names[static_cast<std::size_t>(row)] + "][" + state_name(k) + "]");
      }
    for (int row = 0; row < nx; ++row)
      for (int k = 0; k < ni; ++k) {
        linearization.outputs.push_back(b_columns[static_cast<std::size_t>(k)][static_cast<std::size_t>(row)]);
        linearization.output_names.push_back("B[" + rhs.output_names[static_cast<std::size_t>(row)] + "][" +
                                             model.inputs[static_cast<std::size_t>(k)].get_name() + "]");
      }
  }

  Kernel energy = registered("energy");
  energy.outputs.push_back(node_of(eq.energy_terms.at(0)));
  energy.output_names.push_back("E");

  set.kernels = {kinematics, mass, forcing, gamma, rhs, jacobian, energy};
  if (want("linearization")) set.kernels.push_back(linearization);
  if (!eq.constraint_residual.empty()) {
    Kernel residual = registered("constraint_residual");
    for (std::size_t k = 0; k < eq.constraint_residual.size(); ++k) {
      residual.outputs.push_back(node_of(eq.constraint_residual[k]));
      residual.output_names.push_back(name_of(sys.constrained[k]));
    }
    set.kernels.push_back(residual);
  }
  if (derivation.bundle) {
    const BundleGeometry& geo = *derivation.bundle;
    const Bundle& b = *model.bundle;
    const std::size_t m = b.group_velocity.size();
    Kernel xi = registered("group_velocity");
    for (std::size_t a = 0; a < m; ++a) {
      xi.outputs.push_back(node_of(derivation.group_velocity[a]));
      xi.output_names.push_back(b.group_velocity[a].get_name());
    }
    set.kernels.push_back(xi);
    // Kinematic trees: A = L⁻¹K solved in the kernel (unrolled LDLᵀ of the locked inertia), not symbolically;
    // placeholders (node 0) when neither kernel that uses it is built.
    const std::vector<std::vector<int>> solved =
        !geo.connection_derived && n > 0 && (want("connection") || want("shape_inertia"))
            ? solved_connection(g, geo, node_of)
            : std::vector<std::vector<int>>(m, std::vector<int>(static_cast<std::size_t>(n)));
    const auto connection_node = [&](std::size_t a, int I) {
      return geo.connection_derived ? node_of(geo.connection(static_cast<unsigned>(a), static_cast<unsigned>(I)))
                                    : solved[a][static_cast<std::size_t>(I)];
    };
    if (n > 0) {
      Kernel conn = registered("connection");
      for (std::size_t a = 0; a < m; ++a)
        for (int I = 0; I < n; ++I) {
          conn.outputs.push_back(connection_node(a, I));
          conn.output_names.push_back("A[" + b.group_velocity[a].get_name() + "][" +
                                      sys.coordinates[static_cast<std::size_t>(I)].get_name() + "]");
        }
      set.kernels.push_back(conn);
    }
    if (geo.quadratic) {
      Kernel locked = registered("locked_inertia");
      for (std::size_t a = 0; a < m; ++a)
        for (std::size_t c = 0; c < m; ++c) {
          locked.outputs.push_back(node_of(geo.L(static_cast<unsigned>(a), static_cast<unsigned>(c))));
          locked.output_names.push_back("L[" + b.group_velocity[a].get_name() + "][" + b.group_velocity[c].get_name() +
                                        "]");
        }
      set.kernels.push_back(locked);
    }
    if (b.mechanical && n > 0 && want("shape_inertia")) {
      // The lower block of M^Ω = diag(L, S − AᵀLA) (MOmega); the upper block is locked_inertia.
      Kernel shape = registered("shape_inertia");
      for (int I = 0; I < n; ++I)
        for (int J = 0; J < n; ++J) {
          if (geo.connection_derived) {
            shape.outputs.push_back(node_of(geo.shape_inertia(static_cast<unsigned>(I), static_cast<unsigned>(J))));
          } else if (J < I) {  // symmetric: the entry above the diagonal
            shape.outputs.push_back(shape.outputs[static_cast<std::size_t>(J * n + I)]);
          } else {  // S − KᵀA with A = L⁻¹K (= S − AᵀLA)
            int v = node_of(geo.S(static_cast<unsigned>(I), static_cast<unsigned>(J)));
            for (std::size_t a = 0; a < m; ++a)
              v = g.binary(Op::sub, v,
                           g.binary(Op::mul, node_of(geo.K(static_cast<unsigned>(a), static_cast<unsigned>(I))),
                                    solved[a][static_cast<std::size_t>(J)]));
            shape.outputs.push_back(v);
          }
          shape.output_names.push_back("M_shape[" + sys.coordinates[static_cast<std::size_t>(I)].get_name() + "][" +
                                       sys.coordinates[static_cast<std::size_t>(J)].get_name() + "]");
        }
      set.kernels.push_back(shape);
    }
  }
  // The Riemannian view (derive/riemann.hpp), built only when asked for by name: it is defined only for
  // unconstrained models in general coordinates with L = ½ g_ab q̇ᵃq̇ᵇ − V. Matrices in the coordinate basis
  // ∂/∂qᵃ at the state's velocity q̇ = B(q) u_I (qadot); for A = I that is q̇ = u.
  if (want("riemann_linearization")) {
    const RiemannGeometry riemann = derive_riemann(model, tape);
    for (int a = 0; a < n; ++a)
      leaves[model.rates[static_cast<std::size_t>(a)]] = node_of(eq.kinematics[static_cast<std::size_t>(a)]);
    Kernel linearization = registered("riemann_linearization");
    const auto name = [&](const char* label, int a, int b) {
      return std::string(label) + "[" + sys.coordinates[static_cast<std::size_t>(a)].get_name() + "][" +
             sys.coordinates[static_cast<std::size_t>(b)].get_name() + "]";
    };
    const std::pair<const char*, const GiNaC::matrix*> blocks[] = {
        {"g", &riemann.metric}, {"G", &riemann.connection_rate}, {"K", &riemann.stiffness}};
    std::vector<int> connection_rate;
    for (const auto& [label, m] : blocks)
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          linearization.outputs.push_back(node_of((*m)(static_cast<unsigned>(a), static_cast<unsigned>(b))));
          linearization.output_names.push_back(name(label, a, b));
          if (m == &riemann.connection_rate) connection_rate.push_back(linearization.outputs.back());
        }
    // Ġ along the motion, by forward mode through G's program with the state's tangent x' = (q̇, u̇_I) (the
    // rhs kernel's outputs): what the first-order form of the covariant equations needs
    // (docs/linearization.md).
    std::map<int, int> along_motion;
    for (std::size_t k = 0; k < rhs.outputs.size(); ++k)
      along_motion[g.input(Argument::state, static_cast<int>(k))] = rhs.outputs[k];
    const std::vector<int> connection_rate_dot = tangent(g, connection_rate, along_motion);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        linearization.outputs.push_back(connection_rate_dot[static_cast<std::size_t>(a * n + b)]);
        linearization.output_names.push_back(name("G_dot", a, b));
      }
    set.kernels.push_back(linearization);
  }
  // Prepared parameters: the parameter-only work of rhs and jacobian hoisted into prepare (KernelSet::Prepared).
  const bool prepared_named = only.count("rhs_prepared") > 0 || only.count("jacobian_prepared") > 0;
  if (only.empty() || prepared_named) {
    std::vector<const Kernel*> originals;
    if (want("rhs") || only.count("rhs_prepared")) originals.push_back(&rhs);
    if (build_jacobian && !jacobian.outputs.empty())
      originals.push_back(&jacobian);
    // Parameter-only factors and divisors gathered, so that their products and reciprocals are prepared too;
    // or, where it leaves fewer operations per call, polynomial outputs as Σ coefficient · monomial.
    std::vector<std::vector<int>> rewritten;
    std::vector<int> all;
    for (const Kernel* k : originals) {
      std::vector<int> grouped = group_invariants(g, k->outputs);
      std::vector<int> polynomial = polynomial_form(g, k->outputs);
      const bool fewer = run_time_operations(g, polynomial).total() < run_time_operations(g, grouped).total();
      rewritten.push_back(fewer ? std::move(polynomial) : std::move(grouped));
      all.insert(all.end(), rewritten.back().begin(), rewritten.back().end());
    }
    const std::vector<int> frontier = parameter_frontier(g, all);
    KernelSet::Prepared prepared;
    prepared.rhs = g.count(g.schedule(rhs.outputs));
    prepared.once = g.count(g.schedule(frontier));
    if (!rewritten.empty() && originals.front() == &rhs) prepared.rhs_prepared = run_time_operations(g, rewritten.front());
    if (prepared_named || (!rewritten.empty() && originals.front() == &rhs &&
                           prepared.rhs_prepared.total() <= kPreparedShare * prepared.rhs.total())) {
      const int n_p = static_cast<int>(model.parameters.size());
      prepared.prepare = {"prepare_parameters", "P = (p, then the parameter-only values of rhs and jacobian)", {}, {}};
      for (int k = 0; k < n_p; ++k) {
        prepared.prepare.outputs.push_back(g.input(Argument::parameter, k));
        prepared.prepare.output_names.push_back(model.parameters[static_cast<std::size_t>(k)].symbol.get_name());
      }
      std::map<int, int> replace;
      for (std::size_t j = 0; j < frontier.size(); ++j) {
        prepared.prepare.outputs.push_back(frontier[j]);
        prepared.prepare.output_names.push_back("prepared " + std::to_string(j));
        replace[frontier[j]] = g.input(Argument::parameter, n_p + static_cast<int>(j));
      }
      for (std::size_t i = 0; i < originals.size(); ++i) {
        Kernel variant = *originals[i];
        const KernelSpec& spec = kernel_spec(originals[i]->name + "_prepared");
        variant.name = spec.name;
        variant.summary = spec.summary;
        variant.outputs = substitute(g, rewritten[i], replace);
        prepared.kernels.push_back(variant);
      }
      set.prepared = prepared;
    }
  }
  if (!want("rhs")) set.rhs_pivots.clear();
  if (!only.empty()) {
    std::vector<Kernel> kept;
    for (const Kernel& k : set.kernels)
      if (only.count(k.name)) kept.push_back(k);
    set.kernels = kept;
  }
  return set;
}

std::vector<std::string> drop_unrepresentable(KernelSet& set, bool named, const std::string& model_path) {
  const ExpressionGraph& g = set.graph;
  // "kernel 'mass_matrix', output M[w][w], needs the constant 1.0e400, ...", or "" when all is representable.
  const auto problem = [&](const Kernel& k, const std::vector<int>& extra = {}) -> std::string {
    std::vector<int> outputs = k.outputs;
    outputs.insert(outputs.end(), extra.begin(), extra.end());
    const auto [output, node] = g.first_unrepresentable(outputs);
    if (node < 0) return "";
    const std::size_t o = static_cast<std::size_t>(output);
    const std::string what = o < k.output_names.size() ? "output " + k.output_names[o] : "a pivot of its solve";
    return "kernel '" + k.name + "', " + what + ", needs the constant " + g.unrepresentable_value(node) +
           ", beyond the range of a double (about 2.2e-308 to 1.8e308 in magnitude), which it would compute as " +
           (std::isinf(g.node(node).value) ? "infinity" : std::isnan(g.node(node).value) ? "NaN" : "0");
  };
  std::vector<std::string> notes, errors;
  std::vector<Kernel> kept;
  for (const Kernel& k : set.kernels) {
    const std::string p = problem(k, k.name == "rhs" ? set.rhs_pivots : std::vector<int>{});
    if (p.empty()) {
      kept.push_back(k);
      continue;
    }
    errors.push_back(p);
    if (k.name == "rhs") set.rhs_pivots.clear();
  }
  if (set.prepared) {
    std::string p = problem(set.prepared->prepare);
    for (const Kernel& k : set.prepared->kernels)
      if (p.empty()) p = problem(k);
    if (!p.empty()) {
      errors.push_back(p);
      set.prepared.reset();
    }
  }
  if (errors.empty()) return notes;
  if (named)
    throw InputError(model_path + ": error: " + errors.front() +
                     "; expected constants that fit a double (do not ask for this kernel, or rescale the model)");
  if (kept.empty() && !set.prepared)
    throw InputError(model_path + ": error: no kernel can be emitted: " + errors.front() +
                     "; expected constants that fit a double (rescale the model)");
  set.kernels = kept;
  for (const std::string& e : errors) notes.push_back("hamel: note: " + model_path + ": left out " + e);
  return notes;
}

}  // namespace hamel
