#include "emit/kernels.hpp"

#include "derive/riemann.hpp"
#include "emit/equations_of_motion.hpp"
#include "emit/kernel_registry.hpp"
#include "emit/linear_solve.hpp"
#include "emit/polynomial_form.hpp"
#include "emit/zero_test.hpp"
#include "model/fold_parameters.hpp"
#include "model/input_error.hpp"
#include "rbd/centroidal.hpp"

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

// An empty kernel with its registered name and summary, and `how` appended to the summary.
Kernel registered(const char* name, const std::string& how = "") {
  const KernelSpec& spec = kernel_spec(name);
  return {spec.name, spec.summary + how, {}, {}, nullptr};
}

// build_kernels' work in steps that share the graph, the leaves and the converter: the equations' kernels
// (kinematics, M, f, γ, rhs), the Jacobian's columns, the linearization, a bundle's kernels, the Riemannian
// linearization and prepared parameters, each built when wanted.
class KernelBuilder {
 public:
  KernelBuilder(const Model& model, const Derivation& derivation, const std::set<std::string>& only,
                const DynamicsOptions& dynamics)
      : model_(model),
        derivation_(derivation),
        eq_(derivation.equations),
        sys_(derivation.system),
        only_(only),
        dynamics_(dynamics),
        n_(static_cast<int>(sys_.coordinates.size())),
        d_(eq_.independent.size()),
        tape_(eq_.intermediates),
        node_of_(g_, leaves_, tape_) {
    leaves_[model.time] = g_.input(Argument::time, 0);
    for (int a = 0; a < n_; ++a) leaves_[sys_.coordinates[static_cast<std::size_t>(a)]] = g_.input(Argument::state, a);
    for (std::size_t i = 0; i < d_; ++i)
      leaves_[sys_.velocities[static_cast<std::size_t>(eq_.independent[i])]] =
          g_.input(Argument::state, n_ + static_cast<int>(i));
    for (int alpha : sys_.constrained) leaves_[sys_.velocities[static_cast<std::size_t>(alpha)]] = g_.constant(0);
    for (std::size_t k = 0; k < model.parameters.size(); ++k)
      leaves_[model.parameters[k].symbol] = g_.input(Argument::parameter, static_cast<int>(k));
    for (std::size_t k = 0; k < model.inputs.size(); ++k)
      leaves_[model.inputs[k]] = g_.input(Argument::input, static_cast<int>(k));
  }

  KernelBuilder(const KernelBuilder&) = delete;  // holds references into its own members
  KernelBuilder& operator=(const KernelBuilder&) = delete;

