// The control-loop example (tools/control_loop_example) builds against a freshly emitted package of
// models/satellite_wheels_controlled.yaml alone, with the strict firmware flags, and its 1 kHz wheel-torque
// PD loop brings the satellite from a 0.2 rad attitude error to below 1e-3 rad within 10 s of simulated
// time. Double with g++, float with clang++ (g++ when clang++ is missing).
#include "package_support.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace hamel::package_test {
namespace {

class ControlLoopExample : public ::testing::TestWithParam<std::string> {};

TEST_P(ControlLoopExample, SettlesTheAttitudeWithinTenSeconds) {
  const std::string real = GetParam();
  const std::string cxx = real == "float" && std::string(HAMEL_CLANGXX) != "" ? HAMEL_CLANGXX : HAMEL_GXX;
  Scratch dir("control_loop_" + real);
  const ListedPackage listed = listed_package("satellite_wheels_controlled");
  const Outcome emitted = emit(source(listed.source), listed.flags, dir.path() / "package");
  ASSERT_EQ(emitted.status, 0) << emitted.out;
  const Outcome built = cmake_build(
      source("tools/control_loop_example"), dir.path() / "build", cxx, strict_flags,
      {{"HAMEL_PACKAGE_DIR", (dir.path() / "package").string()}, {"HAMEL_SATELLITE_WHEELS_CONTROLLED_REAL", real}});
  ASSERT_EQ(built.status, 0) << built.out;
  EXPECT_EQ(built.out.find("warning"), std::string::npos) << built.out;

  const Outcome ran = run(quote((dir.path() / "build" / "control_loop").string()) + " 10");
  std::printf("%s", ran.out.c_str());
  EXPECT_EQ(ran.status, 0) << ran.out;
  double error = 1, settled = -1;
  const std::size_t at_error = ran.out.find("final attitude error ");
  const std::size_t at_settled = ran.out.find("settled below 1e-3 rad at t = ");
  ASSERT_NE(at_error, std::string::npos);
  ASSERT_NE(at_settled, std::string::npos);
  ASSERT_EQ(std::sscanf(ran.out.c_str() + at_error, "final attitude error %lf", &error), 1);
  ASSERT_EQ(std::sscanf(ran.out.c_str() + at_settled, "settled below 1e-3 rad at t = %lf", &settled), 1);
  EXPECT_LT(error, 1e-3);
  EXPECT_GT(settled, 0.5);  // it starts at 0.2 rad; the torque limit makes it take a while
  EXPECT_LT(settled, 10.0);
  EXPECT_NE(ran.out.find(std::string("real = ") + real), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Scalars, ControlLoopExample, ::testing::Values("double", "float"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace hamel::package_test
