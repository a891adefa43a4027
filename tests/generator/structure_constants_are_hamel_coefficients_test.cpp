// Proof of Lemma lemKiCon (and the remark before gammaRight): in canonical coordinates s on G the
// Hamel coefficients (gamma) of the left-invariant velocity ξ̂ = g⁻¹ġ are the structure constants,
// γ^α_βλ = +c^α_βλ, and those of the right-invariant ξ̂ = ġg⁻¹ are −c^α_βλ. The velocities are built here
// from explicit group matrices (group_charts.hpp: ZYX Euler angles, position), the coefficients by the
// core path (derive_quasi_velocities, hamel_coefficients) and c by structure_constants(lie_algebra(...)),
// which works from the generator's matrix basis; the difference must simplify to exactly zero.
#include "group_charts.hpp"

#include "algebra/simplify.hpp"
#include "derive/hamel_coefficients.hpp"
#include "derive/quasi_velocities.hpp"
#include "lie/lie_algebra.hpp"

#include <gtest/gtest.h>

#include <map>
#include <tuple>

namespace {

using Key = std::tuple<int, int, int>;

// A core model on G alone: coordinates s, quasi-velocities ξ = A_s(s) ṡ with B_s given (so that
// derive_quasi_velocities checks A B = I exactly).
hamel::Model model_on_group(const hamel::test::GroupChart& chart) {
  hamel::Model model;
  model.name = "chart";
  model.source_path = "chart";
  for (std::size_t k = 0; k < chart.s.size(); ++k) {
    model.coordinates.push_back(chart.s[k]);
    model.rates.emplace_back(chart.s[k].get_name() + "_dot");
    model.quasi_velocities.emplace_back("xi" + std::to_string(k));
  }
  model.A = chart.A;
  model.B = chart.B;
  model.B_given = true;
  model.lagrangian = 0;
  return model;
}

std::map<Key, GiNaC::ex> core_gamma(const hamel::test::GroupChart& chart) {
  const hamel::Model model = model_on_group(chart);
  const hamel::QuasiVelocities qv = hamel::derive_quasi_velocities(model);
  std::map<Key, GiNaC::ex> out;
  for (const auto& g : hamel::hamel_coefficients(model, qv)) out[{g.upper, g.lower_a, g.lower_b}] = g.value;
  return out;
}

void expect_gamma_is_signed_c(const std::string& group, bool right, std::size_t expected_nonzero) {
  SCOPED_TRACE(group + (right ? " right" : " left"));
  const hamel::test::GroupChart chart = hamel::test::group_chart(group, right);
  const std::map<Key, GiNaC::ex> gamma = core_gamma(chart);
  std::map<Key, GiNaC::ex> expected;
  for (const auto& c : hamel::structure_constants(hamel::lie_algebra(group)))
    expected[{c.upper, c.lower_a, c.lower_b}] = (right ? -1 : 1) * c.value;
  ASSERT_EQ(chart.s.size(), hamel::lie_algebra(group).dim());
  // Non-abelian groups must give something to compare (guards against an empty/empty pass).
  EXPECT_EQ(expected.size(), expected_nonzero);
  std::map<Key, GiNaC::ex> all = gamma;
  all.insert(expected.begin(), expected.end());
  for (const auto& [key, unused] : all) {
    (void)unused;
    const GiNaC::ex got = gamma.count(key) ? gamma.at(key) : GiNaC::ex(0);
    const GiNaC::ex want = expected.count(key) ? expected.at(key) : GiNaC::ex(0);
    EXPECT_TRUE(hamel::is_zero_almost_surely(got - want))
        << "gamma^" << std::get<0>(key) << "_" << std::get<1>(key) << "," << std::get<2>(key) << " = " << got
        << ", expected " << want;
  }
}

TEST(StructureConstantsAreHamelCoefficients, SO3) {
  expect_gamma_is_signed_c("SO3", false, 6);
  expect_gamma_is_signed_c("SO3", true, 6);
}

TEST(StructureConstantsAreHamelCoefficients, SE3) {
  // so(3) brackets (6) and [ω, v] (ω × v: 6 pairs of (β, λ) in both orders → 12).
  expect_gamma_is_signed_c("SE3", false, 18);
  expect_gamma_is_signed_c("SE3", true, 18);
}

TEST(StructureConstantsAreHamelCoefficients, SO3xR3) {
  expect_gamma_is_signed_c("SO3xR3", false, 6);
  expect_gamma_is_signed_c("SO3xR3", true, 6);
}

TEST(StructureConstantsAreHamelCoefficients, SE2) {
  expect_gamma_is_signed_c("SE2", false, 4);
  expect_gamma_is_signed_c("SE2", true, 4);
}

// The spatial-velocity chart is not the body one: with right = false the coefficients of the right chart
// must come out as −c, i.e. the comparison can fail (this is what a sign error would look like).
TEST(StructureConstantsAreHamelCoefficients, LeftAndRightChartsDifferInSign) {
  const hamel::test::GroupChart right = hamel::test::group_chart("SE3", true);
  const std::map<Key, GiNaC::ex> gamma = core_gamma(right);
  int compared = 0;
  for (const auto& c : hamel::structure_constants(hamel::lie_algebra("SE3"))) {
    const Key key{c.upper, c.lower_a, c.lower_b};
    ASSERT_TRUE(gamma.count(key));
    EXPECT_FALSE(hamel::is_zero_almost_surely(gamma.at(key) - c.value));
    ++compared;
  }
  EXPECT_EQ(compared, 18);
}

}  // namespace
