// The emitted riemann_linearization kernel (the paper's covariant linearization, derive/riemann.hpp),
// compiled with -Wall -Wextra -Werror -pedantic, against the plain linearization of an independent
// Euler–Lagrange right-hand side along a simulated nominal trajectory.
//
// Independent side, built here from the model's Lagrangian with GiNaC (definitions inlined, quasi-velocities
// replaced by A q̇; nothing of hamel's equations or of derive_riemann): M(q) q̈ = ∂L/∂q − ∂²L/∂q̇∂q q̇ −
// ∂²L/∂q̇∂t + F, evaluated at 30 digits. The nominal (q, q̇)(t) is integrated with RK4 on it; at points of the
// trajectory the Jacobian J = ∂(q̇, q̈)/∂(q, q̇) is taken by central differences (h = 1e-7, at 30 digits).
//
// Covariant side, from the kernel's g, G = Γ q̇, K = R q̇q̇ − ∇Q and Ġ = dG/dt along the motion at the state
// (q, u = A(q) q̇): with y = D x/dt = ẋ + G x the equations g Dy/dt + K x = 0 read ẏ = −G y − g⁻¹K x, so in
// (x, v = ẋ)
//   ẋ = v,   v̇ = −(G G + g⁻¹K + Ġ) x − 2 G v.
// That matrix must be J. The kernel's Ġ is also compared with a five-point difference of its G along the
// independent flow.
#include "model/load_model.hpp"

#include "double_pendulum.hpp"
#include "forced_pendulum.hpp"
#include "rigid_body_euler_zyx.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;
using Kernel = void (*)(double, const double*, const double*, const double*, double*);

std::string source(const std::string& relative) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/" + relative;
}

double number(const ex& e) { return GiNaC::ex_to<GiNaC::numeric>(e.evalf()).to_double(); }

// q̈ = M⁻¹ (∂L/∂q − ∂²L/∂q̇∂q q̇ − ∂²L/∂q̇∂t + F) from L itself.
class EulerLagrange {
 public:
  explicit EulerLagrange(const hamel::Model& model) : model_(model), n_(static_cast<unsigned>(model.n())) {
    GiNaC::exmap parameters;
    for (const auto& p : model.parameters) parameters[p.symbol] = GiNaC::numeric(p.default_value);
    GiNaC::exmap to_rates;
    for (unsigned a = 0; a < n_; ++a) {
      ex u = 0;
      for (unsigned b = 0; b < n_; ++b) u += model.definitions.inline_all(model.A(a, b)) * model.rates[b];
      to_rates[model.quasi_velocities[a]] = u;
    }
    const ex L = model.definitions.inline_all(model.lagrangian).subs(to_rates).subs(parameters);
    mass_ = GiNaC::matrix(n_, n_);
    for (unsigned a = 0; a < n_; ++a) {
      const ex p = L.diff(model.rates[a]);
      ex f = L.diff(model.coordinates[a]) - p.diff(model.time) +
             model.definitions.inline_all(model.forces[a]).subs(to_rates).subs(parameters);
      for (unsigned b = 0; b < n_; ++b) {
        mass_(a, b) = p.diff(model.rates[b]);
        f -= p.diff(model.coordinates[b]) * model.rates[b];
      }
      force_.push_back(f);
    }
    A_ = GiNaC::matrix(n_, n_);
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b) A_(a, b) = model.definitions.inline_all(model.A(a, b)).subs(parameters);
  }

  // (q̇, q̈) at the state (q, q̇), at 30 digits.
  std::vector<GiNaC::numeric> flow(double t, const std::vector<GiNaC::numeric>& state) const {
    const GiNaC::exmap at = point(t, state);
    GiNaC::matrix M(n_, n_), f(n_, 1);
    for (unsigned a = 0; a < n_; ++a) {
      f(a, 0) = force_[a].subs(at).evalf();
      for (unsigned b = 0; b < n_; ++b) M(a, b) = mass_(a, b).subs(at).evalf();
    }
    const GiNaC::matrix acceleration = M.inverse().mul(f);  // numeric entries at 30 digits
    std::vector<GiNaC::numeric> out(state.begin() + n_, state.end());
    for (unsigned a = 0; a < n_; ++a) out.push_back(GiNaC::ex_to<GiNaC::numeric>(acceleration(a, 0)));
    return out;
  }

  std::vector<double> flow(double t, const std::vector<double>& state) const {
    std::vector<double> out;
    for (const GiNaC::numeric& v : flow(t, exact(state))) out.push_back(v.to_double());
    return out;
  }

  static std::vector<GiNaC::numeric> exact(const std::vector<double>& x) {
    return std::vector<GiNaC::numeric>(x.begin(), x.end());
  }

  // u = A(q) q̇, the kernel's velocity part of the state.
  std::vector<double> kernel_state(const std::vector<double>& state) const {
    const GiNaC::exmap at = point(0, exact(state));
    std::vector<double> x(state.begin(), state.begin() + n_);
    for (unsigned a = 0; a < n_; ++a) {
      double u = 0;
      for (unsigned b = 0; b < n_; ++b) u += number(A_(a, b).subs(at)) * state[n_ + b];
      x.push_back(u);
    }
    return x;
  }

 private:
  GiNaC::exmap point(double t, const std::vector<GiNaC::numeric>& state) const {
    GiNaC::exmap at;
    at[model_.time] = GiNaC::numeric(t);
    for (unsigned a = 0; a < n_; ++a) at[model_.coordinates[a]] = state[a], at[model_.rates[a]] = state[n_ + a];
    return at;
  }
  const hamel::Model& model_;
  unsigned n_;
  GiNaC::matrix mass_, A_;
  std::vector<ex> force_;
};

