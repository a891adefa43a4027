// tests/loops/four_bar_weld.yaml: the four-bar closed by a `weld` (the coupler's tip frame held on a massless hub that
// hinges on the rocker's tip), its emitted kernels against the four-bar written out by hand in absolute angles
// (tests/holonomic/four_bar_reference.hpp: Lagrange multipliers, Eigen; nothing of hamel). Joints: crank = theta1,
// coupler = theta2 - theta1, rocker = theta3, hinge = theta2 - theta3 (the hub turns with the coupler).
//  (a) at random states on the loop, `rhs` gives the joints' rates and the independent joint's acceleration;
//  (b) `constraint_position` is the weld's gap (x, y) and sin of the relative turn (rz, zero on the loop).
#include "four_bar_reference.hpp"
#include "four_bar_weld.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace {

namespace ref = four_bar_reference;
namespace fw = four_bar_weld;

static_assert(fw::n_coordinates == 4 && fw::n_independent == 1 && fw::n_out_constraint_position == 3);

Eigen::Vector4d joints(const ref::Vector3& t) { return {t[0], t[1] - t[0], t[2], t[1] - t[2]}; }

TEST(FourBarWeld, RhsMatchesLagrangeMultipliersOnTheLoop) {
  int I = -1;
  for (int a = 0; a < 4; ++a)
    if (std::string(fw::state_names[4]) == std::string(fw::state_names[a]) + "_dot") I = a;
  ASSERT_GE(I, 0) << fw::state_names[4];
  std::printf("independent joint: %s\n", fw::state_names[I]);
  const ref::Parameters p;  // the model's defaults, in the same order (l1, l2, l3, d, m1, m2, m3, g)
  const auto P = p.array();
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20.0, 20.0);
  double worst_velocity = 0, worst_acceleration = 0, worst_g = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const ref::Vector3 theta = ref::closed(p, angle(rng));
    const ref::Vector3 v = ref::velocities(p, theta, rate(rng));
    const ref::Vector3 a = ref::accelerations(p, theta, v);
    const Eigen::Vector4d q = joints(theta), qd = joints(v), qdd = joints(a);
    const double x[5] = {q[0], q[1], q[2], q[3], qd[I]};
    double f[5], g[3];
    fw::rhs(0.0, x, P.data(), nullptr, f);
    fw::constraint_position(0.0, x, P.data(), nullptr, g);
    for (int i = 0; i < 4; ++i)
      worst_velocity = std::max(worst_velocity, std::fabs(f[i] - qd[i]) / std::max(1.0, qd.norm()));
    worst_acceleration = std::max(worst_acceleration, std::fabs(f[4] - qdd[I]) / std::max(1.0, qdd.norm()));
    worst_g = std::max({worst_g, std::fabs(g[0]), std::fabs(g[1]), std::fabs(g[2])});
  }
  std::printf("200 states: velocities %.2e, acceleration %.2e (relative), |g| on the loop %.2e\n", worst_velocity,
              worst_acceleration, worst_g);
  EXPECT_LT(worst_velocity, 1e-13);
  EXPECT_LT(worst_acceleration, 1e-11);
  EXPECT_LT(worst_g, 1e-15);
}

TEST(FourBarWeld, ConstraintPositionIsTheWeldsGap) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  const ref::Parameters p;
  const auto P = p.array();
  for (int trial = 0; trial < 50; ++trial) {
    const double x[5] = {angle(rng), angle(rng), angle(rng), angle(rng), 0.0};
    double g[3];
    fw::constraint_position(0.0, x, P.data(), nullptr, g);
    const ref::Vector2 gap = ref::loop(p, ref::Vector3(x[0], x[0] + x[1], x[2]));
    EXPECT_NEAR(g[0], gap[0], 1e-15);
    EXPECT_NEAR(g[1], gap[1], 1e-15);
    // The turn of the hub's frame relative to the coupler's about z: sin(theta_hub - theta_coupler).
    EXPECT_NEAR(g[2], std::sin((x[2] + x[3]) - (x[0] + x[1])), 1e-15);
  }
}

}  // namespace
