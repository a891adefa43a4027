// The rolling ball of paper Sec. 4 (uaBall) in Euler angles plus contact point: the Hamel coefficients
// are exact symbolic values (γ^u3_{vy vx} = 1/R², γ^u3_{vx vy} = −1/R², γ^α_βλ = −ε_αβλ for the
// spatial angular velocity), and the mass matrix is (7/5) m I (m δ_IJ + Θ A A: the paper's
// (HEBall) prints m − ΘAA).
#include "derive/derivation.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>

namespace {

TEST(RollingBall, HamelCoefficientsAndMassMatrixAreExact) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  const hamel::Model model = hamel::load_model(std::string(dir ? dir : ".") + "/models/rolling_ball.yaml");
  const hamel::Derivation d = hamel::derive(model);
  std::map<std::string, GiNaC::ex> gamma;
  auto name = [&](int a) { return model.quasi_velocities[static_cast<std::size_t>(a)].get_name(); };
  for (const auto& g : d.system.gamma) gamma[name(g.upper) + "_" + name(g.lower_a) + "_" + name(g.lower_b)] = g.value;

  GiNaC::ex R;
  for (const auto& p : model.parameters)
    if (p.symbol.get_name() == "R") R = p.symbol;
  ASSERT_TRUE(gamma.count("u3_vy_vx"));
  EXPECT_TRUE((gamma["u3_vy_vx"] - 1 / (R * R)).is_zero()) << gamma["u3_vy_vx"];
  EXPECT_TRUE((gamma["u3_vx_vy"] + 1 / (R * R)).is_zero()) << gamma["u3_vx_vy"];
  EXPECT_EQ(gamma.count("u1_vx_vy") + gamma.count("u2_vx_vy"), 0u);  // only α = 3 is curved

  const char* omega[3] = {"u1", "u2", "u3"};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) {
        const int epsilon = (a == b || b == c || a == c) ? 0 : (((b - a + 3) % 3 == 1) ? 1 : -1);
        const std::string key = std::string(omega[c]) + "_" + omega[a] + "_" + omega[b];
        const GiNaC::ex value = gamma.count(key) ? gamma[key] : GiNaC::ex(0);
        EXPECT_EQ(value, GiNaC::ex(-epsilon)) << "gamma^" << key;
      }

  GiNaC::ex m;
  for (const auto& p : model.parameters)
    if (p.symbol.get_name() == "m") m = p.symbol;
  const GiNaC::matrix& M = d.equations.mass_matrix;
  EXPECT_TRUE((M(0, 0) - GiNaC::numeric(7, 5) * m).is_zero()) << M(0, 0);
  EXPECT_TRUE((M(1, 1) - GiNaC::numeric(7, 5) * m).is_zero()) << M(1, 1);
  EXPECT_TRUE(M(0, 1).is_zero());
}

}  // namespace
