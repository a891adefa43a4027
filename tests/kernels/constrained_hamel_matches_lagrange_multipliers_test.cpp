// The emitted constrained Hamel equations (BHconstr) with (qadot) against an independent formulation of
// the same mechanics: the Euler–Lagrange equations in the coordinates q with Lagrange multipliers for the
// Pfaffian constraints A_α(q) q̇ = 0, differentiated in this test with GiNaC from the model file as loaded
// (A, L, forces) and solved as a KKT system with Eigen. Nothing of the generator's derivation is used.
//
//   [ M_q   −A_αᵀ ] [ q̈ ]   [ Q − h      ]      M_q = ∂²L/∂q̇∂q̇,
//   [ A_α    0    ] [ λ  ] = [ −Ȧ_α q̇   ],     h   = ∂²L/∂q̇∂q q̇ + ∂²L/∂q̇∂t − ∂L/∂q,
//                                               Ȧ_α q̇ = Σ_b Σ_c ∂A_αb/∂q_c q̇_c q̇_b.
//
// (a) At random consistent states (q̇ = B_I u_I with B = A(q)⁻¹ computed numerically) the emitted rhs
//     gives u̇_I = d/dt(A_I q̇) = A_I q̈ + Ȧ_I q̇ of the KKT solution (relative 1e-10), and the emitted
//     kinematics give q̇.
// (b) The emitted rhs (state (q, u_I)) and the KKT system (state (q, q̇)), both integrated with dopri5 at
//     rtol = atol = 1e-11, end at the same q(T), and the KKT trajectory keeps A_α q̇ ≈ 0.
// (c) `hamel linearize`'s A = dx'/dx and B = dx'/d(in) (the `linearization` kernel: forward mode through the
//     rhs program, derived with every parameter symbolic) against central differences of the reduced KKT flow
//     F(q, u_I) = (B_I u_I, A_I q̈ + Ȧ_I q̇), for holonomic and nonholonomic models; a steady circular
//     motion of Routh's disk found by `linearize --steady` is a relative equilibrium of the KKT flow; and for
//     bundle models (no Lagrange-multiplier form here) A against central differences of the compiled emitted
//     rhs, whose dynamics the bundle tests check against independent references: this checks the forward-mode
//     differentiation and the state layout.
#include "compiled_models.hpp"

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/linearization.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <ostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using hamel::test::CompiledModel;

// ---------------------------------------------------------------------------------------------------
// A small tree evaluator for GiNaC expressions, so that the reference system can be integrated in
// reasonable time (GiNaC's subs + evalf costs tens of microseconds per expression).
using VarIndex = std::map<GiNaC::ex, int, GiNaC::ex_is_less>;

class NumericExpr {
 public:
  NumericExpr() = default;
  NumericExpr(const GiNaC::ex& e, const VarIndex& vars) { root_ = build(e, vars); }
  double operator()(const double* v) const { return eval(root_, v); }

 private:
  enum class Op { constant, variable, add, mul, int_pow, pow, sin, cos, tan, exp, log, abs, atan };
  struct Node {
    Op op;
    double value = 0;
    int index = 0;  // variable index or integer exponent
    std::vector<int> args;
  };
  std::vector<Node> nodes_;
  int root_ = -1;

  int push(Node n) {
    nodes_.push_back(std::move(n));
    return static_cast<int>(nodes_.size()) - 1;
  }