  KernelSet build() {
    equation_kernels();
    build_jacobian_ = want("jacobian") || only_.count("jacobian_prepared") > 0;  // its variant needs it
    // The linearization's A is the Jacobian: a tree's analytical columns are shared with it.
    if (build_jacobian_ || (want("linearization") && eq_.tree)) jacobian_columns();
    if (build_jacobian_) {
      const std::size_t nx = column_.size();
      for (std::size_t row = 0; row < nx; ++row)
        for (std::size_t k = 0; k < nx; ++k) {
          jacobian_.outputs.push_back(column_[k][row]);
          jacobian_.output_names.push_back("d" + rhs_.output_names[row] + "/d" + state_name(static_cast<int>(k)));
        }
      jacobian_.calls = column_calls_;
    }
    Kernel energy = registered("energy");
    energy.outputs.push_back(node_of_(eq_.energy_terms.at(0)));
    energy.output_names.push_back("E");

    set_.kernels = {kinematics_, mass_, forcing_, gamma_, rhs_, jacobian_, energy};
    if (want("linearization")) set_.kernels.push_back(linearization());
    for (const char* by : {"input_jacobian", "parameter_jacobian"})
      if (want(by)) set_.kernels.push_back(jacobian_by(by));
    const std::vector<PositionConstraint>& positions = sys_.position_constraints;
    if (!eq_.constraint_residual.empty() || !positions.empty()) {
      Kernel residual =
          registered("constraint_residual", positions.empty() ? "" : ", then g(q) of the position constraints");
      for (std::size_t k = 0; k < eq_.constraint_residual.size(); ++k) {
        residual.outputs.push_back(node_of_(eq_.constraint_residual[k]));
        residual.output_names.push_back(name_of(sys_.constrained[k]));
      }
      for (const PositionConstraint& c : positions) {
        residual.outputs.push_back(node_of_(c.g));
        residual.output_names.push_back("g[" + c.name + "]");
      }
      set_.kernels.push_back(residual);
    }
    if (!positions.empty()) {
      Kernel position = registered("constraint_position"), jacobian = registered("constraint_position_jacobian");
      for (const PositionConstraint& c : positions) {
        position.outputs.push_back(node_of_(c.g));
        position.output_names.push_back(c.name);
        for (int a = 0; a < n_; ++a) {
          jacobian.outputs.push_back(node_of_(c.gradient[static_cast<std::size_t>(a)]));
          jacobian.output_names.push_back("d" + c.name + "/d" +
                                          sys_.coordinates[static_cast<std::size_t>(a)].get_name());
        }
      }
      set_.kernels.push_back(position);
      set_.kernels.push_back(jacobian);
    }
    if (derivation_.bundle) bundle_kernels();
    if (want("riemann_linearization")) set_.kernels.push_back(riemann_linearization());
    if (want("centroidal_momentum")) set_.kernels.push_back(centroidal_momentum());
    drop_identical_zeros();
    const bool prepared_named = only_.count("rhs_prepared") > 0 || only_.count("jacobian_prepared") > 0;
    if (only_.empty() || prepared_named) prepared_kernels(prepared_named);
    if (!want("rhs")) set_.rhs_pivots.clear();
    if (!only_.empty()) {
      std::vector<Kernel> kept;
      for (const Kernel& k : set_.kernels)
        if (only_.count(k.name)) kept.push_back(k);
      set_.kernels = kept;
    }
    return std::move(set_);
  }

 private:
  // A kernel is built when named, or, when none is named, if the registry builds it by default.
  bool want(const char* name) const { return only_.empty() ? kernel_spec(name).by_default : only_.count(name) > 0; }
  std::string name_of(int a) const { return sys_.velocities[static_cast<std::size_t>(a)].get_name(); }
  std::string state_name(int k) const {
    return k < n_ ? sys_.coordinates[static_cast<std::size_t>(k)].get_name()
                  : name_of(eq_.independent[static_cast<std::size_t>(k - n_)]);
  }
  // Forward mode through the rhs program: d(rhs)/d(argument k) for k < count, one tangent pass each.
  std::vector<std::vector<int>> forward_columns(Argument argument, int count) {
    std::vector<std::vector<int>> columns;
    for (int k = 0; k < count; ++k)
      columns.push_back(tangent(g_, rhs_.outputs, {{g_.input(argument, k), g_.constant(1)}}));
    return columns;
  }
  void equation_kernels();
  void jacobian_columns();
  void drop_identical_zeros();
  Kernel linearization();
  Kernel jacobian_by(const std::string& name);
  void bundle_kernels();
  Kernel riemann_linearization();
  Kernel centroidal_momentum();
  void prepared_kernels(bool named);

  const Model& model_;
  const Derivation& derivation_;
  const HamelEquations& eq_;
  const HamelSystem& sys_;
  const std::set<std::string>& only_;
  const DynamicsOptions dynamics_;
  const int n_;          ///< coordinates
  const std::size_t d_;  ///< independent quasi-velocities

  KernelSet set_;
  ExpressionGraph& g_ = set_.graph;
  std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves_;
  // Intermediate symbols become the nodes of their definitions when an expression first needs them
  // (definitions before their users); differentiation (the Jacobian) may add definitions to this copy.
  // Some definitions use symbols that get their nodes late (the acceleration symbols of a tree's recursion).
  Intermediates tape_;
  ProgramConverter node_of_;

