// The Riemannian view (derive/riemann.hpp) against the textbook formulas evaluated by central differences
// of a metric computed here, independently: g_ab = ∂²L/∂q̇ᵃ∂q̇ᵇ of the model's Lagrangian with every
// definition inlined and the quasi-velocities replaced by A q̇ (plain GiNaC diff, no intermediates), evaluated
// with evalf at 40 digits; then, with central differences of step h = 1e-10 (truncation ~h² = 1e-20,
// rounding ~1e-40/h² = 1e-20 for the nested second differences),
//   Γ_a,bc = ½ (∂_b g_ac + ∂_c g_ab − ∂_a g_bc),   Γᵃ_bc = (g⁻¹)^ad Γ_d,bc,
//   Rᵃ_bcd = ∂_c Γᵃ_db − ∂_d Γᵃ_cb + Γᵃ_ce Γᵉ_db − Γᵃ_de Γᵉ_cb,   R_abcd = g_ae Rᵉ_bcd,
//   K_ab = R_cbda q̇ᶜq̇ᵈ − (∂_b Q_a − Γᶜ_ba Q_c),  Q_a = F_a − ∂V/∂qᵃ,  V = −L(q, 0).
// Every component of Γ (both kinds), R and K is compared, not only those hamel reports as non-zero. Models:
// the double pendulum, the rigid body in ZYX Euler angles (3-D, quasi-velocities ≠ rates), the spherical
// pendulum (constant curvature, known exactly), the forced pendulum and a rod on a gimbal given by `bodies`
// (tests/generator/riemann_models); flat metrics (Cartesian particles: no Γ, no R; polar coordinates: Γ ≠ 0,
// R = 0 exactly).
#include "algebra/identity_test.hpp"
#include "derive/riemann.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using GiNaC::ex;
using GiNaC::numeric;

std::string source(const std::string& relative) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/" + relative;
}

using Tensor2 = std::vector<std::vector<numeric>>;
using Tensor3 = std::vector<Tensor2>;

numeric number(const ex& e) {
  const ex v = e.evalf();
  if (!GiNaC::is_a<numeric>(v)) {
    std::ostringstream text;
    text << "not a number: " << v;
    throw std::runtime_error(text.str());
  }
  return GiNaC::ex_to<numeric>(v);
}