  int build(const GiNaC::ex& e, const VarIndex& vars) {
    using namespace GiNaC;
    if (is_a<numeric>(e)) {
      const numeric& n = ex_to<numeric>(e);
      if (!n.is_real()) throw std::runtime_error("complex number in expression");
      return push({Op::constant, n.to_double(), 0, {}});
    }
    if (is_a<symbol>(e)) {
      auto it = vars.find(e);
      if (it == vars.end()) throw std::runtime_error("unknown symbol in expression: " + ex_to<symbol>(e).get_name());
      return push({Op::variable, 0, it->second, {}});
    }
    if (is_a<add>(e) || is_a<mul>(e)) {
      std::vector<int> args;
      for (std::size_t k = 0; k < e.nops(); ++k) args.push_back(build(e.op(k), vars));
      return push({is_a<add>(e) ? Op::add : Op::mul, 0, 0, args});
    }
    if (is_a<power>(e)) {
      const int base = build(e.op(0), vars);
      if (is_a<numeric>(e.op(1)) && ex_to<numeric>(e.op(1)).is_integer())
        return push({Op::int_pow, 0, ex_to<numeric>(e.op(1)).to_int(), {base}});
      const int exponent = build(e.op(1), vars);
      return push({Op::pow, 0, 0, {base, exponent}});
    }
    const std::pair<Op, bool> functions[] = {
        {Op::sin, is_ex_the_function(e, sin)},  {Op::cos, is_ex_the_function(e, cos)},
        {Op::tan, is_ex_the_function(e, tan)},  {Op::exp, is_ex_the_function(e, exp)},
        {Op::log, is_ex_the_function(e, log)},  {Op::abs, is_ex_the_function(e, abs)},
        {Op::atan, is_ex_the_function(e, atan)}};
    for (const auto& [op, match] : functions)
      if (match) return push({op, 0, 0, {build(e.op(0), vars)}});
    std::ostringstream s;
    s << "unsupported expression " << e;
    throw std::runtime_error(s.str());
  }

  double eval(int i, const double* v) const {
    const Node& n = nodes_[static_cast<std::size_t>(i)];
    switch (n.op) {
      case Op::constant:
        return n.value;
      case Op::variable:
        return v[n.index];
      case Op::add: {
        double s = 0;
        for (int a : n.args) s += eval(a, v);
        return s;
      }
      case Op::mul: {
        double s = 1;
        for (int a : n.args) s *= eval(a, v);
        return s;
      }
      case Op::int_pow: {
        const double b = eval(n.args[0], v);
        double r = 1;
        for (int k = 0; k < std::abs(n.index); ++k) r *= b;
        return n.index < 0 ? 1.0 / r : r;
      }
      case Op::pow:
        return std::pow(eval(n.args[0], v), eval(n.args[1], v));
      case Op::sin:
        return std::sin(eval(n.args[0], v));
      case Op::cos:
        return std::cos(eval(n.args[0], v));
      case Op::tan:
        return std::tan(eval(n.args[0], v));
      case Op::exp:
        return std::exp(eval(n.args[0], v));
      case Op::log:
        return std::log(eval(n.args[0], v));
      case Op::abs:
        return std::fabs(eval(n.args[0], v));
      case Op::atan:
        return std::atan(eval(n.args[0], v));
    }
    return NAN;
  }
};

// ---------------------------------------------------------------------------------------------------
// The reference: Euler–Lagrange equations with multipliers, built from the model file only.
class LagrangeMultiplierSystem {
 public:
  explicit LagrangeMultiplierSystem(const hamel::Model& model)
      : n_(static_cast<int>(model.n())), constrained_(model.constrained), independent_(model.independent()) {
    using GiNaC::ex;
    // Variable layout: t, q, q̇, parameters, inputs.
    VarIndex vars;
    int next = 0;
    vars[model.time] = next++;
    for (const auto& s : model.coordinates) vars[s] = next++;
    for (const auto& s : model.rates) vars[s] = next++;
    for (const auto& p : model.parameters) vars[p.symbol] = next++;
    for (const auto& s : model.inputs) vars[s] = next++;
    n_parameters_ = static_cast<int>(model.parameters.size());
    n_inputs_ = static_cast<int>(model.inputs.size());
    values_.assign(static_cast<std::size_t>(next), 0.0);

    // Quasi-velocity names in L (or in the forces) stand for A(q) q̇.
    GiNaC::exmap u_of_qdot;
    for (int k = 0; k < n_; ++k) {
      ex row = 0;
      for (int b = 0; b < n_; ++b) row += model.A(static_cast<unsigned>(k), static_cast<unsigned>(b)) * rate(model, b);
      u_of_qdot[model.quasi_velocities[static_cast<std::size_t>(k)]] = row;
    }
    const ex L = model.lagrangian.subs(u_of_qdot);

    for (int a = 0; a < n_; ++a) {
      const ex dL_dqdot = L.diff(rate(model, a));
      for (int b = 0; b < n_; ++b) M_.emplace_back(dL_dqdot.diff(rate(model, b)), vars);
      ex h = dL_dqdot.diff(model.time) - L.diff(coordinate(model, a));
      for (int c = 0; c < n_; ++c) h += dL_dqdot.diff(coordinate(model, c)) * rate(model, c);
      h_.emplace_back(h, vars);
      Q_.emplace_back(model.forces[static_cast<std::size_t>(a)].subs(u_of_qdot), vars);
    }
    for (int k = 0; k < n_; ++k) {
      ex adot_qdot = 0;
      for (int b = 0; b < n_; ++b) {
        const ex Akb = model.A(static_cast<unsigned>(k), static_cast<unsigned>(b));
        A_.emplace_back(Akb, vars);
        for (int c = 0; c < n_; ++c) adot_qdot += Akb.diff(coordinate(model, c)) * rate(model, c) * rate(model, b);
      }
      Adot_qdot_.emplace_back(adot_qdot, vars);
    }
  }

