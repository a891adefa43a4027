// models/four_bar_tree.yaml: the four-bar as a kinematic tree on a fixed base with one `connect` loop (joints crank,
// coupler relative to the crank, rocker), its emitted kernels compiled as firmware compiles them, against the
// four-bar written out by hand in absolute angles (tests/holonomic/four_bar_reference.hpp: Euler-Lagrange equations
// with Lagrange multipliers for the loop, solved with Eigen; nothing of hamel). The joints map to the reference's
// angles by theta1 = crank, theta2 = crank + coupler, theta3 = rocker.
//  (a) at random states on the loop, `rhs` gives the joints' rates (kinematics) and the independent joint's
//      acceleration of the KKT system; `energy` is T + V;
//  (b) `constraint_position` is the loop's gap (the coupler's tip minus the rocker's, x and y: the z equation is
//      dropped) and `constraint_position_jacobian` its derivative;
//  (c) integrated with the runtime's dopri5 and the projector on these kernels, the motion over 5 s is the KKT
//      system's (integrated on its own at tight tolerance), with the loop closed at rounding level.
#include "four_bar_reference.hpp"
#include "four_bar_tree.hpp"

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/projection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

namespace ref = four_bar_reference;
namespace fb = four_bar_tree;

static_assert(fb::n_coordinates == 3 && fb::n_independent == 1 && fb::n_state == 4);
static_assert(fb::n_out_constraint_position == 2 && fb::n_out_constraint_position_jacobian == 6);

// The joint whose rate is the state's velocity (hamel's choice at the initial configuration), from the state names.
int independent_joint() {
  const std::string u = fb::state_names[3];
  for (int a = 0; a < 3; ++a)
    if (u == std::string(fb::state_names[a]) + "_dot") return a;
  ADD_FAILURE() << "the velocity " << u << " is no joint's rate";
  return 0;
}

// Joints (crank, coupler, rocker) from the reference's absolute angles, and back; rates and accelerations alike.
ref::Vector3 joints(const ref::Vector3& theta) { return {theta[0], theta[1] - theta[0], theta[2]}; }
ref::Vector3 absolute(const double* q) { return {q[0], q[0] + q[1], q[2]}; }

// The model's parameters in the order of the emitted kernels, from the reference's.
std::vector<double> parameters(const ref::Parameters& p) {
  std::vector<double> out;
  for (int i = 0; i < fb::n_parameters; ++i) {
    const std::string name = fb::parameter_names[i];
    out.push_back(name == "l1"   ? p.l1
                  : name == "l2" ? p.l2
                  : name == "l3" ? p.l3
                  : name == "d"  ? p.d
                  : name == "m1" ? p.m1
                  : name == "m2" ? p.m2
                  : name == "m3" ? p.m3
                                 : p.g);
  }
  return out;
}

TEST(FourBarTree, RhsMatchesLagrangeMultipliersOnTheLoop) {
  const int I = independent_joint();
  std::printf("independent joint: %s\n", fb::state_names[I]);
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20.0, 20.0), scale(0.8, 1.25);
  double worst_velocity = 0, worst_acceleration = 0, worst_energy = 0;
  for (int trial = 0; trial < 200; ++trial) {
    ref::Parameters p;
    if (trial % 2) p.l2 *= scale(rng), p.l3 *= scale(rng), p.m1 *= scale(rng), p.m2 *= scale(rng), p.g *= scale(rng);
    const std::vector<double> P = parameters(p);
    const ref::Vector3 theta = ref::closed(p, angle(rng));
    const ref::Vector3 v = ref::velocities(p, theta, rate(rng));
    const ref::Vector3 a = ref::accelerations(p, theta, v);
    const ref::Vector3 q = joints(theta), qd = joints(v), qdd = joints(a);
    const double x[4] = {q[0], q[1], q[2], qd[I]};
    double f[4], E;
    fb::rhs(0.0, x, P.data(), nullptr, f);
    fb::energy(0.0, x, P.data(), nullptr, &E);
    const double speed = std::max(1.0, qd.norm());
    for (int i = 0; i < 3; ++i) worst_velocity = std::max(worst_velocity, std::fabs(f[i] - qd[i]) / speed);
    worst_acceleration = std::max(worst_acceleration, std::fabs(f[3] - qdd[I]) / std::max(1.0, qdd.norm()));
    const double E_ref = ref::energy(p, theta, v);
    worst_energy = std::max(worst_energy, std::fabs(E - E_ref) / std::max(1.0, std::fabs(E_ref)));
  }
  std::printf("200 states: velocities %.2e, acceleration %.2e, energy %.2e (relative)\n", worst_velocity,
              worst_acceleration, worst_energy);
  EXPECT_LT(worst_velocity, 1e-13);
  EXPECT_LT(worst_acceleration, 1e-11);
  EXPECT_LT(worst_energy, 1e-13);
}

