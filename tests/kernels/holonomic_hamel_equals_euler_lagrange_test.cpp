// For a holonomic system written with u = q̇ (the double pendulum, A = identity) the Hamel coefficients
// (gamma) vanish and the Boltzmann–Hamel equations (BHEqu2) are the Euler–Lagrange equations. Checked
// independently of the generator's derivation:
//  - the compiled table reports no Hamel coefficient, the emitted hamel_coefficients kernel writes nothing,
//    and γᶜ_ab = (∂Aᶜ_r/∂qˢ − ∂Aᶜ_s/∂qʳ) Bʳ_a Bˢ_b computed here from the model's A is zero;
//  - the emitted mass_matrix and forcing equal M_q = ∂²L/∂q̇∂q̇ and Q − h,
//    h = ∂²L/∂q̇∂q q̇ + ∂²L/∂q̇∂t − ∂L/∂q, differentiated here with GiNaC from the model's L (relative 1e-12);
//  - the emitted rhs equals the textbook closed-form double-pendulum accelerations (relative 1e-12).
#include "compiled_models.hpp"

#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace {

using hamel::test::CompiledModel;

constexpr double kPi = 3.14159265358979323846;

double evaluate(const GiNaC::ex& e, const GiNaC::exmap& values) {
  const GiNaC::ex v = e.subs(values).evalf();
  EXPECT_TRUE(GiNaC::is_a<GiNaC::numeric>(v)) << e << " did not evaluate to a number: " << v;
  return GiNaC::is_a<GiNaC::numeric>(v) ? GiNaC::ex_to<GiNaC::numeric>(v).to_double() : NAN;
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

/// Largest |a_k − b_k| / max(1, max_k |b_k|).
double relative_error(const std::vector<double>& a, const std::vector<double>& b) {
  const double scale = std::max(1.0, max_abs(b));
  double e = 0;
  for (std::size_t k = 0; k < b.size(); ++k) e = std::max(e, std::fabs(a[k] - b[k]) / scale);
  return e;
}

const CompiledModel& pendulum() { return hamel::test::compiled_model("double_pendulum"); }

TEST(HolonomicHamel, DoublePendulumHasNoHamelCoefficients) {
  const CompiledModel& cm = pendulum();
  EXPECT_EQ(cm.n_hamel, 0);
  EXPECT_EQ(cm.n_constraints, 0);
  EXPECT_EQ(cm.constraint_residual, nullptr);
  EXPECT_EQ(cm.n_independent, cm.n_coordinates);

  // The kernel must not write a single output: every sentinel survives.
  const double sentinel = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> out(64, sentinel);
  std::vector<double> x = {0.3, -0.7, 1.1, -2.0};
  std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
  double dummy_input = 0;
  cm.hamel_coefficients(0.0, x.data(), p.data(), &dummy_input, out.data());
  for (std::size_t k = 0; k < out.size(); ++k)
    EXPECT_TRUE(std::isnan(out[k])) << "hamel_coefficients wrote out[" << k << "]";

  // Independently from the model's A: γᶜ_ab ≡ 0 (eq. (gamma)).
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  const unsigned n = static_cast<unsigned>(model.n());
  const GiNaC::matrix B = model.A.inverse();
  for (unsigned c = 0; c < n; ++c)
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b < n; ++b) {
        GiNaC::ex g = 0;
        for (unsigned r = 0; r < n; ++r)
          for (unsigned s = 0; s < n; ++s)
            g += (model.A(c, r).diff(model.coordinates[s]) - model.A(c, s).diff(model.coordinates[r])) * B(r, a) *
                 B(s, b);
        EXPECT_TRUE(g.normal().is_zero()) << "gamma^" << c << "_" << a << b << " = " << g;
      }
}