  Kernel kinematics_ = registered("kinematics"), mass_ = registered("mass_matrix"), forcing_ = registered("forcing"),
         gamma_ = registered("hamel_coefficients"), rhs_, jacobian_ = registered("jacobian");
  std::unique_ptr<EquationsOfMotion> motion_;  ///< how rhs computes u_I' and the Jacobian its columns
  bool build_jacobian_ = false;
  std::vector<std::vector<int>> column_;  ///< column_[k][row] = d(x'_row)/dx_k
  /// How the jacobian kernel is printed when its columns' solve is one subroutine (jacobian row-major).
  std::shared_ptr<const Subroutine> column_calls_;
};

void KernelBuilder::equation_kernels() {
  for (int a = 0; a < n_; ++a) {
    kinematics_.outputs.push_back(node_of_(eq_.kinematics[static_cast<std::size_t>(a)]));
    kinematics_.output_names.push_back(sys_.coordinates[static_cast<std::size_t>(a)].get_name() + "_dot");
  }
  std::vector<std::vector<int>> M(d_, std::vector<int>(d_));
  for (std::size_t i = 0; i < d_; ++i)
    for (std::size_t j = 0; j < d_; ++j) {
      M[i][j] = node_of_(eq_.mass_matrix(static_cast<unsigned>(i), static_cast<unsigned>(j)));
      mass_.outputs.push_back(M[i][j]);
      mass_.output_names.push_back("M[" + name_of(eq_.independent[i]) + "][" + name_of(eq_.independent[j]) + "]");
    }
  for (std::size_t i = 0; i < d_; ++i) {
    forcing_.outputs.push_back(node_of_(eq_.forcing[i]));
    forcing_.output_names.push_back("f[" + name_of(eq_.independent[i]) + "]");
  }
  for (const HamelCoefficient& h : sys_.gamma) {
    gamma_.outputs.push_back(node_of_(h.value));
    gamma_.output_names.push_back("gamma^" + name_of(h.upper) + "_" + name_of(h.lower_a) + "," + name_of(h.lower_b));
  }

  motion_ = equations_of_motion(model_, derivation_, dynamics_, {g_, tape_, node_of_, leaves_}, M, forcing_.outputs);
  const EquationsOfMotion::Accelerations& accel = motion_->accelerations();
  rhs_ = registered("rhs", accel.how);
  rhs_.outputs = kinematics_.outputs;
  rhs_.output_names = kinematics_.output_names;
  set_.rhs_pivots = accel.pivots;
  for (std::size_t i = 0; i < d_; ++i) {
    rhs_.outputs.push_back(accel.values[i]);
    rhs_.output_names.push_back(name_of(eq_.independent[i]) + "_rate");
  }
}

// d(x')/dx for implicit integrators, as the equations of motion form it (emit/equations_of_motion.hpp).
void KernelBuilder::jacobian_columns() {
  EquationsOfMotion::Jacobian jacobian = motion_->jacobian(rhs_.outputs);
  column_ = std::move(jacobian.columns);
  column_calls_ = std::move(jacobian.calls);
  jacobian_.summary += jacobian.how;
}

// Every value the kernels compute that vanishes identically printed as 0 (emit/zero_test.hpp): derivatives by
// a coordinate the dynamics do not depend on, which the derivation forms from the structure (the convective terms
// of a cyclic coordinate, the Jacobian's column of a yaw angle or a wheel's rotation). One pass over all kernels,
// the pivots and what calls read, so that work they share stays one program.
void KernelBuilder::drop_identical_zeros() {
  std::vector<std::vector<int>*> lists{&set_.rhs_pivots};
  std::vector<std::shared_ptr<Subroutine>> subroutines(set_.kernels.size());
  for (std::size_t k = 0; k < set_.kernels.size(); ++k) {
    Kernel& kernel = set_.kernels[k];
    if (kernel_spec(kernel.name).residual) continue;
    lists.push_back(&kernel.outputs);
    if (!kernel.calls) continue;
    subroutines[k] = std::make_shared<Subroutine>(*kernel.calls);
    lists.push_back(&subroutines[k]->shared);
    for (Subroutine::Call& call : subroutines[k]->calls) lists.push_back(&call.arguments);
  }
  std::vector<int> all;
  for (const std::vector<int>* list : lists) all.insert(all.end(), list->begin(), list->end());
  const std::vector<int> kept = without_identical_zeros(g_, all);
  if (kept == all) return;
  std::size_t at = 0;
  for (std::vector<int>* list : lists)
    for (int& node : *list) node = kept[at++];
  for (std::size_t k = 0; k < set_.kernels.size(); ++k)
    if (subroutines[k]) set_.kernels[k].calls = subroutines[k];
}

