// Proposition propHC1 (and Lemma lemKiCon, eqs. gamma41–gamma43): for every shipped bundle model with a
// shape, the same system written in coordinates (s, r) — s canonical coordinates on G (group_charts.hpp,
// built from explicit group matrices), quasi-velocities u^α = A_s(s)^α_β ṡ^β + A^α_I(r) ṙ^I and u^I = ṙ^I,
// q̇ = B u with B = [[B_s, −B_s A], [0, I]] — has core Hamel coefficients (eq. gamma, hamel_coefficients)
// equal to what the bundle derivation reports: γ^α_IJ = curvature B^α_IJ (paper sign), γ^α_Iβ = E^α_βI,
// γ^α_βI = −E^α_βI, γ^α_βλ = ±c^α_βλ, and nothing else. Exact symbolic comparison. The rolling ball is
// also checked across its two shipped descriptions: models/rolling_ball.yaml (core, Euler angles) against
// models/rolling_ball_bundle.yaml (bundle), with the parameters kept symbolic.
#include "group_charts.hpp"
#include "support/command.hpp"

#include "algebra/simplify.hpp"
#include "derive/bundle_connection.hpp"
#include "derive/hamel_coefficients.hpp"
#include "derive/quasi_velocities.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <tuple>
#include <vector>