  void set_parameters(const std::vector<double>& p, const std::vector<double>& in) {
    for (int k = 0; k < n_parameters_; ++k)
      values_[static_cast<std::size_t>(1 + 2 * n_ + k)] = p[static_cast<std::size_t>(k)];
    for (int k = 0; k < n_inputs_; ++k)
      values_[static_cast<std::size_t>(1 + 2 * n_ + n_parameters_ + k)] = in[static_cast<std::size_t>(k)];
  }

  struct Terms {
    Eigen::MatrixXd M, A;
    Eigen::VectorXd Q_minus_h, Adot_qdot;
  };

  Terms evaluate(double t, const double* q, const double* qdot) {
    values_[0] = t;
    for (int a = 0; a < n_; ++a) {
      values_[static_cast<std::size_t>(1 + a)] = q[a];
      values_[static_cast<std::size_t>(1 + n_ + a)] = qdot[a];
    }
    const double* v = values_.data();
    Terms r{Eigen::MatrixXd(n_, n_), Eigen::MatrixXd(n_, n_), Eigen::VectorXd(n_), Eigen::VectorXd(n_)};
    for (int a = 0; a < n_; ++a) {
      for (int b = 0; b < n_; ++b) {
        r.M(a, b) = M_[static_cast<std::size_t>(a * n_ + b)](v);
        r.A(a, b) = A_[static_cast<std::size_t>(a * n_ + b)](v);
      }
      r.Q_minus_h(a) = Q_[static_cast<std::size_t>(a)](v) - h_[static_cast<std::size_t>(a)](v);
      r.Adot_qdot(a) = Adot_qdot_[static_cast<std::size_t>(a)](v);
    }
    return r;
  }

  /// q̈ from the KKT system.
  Eigen::VectorXd acceleration(const Terms& s) const {
    const int m = static_cast<int>(constrained_.size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n_ + m, n_ + m);
    Eigen::VectorXd rhs(n_ + m);
    K.topLeftCorner(n_, n_) = s.M;
    rhs.head(n_) = s.Q_minus_h;
    for (int k = 0; k < m; ++k) {
      const int alpha = constrained_[static_cast<std::size_t>(k)];
      K.block(0, n_ + k, n_, 1) = -s.A.row(alpha).transpose();
      K.block(n_ + k, 0, 1, n_) = s.A.row(alpha);
      rhs(n_ + k) = -s.Adot_qdot(alpha);
    }
    return K.fullPivLu().solve(rhs).head(n_);
  }

  /// The KKT system as a first-order ODE in (q, q̇).
  void rhs(double t, const double* x, double* xdot) {
    const Terms s = evaluate(t, x, x + n_);
    const Eigen::VectorXd qddot = acceleration(s);
    for (int a = 0; a < n_; ++a) {
      xdot[a] = x[n_ + a];
      xdot[n_ + a] = qddot(a);
    }
  }

  /// q̇ = Σ_I B_I u_I with B = A(q)⁻¹ (numeric), u_α = 0.
  Eigen::VectorXd qdot_from_u(const double* q, const double* u_independent) {
    std::vector<double> zero(static_cast<std::size_t>(n_), 0.0);
    const Terms s = evaluate(0.0, q, zero.data());
    const Eigen::MatrixXd B = s.A.inverse();
    Eigen::VectorXd qdot = Eigen::VectorXd::Zero(n_);
    for (std::size_t i = 0; i < independent_.size(); ++i) qdot += B.col(independent_[i]) * u_independent[i];
    return qdot;
  }

  const std::vector<int>& constrained() const { return constrained_; }
  const std::vector<int>& independent() const { return independent_; }

