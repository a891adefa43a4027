// The emitted kernels of models/four_bar.yaml (three angles, two holonomic loop constraints, every parameter symbolic),
// compiled as firmware compiles them, against the four-bar written out by hand (four_bar_reference.hpp: the
// Euler-Lagrange equations with Lagrange multipliers for the loop, solved with Eigen; nothing of hamel):
//  (a) at random states on the loop, `rhs` gives the loop's velocities (kinematics) and the crank's acceleration of
//      the KKT system, at the default and at other parameter values; `energy` is T + V;
//  (b) `constraint_position` and `constraint_position_jacobian` are g and G (and G is the derivative of g);
//      `constraint_residual` is the velocity residual (zero) then g;
//  (c) integrated with the runtime's dopri5 and the projector on these kernels, the motion over 5 s is the KKT system's
//      (integrated on its own at tight tolerance), with the energy conserved and the loop closed at rounding level;
//  (d) without the projector, at the default tolerance, the loop opens by orders of magnitude more than with it (what
//      the projector is for).
#include "four_bar.hpp"
#include "four_bar_reference.hpp"

#include "hamel/runtime/dop853.hpp"
#include "hamel/runtime/dopri5.hpp"
#include "hamel/runtime/projection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace {

namespace ref = four_bar_reference;

static_assert(four_bar::n_coordinates == 3 && four_bar::n_independent == 1 && four_bar::n_state == 4);
static_assert(four_bar::n_out_constraint_position == 2 && four_bar::n_out_constraint_position_jacobian == 6);

double relative(double a, double b) { return std::fabs(a - b) / std::max(1.0, std::fabs(b)); }

TEST(FourBar, RhsMatchesLagrangeMultipliersOnTheLoop) {
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-20.0, 20.0), scale(0.8, 1.25);
  double worst_velocity = 0, worst_acceleration = 0, worst_energy = 0;
  for (int trial = 0; trial < 200; ++trial) {
    ref::Parameters p;
    if (trial % 2) {  // other lengths and masses of a crank-rocker (the crank stays the shortest link)
      p.l2 *= scale(rng), p.l3 *= scale(rng), p.m1 *= scale(rng), p.m2 *= scale(rng), p.m3 *= scale(rng);
      p.g *= scale(rng);
    }
    const auto P = p.array();
    const ref::Vector3 q = ref::closed(p, angle(rng));
    ASSERT_LT(ref::loop(p, q).norm(), 1e-15);
    const double w = rate(rng);
    const ref::Vector3 v = ref::velocities(p, q, w);
    const ref::Vector3 a = ref::accelerations(p, q, v);
    const double x[4] = {q[0], q[1], q[2], w};
    double f[4], E;
    four_bar::rhs(0.0, x, P.data(), nullptr, f);
    four_bar::energy(0.0, x, P.data(), nullptr, &E);
    for (int i = 0; i < 3; ++i)
      worst_velocity = std::max(worst_velocity, relative(f[i], v[i]) / std::max(1.0, std::fabs(w)));
    worst_acceleration = std::max(worst_acceleration, std::fabs(f[3] - a[0]) / std::max(1.0, a.norm()));
    worst_energy = std::max(worst_energy, relative(E, ref::energy(p, q, v)));
  }
  std::printf("200 states: velocities %.2e, crank acceleration %.2e, energy %.2e (relative)\n", worst_velocity,
              worst_acceleration, worst_energy);
  EXPECT_LT(worst_velocity, 1e-13);
  EXPECT_LT(worst_acceleration, 1e-11);
  EXPECT_LT(worst_energy, 1e-13);
}

TEST(FourBar, ConstraintKernelsAreTheLoopAndItsJacobian) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  const ref::Parameters p;
  const auto P = p.array();
  for (int trial = 0; trial < 50; ++trial) {
    const ref::Vector3 q(angle(rng), angle(rng), angle(rng));  // anywhere, on the loop or not
    double x[4] = {q[0], q[1], q[2], 3.0};
    double g[2], G[6], residual[4];
    four_bar::constraint_position(0.0, x, P.data(), nullptr, g);
    four_bar::constraint_position_jacobian(0.0, x, P.data(), nullptr, G);
    four_bar::constraint_residual(0.0, x, P.data(), nullptr, residual);
    const ref::Vector2 g_ref = ref::loop(p, q);
    const ref::Jacobian G_ref = ref::loop_jacobian(p, q);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(g[i], g_ref[i], 1e-15);
      EXPECT_NEAR(residual[2 + i], g_ref[i], 1e-15);  // after the two velocity residuals
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(G[i * 3 + a], G_ref(i, a), 1e-15);
    }
    // G q' = 0 for q' = B_I u_I: the velocity residuals are rounding (where G_s is regular).
    EXPECT_LT(std::fabs(residual[0]) + std::fabs(residual[1]), 1e-12);
    // G is the derivative of the constraint_position kernel (central differences).
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-6;
      double plus[4] = {x[0], x[1], x[2], x[3]}, minus[4] = {x[0], x[1], x[2], x[3]}, gp[2], gm[2];
      plus[a] += h;
      minus[a] -= h;
      four_bar::constraint_position(0.0, plus, P.data(), nullptr, gp);
      four_bar::constraint_position(0.0, minus, P.data(), nullptr, gm);
      for (int i = 0; i < 2; ++i) EXPECT_NEAR((gp[i] - gm[i]) / (2 * h), G[i * 3 + a], 1e-9);
    }
  }
}