namespace {

using Key = std::tuple<int, int, int>;
using Coefficients = std::map<Key, GiNaC::ex>;

using hamel::test::source_dir;

hamel::Model fold_all(const hamel::Model& model) {
  std::map<std::string, double> values;
  for (const auto& p : model.parameters) values[p.symbol.get_name()] = p.default_value;
  return hamel::fold_parameters(model, values);
}

// The bundle model in coordinates (s, r) as a core model; `connection` is A^α_I(r) (m × d).
hamel::Model core_model_in_group_coordinates(const hamel::Model& bundle_model, const GiNaC::matrix& connection,
                                             const hamel::test::GroupChart& chart) {
  const unsigned m = static_cast<unsigned>(chart.s.size());
  const unsigned d = static_cast<unsigned>(bundle_model.coordinates.size());
  hamel::Model core;
  core.name = bundle_model.name + "_in_group_coordinates";
  core.source_path = core.name;
  for (unsigned a = 0; a < m; ++a) {
    core.coordinates.push_back(chart.s[a]);
    core.rates.emplace_back(chart.s[a].get_name() + "_dot");
    core.quasi_velocities.emplace_back("u" + std::to_string(a));
  }
  for (unsigned I = 0; I < d; ++I) {
    core.coordinates.push_back(bundle_model.coordinates[I]);
    core.rates.push_back(bundle_model.rates[I]);
    core.quasi_velocities.emplace_back("u_" + bundle_model.coordinates[I].get_name());
  }
  core.A = GiNaC::matrix(m + d, m + d);
  core.B = GiNaC::matrix(m + d, m + d);
  const GiNaC::matrix BsA = chart.B.mul(connection);
  for (unsigned a = 0; a < m; ++a) {
    for (unsigned b = 0; b < m; ++b) {
      core.A(a, b) = chart.A(a, b);
      core.B(a, b) = chart.B(a, b);
    }
    for (unsigned I = 0; I < d; ++I) {
      core.A(a, m + I) = connection(a, I);
      core.B(a, m + I) = -BsA(a, I);
    }
  }
  for (unsigned I = 0; I < d; ++I) core.A(m + I, m + I) = core.B(m + I, m + I) = 1;
  core.B_given = true;  // derive_quasi_velocities checks A B = I exactly
  core.lagrangian = 0;
  return core;
}

Coefficients core_gamma(const hamel::Model& core) {
  const hamel::QuasiVelocities qv = hamel::derive_quasi_velocities(core);
  Coefficients out;
  for (const auto& g : hamel::hamel_coefficients(core, qv)) out[{g.upper, g.lower_a, g.lower_b}] = g.value;
  return out;
}

// What the bundle derivation says the Hamel coefficients of (u^α, ṙ^I) are, indices I → m + I.
Coefficients bundle_gamma(const hamel::BundleGeometry& geo) {
  const int m = static_cast<int>(geo.algebra.dim());
  Coefficients out;
  for (const auto& c : geo.structure_constants)
    out[{c.upper, c.lower_a, c.lower_b}] = geo.trivialization_sign * c.value;
  for (const auto& e : geo.E) {
    out[{e.upper, m + e.lower_b, e.lower_a}] = e.value;   // γ^α_Iβ = E^α_βI
    out[{e.upper, e.lower_a, m + e.lower_b}] = -e.value;  // γ^α_βI = −E^α_βI
  }
  for (const auto& b : geo.curvature) out[{b.upper, m + b.lower_a, m + b.lower_b}] = b.value;
  return out;
}

// Compares every key of either map; returns the number of non-zero coefficients compared.
int expect_same(const Coefficients& got, const Coefficients& want, const GiNaC::exmap& rename = {}) {
  Coefficients all = got;
  all.insert(want.begin(), want.end());
  int nonzero = 0;
  for (const auto& [key, unused] : all) {
    (void)unused;
    const GiNaC::ex g = got.count(key) ? got.at(key) : GiNaC::ex(0);
    const GiNaC::ex w = want.count(key) ? want.at(key).subs(rename) : GiNaC::ex(0);
    EXPECT_TRUE(hamel::is_zero_almost_surely(g - w)) << "gamma^" << std::get<0>(key) << "_" << std::get<1>(key) << ","
                                                     << std::get<2>(key) << ": core " << g << ", bundle " << w;
    if (!hamel::is_zero_almost_surely(w)) ++nonzero;
  }
  return nonzero;
}

// The shipped bundle models with a shape, one test each (so that ctest spreads them over the cores; under the
// sanitizers satellite_se3 alone takes minutes). Tree models (key `tree`) have no hand-written kinetic energy
// and a connection far too large to form symbolically (space_robot); tests/tree checks them against an
// independent Newton-Euler computation.
std::vector<std::string> bundle_models_with_shape() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(source_dir() + "/models")) {
    if (entry.path().extension() != ".yaml") continue;
    const hamel::Model loaded = hamel::load_model(entry.path().string());
    if (loaded.bundle && !loaded.coordinates.empty() && !loaded.bundle->tree) names.push_back(loaded.name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(CurvatureIsHamelCoefficient, TheShippedCurvedModelsAreAmongThoseChecked) {
  const std::vector<std::string> names = bundle_models_with_shape();
  for (const char* name : {"rolling_ball_bundle", "satellite_se3", "satellite_so3xr3"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
}

class ShippedBundleModel : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedBundleModel, CoreCoefficientsAreTheBundleOnesAndCurved) {
  const hamel::Model loaded = hamel::load_model(source_dir() + "/models/" + GetParam() + ".yaml");
  const hamel::Model model = fold_all(loaded);
  const hamel::BundleGeometry geo = hamel::inlined(hamel::derive_bundle_geometry(model));
  const hamel::test::GroupChart chart = hamel::test::group_chart(model.bundle->group, model.bundle->right);
  ASSERT_EQ(chart.s.size(), geo.algebra.dim());
  const hamel::Model core = core_model_in_group_coordinates(model, geo.connection, chart);
  const Coefficients want = bundle_gamma(geo);
  // satellite_se3: 162 non-zero coefficients, satellite_so3xr3: 60, rolling_ball_bundle: 16, snakeboard (its
  // nonholonomic connection): 14.
  EXPECT_GE(expect_same(core_gamma(core), want), 14);
  // The curvature block on its own, so that a missing curvature cannot hide in the other blocks. The shipped
  // bundle models with a shape all have a curved connection (non-abelian G, A ≠ 0).
  int curved = 0;
  for (const auto& b : geo.curvature) {
    EXPECT_FALSE(hamel::is_zero_almost_surely(b.value));
    ++curved;
  }
  EXPECT_GT(curved, 0);
}

INSTANTIATE_TEST_SUITE_P(EveryShippedModelWithShape, ShippedBundleModel,
                         ::testing::ValuesIn(bundle_models_with_shape()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// The rolling ball in its two descriptions: the core model (Euler angles, spatial ω, kinematic
// connection in A) has exactly the Hamel coefficients the bundle model derives, in particular
// γ^u3_(vx,vy) = B^omega_z_(x,y) = −1/R². Parameters stay symbolic (the bundle's R is renamed to the core's).
TEST(CurvatureIsHamelCoefficient, RollingBallCoreModelMatchesBundleModel) {
  const hamel::Model core = hamel::load_model(source_dir() + "/models/rolling_ball.yaml");
  const hamel::Model bundle = hamel::load_model(source_dir() + "/models/rolling_ball_bundle.yaml");
  ASSERT_TRUE(bundle.bundle && bundle.bundle->right);
  const hamel::BundleGeometry geo = hamel::inlined(hamel::derive_bundle_geometry(bundle));
  GiNaC::exmap rename;
  GiNaC::ex R;
  for (const auto& p : bundle.parameters)
    for (const auto& q : core.parameters)
      if (p.symbol.get_name() == q.symbol.get_name()) {
        rename[p.symbol] = q.symbol;
        if (q.symbol.get_name() == "R") R = q.symbol;
      }
  ASSERT_EQ(rename.size(), 2u);

  const Coefficients got = core_gamma(core);
  const Coefficients want = bundle_gamma(geo);
  // 6 (−ε) + E (rows ω_x, ω_y, ω_z coupled to x, y: 8 in both orders) + curvature (2).
  EXPECT_EQ(expect_same(got, want, rename), 16);

  const int u3 = 2, vx = 3, vy = 4;
  ASSERT_TRUE(got.count({u3, vx, vy}));
  GiNaC::ex B_z_xy;
  for (const auto& b : geo.curvature)
    if (b.upper == 2 && b.lower_a == 0 && b.lower_b == 1) B_z_xy = b.value.subs(rename);
  EXPECT_TRUE(hamel::is_zero_almost_surely(got.at({u3, vx, vy}) - B_z_xy)) << got.at({u3, vx, vy}) << " vs " << B_z_xy;
  EXPECT_TRUE(hamel::is_zero_almost_surely(B_z_xy + 1 / (R * R))) << B_z_xy;
}

}  // namespace