 private:
  static const GiNaC::realsymbol& rate(const hamel::Model& m, int a) { return m.rates[static_cast<std::size_t>(a)]; }
  static const GiNaC::realsymbol& coordinate(const hamel::Model& m, int a) {
    return m.coordinates[static_cast<std::size_t>(a)];
  }

  int n_, n_parameters_ = 0, n_inputs_ = 0;
  std::vector<int> constrained_, independent_;
  std::vector<NumericExpr> M_, h_, Q_, A_, Adot_qdot_;
  std::vector<double> values_;
};

double max_abs(const Eigen::VectorXd& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

// ---------------------------------------------------------------------------------------------------
struct Scene {
  std::string model;
  std::vector<double> q0, u0, inputs;
  double t_end;
};

/// Test names and failure messages print the scene's model, not the struct's bytes.
void PrintTo(const Scene& s, std::ostream* os) { *os << s.model; }

class ConstrainedHamel : public ::testing::TestWithParam<Scene> {};

TEST_P(ConstrainedHamel, AccelerationsMatchKktAtRandomStates) {
  const CompiledModel& cm = hamel::test::compiled_model(GetParam().model);
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  LagrangeMultiplierSystem ref(model);
  const int n = cm.n_coordinates, m = cm.n_independent;
  ASSERT_EQ(static_cast<std::size_t>(n), model.n());
  ASSERT_EQ(static_cast<std::size_t>(m), ref.independent().size());
  ASSERT_EQ(static_cast<std::size_t>(cm.n_constraints), ref.constrained().size());
  ASSERT_GT(cm.n_constraints, 0);

  std::mt19937 rng(20230732);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst_accel = 0, worst_kin = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const double t = uniform(rng);
    std::vector<double> x(static_cast<std::size_t>(n + m));
    std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
    std::vector<double> in(static_cast<std::size_t>(std::max(cm.n_inputs, 1)));
    for (double& v : x) v = uniform(rng);
    for (double& v : p) v *= 1.0 + 0.1 * uniform(rng);
    for (double& v : in) v = uniform(rng);
    ref.set_parameters(p, in);

    const Eigen::VectorXd qdot = ref.qdot_from_u(x.data(), x.data() + n);
    const LagrangeMultiplierSystem::Terms s = ref.evaluate(t, x.data(), qdot.data());
    for (int alpha : ref.constrained()) ASSERT_NEAR(s.A.row(alpha).dot(qdot), 0.0, 1e-13 * (1 + max_abs(qdot)));
    const Eigen::VectorXd qddot = ref.acceleration(s);

    std::vector<double> kin(static_cast<std::size_t>(n)), out(static_cast<std::size_t>(n + m));
    cm.kinematics(t, x.data(), p.data(), in.data(), kin.data());
    cm.rhs(t, x.data(), p.data(), in.data(), out.data());

    const double qdot_scale = std::max(1.0, max_abs(qdot));
    for (int a = 0; a < n; ++a) {
      EXPECT_NEAR(kin[static_cast<std::size_t>(a)], qdot(a), 1e-12 * qdot_scale)
          << cm.name << " kinematics q_dot[" << a << "]";
      EXPECT_NEAR(out[static_cast<std::size_t>(a)], qdot(a), 1e-12 * qdot_scale)
          << cm.name << " rhs q_dot[" << a << "]";
      worst_kin = std::max(worst_kin, std::fabs(kin[static_cast<std::size_t>(a)] - qdot(a)) / qdot_scale);
    }

    Eigen::VectorXd udot_ref(m);
    for (int i = 0; i < m; ++i) {
      const int I = ref.independent()[static_cast<std::size_t>(i)];
      udot_ref(i) = s.A.row(I).dot(qddot) + s.Adot_qdot(I);
    }
    // The scale of the terms that cancel in u̇_ref: |A_I| |q̈| and |Ȧ_I q̇|.
    const double scale = std::max({1.0, max_abs(udot_ref), max_abs(qddot), max_abs(s.Adot_qdot)});
    for (int i = 0; i < m; ++i) {
      const double emitted = out[static_cast<std::size_t>(n + i)];
      EXPECT_NEAR(emitted, udot_ref(i), 1e-10 * scale)
          << cm.name << " u_dot["
          << model.quasi_velocities[static_cast<std::size_t>(ref.independent()[static_cast<std::size_t>(i)])]
          << "] at trial " << trial;
      worst_accel = std::max(worst_accel, std::fabs(emitted - udot_ref(i)) / scale);
    }
  }
  std::printf("[measured] %s: max relative |u_dot - u_dot_KKT| = %.3g, max relative |q_dot - B_I u_I| = %.3g\n",
              cm.name.c_str(), worst_accel, worst_kin);
}

