// SPDX-License-Identifier: MIT
// The coupled Munthe-Kaas RK4 (x' = f(t, x) with g' = g hat(xi(t, x)) or
// hat(xi(t, x)) g) converges at order 4 on a problem with a closed-form
// solution in which the group velocity is a function of the integrated state;
// it reproduces integrate_rkmk4 when f = 0 and integrate_rk4 on a trivial
// group; its samples are fourth-order accurate; failures are reported.
//
// The problem: x = (u, w, y) with u' = om w, w' = -om u, y' = y (1 - y), so
// u = sin(om t), w = cos(om t), y = 1 / (1 + 4 exp(-t)). The motion is
// R = Rz(f) Rx(a) with f = s t + u/2, a = 1.2 w + 0.3 y, p = (u, y, t w):
// f' = s + om w / 2, a' = -1.2 om u + 0.3 y (1 - y), p' = (om w, y (1 - y),
// w - t om u), all written in terms of x (not of t alone).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rkmk.hpp"
#include "hamel/runtime/lie/rkmk_coupled.hpp"
#include "hamel/runtime/lie/rn.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "hamel/runtime/lie/so3xr3.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace {

namespace lie = hamel::runtime::lie;
using hamel::runtime::Status;
using lie::integrate_rkmk4;
using lie::integrate_rkmk4_coupled;
using lie::Mat3;
using lie::NoCoupledObserver;
using lie::NoGroupObserver;
using lie::SE3;
using lie::SO3;
using lie::SO3xR3;
using lie::Trivialization;
using lie::Vec3;
using lie::operator*;
using lie::operator+;
using lie::operator-;

Mat3 rot_x(double a) { return {1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a)}; }
Mat3 rot_z(double a) { return {std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1}; }

double frobenius_distance(const Mat3& a, const Mat3& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < 9; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s);
}

void write(const Vec3& a, double* out) {
  for (std::size_t i = 0; i < 3; ++i) out[i] = a[i];
}
void write6(const Vec3& a, const Vec3& b, double* out) {
  write(a, out);
  write(b, out + 3);
}

struct Problem {
  double om = 2.0;    // oscillator frequency
  double spin = 3.0;  // mean spin rate s

  // Reduced dynamics.
  void f(double, const double* x, double* dx) const {
    dx[0] = om * x[1];
    dx[1] = -om * x[0];
    dx[2] = x[2] * (1.0 - x[2]);
  }
  std::vector<double> x_exact(double t) const {
    return {std::sin(om * t), std::cos(om * t), 1.0 / (1.0 + 4.0 * std::exp(-t))};
  }

  // The motion as a function of (t, x).
  double angle_f(double t, const double* x) const { return spin * t + 0.5 * x[0]; }
  double angle_a(const double* x) const { return 1.2 * x[1] + 0.3 * x[2]; }
  double rate_f(const double* x) const { return spin + 0.5 * om * x[1]; }
  double rate_a(const double* x) const { return -1.2 * om * x[0] + 0.3 * x[2] * (1.0 - x[2]); }
  Mat3 R(double t, const double* x) const { return rot_z(angle_f(t, x)) * rot_x(angle_a(x)); }
  Vec3 p(double t, const double* x) const { return {x[0], x[2], t * x[1]}; }
  Vec3 p_dot(double t, const double* x) const { return {om * x[1], x[2] * (1.0 - x[2]), x[1] - t * om * x[0]}; }
  Vec3 body(const double* x) const {
    const double a = angle_a(x), df = rate_f(x);
    return {rate_a(x), df * std::sin(a), df * std::cos(a)};
  }
  Vec3 spatial(double t, const double* x) const {
    const double f = angle_f(t, x), da = rate_a(x);
    return {da * std::cos(f), da * std::sin(f), rate_f(x)};
  }

  // The exact solution.
  Mat3 R_exact(double t) const { return R(t, x_exact(t).data()); }
  Vec3 p_exact(double t) const { return p(t, x_exact(t).data()); }
};

double vector_error(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s);
}

template <class ErrorAt>
void expect_fourth_order(const char* name, ErrorAt error_at, const std::vector<double>& steps) {
  double previous = error_at(steps[0]);
  std::printf("%-40s h=%-8g error=%.3e\n", name, steps[0], previous);
  for (std::size_t i = 1; i < steps.size(); ++i) {
    const double e = error_at(steps[i]);
    const double order = std::log(previous / e) / std::log(steps[i - 1] / steps[i]);
    std::printf("%-40s h=%-8g error=%.3e order=%.3f\n", name, steps[i], e, order);
    EXPECT_NEAR(order, 4.0, 0.3) << name << " at h = " << steps[i];
    previous = e;
  }
}

