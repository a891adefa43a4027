// singular_tree_joint (model/physical_checks.hpp): a tree's mass matrix singular at every configuration is found at
// the joint whose articulated-body pivot vanishes, and a long regular chain is not taken for singular. The pivots are
// judged relative to what each joint moves; in world coordinates about the world's origin the inertias of bodies
// 1000 m out were 1e6 and rounded a zero pivot to 2e-11 of that, while a regular 10 000-link chain has pivots of 5e-10
// of it: both are decided right only with each body's inertia held about its own joint.
#include "model/physical_checks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

using hamel::NumericTreeBody;

NumericTreeBody link(int parent, double mass, double inertia) {
  NumericTreeBody b;
  b.parent = parent;
  b.axis[0] = 0, b.axis[1] = 1, b.axis[2] = 0;
  b.offset[2] = parent < 0 ? 0 : 0.1;
  b.mass = mass;
  for (int i = 0; i < 3; ++i) b.inertia[i][i] = inertia;
  return b;
}

// R = Rz(yaw) Ry(pitch) Rx(roll), as URDF's rpy.
void turn(NumericTreeBody& b, double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch), cy = std::cos(yaw),
               sy = std::sin(yaw);
  const double R[3][3] = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                          {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                          {-sp, cp * sr, cp * cr}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) b.rotation[i][j] = R[i][j];
}

// n links 0.1 apart on hinges about y, each a unit mass on its hinge with unit inertia: a straight chain 1000 m long
// at 10 000 links (tests/generator/inputs_are_bounded_test.cpp imports such a chain), or, `curled`, each joint frame
// turned by rpy (0.1, 0.2, 0.3) with the centre of mass off the axis.
std::vector<NumericTreeBody> chain(int n, bool curled) {
  std::vector<NumericTreeBody> bodies;
  for (int k = 0; k < n; ++k) {
    bodies.push_back(link(k - 1, 1, 1));
    if (curled) {
      turn(bodies.back(), 0.1, 0.2, 0.3);
      bodies.back().com[0] = 0.05, bodies.back().com[2] = 0.03;
    }
  }
  return bodies;
}

TEST(SingularTreeJoint, ALongRegularChainIsRegular) {
  EXPECT_EQ(hamel::singular_tree_joint(chain(10000, false)), -1);
  EXPECT_EQ(hamel::singular_tree_joint(chain(10000, true)), -1);
}

TEST(SingularTreeJoint, CoaxialHingesAtTheTipOfALongChainAreFound) {
  std::vector<NumericTreeBody> bodies = chain(10000, true);
  NumericTreeBody spacer = link(9999, 0, 0), tip = link(10000, 2, 1);
  spacer.offset[0] = 0.7, spacer.offset[1] = 0.2;
  spacer.axis[0] = 0.6, spacer.axis[1] = 0, spacer.axis[2] = 0.8;
  turn(spacer, 0.3, 0.1, 0.2);
  tip.com[0] = 0.3, tip.com[1] = 0.1, tip.com[2] = 0.2;
  tip.offset[0] = tip.offset[1] = tip.offset[2] = 0;  // the same axis through the same point
  tip.axis[0] = 0.6, tip.axis[1] = 0, tip.axis[2] = 0.8;
  bodies.push_back(spacer);
  bodies.push_back(tip);
  EXPECT_EQ(hamel::singular_tree_joint(bodies), 10000);
  // With an armature on the spacer's joint it is regular again.
  bodies[10000].armature = 0.01;
  EXPECT_EQ(hamel::singular_tree_joint(bodies), -1);
}

TEST(SingularTreeJoint, AFloatingBaseWithoutMassIsFoundInItsFirstTranslation) {
  std::vector<NumericTreeBody> bodies{link(-1, 0, 2)};  // a massless rotor with rotational inertia
  NumericTreeBody base = link(-1, 0, 1);
  int direction = -1;
  EXPECT_EQ(hamel::singular_tree_joint(bodies, &base, {0, 1, 2, 3, 4, 5}, &direction), -2);
  EXPECT_EQ(direction, 3);  // vx
  base.mass = 5;
  EXPECT_EQ(hamel::singular_tree_joint(bodies, &base, {0, 1, 2, 3, 4, 5}, &direction), -1);
}

}  // namespace
