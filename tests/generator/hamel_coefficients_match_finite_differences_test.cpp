// γ^c_ab from the generator against γ computed numerically: central finite differences of A(q) as
// written in the model file, B = A⁻¹ by Eigen, then eq. (gamma) in floating point. Covers every
// shipped model and two canonical-coordinate charts on SO(3) (body and spatial angular velocity),
// where γ must also equal ±ε (Hamel: γ = +c for left-, −c for right-invariant velocities).
#include "derive/derivation.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

namespace {

using hamel::test::source_dir;

// Coordinates and parameters at `q` and the defaults, with every intermediate of `program` (the model's
// definitions, rows of A given as expressions) evaluated through its definition.
GiNaC::exmap values_at(const hamel::Model& model, const hamel::Intermediates& program, const std::vector<double>& q) {
  GiNaC::exmap values;
  for (std::size_t a = 0; a < q.size(); ++a) values[model.coordinates[a]] = q[a];
  for (const auto& p : model.parameters) values[p.symbol] = p.default_value;
  return program.evaluate(values);
}

Eigen::MatrixXd numeric_A(const hamel::Model& model, const std::vector<double>& q) {
  const GiNaC::exmap values = values_at(model, model.definitions, q);
  const int n = static_cast<int>(model.n());
  Eigen::MatrixXd A(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      A(r, c) =
          GiNaC::ex_to<GiNaC::numeric>(model.A(static_cast<unsigned>(r), static_cast<unsigned>(c)).subs(values).evalf())
              .to_double();
  return A;
}

// γ[c](a, b) by eq. (gamma) with derivatives by central differences (step h).
std::vector<Eigen::MatrixXd> finite_difference_gamma(const hamel::Model& model, const std::vector<double>& q) {
  const int n = static_cast<int>(model.n());
  const double h = 1e-5;
  std::vector<Eigen::MatrixXd> dA(static_cast<std::size_t>(n));  // dA[s](c, r) = ∂A^c_r/∂q^s
  for (int s = 0; s < n; ++s) {
    std::vector<double> plus = q, minus = q;
    plus[static_cast<std::size_t>(s)] += h;
    minus[static_cast<std::size_t>(s)] -= h;
    dA[static_cast<std::size_t>(s)] = (numeric_A(model, plus) - numeric_A(model, minus)) / (2 * h);
  }
  const Eigen::MatrixXd B = numeric_A(model, q).inverse();
  std::vector<Eigen::MatrixXd> gamma(static_cast<std::size_t>(n), Eigen::MatrixXd::Zero(n, n));
  for (int c = 0; c < n; ++c)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int r = 0; r < n; ++r)
          for (int s = 0; s < n; ++s)
            gamma[static_cast<std::size_t>(c)](a, b) +=
                (dA[static_cast<std::size_t>(s)](c, r) - dA[static_cast<std::size_t>(r)](c, s)) * B(r, a) * B(s, b);
  return gamma;
}

std::vector<Eigen::MatrixXd> generator_gamma(const hamel::Model& model, const std::vector<double>& q) {
  // Through the derivation's program (B by elimination, γ by the chain rule), evaluated numerically.
  hamel::Intermediates program = model.definitions;
  const hamel::QuasiVelocities qv = hamel::derive_quasi_velocities(model, program);
  const std::vector<hamel::HamelCoefficient> coefficients = hamel::hamel_coefficients(model, qv, program);
  const GiNaC::exmap values = values_at(model, program, q);
  const int n = static_cast<int>(model.n());
  std::vector<Eigen::MatrixXd> gamma(static_cast<std::size_t>(n), Eigen::MatrixXd::Zero(n, n));
  for (const auto& g : coefficients)
    gamma[static_cast<std::size_t>(g.upper)](g.lower_a, g.lower_b) =
        GiNaC::ex_to<GiNaC::numeric>(g.value.subs(values).evalf()).to_double();
  return gamma;
}

void expect_gamma_matches(const hamel::Model& model, int trials) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<double> q(model.n());
    for (double& v : q) v = uniform(rng);
    const auto fd = finite_difference_gamma(model, q);
    const auto gen = generator_gamma(model, q);
    double scale = 1;
    for (const auto& m : fd) scale = std::max(scale, m.cwiseAbs().maxCoeff());
    for (std::size_t c = 0; c < fd.size(); ++c)
      for (int a = 0; a < fd[c].rows(); ++a)
        for (int b = 0; b < fd[c].cols(); ++b)
          EXPECT_NEAR(gen[c](a, b), fd[c](a, b), 1e-7 * scale)
              << model.name << ": gamma^" << model.quasi_velocities[c] << "_"
              << model.quasi_velocities[static_cast<std::size_t>(a)] << ","
              << model.quasi_velocities[static_cast<std::size_t>(b)];
  }
}

TEST(HamelCoefficients, MatchFiniteDifferencesForEveryShippedModel) {
  int models = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source_dir() + "/models")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const hamel::Model model = hamel::load_model(entry.path().string());
    if (model.bundle) continue;  // no coordinates on G: bundle_geometry tests cover them
    expect_gamma_matches(model, 5);
    ++models;
  }
  EXPECT_GE(models, 4);
}

// ZYX Euler angles with the body (left-invariant) or spatial (right-invariant) angular velocity.
std::string so3_model(bool body) {
  const std::string rows = body ? R"yaml(
    - ["-sin(theta)", 0, 1]
    - ["cos(theta)*sin(phi)", "cos(phi)", 0]
    - ["cos(theta)*cos(phi)", "-sin(phi)", 0])yaml"
                                : R"yaml(
    - [0, "-sin(psi)", "cos(psi)*cos(theta)"]
    - [0, "cos(psi)", "sin(psi)*cos(theta)"]
    - [1, 0, "-sin(theta)"])yaml";
  return "name: so3\ncoordinates: [psi, theta, phi]\nquasi_velocities:\n  names: [w1, w2, w3]\n  A:" + rows +
         "\nlagrangian: \"psi_dot^2 + theta_dot^2 + phi_dot^2\"\n";
}

TEST(HamelCoefficients, AreStructureConstantsOfSO3) {
  for (bool body : {true, false}) {
    const hamel::Model model =
        hamel::load_model_from_text(so3_model(body), body ? "so3_body.yaml" : "so3_spatial.yaml");
    expect_gamma_matches(model, 3);
    const hamel::QuasiVelocities qv = hamel::derive_quasi_velocities(model);
    const auto gamma = hamel::hamel_coefficients(model, qv);
    ASSERT_EQ(gamma.size(), 6u);
    for (const auto& g : gamma) {
      // ε_abc for a cyclic (a, b, c): +1 for (0,1,2), (1,2,0), (2,0,1).
      const int epsilon = ((g.lower_b - g.lower_a + 3) % 3 == 1) ? 1 : -1;
      EXPECT_EQ(g.value, GiNaC::ex(body ? epsilon : -epsilon))
          << "gamma^" << g.upper << "_" << g.lower_a << g.lower_b << (body ? " (body)" : " (spatial)");
    }
  }
}

}  // namespace