TEST_P(ConstrainedHamel, TrajectoriesMatchKkt) {
  const Scene& scene = GetParam();
  const CompiledModel& cm = hamel::test::compiled_model(scene.model);
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  LagrangeMultiplierSystem ref(model);
  const int n = cm.n_coordinates, m = cm.n_independent;
  ASSERT_EQ(scene.q0.size(), static_cast<std::size_t>(n));
  ASSERT_EQ(scene.u0.size(), static_cast<std::size_t>(m));
  ASSERT_EQ(scene.inputs.size(), static_cast<std::size_t>(cm.n_inputs));

  const std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
  std::vector<double> in = scene.inputs;
  in.resize(std::max<std::size_t>(in.size(), 1), 0.0);
  ref.set_parameters(p, in);

  hamel::runtime::Dopri5Options opt;
  opt.rtol = 1e-11;
  opt.atol = 1e-11;

  // Emitted Hamel equations, state (q, u_I).
  std::vector<double> x0 = scene.q0;
  x0.insert(x0.end(), scene.u0.begin(), scene.u0.end());
  const auto hamel_rhs = [&](double t, const double* x, double* xdot) { cm.rhs(t, x, p.data(), in.data(), xdot); };
  const auto hamel_result =
      hamel::runtime::integrate_dopri5(hamel_rhs, x0, 0.0, scene.t_end, opt, 0.0, hamel::runtime::NoObserver{});
  ASSERT_EQ(hamel_result.status, hamel::runtime::Status::ok);

  // KKT system, state (q, q̇); observe the constraint A_α q̇ and how far q moves.
  const Eigen::VectorXd qdot0 = ref.qdot_from_u(scene.q0.data(), scene.u0.data());
  std::vector<double> y0 = scene.q0;
  for (int a = 0; a < n; ++a) y0.push_back(qdot0(a));
  double worst_constraint = 0, qdot_scale = 1;
  const auto kkt_rhs = [&](double t, const double* y, double* ydot) { ref.rhs(t, y, ydot); };
  const auto observe = [&](double t, const double* y) {
    const LagrangeMultiplierSystem::Terms s = ref.evaluate(t, y, y + n);
    const Eigen::Map<const Eigen::VectorXd> qdot(y + n, n);
    qdot_scale = std::max(qdot_scale, max_abs(qdot));
    for (int alpha : ref.constrained())
      worst_constraint = std::max(worst_constraint, std::fabs(s.A.row(alpha).dot(qdot)));
  };
  const auto kkt_result = hamel::runtime::integrate_dopri5(kkt_rhs, y0, 0.0, scene.t_end, opt, 0.01, observe);
  ASSERT_EQ(kkt_result.status, hamel::runtime::Status::ok);

  // q(T): absolute 1e-8, relative to the size of the motion for coordinates that grow.
  double q_scale = 1;
  for (int a = 0; a < n; ++a) q_scale = std::max(q_scale, std::fabs(kkt_result.x[static_cast<std::size_t>(a)]));
  double worst_q = 0;
  for (int a = 0; a < n; ++a) {
    const double diff =
        std::fabs(hamel_result.x[static_cast<std::size_t>(a)] - kkt_result.x[static_cast<std::size_t>(a)]);
    EXPECT_LE(diff, 1e-8 * q_scale) << scene.model << " q[" << a << "](T): Hamel "
                                    << hamel_result.x[static_cast<std::size_t>(a)] << ", KKT "
                                    << kkt_result.x[static_cast<std::size_t>(a)];
    worst_q = std::max(worst_q, diff);
  }
  // u_I(T) = A_I(q(T)) q̇(T) of the KKT trajectory against the Hamel state.
  const LagrangeMultiplierSystem::Terms sT = ref.evaluate(scene.t_end, kkt_result.x.data(), kkt_result.x.data() + n);
  const Eigen::Map<const Eigen::VectorXd> qdotT(kkt_result.x.data() + n, n);
  double worst_u = 0, u_scale = 1;
  for (int i = 0; i < m; ++i) u_scale = std::max(u_scale, std::fabs(hamel_result.x[static_cast<std::size_t>(n + i)]));
  for (int i = 0; i < m; ++i) {
    const double u_kkt = sT.A.row(ref.independent()[static_cast<std::size_t>(i)]).dot(qdotT);
    const double diff = std::fabs(hamel_result.x[static_cast<std::size_t>(n + i)] - u_kkt);
    EXPECT_LE(diff, 1e-8 * u_scale) << scene.model << " u_I[" << i << "](T)";
    worst_u = std::max(worst_u, diff);
  }
  EXPECT_LE(worst_constraint, 1e-8 * qdot_scale) << scene.model << " constraint drift of the KKT trajectory";

  // The scene must actually move, or the comparison proves little.
  double travelled = 0;
  for (int a = 0; a < n; ++a)
    travelled = std::max(travelled,
                         std::fabs(kkt_result.x[static_cast<std::size_t>(a)] - scene.q0[static_cast<std::size_t>(a)]));
  EXPECT_GT(travelled, 0.5) << scene.model;

  std::printf(
      "[measured] %s over %.1f s: max |q_Hamel - q_KKT|(T) = %.3g (q scale %.3g), max |u_I diff|(T) = %.3g, "
      "max |A_alpha q_dot| on KKT trajectory = %.3g, steps Hamel %ld / KKT %ld\n",
      scene.model.c_str(), scene.t_end, worst_q, q_scale, worst_u, worst_constraint, hamel_result.stats.steps,
      kkt_result.stats.steps);
}