// A = d(x')/dx and B = d(x')/d(in) along any state: A is the Jacobian's columns when they are built (for
// trees always: analytical), otherwise forward mode through the rhs program like B (one tangent pass per
// state or input component). Built only when asked for by name.
Kernel KernelBuilder::linearization() {
  Kernel linearization = registered("linearization");
  const int nx = static_cast<int>(rhs_.outputs.size());
  const int ni = static_cast<int>(model_.inputs.size());
  const std::vector<std::vector<int>> a_columns = column_.empty() ? forward_columns(Argument::state, nx) : column_;
  const std::vector<std::vector<int>> b_columns = forward_columns(Argument::input, ni);
  for (int row = 0; row < nx; ++row)
    for (int k = 0; k < nx; ++k) {
      linearization.outputs.push_back(a_columns[static_cast<std::size_t>(k)][static_cast<std::size_t>(row)]);
      linearization.output_names.push_back("A[" + rhs_.output_names[static_cast<std::size_t>(row)] + "][" +
                                           state_name(k) + "]");
    }
  for (int row = 0; row < nx; ++row)
    for (int k = 0; k < ni; ++k) {
      linearization.outputs.push_back(b_columns[static_cast<std::size_t>(k)][static_cast<std::size_t>(row)]);
      linearization.output_names.push_back("B[" + rhs_.output_names[static_cast<std::size_t>(row)] + "][" +
                                           model_.inputs[static_cast<std::size_t>(k)].get_name() + "]");
    }
  return linearization;
}

// d(x')/d(in) (input_jacobian) or d(x')/dp by the parameters not folded (parameter_jacobian), with the jacobian's
// machinery (EquationsOfMotion::jacobian_by); an InputError when the model has no such inputs or parameters.
Kernel KernelBuilder::jacobian_by(const std::string& name) {
  const bool inputs = name == "input_jacobian";
  std::vector<GiNaC::ex> by;
  std::vector<std::string> by_names;
  if (inputs) {
    for (const GiNaC::realsymbol& u : model_.inputs) by.push_back(u), by_names.push_back(u.get_name());
  } else {
    for (std::size_t i : symbolic_parameters(model_))
      by.push_back(model_.parameters[i].symbol), by_names.push_back(model_.parameters[i].symbol.get_name());
  }
  if (by.empty()) {
    const std::string what = model_.source_path + ": error: --kernels: kernel '" + name + "' differentiates rhs by ";
    if (inputs)
      throw InputError(what + "the run-time inputs, and '" + model_.name +
                       "' has none (key 'inputs'); expected a model with inputs, or --kernels without " + name);
    if (model_.parameters.empty())
      throw InputError(what + "the parameters, and '" + model_.name +
                       "' has none (key 'parameters'); expected a model with parameters, or --kernels without " + name);
    throw InputError(what + "the parameters that are not folded, and every parameter of '" + model_.name +
                     "' is folded (--fold); unfold some: --fold a,b folds only a and b, --fold none none of them");
  }
  const EquationsOfMotion::Jacobian columns = motion_->jacobian_by(by, rhs_.outputs);
  Kernel k = registered(name.c_str(), columns.how);
  for (std::size_t row = 0; row < rhs_.outputs.size(); ++row)
    for (std::size_t c = 0; c < by.size(); ++c) {
      k.outputs.push_back(columns.columns[c][row]);
      k.output_names.push_back("d" + rhs_.output_names[row] + "/d" + by_names[c]);
    }
  k.calls = columns.calls;
  return k;
}