TEST(FourBarTree, ConstraintKernelsAreTheLoopAndItsJacobian) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  const ref::Parameters p;
  const std::vector<double> P = parameters(p);
  for (int trial = 0; trial < 50; ++trial) {
    const double x[4] = {angle(rng), angle(rng), angle(rng), 3.0};  // anywhere, on the loop or not
    double g[2], G[6];
    fb::constraint_position(0.0, x, P.data(), nullptr, g);
    fb::constraint_position_jacobian(0.0, x, P.data(), nullptr, G);
    const ref::Vector2 g_ref = ref::loop(p, absolute(x));
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(g[i], g_ref[i], 1e-15);
    for (int a = 0; a < 3; ++a) {  // central differences of the reference's gap in the joints
      const double h = 1e-6;
      double plus[3] = {x[0], x[1], x[2]}, minus[3] = {x[0], x[1], x[2]};
      plus[a] += h, minus[a] -= h;
      const ref::Vector2 d = (ref::loop(p, absolute(plus)) - ref::loop(p, absolute(minus))) / (2 * h);
      for (int i = 0; i < 2; ++i) EXPECT_NEAR(G[i * 3 + a], d[i], 1e-9);
    }
  }
}

TEST(FourBarTree, ProjectedMotionIsTheLagrangeMultiplierMotion) {
  const int I = independent_joint();
  const ref::Parameters p;
  const std::vector<double> P = parameters(p);
  const ref::Vector3 theta0 = ref::closed(p, 0.5);
  const ref::Vector3 v0 = ref::velocities(p, theta0, 15.0);
  // The reference: the KKT system in absolute angles, dop853 at 1e-13, observed every 0.5 s.
  auto kkt = [&](double, const double* s, double* f) {
    const ref::Vector3 q(s[0], s[1], s[2]), v(s[3], s[4], s[5]);
    const ref::Vector3 a = ref::accelerations(p, q, v);
    for (int i = 0; i < 3; ++i) f[i] = v[i], f[3 + i] = a[i];
  };
  std::vector<std::vector<double>> reference;
  hamel::runtime::Dop853Options tight;
  tight.rtol = tight.atol = 1e-13;
  const auto r =
      hamel::runtime::integrate_dop853(kkt, {theta0[0], theta0[1], theta0[2], v0[0], v0[1], v0[2]}, 0.0, 5.0, tight,
                                       0.5, [&](double, const double* s) { reference.emplace_back(s, s + 6); });
  ASSERT_EQ(r.status, hamel::runtime::Status::ok);

  // The emitted rhs in (q, u_I), dopri5 at 1e-12 with the projector on the emitted constraint kernels.
  auto position = [&](double t, const double* x, double* out) {
    fb::constraint_position(t, x, P.data(), nullptr, out);
  };
  auto jacobian = [&](double t, const double* x, double* out) {
    fb::constraint_position_jacobian(t, x, P.data(), nullptr, out);
  };
  std::vector<double> work(hamel::runtime::ProjectionWorkspace::doubles(3, 2));
  hamel::runtime::ConstraintProjector<decltype(position), decltype(jacobian)> project(position, jacobian, 3, 2,
                                                                                      {work.data(), work.size()});
  const ref::Vector3 q0 = joints(theta0), u0 = joints(v0);
  std::vector<std::vector<double>> rows;
  double worst_closure = 0;
  hamel::runtime::Dopri5Options o;
  o.rtol = o.atol = 1e-12;
  const auto e = hamel::runtime::integrate_dopri5(
      [&](double t, const double* x, double* f) { fb::rhs(t, x, P.data(), nullptr, f); }, {q0[0], q0[1], q0[2], u0[I]},
      0.0, 5.0, o, 0.5,
      [&](double, const double* x) {
        rows.emplace_back(x, x + 4);
        worst_closure = std::max(worst_closure, ref::loop(p, absolute(x)).norm());
      },
      project);
  ASSERT_EQ(e.status, hamel::runtime::Status::ok);
  ASSERT_EQ(rows.size(), reference.size());
  double worst = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const ref::Vector3 q = joints(ref::Vector3(reference[i][0], reference[i][1], reference[i][2]));
    const ref::Vector3 v = joints(ref::Vector3(reference[i][3], reference[i][4], reference[i][5]));
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::fabs(rows[i][a] - q[a]));
    worst = std::max(worst, std::fabs(rows[i][3] - v[I]) / 15.0);
  }
  std::printf("5 s against the KKT system: max |q - q_ref| %.2e; closure %.2e; %ld projections\n", worst, worst_closure,
              project.stats().projections);
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(worst_closure, 1e-14);
}

}  // namespace