// The reference: everything from the inlined Lagrangian, by plain GiNaC and central differences.
class Reference {
 public:
  explicit Reference(const hamel::Model& model) : model_(model), n_(static_cast<unsigned>(model.n())) {
    for (const auto& p : model.parameters) parameters_[p.symbol] = numeric(p.default_value);
    GiNaC::exmap to_rates;
    for (unsigned a = 0; a < n_; ++a) {
      ex u = 0;
      for (unsigned b = 0; b < n_; ++b) u += model.definitions.inline_all(model.A(a, b)) * model.rates[b];
      to_rates[model.quasi_velocities[a]] = u;
    }
    const ex lagrangian = model.definitions.inline_all(model.lagrangian).subs(to_rates);
    GiNaC::exmap at_rest;
    for (const auto& r : model.rates) at_rest[r] = 0;
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b)
        metric_.push_back(lagrangian.diff(model.rates[a]).diff(model.rates[b]).subs(at_rest).subs(parameters_));
    potential_ = (-lagrangian.subs(at_rest)).subs(parameters_);
    for (const ex& f : model.forces)
      forces_.push_back(model.definitions.inline_all(f).subs(to_rates).subs(parameters_));
  }

  Tensor2 metric(const std::vector<numeric>& q) const {
    const GiNaC::exmap at = point(q);
    Tensor2 g(n_, std::vector<numeric>(n_));
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b) g[a][b] = number(metric_[a * n_ + b].subs(at));
    return g;
  }

  // ∂_c g_ab by central differences: d[c][a][b].
  Tensor3 metric_derivative(const std::vector<numeric>& q) const {
    Tensor3 d(n_);
    for (unsigned c = 0; c < n_; ++c) {
      const Tensor2 plus = metric(shifted(q, c, h_)), minus = metric(shifted(q, c, -h_));
      d[c] = Tensor2(n_, std::vector<numeric>(n_));
      for (unsigned a = 0; a < n_; ++a)
        for (unsigned b = 0; b < n_; ++b) d[c][a][b] = (plus[a][b] - minus[a][b]) / (2 * h_);
    }
    return d;
  }

  // Γ_a,bc: first[a][b][c].
  Tensor3 first_kind(const std::vector<numeric>& q) const {
    const Tensor3 d = metric_derivative(q);
    Tensor3 first(n_, Tensor2(n_, std::vector<numeric>(n_)));
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b)
        for (unsigned c = 0; c < n_; ++c) first[a][b][c] = (d[b][a][c] + d[c][a][b] - d[a][b][c]) / 2;
    return first;
  }

  // Γᵃ_bc: second[a][b][c], with g⁻¹ by GiNaC's numeric inverse.
  Tensor3 second_kind(const std::vector<numeric>& q) const {
    const Tensor3 first = first_kind(q);
    const Tensor2 g = metric(q);
    GiNaC::matrix G(n_, n_);
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b) G(a, b) = g[a][b];
    const GiNaC::matrix inverse = G.inverse();
    Tensor3 second(n_, Tensor2(n_, std::vector<numeric>(n_)));
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b)
        for (unsigned c = 0; c < n_; ++c) {
          numeric s = 0;
          for (unsigned d = 0; d < n_; ++d) s += number(inverse(a, d)) * first[d][b][c];
          second[a][b][c] = s;
        }
    return second;
  }

  // R_abcd, lowered with g.
  std::vector<Tensor3> curvature(const std::vector<numeric>& q) const {
    const Tensor3 second = second_kind(q);
    const Tensor2 g = metric(q);
    std::vector<Tensor3> dsecond(n_);  // ∂_c Γᵃ_bc: dsecond[c][a][b][d]
    for (unsigned c = 0; c < n_; ++c) {
      const Tensor3 plus = second_kind(shifted(q, c, h_)), minus = second_kind(shifted(q, c, -h_));
      dsecond[c] = Tensor3(n_, Tensor2(n_, std::vector<numeric>(n_)));
      for (unsigned a = 0; a < n_; ++a)
        for (unsigned b = 0; b < n_; ++b)
          for (unsigned d = 0; d < n_; ++d) dsecond[c][a][b][d] = (plus[a][b][d] - minus[a][b][d]) / (2 * h_);
    }
    std::vector<Tensor3> upper(n_, Tensor3(n_, Tensor2(n_, std::vector<numeric>(n_))));  // Rᵃ_bcd
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b)
        for (unsigned c = 0; c < n_; ++c)
          for (unsigned d = 0; d < n_; ++d) {
            numeric r = dsecond[c][a][d][b] - dsecond[d][a][c][b];
            for (unsigned e = 0; e < n_; ++e)
              r += second[a][c][e] * second[e][d][b] - second[a][d][e] * second[e][c][b];
            upper[a][b][c][d] = r;
          }
    std::vector<Tensor3> lower(n_, Tensor3(n_, Tensor2(n_, std::vector<numeric>(n_))));
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b)
        for (unsigned c = 0; c < n_; ++c)
          for (unsigned d = 0; d < n_; ++d) {
            numeric r = 0;
            for (unsigned e = 0; e < n_; ++e) r += g[a][e] * upper[e][b][c][d];
            lower[a][b][c][d] = r;
          }
    return lower;
  }

  // Q_a = F_a − ∂V/∂qᵃ at (q, t).
  std::vector<numeric> forces(const std::vector<numeric>& q, const numeric& t) const {
    std::vector<numeric> Q(n_);
    for (unsigned a = 0; a < n_; ++a) {
      GiNaC::exmap at = point(q);
      at[model_.time] = t;
      const numeric plus = number(potential_.subs(point(shifted(q, a, h_)))),
                    minus = number(potential_.subs(point(shifted(q, a, -h_))));
      Q[a] = number(forces_[a].subs(at)) - (plus - minus) / (2 * h_);
    }
    return Q;
  }

  // K_ab = R_cbda q̇ᶜq̇ᵈ − (∂_b Q_a − Γᶜ_ba Q_c).
  Tensor2 stiffness(const std::vector<numeric>& q, const std::vector<numeric>& rate, const numeric& t) const {
    const std::vector<Tensor3> R = curvature(q);
    const Tensor3 second = second_kind(q);
    const std::vector<numeric> Q = forces(q, t);
    Tensor2 K(n_, std::vector<numeric>(n_));
    for (unsigned a = 0; a < n_; ++a)
      for (unsigned b = 0; b < n_; ++b) {
        const std::vector<numeric> Qp = forces(shifted(q, b, h_), t), Qm = forces(shifted(q, b, -h_), t);
        numeric k = -(Qp[a] - Qm[a]) / (2 * h_);
        for (unsigned c = 0; c < n_; ++c) {
          k += second[c][b][a] * Q[c];
          for (unsigned d = 0; d < n_; ++d) k += R[c][b][d][a] * rate[c] * rate[d];
        }
        K[a][b] = k;
      }
    return K;
  }

  GiNaC::exmap point(const std::vector<numeric>& q) const {
    GiNaC::exmap at;
    for (unsigned a = 0; a < n_; ++a) at[model_.coordinates[a]] = q[a];
    return at;
  }

  const GiNaC::exmap& parameters() const { return parameters_; }

 private:
  static std::vector<numeric> shifted(std::vector<numeric> q, unsigned k, const numeric& by) {
    q[k] += by;
    return q;
  }
  const hamel::Model& model_;
  unsigned n_;
  numeric h_ = numeric(1, 10000000000);
  GiNaC::exmap parameters_;
  std::vector<ex> metric_;
  ex potential_;
  std::vector<ex> forces_;
};

