// Conservative scenes keep their energy: the emitted rhs integrated with dopri5 (rtol = atol = 1e-10) over
// 100 s, the emitted energy kernel sampled every 0.1 s, relative drift below 1e-8. Ideal constraints do no
// work, so this holds for the non-holonomic sleigh, disk and ball (inputs zero) as for the double pendulum;
// a wrong sign of a Hamel-coefficient term (gamma) or of a force breaks it.
//
// The Chaplygin sleigh is also checked against facts derived by hand, not by the generator: with zero
// inputs E = ½ m v² + ½ (J + m a²) ω² is constant, v never decreases (v̇ = a ω²), and for t → ∞ the yaw rate
// dies out, ω → 0, while v → +sqrt(v0² + (J + m a²)/m ω0²) by energy conservation, whatever the sign of v0.
// The decay of ω is exponential with rate m a v∞ / (J + m a²) (≈ 2.3 /s here), so after 100 s ω is zero to
// the integrator's tolerance.
#include "compiled_models.hpp"

#include "hamel/runtime/dopri5.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

namespace {

using hamel::test::CompiledModel;

struct Scene {
  std::string label, model;
  std::vector<double> x0;  // (q, u_I)
};

void PrintTo(const Scene& s, std::ostream* os) { *os << s.label; }

hamel::runtime::Dopri5Options tolerances() {
  hamel::runtime::Dopri5Options opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-10;
  return opt;
}

class EnergyConservation : public ::testing::TestWithParam<Scene> {};

TEST_P(EnergyConservation, EmittedEnergyDriftsLessThan1e8Over100s) {
  const Scene& scene = GetParam();
  const CompiledModel& cm = hamel::test::compiled_model(scene.model);
  ASSERT_EQ(scene.x0.size(), static_cast<std::size_t>(cm.n_coordinates + cm.n_independent));
  const std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
  const std::vector<double> in(static_cast<std::size_t>(std::max(cm.n_inputs, 1)), 0.0);  // no inputs: conservative

  auto energy = [&](double t, const double* x) {
    double e = 0;
    cm.energy(t, x, p.data(), in.data(), &e);
    return e;
  };
  const double e0 = energy(0.0, scene.x0.data());
  ASSERT_GT(std::fabs(e0), 1e-3) << "scene without energy proves nothing";

  double worst_drift = 0;
  int samples = 0;
  const auto rhs = [&](double t, const double* x, double* xdot) { cm.rhs(t, x, p.data(), in.data(), xdot); };
  const auto observe = [&](double t, const double* x) {
    worst_drift = std::max(worst_drift, std::fabs(energy(t, x) - e0) / std::fabs(e0));
    ++samples;
  };
  const auto result = hamel::runtime::integrate_dopri5(rhs, scene.x0, 0.0, 100.0, tolerances(), 0.1, observe);
  ASSERT_EQ(result.status, hamel::runtime::Status::ok);
  EXPECT_EQ(samples, 1001);
  EXPECT_LT(worst_drift, 1e-8) << scene.label;

  // The scene must move, or energy conservation is trivial.
  double travelled = 0;
  for (int a = 0; a < cm.n_coordinates; ++a)
    travelled =
        std::max(travelled, std::fabs(result.x[static_cast<std::size_t>(a)] - scene.x0[static_cast<std::size_t>(a)]));
  EXPECT_GT(travelled, 1.0) << scene.label;

  std::printf("[measured] %s: E0 = %.6g, max |E - E0| / |E0| over 100 s = %.3g (%ld steps)\n", scene.label.c_str(), e0,
              worst_drift, result.stats.steps);
}

// The ball rolls 0.6 rad off the y axis from the identity orientation, so its Euler angle theta stays
// within ±0.6 rad, away from the ZYX singularity, for all time.
INSTANTIATE_TEST_SUITE_P(
    ConservativeScenes, EnergyConservation,
    ::testing::Values(
        Scene{"double_pendulum", "double_pendulum", {1.0, -0.5, 0.0, 0.0}},
        Scene{"rolling_ball", "rolling_ball", {0.0, 0.0, 0.0, 0.0, 0.0, 0.3 * std::sin(0.6), -0.3 * std::cos(0.6)}},
        Scene{"chaplygin_sleigh", "chaplygin_sleigh", {0.0, 0.0, 0.0, 0.5, 2.0}},
        Scene{"chaplygin_sleigh_reversing", "chaplygin_sleigh", {0.0, 0.0, 0.0, -0.5, 2.0}},
        Scene{"rolling_disk", "rolling_disk", {0.0, 0.0, 0.0, 0.0, 0.7, 3.0}}),
    [](const ::testing::TestParamInfo<Scene>& info) { return info.param.label; });

// The double pendulum's energy written out by hand (potential zero at the pivot) equals the emitted one.
TEST(EnergyConservation, DoublePendulumEnergyIsKineticPlusPotential) {
  const CompiledModel& cm = hamel::test::compiled_model("double_pendulum");
  const std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);
  const double m1 = p[0], m2 = p[1], l1 = p[2], l2 = p[3], g = p[4];
  const std::vector<std::vector<double>> states = {
      {1.0, -0.5, 0.0, 0.0}, {0.3, 2.0, -1.5, 0.7}, {-2.5, 0.1, 3.0, -4.0}};
  for (const auto& x : states) {
    double e = 0, dummy_input = 0;
    cm.energy(0.0, x.data(), p.data(), &dummy_input, &e);
    const double T = 0.5 * (m1 + m2) * l1 * l1 * x[2] * x[2] + 0.5 * m2 * l2 * l2 * x[3] * x[3] +
                     m2 * l1 * l2 * x[2] * x[3] * std::cos(x[0] - x[1]);
    const double V = -(m1 + m2) * g * l1 * std::cos(x[0]) - m2 * g * l2 * std::cos(x[1]);
    EXPECT_NEAR(e, T + V, 1e-12 * std::max({1.0, std::fabs(T), std::fabs(V)}));
  }
}