void KernelBuilder::bundle_kernels() {
  const BundleGeometry& geo = *derivation_.bundle;
  const Bundle& b = *model_.bundle;
  const std::size_t m = b.group_velocity.size();
  const int n = static_cast<int>(model_.coordinates.size());  // shape coordinates (the state may also hold Γ)
  Kernel xi = registered("group_velocity");
  for (std::size_t a = 0; a < m; ++a) {
    xi.outputs.push_back(node_of_(derivation_.group_velocity[a]));
    xi.output_names.push_back(b.group_velocity[a].get_name());
  }
  set_.kernels.push_back(xi);
  // Kinematic trees: A = L⁻¹K solved in the kernel (unrolled LDLᵀ of the locked inertia), not symbolically;
  // placeholders (node 0) when neither kernel that uses it is built.
  const std::vector<std::vector<int>> solved =
      !geo.connection_derived && n > 0 && (want("connection") || want("shape_inertia"))
          ? solved_connection(g_, geo, node_of_)
          : std::vector<std::vector<int>>(m, std::vector<int>(static_cast<std::size_t>(n)));
  const auto connection_node = [&](std::size_t a, int I) {
    return geo.connection_derived ? node_of_(geo.connection(static_cast<unsigned>(a), static_cast<unsigned>(I)))
                                  : solved[a][static_cast<std::size_t>(I)];
  };
  if (n > 0) {
    Kernel conn = registered("connection");
    for (std::size_t a = 0; a < m; ++a)
      for (int I = 0; I < n; ++I) {
        conn.outputs.push_back(connection_node(a, I));
        conn.output_names.push_back("A[" + b.group_velocity[a].get_name() + "][" +
                                    sys_.coordinates[static_cast<std::size_t>(I)].get_name() + "]");
      }
    set_.kernels.push_back(conn);
  }
  if (geo.quadratic) {
    Kernel locked = registered("locked_inertia");
    for (std::size_t a = 0; a < m; ++a)
      for (std::size_t c = 0; c < m; ++c) {
        locked.outputs.push_back(node_of_(geo.L(static_cast<unsigned>(a), static_cast<unsigned>(c))));
        locked.output_names.push_back("L[" + b.group_velocity[a].get_name() + "][" + b.group_velocity[c].get_name() +
                                      "]");
      }
    set_.kernels.push_back(locked);
  }
  if (b.mechanical && n > 0 && want("shape_inertia")) {
    // The lower block of M^Ω = diag(L, S − AᵀLA) (MOmega); the upper block is locked_inertia.
    Kernel shape = registered("shape_inertia");
    for (int I = 0; I < n; ++I)
      for (int J = 0; J < n; ++J) {
        if (geo.connection_derived) {
          shape.outputs.push_back(node_of_(geo.shape_inertia(static_cast<unsigned>(I), static_cast<unsigned>(J))));
        } else if (J < I) {  // symmetric: the entry above the diagonal
          shape.outputs.push_back(shape.outputs[static_cast<std::size_t>(J * n + I)]);
        } else {  // S − KᵀA with A = L⁻¹K (= S − AᵀLA)
          int v = node_of_(geo.S(static_cast<unsigned>(I), static_cast<unsigned>(J)));
          for (std::size_t a = 0; a < m; ++a)
            v = g_.binary(Op::sub, v,
                          g_.binary(Op::mul, node_of_(geo.K(static_cast<unsigned>(a), static_cast<unsigned>(I))),
                                    solved[a][static_cast<std::size_t>(J)]));
          shape.outputs.push_back(v);
        }
        shape.output_names.push_back("M_shape[" + sys_.coordinates[static_cast<std::size_t>(I)].get_name() + "][" +
                                     sys_.coordinates[static_cast<std::size_t>(J)].get_name() + "]");
      }
    set_.kernels.push_back(shape);
  }
}

