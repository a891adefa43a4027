// SPDX-License-Identifier: MIT
// DriftMonitor keeps the worst deviation, absolute and relative, and never forgets a NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hamel/runtime/monitor.hpp"

namespace {

using hamel::runtime::DriftMonitor;

TEST(RuntimeDriftMonitor, StartsWithoutDeviation) {
  const DriftMonitor m(-4.0);
  EXPECT_EQ(m.initial(), -4.0);
  EXPECT_EQ(m.max_abs_deviation(), 0.0);
  EXPECT_EQ(m.max_relative_deviation(), 0.0);
}

TEST(RuntimeDriftMonitor, KeepsTheWorstDeviationInEitherDirection) {
  DriftMonitor m(-4.0);
  m.update(-4.5);   // 0.5 below
  m.update(-3.0);   // 1.0 above: the worst
  m.update(-4.25);  // smaller again: must not reduce the maximum
  EXPECT_DOUBLE_EQ(m.max_abs_deviation(), 1.0);
  EXPECT_DOUBLE_EQ(m.max_relative_deviation(), 0.25);
}

TEST(RuntimeDriftMonitor, NaNIsSticky) {
  DriftMonitor m(1.0);
  m.update(1.5);
  m.update(std::numeric_limits<double>::quiet_NaN());
  m.update(1.0);
  m.update(3.0);
  EXPECT_TRUE(std::isnan(m.max_abs_deviation()));
  EXPECT_TRUE(std::isnan(m.max_relative_deviation()));
}

TEST(RuntimeDriftMonitor, ZeroInitialValueMakesAnyRelativeDriftHuge) {
  DriftMonitor m(0.0);
  m.update(0.0);
  EXPECT_EQ(m.max_relative_deviation(), 0.0);
  m.update(1e-12);
  EXPECT_DOUBLE_EQ(m.max_abs_deviation(), 1e-12);
  EXPECT_GT(m.max_relative_deviation(), 1e290);
}

}  // namespace