// The runtime's projector on the emitted kernels, at the default parameters.
struct Kernels {
  const double* p = four_bar::default_parameters;
  void rhs(double t, const double* x, double* f) const { four_bar::rhs(t, x, p, nullptr, f); }
};

auto position = [](double t, const double* x, double* out) {
  four_bar::constraint_position(t, x, four_bar::default_parameters, nullptr, out);
};
auto position_jacobian = [](double t, const double* x, double* out) {
  four_bar::constraint_position_jacobian(t, x, four_bar::default_parameters, nullptr, out);
};
using Projector = hamel::runtime::ConstraintProjector<decltype(position), decltype(position_jacobian)>;

double closure(const double* x) { return ref::loop(ref::Parameters{}, ref::Vector3(x[0], x[1], x[2])).norm(); }

TEST(FourBar, ProjectedMotionIsTheLagrangeMultiplierMotion) {
  const ref::Parameters p;
  const double w0 = 15.0;
  const ref::Vector3 q0 = ref::closed(p, 0.5);
  // The reference: the KKT system in (q, q'), dop853 at 1e-13, observed every 0.5 s.
  auto kkt = [&](double, const double* s, double* f) {
    const ref::Vector3 q(s[0], s[1], s[2]), v(s[3], s[4], s[5]);
    const ref::Vector3 a = ref::accelerations(p, q, v);
    for (int i = 0; i < 3; ++i) f[i] = v[i], f[3 + i] = a[i];
  };
  const ref::Vector3 v0 = ref::velocities(p, q0, w0);
  std::vector<std::vector<double>> reference;
  auto keep = [&](double, const double* s) { reference.emplace_back(s, s + 6); };
  hamel::runtime::Dop853Options tight;
  tight.rtol = tight.atol = 1e-13;
  const auto r =
      hamel::runtime::integrate_dop853(kkt, {q0[0], q0[1], q0[2], v0[0], v0[1], v0[2]}, 0.0, 5.0, tight, 0.5, keep);
  ASSERT_EQ(r.status, hamel::runtime::Status::ok);

  // The emitted rhs in (q, u_I), dopri5 at 1e-12 with the projector.
  std::vector<double> work(hamel::runtime::ProjectionWorkspace::doubles(3, 2));
  Projector project(position, position_jacobian, 3, 2, {work.data(), work.size()});
  const Kernels k;
  std::vector<std::vector<double>> rows;
  double worst_closure = 0, E0 = 0, worst_energy = 0;
  auto observe = [&](double, const double* x) {
    rows.emplace_back(x, x + 4);
    worst_closure = std::max(worst_closure, closure(x));
    const ref::Vector3 q(x[0], x[1], x[2]);
    const double E = ref::energy(p, q, ref::velocities(p, q, x[3]));
    if (rows.size() == 1) E0 = E;
    worst_energy = std::max(worst_energy, std::fabs(E - E0) / std::fabs(E0));
  };
  hamel::runtime::Dopri5Options o;
  o.rtol = o.atol = 1e-12;
  const auto e = hamel::runtime::integrate_dopri5([&](double t, const double* x, double* f) { k.rhs(t, x, f); },
                                                  {q0[0], q0[1], q0[2], w0}, 0.0, 5.0, o, 0.5, observe, project);
  ASSERT_EQ(e.status, hamel::runtime::Status::ok);
  ASSERT_EQ(rows.size(), reference.size());
  double worst = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::fabs(rows[i][a] - reference[i][a]));
    worst = std::max(worst, std::fabs(rows[i][3] - reference[i][3]) / w0);
  }
  std::printf("5 s against the KKT system: max |q - q_ref| %.2e; closure %.2e; energy drift %.2e; %ld projections\n",
              worst, worst_closure, worst_energy, project.stats().projections);
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(worst_closure, 1e-15);
  EXPECT_LT(worst_energy, 1e-10);
}

TEST(FourBar, WithoutTheProjectorTheLoopOpens) {
  const ref::Vector3 q0 = ref::closed(ref::Parameters{}, 0.5);
  const Kernels k;
  auto rhs = [&](double t, const double* x, double* f) { k.rhs(t, x, f); };
  hamel::runtime::Dopri5Options o;
  o.rtol = o.atol = 1e-8;  // hamel simulate's default
  double open = 0, closed = 0;
  hamel::runtime::integrate_dopri5(rhs, {q0[0], q0[1], q0[2], 15.0}, 0.0, 10.0, o, 0.0,
                                   [&](double, const double* x) { open = std::max(open, closure(x)); });
  std::vector<double> work(hamel::runtime::ProjectionWorkspace::doubles(3, 2));
  Projector project(position, position_jacobian, 3, 2, {work.data(), work.size()});
  hamel::runtime::integrate_dopri5(
      rhs, {q0[0], q0[1], q0[2], 15.0}, 0.0, 10.0, o, 0.0,
      [&](double, const double* x) { closed = std::max(closed, closure(x)); }, project);
  std::printf("10 s of dopri5 at 1e-8: the loop opens to %.2e without the projector, %.2e with it\n", open, closed);
  EXPECT_GT(open, 1e-10);
  EXPECT_LT(closed, 1e-15);
}

}  // namespace