std::vector<double> axpy(const std::vector<double>& x, double h, const std::vector<double>& k) {
  std::vector<double> out(x);
  for (std::size_t i = 0; i < x.size(); ++i) out[i] += h * k[i];
  return out;
}

struct Case {
  std::string file;
  Kernel linearization;
  const double* parameters;
  std::vector<double> initial;  ///< (q, q̇)
};

void check(const Case& c) {
  SCOPED_TRACE(c.file);
  const long saved = GiNaC::Digits;
  GiNaC::Digits = 30;
  const hamel::Model model = hamel::load_model(source(c.file));
  const EulerLagrange el(model);
  const int n = static_cast<int>(model.n());
  const double in[1] = {0};

  // g, G, K, Ġ from the kernel at the state (q, q̇) and time t.
  struct Blocks {
    Eigen::MatrixXd g, G, K, G_dot;
  };
  const auto blocks = [&](double t, const std::vector<double>& state) {
    const std::vector<double> x = el.kernel_state(state);
    std::vector<double> out(static_cast<std::size_t>(4 * n * n));
    c.linearization(t, x.data(), c.parameters, in, out.data());
    Blocks b{Eigen::MatrixXd(n, n), Eigen::MatrixXd(n, n), Eigen::MatrixXd(n, n), Eigen::MatrixXd(n, n)};
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        b.g(i, j) = out[static_cast<std::size_t>(i * n + j)];
        b.G(i, j) = out[static_cast<std::size_t>(n * n + i * n + j)];
        b.K(i, j) = out[static_cast<std::size_t>(2 * n * n + i * n + j)];
        b.G_dot(i, j) = out[static_cast<std::size_t>(3 * n * n + i * n + j)];
      }
    return b;
  };

  std::vector<double> state = c.initial;
  double t = 0, worst = 0, worst_G_dot = 0;
  const double dt = 0.01;
  for (int step = 0; step <= 60; ++step) {
    if (step % 20 == 0) {
      // Plain linearization by central differences of the independent right-hand side (at 30 digits).
      Eigen::MatrixXd J(2 * n, 2 * n);
      const GiNaC::numeric h_state(1, 10000000);
      for (int k = 0; k < 2 * n; ++k) {
        std::vector<GiNaC::numeric> plus = EulerLagrange::exact(state), minus = plus;
        plus[static_cast<std::size_t>(k)] += h_state;
        minus[static_cast<std::size_t>(k)] -= h_state;
        const std::vector<GiNaC::numeric> fp = el.flow(t, plus), fm = el.flow(t, minus);
        for (int r = 0; r < 2 * n; ++r)
          J(r, k) = ((fp[static_cast<std::size_t>(r)] - fm[static_cast<std::size_t>(r)]) / (2 * h_state)).to_double();
      }
      // Covariant linearization in first-order form, from the kernel's outputs alone.
      const Blocks b = blocks(t, state);
      Eigen::MatrixXd C = Eigen::MatrixXd::Zero(2 * n, 2 * n);
      C.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
      C.bottomLeftCorner(n, n) = -(b.G * b.G + b.g.ldlt().solve(b.K) + b.G_dot);
      C.bottomRightCorner(n, n) = -2 * b.G;
      const double error = (C - J).cwiseAbs().maxCoeff() / J.cwiseAbs().maxCoeff();
      // Ġ = d/ds G(state + s f) at s = 0 along the independent flow f, five-point stencil (truncation ~h⁴,
      // rounding ~1e-16/h).
      const std::vector<double> f = el.flow(t, state);
      const double h = 1e-4;
      const auto G_at = [&](double s) { return blocks(t + s, axpy(state, s, f)).G; };
      const Eigen::MatrixXd G_dot = (G_at(-2 * h) - 8 * G_at(-h) + 8 * G_at(h) - G_at(2 * h)) / (12 * h);
      const double error_G_dot =
          (b.G_dot - G_dot).cwiseAbs().maxCoeff() / std::max(G_dot.cwiseAbs().maxCoeff(), 1e-300);
      std::cout << "[ measured ] " << c.file << " t = " << t << ": |covariant - Jacobian| / |Jacobian| = " << error
                << ", |G_dot - difference| / |G_dot| = " << error_G_dot << "\n";
      worst = std::max(worst, error);
      worst_G_dot = std::max(worst_G_dot, error_G_dot);
      // The metric is the mass matrix: symmetric positive definite along the way.
      EXPECT_LT((b.g - b.g.transpose()).cwiseAbs().maxCoeff(), 1e-14 * b.g.cwiseAbs().maxCoeff());
      EXPECT_GT(b.g.ldlt().vectorD().minCoeff(), 0.0);
    }
    // RK4 on the independent right-hand side.
    const std::vector<double> k1 = el.flow(t, state), k2 = el.flow(t + dt / 2, axpy(state, dt / 2, k1)),
                              k3 = el.flow(t + dt / 2, axpy(state, dt / 2, k2)),
                              k4 = el.flow(t + dt, axpy(state, dt, k3));
    for (std::size_t i = 0; i < state.size(); ++i) state[i] += dt / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    t += dt;
  }
  GiNaC::Digits = saved;
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(worst_G_dot, 1e-8);
}

TEST(RiemannLinearization, DoublePendulumMatchesTheJacobianAlongATrajectory) {
  check({"models/double_pendulum.yaml",
         double_pendulum::riemann_linearization,
         double_pendulum::default_parameters,
         {0.9, -0.6, 1.1, -0.7}});
}

// Quasi-velocities that are not the rates (body angular velocity): the kernel forms q̇ = B(q) u itself.
TEST(RiemannLinearization, RigidBodyInEulerAnglesMatchesTheJacobianAlongATrajectory) {
  check({"models/rigid_body_euler_zyx.yaml",
         rigid_body_euler_zyx::riemann_linearization,
         rigid_body_euler_zyx::default_parameters,
         {0.2, 0.3, -0.4, 0.8, -0.5, 1.3}});
}

// Non-conservative, time-dependent forces (∇_b Q_a not symmetric) and a Lagrangian in a quasi-velocity.
TEST(RiemannLinearization, ForcedPendulumMatchesTheJacobianAlongATrajectory) {
  check({"tests/generator/riemann_models/forced_pendulum.yaml",
         forced_pendulum::riemann_linearization,
         forced_pendulum::default_parameters,
         {0.5, 0.8, -1.0, 0.6}});
}

}  // namespace