// The Riemannian view (derive/riemann.hpp), built only when asked for by name: it is defined only for
// unconstrained models in general coordinates with L = ½ g_ab q̇ᵃq̇ᵇ − V. Matrices in the coordinate basis
// ∂/∂qᵃ at the state's velocity q̇ = B(q) u_I (qadot); for A = I that is q̇ = u.
Kernel KernelBuilder::riemann_linearization() {
  const int n = n_;
  const RiemannGeometry riemann = derive_riemann(model_, tape_);
  for (int a = 0; a < n; ++a)
    leaves_[model_.rates[static_cast<std::size_t>(a)]] = node_of_(eq_.kinematics[static_cast<std::size_t>(a)]);
  Kernel linearization = registered("riemann_linearization");
  const auto name = [&](const char* label, int a, int b) {
    return std::string(label) + "[" + sys_.coordinates[static_cast<std::size_t>(a)].get_name() + "][" +
           sys_.coordinates[static_cast<std::size_t>(b)].get_name() + "]";
  };
  const std::pair<const char*, const GiNaC::matrix*> blocks[] = {
      {"g", &riemann.metric}, {"G", &riemann.connection_rate}, {"K", &riemann.stiffness}};
  std::vector<int> connection_rate;
  for (const auto& [label, m] : blocks)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        linearization.outputs.push_back(node_of_((*m)(static_cast<unsigned>(a), static_cast<unsigned>(b))));
        linearization.output_names.push_back(name(label, a, b));
        if (m == &riemann.connection_rate) connection_rate.push_back(linearization.outputs.back());
      }
  // Ġ along the motion, by forward mode through G's program with the state's tangent x' = (q̇, u̇_I) (the
  // rhs kernel's outputs): what the first-order form of the covariant equations needs
  // (docs/linearization.md).
  std::map<int, int> along_motion;
  for (std::size_t k = 0; k < rhs_.outputs.size(); ++k)
    along_motion[g_.input(Argument::state, static_cast<int>(k))] = rhs_.outputs[k];
  const std::vector<int> connection_rate_dot = tangent(g_, connection_rate, along_motion);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      linearization.outputs.push_back(connection_rate_dot[static_cast<std::size_t>(a * n + b)]);
      linearization.output_names.push_back(name("G_dot", a, b));
    }
  return linearization;
}

// The centroidal momentum of a tree (rbd/centroidal.hpp), built only when asked for by name: h_G, A_G = dh_G/du
// (forward mode on the state's velocity components: h_G is linear in u, so the columns are exact), and dA_G/dt u, the
// tangent of h_G along q' = kinematics with u held (dh_G/dt = A_G u' + dA_G/dt u).
Kernel KernelBuilder::centroidal_momentum() {
  if (!eq_.tree)
    throw InputError(model_.source_path +
                     ": error: kernel 'centroidal_momentum' applies to kinematic trees (key 'tree'; on a "
                     "floating base in the ep form); '" +
                     model_.name + "' is not one");
  const rbd::CentroidalMomentum c = rbd::centroidal_momentum(
      *eq_.tree, rbd::Namer<GiNaC::ex>([this](const GiNaC::ex& e) { return tape_.define(e); }));
  Kernel k = registered("centroidal_momentum");
  static const char* const component[6] = {"Lx", "Ly", "Lz", "px", "py", "pz"};
  std::vector<int> h;
  for (std::size_t r = 0; r < 6; ++r) h.push_back(node_of_(c.momentum[r]));
  for (std::size_t r = 0; r < 6; ++r) {
    k.outputs.push_back(h[r]);
    k.output_names.push_back(std::string("h_G[") + component[r] + "]");
  }
  std::vector<std::vector<int>> columns;
  for (std::size_t I = 0; I < d_; ++I)
    columns.push_back(tangent(g_, h, {{g_.input(Argument::state, n_ + static_cast<int>(I)), g_.constant(1)}}));
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t I = 0; I < d_; ++I) {
      k.outputs.push_back(columns[I][r]);
      k.output_names.push_back(std::string("A_G[") + component[r] + "][" + name_of(eq_.independent[I]) + "]");
    }
  std::map<int, int> along;
  for (int a = 0; a < n_; ++a) along[g_.input(Argument::state, a)] = kinematics_.outputs[static_cast<std::size_t>(a)];
  const std::vector<int> rate = tangent(g_, h, along);
  for (std::size_t r = 0; r < 6; ++r) {
    k.outputs.push_back(rate[r]);
    k.output_names.push_back(std::string("dA_G/dt u[") + component[r] + "]");
  }
  return k;
}