class SleighInvariants : public ::testing::TestWithParam<double> {};

TEST_P(SleighInvariants, EnergyConstantAndAsymptoticsHold) {
  const CompiledModel& cm = hamel::test::compiled_model("chaplygin_sleigh");
  ASSERT_EQ(cm.n_coordinates, 3);
  ASSERT_EQ(cm.n_independent, 2);  // state (x, y, theta, v, omega)
  const std::vector<double> p(cm.default_parameters, cm.default_parameters + cm.n_parameters);  // m, J, a
  const double m = p[0], J = p[1], a = p[2];
  const std::vector<double> in(static_cast<std::size_t>(cm.n_inputs), 0.0);
  const double v0 = GetParam(), w0 = 2.0;
  const std::vector<double> x0 = {0.3, -0.1, 0.5, v0, w0};

  auto hand_energy = [&](const double* x) { return 0.5 * m * x[3] * x[3] + 0.5 * (J + m * a * a) * x[4] * x[4]; };
  const double e0 = hand_energy(x0.data());
  double worst_drift = 0, worst_vs_emitted = 0, worst_v_decrease = 0, previous_v = v0;
  const auto rhs = [&](double t, const double* x, double* xdot) { cm.rhs(t, x, p.data(), in.data(), xdot); };
  const auto observe = [&](double t, const double* x) {
    const double e = hand_energy(x);
    worst_drift = std::max(worst_drift, std::fabs(e - e0) / e0);
    double emitted = 0;
    cm.energy(t, x, p.data(), in.data(), &emitted);
    worst_vs_emitted = std::max(worst_vs_emitted, std::fabs(emitted - e) / e0);
    worst_v_decrease = std::max(worst_v_decrease, previous_v - x[3]);
    previous_v = x[3];
  };
  const auto result = hamel::runtime::integrate_dopri5(rhs, x0, 0.0, 100.0, tolerances(), 0.1, observe);
  ASSERT_EQ(result.status, hamel::runtime::Status::ok);

  const double v_inf = std::sqrt(v0 * v0 + (J + m * a * a) / m * w0 * w0);
  const double v_end = result.x[3], w_end = result.x[4];
  EXPECT_LT(worst_drift, 1e-8);
  EXPECT_LT(worst_vs_emitted, 1e-12);
  EXPECT_LT(worst_v_decrease, 1e-9) << "v must not decrease: dv/dt = a omega^2";
  EXPECT_LT(std::fabs(w_end), 1e-8) << "omega(100 s)";
  EXPECT_NEAR(v_end, v_inf, 1e-8 * v_inf) << "v(100 s)";

  std::printf(
      "[measured] chaplygin_sleigh v0 = %g, omega0 = %g: hand energy drift %.3g, |E_emitted - E_hand| / E0 %.3g, "
      "omega(100) = %.3g, v(100) - v_inf = %.3g (v_inf = %.12g)\n",
      v0, w0, worst_drift, worst_vs_emitted, w_end, v_end - v_inf, v_inf);
}

// v0 > 0: the sleigh straightens out; v0 < 0: it turns around and ends moving forward.
INSTANTIATE_TEST_SUITE_P(ZeroInputs, SleighInvariants, ::testing::Values(0.5, -0.5),
                         [](const ::testing::TestParamInfo<double>& info) {
                           return std::string(info.param > 0 ? "forward" : "backward") + "_start";
                         });

}  // namespace
