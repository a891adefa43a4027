// The rotation vector drawn by `hamel phase` on SO(3) (numeric/group_pose.hpp): exp(w) = R at every sample,
// and w continuous through |w| = pi, so a steady spin about a fixed axis gives w = angle * axis for angles
// of many turns, and a spin about a tilted axis stays on that axis.
#include "numeric/group_pose.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using hamel::GroupPose;
using hamel::runtime::lie::SO3;

constexpr double kPi = 3.14159265358979323846;

TEST(RotationVector, SteadySpinUnwrapsThroughPi) {
  const std::array<double, 3> axis{0.36, -0.48, 0.8};  // unit
  std::vector<GroupPose> poses;
  for (int k = 0; k <= 400; ++k) {
    const double angle = -8 * kPi / 3 * k / 400.0;  // 4 cycles of -2 pi / 3: through -pi and -2 pi
    poses.push_back(hamel::pose_of(k / 100.0, SO3::exp({angle * axis[0], angle * axis[1], angle * axis[2]})));
  }
  const auto w = hamel::unwrapped_rotation_vectors(poses);
  ASSERT_EQ(w.size(), poses.size());
  double worst = 0;
  for (std::size_t k = 0; k < w.size(); ++k) {
    const double angle = -8 * kPi / 3 * static_cast<double>(k) / 400.0;
    for (std::size_t i = 0; i < 3; ++i) worst = std::fmax(worst, std::fabs(w[k][i] - angle * axis[i]));
    const auto R = SO3::exp({w[k][0], w[k][1], w[k][2]});
    for (std::size_t i = 0; i < 9; ++i) EXPECT_NEAR(R[i], (*poses[k].R)[i], 1e-12);
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(RotationVector, NearestLogarithmOfOneRotation) {
  // R = Rz(0.5): principal w = (0, 0, 0.5); near (0, 0, 6.5) the nearest is 0.5 + 2 pi; near 0 it is 0.5.
  const auto R = SO3::exp({0, 0, 0.5});
  EXPECT_NEAR(hamel::rotation_vector_near(R, {0, 0, 6.5})[2], 0.5 + 2 * kPi, 1e-13);
  EXPECT_NEAR(hamel::rotation_vector_near(R, {0, 0, 0})[2], 0.5, 1e-13);
  EXPECT_NEAR(hamel::rotation_vector_near(R, {0, 0, -5.5})[2], 0.5 - 2 * kPi, 1e-13);
  // The identity after a whole turn stays at 2 pi about the previous axis.
  const auto I = SO3::exp({0, 0, 0});
  const auto w = hamel::rotation_vector_near(I, {0, 6.2, 0});
  EXPECT_NEAR(w[1], 2 * kPi, 1e-13);
  EXPECT_EQ(w[0], 0.0);
}

}  // namespace