class Linearization : public ::testing::TestWithParam<std::string> {};

TEST_P(Linearization, MatchesCentralDifferencesOfKkt) {
  const hamel::Model model = hamel::load_model(hamel::test::source_path("models/" + GetParam() + ".yaml"));
  const hamel::Derivation derivation = hamel::derive(model, {});
  const hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  const int n = static_cast<int>(model.n()), m = static_cast<int>(model.independent().size());
  const int ni = static_cast<int>(model.inputs.size());
  const hamel::Linearizer linearizer(kernels, n + m, ni);
  // The reference reads the model's definitions (bodies: poses as intermediates) inlined.
  hamel::Model flat = model;
  flat.lagrangian = model.definitions.inline_all(model.lagrangian);
  for (GiNaC::ex& f : flat.forces) f = model.definitions.inline_all(f);
  for (unsigned i = 0; i < flat.A.rows(); ++i)
    for (unsigned j = 0; j < flat.A.cols(); ++j) flat.A(i, j) = model.definitions.inline_all(flat.A(i, j));
  LagrangeMultiplierSystem ref(flat);
  const auto flow = [&](double t, const std::vector<double>& x) {
    const Eigen::VectorXd qdot = ref.qdot_from_u(x.data(), x.data() + n);
    const LagrangeMultiplierSystem::Terms s = ref.evaluate(t, x.data(), qdot.data());
    const Eigen::VectorXd qddot = ref.acceleration(s);
    Eigen::VectorXd out(n + m);
    out.head(n) = qdot;
    for (int i = 0; i < m; ++i) {
      const int I = ref.independent()[static_cast<std::size_t>(i)];
      out(n + i) = s.A.row(I).dot(qddot) + s.Adot_qdot(I);
    }
    return out;
  };
  std::mt19937 rng(4711);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const double t = uniform(rng);
    std::vector<double> x(static_cast<std::size_t>(n + m)), p, in(static_cast<std::size_t>(ni));
    for (double& v : x) v = uniform(rng);
    for (const hamel::Parameter& par : model.parameters) p.push_back(par.default_value * (1.0 + 0.1 * uniform(rng)));
    for (double& v : in) v = uniform(rng);
    ref.set_parameters(p, in);
    const hamel::LinearSystem s = linearizer.at(t, x, p, in);
    const Eigen::VectorXd f0 = flow(t, x);
    double scale = 1;
    for (int k = 0; k < n + m; ++k) scale = std::max(scale, std::fabs(f0(k)));
    for (int k = 0; k < n + m + ni; ++k) {
      // Central differences, h ~ 1e-5: truncation ~ h^2, rounding ~ 1e-16 / h.
      const double h = 1e-5;
      std::vector<double> xp = x, xm = x, inp = in, inm = in;
      if (k < n + m) {
        xp[static_cast<std::size_t>(k)] += h, xm[static_cast<std::size_t>(k)] -= h;
      } else {
        inp[static_cast<std::size_t>(k - n - m)] += h, inm[static_cast<std::size_t>(k - n - m)] -= h;
        ref.set_parameters(p, inp);
      }
      const Eigen::VectorXd fp = flow(t, xp);
      if (k >= n + m) ref.set_parameters(p, inm);
      const Eigen::VectorXd fm = flow(t, xm);
      ref.set_parameters(p, in);
      for (int row = 0; row < n + m; ++row) {
        const double reference = (fp(row) - fm(row)) / (2 * h);
        const double derived = k < n + m ? s.a(row, k) : s.B[static_cast<std::size_t>(row * ni + (k - n - m))];
        const double tolerance = 1e-7 * std::max(scale, std::fabs(reference));
        EXPECT_NEAR(derived, reference, tolerance)
            << GetParam() << ": d x'[" << row << "]/d " << k << " at trial " << trial;
        worst = std::max(worst, std::fabs(derived - reference) / std::max(scale, std::fabs(reference)));
      }
    }
    for (int row = 0; row < n + m; ++row)
      EXPECT_NEAR(s.residual[static_cast<std::size_t>(row)], f0(row), 1e-10 * scale)
          << GetParam() << " x'[" << row << "]";
  }
  std::printf("[measured] %s: linearization against central differences of the KKT flow: max relative %.3g\n",
              GetParam().c_str(), worst);
}