TEST(HolonomicHamel, MassMatrixAndForcingAreEulerLagrange) {
  const CompiledModel& cm = pendulum();
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  const int n = static_cast<int>(model.n());
  ASSERT_EQ(n, cm.n_coordinates);
  ASSERT_EQ(n, cm.n_independent);

  // u = A q̇ with A = I here, but substitute in general: a quasi-velocity name in L stands for A q̇.
  GiNaC::exmap u_of_qdot;
  for (int k = 0; k < n; ++k) {
    GiNaC::ex row = 0;
    for (int b = 0; b < n; ++b)
      row += model.A(static_cast<unsigned>(k), static_cast<unsigned>(b)) * model.rates[static_cast<std::size_t>(b)];
    u_of_qdot[model.quasi_velocities[static_cast<std::size_t>(k)]] = row;
  }
  const GiNaC::ex L = model.lagrangian.subs(u_of_qdot);
  std::vector<GiNaC::ex> M, Q_minus_h;
  for (int a = 0; a < n; ++a) {
    const GiNaC::ex dL_dqdot = L.diff(model.rates[static_cast<std::size_t>(a)]);
    for (int b = 0; b < n; ++b) M.push_back(dL_dqdot.diff(model.rates[static_cast<std::size_t>(b)]));
    GiNaC::ex h = dL_dqdot.diff(model.time) - L.diff(model.coordinates[static_cast<std::size_t>(a)]);
    for (int c = 0; c < n; ++c)
      h += dL_dqdot.diff(model.coordinates[static_cast<std::size_t>(c)]) * model.rates[static_cast<std::size_t>(c)];
    Q_minus_h.push_back(model.forces[static_cast<std::size_t>(a)].subs(u_of_qdot) - h);
  }

  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst_M = 0, worst_f = 0;
  for (int trial = 0; trial < 25; ++trial) {
    const double t = uniform(rng);
    std::vector<double> x(static_cast<std::size_t>(2 * n));
    for (int a = 0; a < n; ++a) {
      x[static_cast<std::size_t>(a)] = kPi * uniform(rng);
      x[static_cast<std::size_t>(n + a)] = 3.0 * uniform(rng);
    }
    std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
    for (double& v : p) v *= 1.0 + 0.3 * uniform(rng);
    double dummy_input = 0;

    GiNaC::exmap values;
    values[model.time] = t;
    for (int a = 0; a < n; ++a) {
      values[model.coordinates[static_cast<std::size_t>(a)]] = x[static_cast<std::size_t>(a)];
      values[model.rates[static_cast<std::size_t>(a)]] = x[static_cast<std::size_t>(n + a)];  // q̇ = u (A = I)
    }
    for (std::size_t k = 0; k < model.parameters.size(); ++k) values[model.parameters[k].symbol] = p[k];

    std::vector<double> M_ref, f_ref;
    for (const auto& e : M) M_ref.push_back(evaluate(e, values));
    for (const auto& e : Q_minus_h) f_ref.push_back(evaluate(e, values));

    std::vector<double> M_emitted(static_cast<std::size_t>(n * n)), f_emitted(static_cast<std::size_t>(n));
    cm.mass_matrix(t, x.data(), p.data(), &dummy_input, M_emitted.data());
    cm.forcing(t, x.data(), p.data(), &dummy_input, f_emitted.data());

    const double eM = relative_error(M_emitted, M_ref), ef = relative_error(f_emitted, f_ref);
    EXPECT_LE(eM, 1e-12) << "mass matrix, trial " << trial;
    EXPECT_LE(ef, 1e-12) << "forcing, trial " << trial << ": emitted (" << f_emitted[0] << ", " << f_emitted[1]
                         << "), Euler-Lagrange (" << f_ref[0] << ", " << f_ref[1] << ")";
    worst_M = std::max(worst_M, eM);
    worst_f = std::max(worst_f, ef);
  }
  std::printf("[measured] double_pendulum: max relative error mass_matrix %.3g, forcing %.3g\n", worst_M, worst_f);
}

// Textbook closed form for point masses on massless rods, angles from the downward vertical.
void closed_form_accelerations(const double* x, double m1, double m2, double l1, double l2, double g, double* acc) {
  const double th1 = x[0], th2 = x[1], w1 = x[2], w2 = x[3];
  const double d = th1 - th2;
  const double den = 2 * m1 + m2 - m2 * std::cos(2 * d);
  acc[0] = (-g * (2 * m1 + m2) * std::sin(th1) - m2 * g * std::sin(th1 - 2 * th2) -
            2 * std::sin(d) * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * std::cos(d))) /
           (l1 * den);
  acc[1] =
      (2 * std::sin(d) * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * std::cos(th1) + w2 * w2 * l2 * m2 * std::cos(d))) /
      (l2 * den);
}

TEST(HolonomicHamel, RhsMatchesClosedFormDoublePendulum) {
  const CompiledModel& cm = pendulum();
  ASSERT_EQ(cm.n_coordinates, 2);
  ASSERT_EQ(cm.n_parameters, 5);  // m1, m2, l1, l2, g in file order
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> x = {kPi * uniform(rng), kPi * uniform(rng), 4.0 * uniform(rng), 4.0 * uniform(rng)};
    std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
    for (double& v : p) v *= 1.0 + 0.3 * uniform(rng);
    double dummy_input = 0;
    std::vector<double> out(4);
    cm.rhs(0.0, x.data(), p.data(), &dummy_input, out.data());
    std::vector<double> ref(4);
    ref[0] = x[2];
    ref[1] = x[3];
    closed_form_accelerations(x.data(), p[0], p[1], p[2], p[3], p[4], &ref[2]);
    const double e = relative_error(out, ref);
    EXPECT_LE(e, 1e-12) << "trial " << trial << ": emitted (" << out[2] << ", " << out[3] << "), closed form ("
                        << ref[2] << ", " << ref[3] << ")";
    worst = std::max(worst, e);
  }
  std::printf("[measured] double_pendulum: max relative error rhs vs closed form %.3g\n", worst);
}

}  // namespace