// Prepared parameters: the parameter-only work of rhs and jacobian hoisted into prepare (KernelSet::Prepared).
void KernelBuilder::prepared_kernels(bool named) {
  // The kernels as they are printed (drop_identical_zeros rewrote them in set_.kernels).
  const Kernel& rhs = set_.get("rhs");
  const Kernel& jacobian = set_.get("jacobian");
  std::vector<const Kernel*> originals;
  if (want("rhs") || only_.count("rhs_prepared")) originals.push_back(&rhs);
  if (build_jacobian_ && !jacobian.outputs.empty()) originals.push_back(&jacobian);
  // Parameter-only factors and divisors gathered, so that their products and reciprocals are prepared too;
  // or, where it leaves fewer operations per call, polynomial outputs as Σ coefficient · monomial.
  std::vector<std::vector<int>> rewritten;
  std::vector<int> all;
  for (const Kernel* k : originals) {
    std::vector<int> grouped = group_invariants(g_, k->outputs);
    std::vector<int> polynomial = polynomial_form(g_, k->outputs);
    const bool fewer = run_time_operations(g_, polynomial).total() < run_time_operations(g_, grouped).total();
    rewritten.push_back(fewer ? std::move(polynomial) : std::move(grouped));
    all.insert(all.end(), rewritten.back().begin(), rewritten.back().end());
  }
  const std::vector<int> frontier = parameter_frontier(g_, all);
  KernelSet::Prepared prepared;
  prepared.rhs = g_.count(g_.schedule(rhs.outputs));
  prepared.once = g_.count(g_.schedule(frontier));
  if (!rewritten.empty() && originals.front() == &rhs)
    prepared.rhs_prepared = run_time_operations(g_, rewritten.front());
  if (!named && (rewritten.empty() || originals.front() != &rhs ||
                 prepared.rhs_prepared.total() > kPreparedShare * prepared.rhs.total()))
    return;
  const int n_p = static_cast<int>(model_.parameters.size());
  prepared.prepare = {
      "prepare_parameters", "P = (p, then the parameter-only values of rhs and jacobian)", {}, {}, nullptr};
  for (int k = 0; k < n_p; ++k) {
    prepared.prepare.outputs.push_back(g_.input(Argument::parameter, k));
    prepared.prepare.output_names.push_back(model_.parameters[static_cast<std::size_t>(k)].symbol.get_name());
  }
  std::map<int, int> replace;
  for (std::size_t j = 0; j < frontier.size(); ++j) {
    prepared.prepare.outputs.push_back(frontier[j]);
    prepared.prepare.output_names.push_back("prepared " + std::to_string(j));
    replace[frontier[j]] = g_.input(Argument::parameter, n_p + static_cast<int>(j));
  }
  for (std::size_t i = 0; i < originals.size(); ++i) {
    Kernel variant = *originals[i];
    const KernelSpec& spec = kernel_spec(originals[i]->name + "_prepared");
    variant.name = spec.name;
    variant.summary = spec.summary;
    variant.outputs = substitute(g_, rewritten[i], replace);
    variant.calls.reset();  // the subroutine's calls read the original program
    prepared.kernels.push_back(variant);
  }
  set_.prepared = prepared;
}

}  // namespace

KernelSet build_kernels(const Model& model, const Derivation& derivation, const std::set<std::string>& only,
                        const DynamicsOptions& dynamics) {
  return KernelBuilder(model, derivation, only, dynamics).build();
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
           (std::isinf(g.node(node).value)   ? "infinity"
            : std::isnan(g.node(node).value) ? "NaN"
                                             : "0");
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