TEST(LinearizationSteady, RouthDiskCircleIsARelativeEquilibriumOfTheKktFlow) {
  const hamel::Model model = hamel::load_model(hamel::test::source_path("models/rolling_disk_routh.yaml"));
  const hamel::Derivation derivation = hamel::derive(model, {});
  const hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  const hamel::Linearizer linearizer(kernels, 8, 0);
  std::vector<double> p;
  for (const hamel::Parameter& par : model.parameters) p.push_back(par.default_value);
  // State (x, y, psi, theta, phi, w_psi, w_theta, w_phi): leaning 0.3 rad, spinning at 20 rad/s (held), a
  // guess of the precession; x, y, psi and phi advance.
  const auto linearize = [&](const std::vector<double>& x) { return linearizer.at(0.0, x, p, {}); };
  const hamel::SteadyResult r =
      hamel::find_steady_motion(linearize, {0, 0, 0, 0.3, 0, 1.0, 0, 20.0}, {3, 5, 6}, {0, 1, 2, 4});
  EXPECT_GT(std::fabs(r.x[3]), 0.1) << "Newton fell back to upright rolling";
  EXPECT_GT(std::fabs(r.x[5]), 1e-3) << "no precession";
  hamel::Model flat = model;
  flat.lagrangian = model.definitions.inline_all(model.lagrangian);
  LagrangeMultiplierSystem ref(flat);
  ref.set_parameters(p, {});
  const Eigen::VectorXd qdot = ref.qdot_from_u(r.x.data(), r.x.data() + 5);
  const LagrangeMultiplierSystem::Terms s = ref.evaluate(0.0, r.x.data(), qdot.data());
  const Eigen::VectorXd qddot = ref.acceleration(s);
  EXPECT_NEAR(qdot(3), 0.0, 1e-10);  // the lean stays
  for (int i = 0; i < 3; ++i) {
    const int I = ref.independent()[static_cast<std::size_t>(i)];
    EXPECT_NEAR(s.A.row(I).dot(qddot) + s.Adot_qdot(I), 0.0, 1e-9) << "u_dot[" << I << "]";
  }
  // Closed form: the lean equation of Routh's disk at constant lean Θ, precession Ω = ψ̇ and spin s = φ̇ (Euler–
  // Lagrange with the rolling multipliers eliminated, done by hand/SymPy for this chart, Rz(ψ) Rx(θ) Ry(φ)):
  //   (C − A + m r²) Ω² sin 2Θ + 2 (C + m r²) Ω s cos Θ + 2 g m r sin Θ = 0.
  const double m = p[0], rr = p[1], A = p[2], C = p[3], g = p[4];
  ASSERT_EQ(model.parameters[4].symbol.get_name(), "g");
  const double Theta = r.x[3], Omega = r.x[5], spin = r.x[7];
  const double lean_balance = (C - A + m * rr * rr) * Omega * Omega * std::sin(2 * Theta) +
                              2 * (C + m * rr * rr) * Omega * spin * std::cos(Theta) + 2 * g * m * rr * std::sin(Theta);
  EXPECT_NEAR(lean_balance, 0.0, 1e-10 * (2 * g * m * rr));
  std::printf("[measured] Routh's disk steady circle: lean %.6f rad, precession %.6f rad/s at spin 20 rad/s\n", r.x[3],
              r.x[5]);
}