// Largest |a − b| over a scale max(|b|) (at least 1e-300) for flat lists of numbers.
struct Comparison {
  double worst = 0, scale = 1e-300;
  void add(const numeric& got, const numeric& want) {
    worst = std::max(worst, std::abs((got - want).to_double()));
    scale = std::max(scale, std::abs(want.to_double()));
  }
  double relative() const { return worst / std::max(scale, 1e-12); }
};

class Digits40 : public ::testing::Test {
 protected:
  void SetUp() override { saved_ = GiNaC::Digits, GiNaC::Digits = 40; }
  void TearDown() override { GiNaC::Digits = saved_; }
  long saved_ = 17;
};

using RiemannAgainstFiniteDifferences = Digits40;

// Γ (both kinds), R (all n⁴ components) and K at three points of each model.
void check_model(const std::string& file, double tolerance) {
  SCOPED_TRACE(file);
  const hamel::Model model = hamel::load_model(source(file));
  hamel::Intermediates program = model.definitions;
  const hamel::RiemannGeometry geometry = hamel::derive_riemann(model, program);
  const Reference reference(model);
  const unsigned n = static_cast<unsigned>(model.n());
  Comparison metric, first, second, curvature, stiffness;
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<numeric> q(n), rate(n);
    for (unsigned a = 0; a < n; ++a) {
      q[a] = numeric(3 + 4 * trial + 5 * static_cast<int>(a), 17) + numeric(trial, 7);  // away from the poles
      rate[a] = numeric(static_cast<int>(a) - 1 + trial, 3);
    }
    const numeric t(trial, 5);
    GiNaC::exmap at = reference.parameters();
    for (unsigned a = 0; a < n; ++a) at[model.coordinates[a]] = q[a], at[model.rates[a]] = rate[a];
    at[model.time] = t;
    at = program.evaluate(at);
    const auto value = [&](const ex& e) { return number(e.subs(at)); };

    const Tensor2 g = reference.metric(q);
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b < n; ++b) metric.add(value(geometry.metric(a, b)), g[a][b]);

    const Tensor3 first_reference = reference.first_kind(q), second_reference = reference.second_kind(q);
    Tensor3 first_hamel(n, Tensor2(n, std::vector<numeric>(n, 0))), second_hamel = first_hamel;
    for (const auto& c : geometry.first_kind)
      first_hamel[c.index][c.b][c.c] = first_hamel[c.index][c.c][c.b] = value(c.value);
    for (const auto& c : geometry.second_kind)
      second_hamel[c.index][c.b][c.c] = second_hamel[c.index][c.c][c.b] = value(c.value);
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b < n; ++b)
        for (unsigned c = 0; c < n; ++c) {
          first.add(first_hamel[a][b][c], first_reference[a][b][c]);
          second.add(second_hamel[a][b][c], second_reference[a][b][c]);
        }

    const std::vector<Tensor3> R = reference.curvature(q);
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b < n; ++b)
        for (unsigned c = 0; c < n; ++c)
          for (unsigned d = 0; d < n; ++d)
            curvature.add(value(hamel::curvature_component(geometry, static_cast<int>(a), static_cast<int>(b),
                                                           static_cast<int>(c), static_cast<int>(d))),
                          R[a][b][c][d]);

    const Tensor2 K = reference.stiffness(q, rate, t);
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b < n; ++b) stiffness.add(value(geometry.stiffness(a, b)), K[a][b]);
  }
  std::cout << "[ measured ] " << file << ": relative error g " << metric.relative() << ", Gamma_a,bc "
            << first.relative() << ", Gamma^a_bc " << second.relative() << ", R_abcd "
            << (curvature.scale > 1e-6 ? curvature.relative() : curvature.worst)
            << (curvature.scale > 1e-6 ? "" : " (absolute: flat)") << ", K " << stiffness.relative() << "\n";
  EXPECT_LT(metric.relative(), tolerance);
  EXPECT_LT(first.relative(), tolerance);
  EXPECT_LT(second.relative(), tolerance);
  EXPECT_LT(stiffness.relative(), tolerance);
  // A flat metric's R is compared absolutely (its scale is rounding).
  EXPECT_LT(curvature.scale > 1e-6 ? curvature.relative() : curvature.worst, tolerance);
}

