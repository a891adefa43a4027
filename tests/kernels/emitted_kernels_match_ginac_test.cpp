// The compiled emitted kernels against GiNaC's evaluation of the derived expressions at random states
// (relative 1e-12). The rhs is checked against an Eigen solve of GiNaC's M and f, not against the
// emitted LDLᵀ. Bundle models (derived in their default form, folded as they were emitted) also have
// their group_velocity, connection and locked_inertia kernels checked, and the kernels against each
// other: ξ^α + A^α_I ṙ^I is the shifted velocity u^α of the state (zero when held).
#include "compiled_models.hpp"

#include "derive/derivation.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

namespace {

using hamel::test::CompiledModel;

double evaluate(const GiNaC::ex& e, const GiNaC::exmap& values) {
  const GiNaC::ex v = e.subs(values).evalf();
  EXPECT_TRUE(GiNaC::is_a<GiNaC::numeric>(v)) << e << " did not evaluate to a number: " << v;
  return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
}

void expect_close(const std::vector<double>& emitted, const std::vector<double>& reference, const std::string& what) {
  ASSERT_EQ(emitted.size(), reference.size()) << what;
  double scale = 0;
  for (double r : reference) scale = std::max(scale, std::fabs(r));
  for (std::size_t k = 0; k < reference.size(); ++k)
    EXPECT_NEAR(emitted[k], reference[k], 1e-12 * std::max({1.0, std::fabs(reference[k]), scale}))
        << what << "[" << k << "]";
}

class EmittedKernels : public ::testing::TestWithParam<CompiledModel> {};

// The model as it was emitted: with `--fold all` every parameter is replaced by its default.
hamel::Model emitted_model(const CompiledModel& cm) {
  const hamel::Model loaded = hamel::load_model(hamel::test::source_path(cm.model_file));
  if (cm.fold.empty()) return loaded;
  EXPECT_EQ(cm.fold, "all");
  std::map<std::string, double> values;
  for (const auto& p : loaded.parameters) values[p.symbol.get_name()] = p.default_value;
  return hamel::fold_parameters(loaded, values);
}

TEST_P(EmittedKernels, MatchGinacAtRandomStates) {
  const CompiledModel& cm = GetParam();
  const hamel::Model model = emitted_model(cm);
  const hamel::Derivation d = hamel::derive(model);
  const hamel::HamelEquations& eq = d.equations;
  const hamel::HamelSystem& sys = d.system;
  const int n = cm.n_coordinates, m = cm.n_independent;
  ASSERT_EQ(static_cast<std::size_t>(n), sys.coordinates.size());
  ASSERT_EQ(static_cast<std::size_t>(n), model.n());
  ASSERT_EQ(static_cast<std::size_t>(m), eq.independent.size());
  ASSERT_EQ(static_cast<std::size_t>(cm.n_constraints), sys.constrained.size());
  ASSERT_EQ(static_cast<std::size_t>(cm.n_hamel), sys.gamma.size());
  ASSERT_EQ(model.bundle.has_value(), cm.group_velocity != nullptr);
  ASSERT_EQ(model.bundle.has_value(), cm.locked_inertia != nullptr);
  ASSERT_EQ(model.bundle && n > 0, cm.connection != nullptr);
  const int g = cm.n_group;
  if (model.bundle) {
    ASSERT_EQ(static_cast<std::size_t>(g), model.bundle->group_velocity.size());
    ASSERT_TRUE(d.bundle->quadratic);
  }

  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double t = uniform(rng);
    std::vector<double> x(static_cast<std::size_t>(n + m)),
        p(cm.default_parameters, cm.default_parameters + cm.n_parameters),
        in(static_cast<std::size_t>(std::max(cm.n_inputs, 1)));
    for (double& v : x) v = uniform(rng);
    // Away from the defaults, still physical; folded kernels must ignore p (GiNaC has no parameters left).
    for (double& v : p) v *= 1.0 + 0.2 * uniform(rng);
    for (double& v : in) v = uniform(rng);

    GiNaC::exmap values;
    values[model.time] = t;
    for (int a = 0; a < n; ++a) values[sys.coordinates[static_cast<std::size_t>(a)]] = x[static_cast<std::size_t>(a)];
    for (int i = 0; i < m; ++i)
      values[sys.velocities[static_cast<std::size_t>(eq.independent[static_cast<std::size_t>(i)])]] =
          x[static_cast<std::size_t>(n + i)];
    for (int alpha : sys.constrained) values[sys.velocities[static_cast<std::size_t>(alpha)]] = 0;
    for (std::size_t k = 0; k < model.parameters.size(); ++k) values[model.parameters[k].symbol] = p[k];
    for (std::size_t k = 0; k < model.inputs.size(); ++k) values[model.inputs[k]] = in[k];
    values = eq.intermediates.evaluate(values);  // kinematic trees: their intermediate symbols, in order

    auto run = [&](hamel::test::KernelFn f, std::size_t size) {
      std::vector<double> out(size);
      f(t, x.data(), p.data(), in.data(), out.data());
      return out;
    };

    std::vector<double> qdot, gamma, forcing;
    for (const auto& e : eq.kinematics) qdot.push_back(evaluate(e, values));
    for (const auto& h : sys.gamma) gamma.push_back(evaluate(h.value, values));
    Eigen::MatrixXd M(m, m);
    Eigen::VectorXd f(m);
    std::vector<double> mass;
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        M(i, j) = evaluate(eq.mass_matrix(static_cast<unsigned>(i), static_cast<unsigned>(j)), values);
        mass.push_back(M(i, j));
      }
      f(i) = evaluate(eq.forcing[static_cast<std::size_t>(i)], values);
      forcing.push_back(f(i));
    }
    const Eigen::VectorXd accel = M.partialPivLu().solve(f);
    std::vector<double> rhs = qdot;
    for (int i = 0; i < m; ++i) rhs.push_back(accel(i));

    expect_close(run(cm.kinematics, qdot.size()), qdot, cm.name + " kinematics");
    expect_close(run(cm.mass_matrix, mass.size()), mass, cm.name + " mass_matrix");
    expect_close(run(cm.forcing, forcing.size()), forcing, cm.name + " forcing");
    expect_close(run(cm.hamel_coefficients, gamma.size()), gamma, cm.name + " hamel_coefficients");
    expect_close(run(cm.rhs, rhs.size()), rhs, cm.name + " rhs");
    expect_close(run(cm.energy, 1), {evaluate(eq.energy_terms.at(0), values)}, cm.name + " energy");
    if (cm.constraint_residual) {
      const std::vector<double> r = run(cm.constraint_residual, static_cast<std::size_t>(cm.n_constraints));
      for (double v : r) EXPECT_NEAR(v, 0.0, 1e-12 * (1 + *std::max_element(qdot.begin(), qdot.end())));
    }
    if (!model.bundle) continue;

    const hamel::BundleGeometry& geo = *d.bundle;
    std::vector<double> xi, connection, locked;
    for (const auto& e : d.group_velocity) xi.push_back(evaluate(e, values));
    for (int a = 0; a < g; ++a) {
      for (int I = 0; I < n && geo.connection_derived; ++I)
        connection.push_back(evaluate(geo.connection(static_cast<unsigned>(a), static_cast<unsigned>(I)), values));
      for (int b = 0; b < g; ++b)
        locked.push_back(evaluate(geo.L(static_cast<unsigned>(a), static_cast<unsigned>(b)), values));
    }
    if (!geo.connection_derived) {  // trees: A = L⁻¹K, here by Eigen's LDLᵀ of GiNaC's L and K
      Eigen::MatrixXd L(g, g), K(g, n);
      for (int a = 0; a < g; ++a) {
        for (int b = 0; b < g; ++b) L(a, b) = locked[static_cast<std::size_t>(a * g + b)];
        for (int I = 0; I < n; ++I)
          K(a, I) = evaluate(geo.K(static_cast<unsigned>(a), static_cast<unsigned>(I)), values);
      }
      const Eigen::MatrixXd A = L.ldlt().solve(K);
      for (int a = 0; a < g; ++a)
        for (int I = 0; I < n; ++I) connection.push_back(A(a, I));
    }
    const std::vector<double> xi_emitted = run(cm.group_velocity, static_cast<std::size_t>(g));
    expect_close(xi_emitted, xi, cm.name + " group_velocity");
    expect_close(run(cm.locked_inertia, locked.size()), locked, cm.name + " locked_inertia");
    if (!cm.connection) continue;
    const std::vector<double> A = run(cm.connection, connection.size());
    expect_close(A, connection, cm.name + " connection");

    // ξ^α + A^α_I ṙ^I = u^α (the locked velocity in lp, 0 in ldap), from the kernels alone; in the ep form
    // of trees u = ξ and A is not the shift.
    if (*d.form == hamel::BundleForm::euler_poincare) continue;
    const std::vector<double> r_dot = run(cm.kinematics, static_cast<std::size_t>(n));
    std::vector<double> u_of(static_cast<std::size_t>(g + n), 0.0);  // all quasi-velocities, held ones 0
    for (int i = 0; i < m; ++i)
      u_of[static_cast<std::size_t>(eq.independent[static_cast<std::size_t>(i)])] = x[static_cast<std::size_t>(n + i)];
    for (int a = 0; a < g; ++a) {
      double shifted = xi_emitted[static_cast<std::size_t>(a)];
      for (int I = 0; I < n; ++I)
        shifted += A[static_cast<std::size_t>(a * n + I)] * r_dot[static_cast<std::size_t>(I)];
      EXPECT_NEAR(shifted, u_of[static_cast<std::size_t>(a)], 1e-12 * (1 + std::fabs(shifted)))
          << cm.name << " xi + A r_dot, alpha = " << a;
    }
  }
}

// Every package has its name tables, read here without knowing whether the model has inputs or constraints: the
// input names are the model's, in order; a table without entries is a null pointer.
TEST_P(EmittedKernels, NameTablesAreTheModelsEvenWhenEmpty) {
  const CompiledModel& cm = GetParam();
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  ASSERT_EQ(cm.n_inputs, static_cast<int>(model.inputs.size())) << cm.name;
  EXPECT_EQ(cm.input_names == nullptr, model.inputs.empty()) << cm.name;
  for (int k = 0; k < cm.n_inputs; ++k)
    EXPECT_EQ(cm.input_names[k], model.inputs[static_cast<std::size_t>(k)].get_name()) << cm.name;
  EXPECT_EQ(cm.constraint_names == nullptr, cm.n_constraints == 0) << cm.name;
  for (int k = 0; k < cm.n_constraints; ++k) EXPECT_NE(cm.constraint_names[k], nullptr) << cm.name;
}

INSTANTIATE_TEST_SUITE_P(ShippedModels, EmittedKernels, ::testing::ValuesIn(hamel::test::compiled_models()),
                         [](const ::testing::TestParamInfo<CompiledModel>& info) { return info.param.name; });

}  // namespace