class BundleLinearization : public ::testing::TestWithParam<std::string> {};

TEST_P(BundleLinearization, MatchesCentralDifferencesOfTheEmittedRhs) {
  const CompiledModel& cm = hamel::test::compiled_model(GetParam());
  hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  if (cm.fold == "all") {
    std::map<std::string, double> values;
    for (const hamel::Parameter& par : model.parameters) values[par.symbol.get_name()] = par.default_value;
    model = hamel::fold_parameters(model, values);
  }
  const hamel::Derivation derivation = hamel::derive(model, {});
  const hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  const int nx = cm.n_coordinates + cm.n_independent;
  const hamel::Linearizer linearizer(kernels, nx, cm.n_inputs);
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
  double worst = 0;
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> x(static_cast<std::size_t>(nx)), in(static_cast<std::size_t>(cm.n_inputs));
    for (double& v : x) v = uniform(rng);
    for (double& v : in) v = uniform(rng);
    const hamel::LinearSystem s = linearizer.at(0.0, x, p, in);
    std::vector<double> fp(static_cast<std::size_t>(nx)), fm(static_cast<std::size_t>(nx));
    for (int k = 0; k < nx; ++k) {
      const double h = 1e-5;
      std::vector<double> xp = x, xm = x;
      xp[static_cast<std::size_t>(k)] += h, xm[static_cast<std::size_t>(k)] -= h;
      cm.rhs(0.0, xp.data(), p.data(), in.empty() ? nullptr : in.data(), fp.data());
      cm.rhs(0.0, xm.data(), p.data(), in.empty() ? nullptr : in.data(), fm.data());
      for (int row = 0; row < nx; ++row) {
        const double reference = (fp[static_cast<std::size_t>(row)] - fm[static_cast<std::size_t>(row)]) / (2 * h);
        const double scale = std::max(1.0, std::fabs(reference));
        EXPECT_NEAR(s.a(row, k), reference, 1e-7 * scale) << GetParam() << ": d x'[" << row << "]/d x[" << k << "]";
        worst = std::max(worst, std::fabs(s.a(row, k) - reference) / scale);
      }
    }
  }
  std::printf("[measured] %s: linearization against central differences of the emitted rhs: max relative %.3g\n",
              GetParam().c_str(), worst);
}

INSTANTIATE_TEST_SUITE_P(BundleModels, BundleLinearization,
                         ::testing::Values("free_rigid_body", "rolling_ball_bundle", "satellite_se3",
                                           "satellite_so3xr3", "planar_swimmer"));

INSTANTIATE_TEST_SUITE_P(GeneralAndConstrainedModels, Linearization,
                         ::testing::Values("double_pendulum", "rigid_body_euler_zyx", "chaplygin_sleigh",
                                           "rolling_disk", "rolling_ball", "rolling_disk_routh"));

// Initial states and constant inputs. The ball rolls along a direction 0.6 rad from the y axis, so that its
// ZYX Euler angle theta stays well away from the singularity ±π/2 (|sin theta| ≤ sin 0.6 from the identity).
INSTANTIATE_TEST_SUITE_P(
    NonholonomicModels, ConstrainedHamel,
    ::testing::Values(
        Scene{"chaplygin_sleigh", {0.1, -0.2, 0.3}, {0.5, 1.5}, {0.05, 0.2}, 3.0},
        Scene{"rolling_disk", {0.0, 0.1, 0.4, 0.2}, {0.7, 3.0}, {0.0005, 0.002}, 5.0},
        Scene{"rolling_ball", {0.0, 0.0, 0.0, 0.1, -0.2}, {0.3 * std::sin(0.6), -0.3 * std::cos(0.6)}, {}, 2.0}),
    [](const ::testing::TestParamInfo<Scene>& info) { return info.param.model; });

}  // namespace
