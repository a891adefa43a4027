// Import errors that a new user hit without a way forward now say which elements and what to do: an MJCF whose free
// body floats while other bodies hang from the world by joints (the "hammock" humanoid: a floating torso and a
// world-jointed hammock) names those bodies and the two ways to one base.
#include "run_hamel.hpp"

#include <gtest/gtest.h>

namespace {

using namespace hamel_test;

TEST(ImportSaysHowToGoOn, AFloatingBodyBesideWorldJointedBodiesNamesThemAndTheWaysForward) {
  const fs::path dir = scratch_dir("import_hammock");
  spit(dir / "hammock.xml",
       "<mujoco model=\"hammock\">\n"
       "  <worldbody>\n"
       "    <body name=\"torso\"><freejoint name=\"root\"/>"
       "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body>\n"
       "    <body name=\"post\"><joint name=\"sway\" type=\"hinge\" axis=\"0 1 0\"/>"
       "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/>\n"
       "      <body name=\"net\" pos=\"0 0 -0.5\"><joint name=\"swing\" type=\"hinge\" axis=\"1 0 0\"/>"
       "<geom type=\"sphere\" size=\"0.1\" mass=\"1\" contype=\"0\" conaffinity=\"0\"/></body></body>\n"
       "  </worldbody>\n"
       "</mujoco>\n");
  const Outcome r = hamel(
      "import " + shell_quote((dir / "hammock.xml").string()) + " -o " + shell_quote((dir / "out.yaml").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("hammock.xml:3:"), std::string::npos) << r.err;  // the free body's line
  EXPECT_NE(r.err.find("'post' hangs from the world"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("'net'"), std::string::npos) << r.err;  // net hangs from post, not from the world
  EXPECT_NE(r.err.find("remove the free joint"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("under the floating body"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.yaml"));
  fs::remove_all(dir);
}

}  // namespace