TEST_F(RiemannAgainstFiniteDifferences, DoublePendulum) { check_model("models/double_pendulum.yaml", 1e-14); }

TEST_F(RiemannAgainstFiniteDifferences, RigidBodyInEulerAngles) {
  check_model("models/rigid_body_euler_zyx.yaml", 1e-14);
}

TEST_F(RiemannAgainstFiniteDifferences, SphericalPendulum) {
  check_model("tests/generator/riemann_models/spherical_pendulum.yaml", 1e-14);
}

TEST_F(RiemannAgainstFiniteDifferences, ForcedPendulumWithQuasiVelocitiesAndDefinitions) {
  check_model("tests/generator/riemann_models/forced_pendulum.yaml", 1e-14);
}

// T assembled from `bodies` through intermediates that depend on the rates.
TEST_F(RiemannAgainstFiniteDifferences, GimballedRodFromBodies) {
  check_model("tests/generator/riemann_models/gimballed_rod.yaml", 1e-14);
}

TEST_F(RiemannAgainstFiniteDifferences, FlatMetrics) {
  check_model("tests/generator/riemann_models/polar_oscillator.yaml", 1e-14);
  check_model("tests/generator/riemann_models/two_particles.yaml", 1e-14);
}

// Known answers, decided exactly (algebra/identity_test): the sphere of radius r with mass m has the metric
// m r² (dθ² + sin²θ dφ²), constant curvature 1/(m r²), R_θφθφ = m r² sin²θ; Γ^θ_φφ = −sin θ cos θ,
// Γ^φ_θφ = cos θ / sin θ.
TEST(RiemannKnownAnswers, SphereHasConstantPositiveCurvature) {
  const hamel::Model model = hamel::load_model(source("tests/generator/riemann_models/spherical_pendulum.yaml"));
  hamel::Intermediates program = model.definitions;
  const hamel::RiemannGeometry r = hamel::derive_riemann(model, program);
  const GiNaC::symtab s = model.symbols();
  const ex m = s.at("m"), radius = s.at("r"), theta = s.at("theta");
  ASSERT_EQ(r.curvature.size(), 1u);
  EXPECT_EQ(hamel::identically_zero(r.curvature[0].value - m * radius * radius * pow(sin(theta), 2), program),
            hamel::Identity::zero);
  ASSERT_EQ(r.second_kind.size(), 2u);  // Γ^θ_(φ,φ) and Γ^φ_(θ,φ)
  EXPECT_EQ(r.second_kind[0].index, 0);
  EXPECT_EQ(hamel::identically_zero(r.second_kind[0].value + sin(theta) * cos(theta), program), hamel::Identity::zero);
  EXPECT_EQ(hamel::identically_zero(r.second_kind[1].value * sin(theta) - cos(theta), program), hamel::Identity::zero);
}

TEST(RiemannKnownAnswers, PolarCoordinatesOfThePlaneAreFlatWithNonZeroChristoffelSymbols) {
  const hamel::Model model = hamel::load_model(source("tests/generator/riemann_models/polar_oscillator.yaml"));
  hamel::Intermediates program = model.definitions;
  const hamel::RiemannGeometry r = hamel::derive_riemann(model, program);
  const ex rho = model.symbols().at("rho");
  EXPECT_TRUE(r.curvature.empty());
  ASSERT_EQ(r.second_kind.size(), 2u);
  // Γ^ρ_(φ,φ) = −ρ, Γ^φ_(ρ,φ) = 1/ρ.
  EXPECT_EQ(r.second_kind[0].index, 0);
  EXPECT_EQ(r.second_kind[0].b, 1);
  EXPECT_EQ(hamel::identically_zero(r.second_kind[0].value + rho, program), hamel::Identity::zero);
  EXPECT_EQ(r.second_kind[1].index, 1);
  EXPECT_EQ(hamel::identically_zero(r.second_kind[1].value * rho - 1, program), hamel::Identity::zero);
}

TEST(RiemannKnownAnswers, CartesianParticlesHaveNoConnectionAndNoCurvature) {
  const hamel::Model model = hamel::load_model(source("tests/generator/riemann_models/two_particles.yaml"));
  hamel::Intermediates program = model.definitions;
  const hamel::RiemannGeometry r = hamel::derive_riemann(model, program);
  EXPECT_TRUE(r.first_kind.empty());
  EXPECT_TRUE(r.second_kind.empty());
  EXPECT_TRUE(r.curvature.empty());
  for (unsigned a = 0; a < 6; ++a)
    for (unsigned b = 0; b < 6; ++b) EXPECT_TRUE(r.connection_rate(a, b).is_zero());
}

}  // namespace
