// The compiled emitted kernels against GiNaC's evaluation of the derived expressions at random states
// (relative 1e-12). The rhs is checked against an Eigen solve of GiNaC's M and f, not against the
// emitted LDLᵀ.
#include "compiled_models.hpp"

#include "derive/derivation.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
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

TEST_P(EmittedKernels, MatchGinacAtRandomStates) {
  const CompiledModel& cm = GetParam();
  const hamel::Model model = hamel::load_model(hamel::test::source_path(cm.model_file));
  const hamel::Derivation d = hamel::derive(model);
  const hamel::HamelEquations& eq = d.equations;
  const int n = cm.n_coordinates, m = cm.n_independent;
  ASSERT_EQ(static_cast<std::size_t>(n), model.n());
  ASSERT_EQ(static_cast<std::size_t>(m), eq.independent.size());
  ASSERT_EQ(static_cast<std::size_t>(cm.n_hamel), d.system.gamma.size());

  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double t = uniform(rng);
    std::vector<double> x(static_cast<std::size_t>(n + m)),
        p(cm.default_parameters, cm.default_parameters + cm.n_parameters),
        in(static_cast<std::size_t>(std::max(cm.n_inputs, 1)));
    for (double& v : x) v = uniform(rng);
    for (double& v : p) v *= 1.0 + 0.2 * uniform(rng);  // away from the defaults, still physical
    for (double& v : in) v = uniform(rng);

    GiNaC::exmap values;
    values[model.time] = t;
    for (int a = 0; a < n; ++a) values[model.coordinates[static_cast<std::size_t>(a)]] = x[static_cast<std::size_t>(a)];
    for (int i = 0; i < m; ++i)
      values[model.quasi_velocities[static_cast<std::size_t>(eq.independent[static_cast<std::size_t>(i)])]] =
          x[static_cast<std::size_t>(n + i)];
    for (std::size_t k = 0; k < model.parameters.size(); ++k) values[model.parameters[k].symbol] = p[k];
    for (std::size_t k = 0; k < model.inputs.size(); ++k) values[model.inputs[k]] = in[k];

    auto run = [&](hamel::test::KernelFn f, std::size_t size) {
      std::vector<double> out(size);
      f(t, x.data(), p.data(), in.data(), out.data());
      return out;
    };

    std::vector<double> qdot, gamma, forcing;
    for (const auto& e : eq.kinematics) qdot.push_back(evaluate(e, values));
    for (const auto& h : d.system.gamma) gamma.push_back(evaluate(h.value, values));
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
  }
}

INSTANTIATE_TEST_SUITE_P(ShippedModels, EmittedKernels, ::testing::ValuesIn(hamel::test::compiled_models()),
                         [](const ::testing::TestParamInfo<CompiledModel>& info) { return info.param.name; });

}  // namespace