const std::vector<double> kSteps = {0.1, 0.05, 0.025, 0.0125};
constexpr double kT = 3.0;

TEST(RuntimeRkmkCoupled, ConvergesAtOrderFourWhenTheVelocityIsPartOfTheSolution) {
  const Problem P;
  const std::vector<double> x0 = P.x_exact(0.0);
  auto f = [&](double t, const double* x, double* dx) { P.f(t, x, dx); };

  expect_fourth_order(
      "SO3 left, xi(t, x) body",
      [&](double h) {
        const auto r = integrate_rkmk4_coupled<SO3>(
            Trivialization::left, f, [&](double, const double* x, double* xi) { write(P.body(x), xi); }, P.R_exact(0.0),
            x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
        EXPECT_EQ(r.status, Status::ok);
        return frobenius_distance(r.g, P.R_exact(kT)) + vector_error(r.x, P.x_exact(kT));
      },
      kSteps);
  expect_fourth_order(
      "SO3 right, xi(t, x) spatial",
      [&](double h) {
        const auto r = integrate_rkmk4_coupled<SO3>(
            Trivialization::right, f, [&](double t, const double* x, double* xi) { write(P.spatial(t, x), xi); },
            P.R_exact(0.0), x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
        EXPECT_EQ(r.status, Status::ok);
        return frobenius_distance(r.g, P.R_exact(kT)) + vector_error(r.x, P.x_exact(kT));
      },
      kSteps);
  // The velocity may also read the group element: xi = R^T w_s.
  expect_fourth_order(
      "SO3 left, xi(t, x, R) = R^T w_s",
      [&](double h) {
        const auto r = integrate_rkmk4_coupled<SO3>(
            Trivialization::left, f,
            [&](double t, const double* x, const Mat3& R, double* xi) {
              write(lie::transpose<3>(R) * P.spatial(t, x), xi);
            },
            P.R_exact(0.0), x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
        EXPECT_EQ(r.status, Status::ok);
        return frobenius_distance(r.g, P.R_exact(kT)) + vector_error(r.x, P.x_exact(kT));
      },
      kSteps);

  const SE3::Element g0{P.R_exact(0.0), P.p_exact(0.0)};
  auto se3_error = [&](const auto& r) {
    EXPECT_EQ(r.status, Status::ok);
    const Vec3 dp = r.g.p - P.p_exact(kT);
    return frobenius_distance(r.g.R, P.R_exact(kT)) + std::sqrt(lie::dot(dp, dp)) + vector_error(r.x, P.x_exact(kT));
  };
  expect_fourth_order(
      "SE3 left, body twist (w_b, R^T p')",
      [&](double h) {
        return se3_error(integrate_rkmk4_coupled<SE3>(
            Trivialization::left, f,
            [&](double t, const double* x, double* xi) {
              write6(P.body(x), lie::transpose<3>(P.R(t, x)) * P.p_dot(t, x), xi);
            },
            g0, x0, 0.0, kT, h, 0.0, NoCoupledObserver{}));
      },
      kSteps);
  expect_fourth_order(
      "SE3 right, spatial twist (w_s, p' - w_s x p)",
      [&](double h) {
        return se3_error(integrate_rkmk4_coupled<SE3>(
            Trivialization::right, f,
            [&](double t, const double* x, double* xi) {
              const Vec3 ws = P.spatial(t, x);
              write6(ws, P.p_dot(t, x) - lie::cross(ws, P.p(t, x)), xi);
            },
            g0, x0, 0.0, kT, h, 0.0, NoCoupledObserver{}));
      },
      kSteps);
  expect_fourth_order(
      "SO3xR3 left, (w_b, p')",
      [&](double h) {
        const auto r = integrate_rkmk4_coupled<SO3xR3>(
            Trivialization::left, f,
            [&](double t, const double* x, double* xi) { write6(P.body(x), P.p_dot(t, x), xi); },
            SO3xR3::Element{g0.R, g0.p}, x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
        EXPECT_EQ(r.status, Status::ok);
        const Vec3 dp = r.g.p - P.p_exact(kT);
        return frobenius_distance(r.g.R, P.R_exact(kT)) + std::sqrt(lie::dot(dp, dp)) +
               vector_error(r.x, P.x_exact(kT));
      },
      kSteps);
}

// Reduced dynamics may read the group element (broken symmetry); they are then
// called with the stage elements g_n exp(eta). A spin at the rate x = 2.5
// about the body axis e3 from R0 is R0 Rz(2.5 t): every element f sees must
// satisfy (R0^T R) e3 = e3.
TEST(RuntimeRkmkCoupled, ReducedDynamicsMayReadTheGroupElement) {
  const Mat3 R0 = rot_x(0.4);
  int calls = 0;
  double worst = 0.0;
  auto f = [&](double, const double*, const Mat3& R, double* dx) {
    ++calls;
    const Mat3 Q = lie::transpose<3>(R0) * R;
    worst = std::fmax(worst, std::fabs(Q[8] - 1.0));
    dx[0] = 0.0;
  };
  const auto r = integrate_rkmk4_coupled<SO3>(
      Trivialization::left, f,
      [](double, const double* x, double* xi) {
        write({0.0, 0.0, x[0]}, xi);
      },
      R0, {2.5}, 0.0, 4.0, 0.01, 0.0, NoCoupledObserver{});
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(calls, r.stats.rhs_evals);
  EXPECT_LT(worst, 1e-14);
  EXPECT_LT(frobenius_distance(r.g, R0 * rot_z(10.0)), 1e-12);
}

// With f = 0 the vector part is constant and the group part is exactly
// integrate_rkmk4 with the velocity xi(t, x0): same stages, same arithmetic.
TEST(RuntimeRkmkCoupled, WithoutReducedDynamicsItIsIntegrateRkmk4) {
  const Problem P;
  const std::vector<double> x0 = {0.3, -0.7, 0.5};
  auto zero = [](double, const double*, double* dx) {
    for (int i = 0; i < 3; ++i) dx[i] = 0.0;
  };
  for (Trivialization side : {Trivialization::left, Trivialization::right}) {
    for (double h : {0.1, 0.0123}) {
      // Velocities depending on (t, x).
      auto xi_x = [&](double t, const double* x, double* xi) {
        const Vec3 ws = P.spatial(t, x);
        write6(ws, P.p_dot(t, x) - lie::cross(ws, P.p(t, x)), xi);
      };
      const SE3::Element g0{rot_x(0.2), {0.1, 0.2, 0.3}};
      const auto a = integrate_rkmk4_coupled<SE3>(side, zero, xi_x, g0, x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
      const auto b = integrate_rkmk4<SE3>(
          side, [&](double t, const SE3::Element&, double* xi) { xi_x(t, x0.data(), xi); }, g0, 0.0, kT, h, 0.0,
          NoGroupObserver{});
      ASSERT_EQ(a.status, Status::ok);
      ASSERT_EQ(b.status, Status::ok);
      EXPECT_EQ(a.x, x0);
      EXPECT_EQ(a.stats.steps, b.stats.steps);
      EXPECT_EQ(a.stats.rhs_evals, b.stats.rhs_evals);
      for (std::size_t i = 0; i < 9; ++i) EXPECT_EQ(a.g.R[i], b.g.R[i]);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(a.g.p[i], b.g.p[i]);

      // Velocities depending on the group element as well: xi = R^T w_s.
      auto xi_g = [&](double t, const double* x, const SE3::Element& g, double* xi) {
        write6(lie::transpose<3>(g.R) * P.spatial(t, x), lie::transpose<3>(g.R) * P.p_dot(t, x), xi);
      };
      const auto c = integrate_rkmk4_coupled<SE3>(side, zero, xi_g, g0, x0, 0.0, kT, h, 0.0, NoCoupledObserver{});
      const auto d = integrate_rkmk4<SE3>(
          side, [&](double t, const SE3::Element& g, double* xi) { xi_g(t, x0.data(), g, xi); }, g0, 0.0, kT, h, 0.0,
          NoGroupObserver{});
      ASSERT_EQ(c.status, Status::ok);
      for (std::size_t i = 0; i < 9; ++i) EXPECT_EQ(c.g.R[i], d.g.R[i]);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(c.g.p[i], d.g.p[i]);
    }
  }
}

// On R^k the coupled method is classic RK4 on the stacked state (x, g).
TEST(RuntimeRkmkCoupled, OnRnItIsClassicRk4OnTheStackedState) {
  using R2 = lie::Rn<2>;
  // x' = -x + g1 cannot be written without g, so use x-only velocities:
  // x' = (x1 x2, -x1), g' = (cos(t) x1, x2^2).
  auto f = [](double, const double* x, double* dx) {
    dx[0] = x[0] * x[1];
    dx[1] = -x[0];
  };
  auto xi = [](double t, const double* x, double* v) {
    v[0] = std::cos(t) * x[0];
    v[1] = x[1] * x[1];
  };
  auto stacked = [&](double t, const double* z, double* dz) {
    f(t, z, dz);
    xi(t, z, dz + 2);
  };
  for (Trivialization side : {Trivialization::left, Trivialization::right}) {
    const auto a = integrate_rkmk4_coupled<R2>(side, f, xi, R2::Element{0.1, -0.2}, {0.5, 0.8}, 0.0, 2.0, 0.05, 0.0,
                                               NoCoupledObserver{});
    const auto b = hamel::runtime::integrate_rk4(stacked, {0.5, 0.8, 0.1, -0.2}, 0.0, 2.0, 0.05, 0.0,
                                                 hamel::runtime::NoObserver{});
    ASSERT_EQ(a.status, Status::ok);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(a.x[i], b.x[i], 1e-15);
      EXPECT_NEAR(a.g[i], b.x[2 + i], 1e-15);
    }
    EXPECT_EQ(a.stats.rhs_evals, b.stats.rhs_evals);
  }
}

// Samples between steps interpolate x and the chart coordinate with cubic
// Hermite polynomials: fourth order as well. t0 and t_end are excluded.
TEST(RuntimeRkmkCoupled, SamplesAreFourthOrderAccurate) {
  const Problem P;
  const std::vector<double> x0 = P.x_exact(0.0);
  auto f = [&](double t, const double* x, double* dx) { P.f(t, x, dx); };
  for (Trivialization side : {Trivialization::left, Trivialization::right}) {
    expect_fourth_order(
        side == Trivialization::left ? "SO3 left samples (R and x)" : "SO3 right samples (R and x)",
        [&](double h) {
          double worst = 0.0, last_t = -1.0;
          int samples = 0;
          const auto r = integrate_rkmk4_coupled<SO3>(
              side, f,
              [&](double t, const double* x, double* xi) {
                write(side == Trivialization::left ? P.body(x) : P.spatial(t, x), xi);
              },
              P.R_exact(0.0), x0, 0.0, 2.0, h, 0.0317,
              [&](double t, const double* x, const Mat3& R) {
                EXPECT_GT(t, last_t);
                last_t = t;
                if (t > 0.0 && t < 2.0) {
                  const std::vector<double> xs(x, x + 3);
                  worst = std::fmax(worst, frobenius_distance(R, P.R_exact(t)) + vector_error(xs, P.x_exact(t)));
                }
                ++samples;
              });
          EXPECT_EQ(r.status, Status::ok);
          EXPECT_EQ(samples, 1 + 63 + 1);  // t0, 0.0317 k for k = 1..63, t_end
          return worst;
        },
        kSteps);
  }
}

TEST(RuntimeRkmkCoupled, CountsStepsEvaluationsAndObservations) {
  int observed = 0;
  auto f = [](double, const double* x, double* dx) { dx[0] = -x[0]; };
  auto xi = [](double, const double* x, double* v) { write({0.1, 0.2, x[0]}, v); };
  const auto r = integrate_rkmk4_coupled<SO3>(Trivialization::left, f, xi, SO3::identity(), {1.0}, 0.0, 1.0, 0.1, 0.0,
                                              [&](double, const double*, const Mat3&) { ++observed; });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.t, 1.0);
  EXPECT_EQ(r.stats.steps, 10);
  EXPECT_EQ(r.stats.rhs_evals, 40);
  EXPECT_EQ(observed, 11);
  EXPECT_NEAR(r.x[0], std::exp(-1.0), 1e-6);
  // Backwards in time undoes the motion.
  const auto back =
      integrate_rkmk4_coupled<SO3>(Trivialization::left, f, xi, r.g, r.x, 1.0, 0.0, 0.1, 0.0, NoCoupledObserver{});
  ASSERT_EQ(back.status, Status::ok);
  EXPECT_LT(frobenius_distance(back.g, SO3::identity()), 1e-6);
  EXPECT_NEAR(back.x[0], 1.0, 1e-6);

  // An empty vector part is allowed: the plain reconstruction.
  const auto empty = integrate_rkmk4_coupled<SO3>(
      Trivialization::left, [](double, const double*, double*) {},
      [](double, const double*, double* v) {
        write({0.0, 0.0, 1.0}, v);
      },
      SO3::identity(), {}, 0.0, 1.0, 0.1, 0.0, NoCoupledObserver{});
  ASSERT_EQ(empty.status, Status::ok);
  EXPECT_LT(frobenius_distance(empty.g, rot_z(1.0)), 1e-15);

  // t0 == t_end: one observation, no step.
  observed = 0;
  const auto none = integrate_rkmk4_coupled<SO3>(Trivialization::left, f, xi, SO3::identity(), {1.0}, 2.0, 2.0, 0.1,
                                                 0.0, [&](double, const double*, const Mat3&) { ++observed; });
  EXPECT_EQ(none.status, Status::ok);
  EXPECT_EQ(none.stats.steps, 0);
  EXPECT_EQ(observed, 1);
}

TEST(RuntimeRkmkCoupled, ReportsFailuresWithTheLastFiniteState) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto xi = [](double, const double* x, double* v) { write6({0.1, 0.2, 0.3}, {x[0], 0.0, 0.0}, v); };
  // The reduced dynamics fail after t = 0.5.
  const auto r = integrate_rkmk4_coupled<SE3>(
      Trivialization::left, [&](double t, const double*, double* dx) { dx[0] = t <= 0.5 ? 1.0 : nan; }, xi,
      SE3::identity(), {0.0}, 0.0, 2.0, 0.01, 0.0, NoCoupledObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_TRUE(SE3::is_finite(r.g));
  ASSERT_EQ(r.x.size(), 1u);
  EXPECT_TRUE(std::isfinite(r.x[0]));
  EXPECT_GE(r.t, 0.48);
  EXPECT_LE(r.t, 0.51);
  EXPECT_NEAR(r.x[0], r.t, 1e-12);  // x = t while f = 1

  // The velocity fails after t = 0.5.
  const auto s = integrate_rkmk4_coupled<SO3>(
      Trivialization::right, [](double, const double*, double* dx) { dx[0] = 1.0; },
      [&](double t, const double*, double* v) {
        write({0.0, 0.0, t <= 0.5 ? 1.0 : nan}, v);
      },
      SO3::identity(), {0.0}, 0.0, 2.0, 0.01, 0.0, NoCoupledObserver{});
  EXPECT_EQ(s.status, Status::non_finite_state);
  EXPECT_GE(s.t, 0.48);
  EXPECT_LE(s.t, 0.51);
  EXPECT_LT(frobenius_distance(s.g, rot_z(s.t)), 1e-12);

  auto f0 = [](double, const double*, double* dx) { dx[0] = 0.0; };
  auto xi0 = [](double, const double*, double* v) { write({0.0, 0.0, 1.0}, v); };
  EXPECT_EQ(integrate_rkmk4_coupled<SO3>(Trivialization::left, f0, xi0, SO3::identity(), {nan}, 0.0, 1.0, 0.1, 0.0,
                                         NoCoupledObserver{})
                .status,
            Status::non_finite_state);
  EXPECT_EQ(integrate_rkmk4_coupled<SO3>(Trivialization::left, f0, xi0, Mat3{nan, 0, 0, 0, 1, 0, 0, 0, 1}, {0.0}, 0.0,
                                         1.0, 0.1, 0.0, NoCoupledObserver{})
                .status,
            Status::non_finite_state);
  EXPECT_EQ(integrate_rkmk4_coupled<SO3>(Trivialization::left, f0, xi0, SO3::identity(), {0.0}, 0.0, 1.0, 0.0, 0.0,
                                         NoCoupledObserver{})
                .status,
            Status::invalid_argument);
  EXPECT_EQ(integrate_rkmk4_coupled<SO3>(Trivialization::left, f0, xi0, SO3::identity(), {0.0}, 0.0, 1.0, 1e-16, 0.0,
                                         NoCoupledObserver{})
                .status,
            Status::too_many_steps);
}

}  // namespace
