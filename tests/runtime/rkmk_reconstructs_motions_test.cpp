// SPDX-License-Identifier: MIT
// The Munthe-Kaas RK4 integrator reconstructs known motions on every group:
// exactly (to rounding) for a constant velocity of many thousand turns, and at
// order 4 for time-varying velocities, with both trivializations and with
// velocities that depend on the state. References are closed-form motions
// built from elementary rotations (not from the exp under test).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rkmk.hpp"
#include "hamel/runtime/lie/rn.hpp"
#include "hamel/runtime/lie/se2.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "hamel/runtime/lie/so3xr3.hpp"
#include "hamel/runtime/rk4.hpp"
#include "hamel/runtime/status.hpp"

namespace {

namespace lie = hamel::runtime::lie;
using hamel::runtime::Status;
using lie::integrate_rkmk4;
using lie::Mat3;
using lie::NoGroupObserver;
using lie::SE2;
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

// ------------------------------------------------------------------ motions

// R(t) = Rz(f(t)) Rx(g(t)) with spin rate `spin`: f = spin t + 0.5 sin 2t,
// g = 1.2 sin 1.3t + 0.3 t. Spatial angular velocity w_s = f' e3 + g' Rz(f) e1,
// body angular velocity w_b = R^T w_s = (g', f' sin g, f' cos g).
struct Tumbling {
  double spin = 3.0;
  double f(double t) const { return spin * t + 0.5 * std::sin(2 * t); }
  double df(double t) const { return spin + std::cos(2 * t); }
  double g(double t) const { return 1.2 * std::sin(1.3 * t) + 0.3 * t; }
  double dg(double t) const { return 1.56 * std::cos(1.3 * t) + 0.3; }
  Mat3 R(double t) const { return rot_z(f(t)) * rot_x(g(t)); }
  Vec3 body(double t) const { return {dg(t), df(t) * std::sin(g(t)), df(t) * std::cos(g(t))}; }
  Vec3 spatial(double t) const { return {dg(t) * std::cos(f(t)), dg(t) * std::sin(f(t)), df(t)}; }
};

// Translation p(t) = (sin t, 0.5 t^2 - t, cos 2t).
Vec3 position(double t) { return {std::sin(t), 0.5 * t * t - t, std::cos(2 * t)}; }
Vec3 velocity(double t) { return {std::cos(t), t - 1.0, -2 * std::sin(2 * t)}; }

void write(const Vec3& a, double* out) {
  for (std::size_t i = 0; i < 3; ++i) out[i] = a[i];
}
void write6(const Vec3& a, const Vec3& b, double* out) {
  write(a, out);
  write(b, out + 3);
}

// Fits the order from errors at halving step sizes and checks 4 +- 0.3.
template <class ErrorAt>
void expect_fourth_order(const char* name, ErrorAt error_at, const std::vector<double>& steps) {
  double previous = error_at(steps[0]);
  std::printf("%-34s h=%-8g error=%.3e\n", name, steps[0], previous);
  for (std::size_t i = 1; i < steps.size(); ++i) {
    const double e = error_at(steps[i]);
    const double order = std::log(previous / e) / std::log(steps[i - 1] / steps[i]);
    std::printf("%-34s h=%-8g error=%.3e order=%.3f\n", name, steps[i], e, order);
    EXPECT_NEAR(order, 4.0, 0.3) << name << " at h = " << steps[i];
    previous = e;
  }
}

const std::vector<double> kSteps = {0.1, 0.05, 0.025, 0.0125};
constexpr double kT = 3.0;

// ------------------------------------------------------------------ SO(3)

// 1000 rad/s about a fixed axis for 10 s is 1592 turns. Each step re-centres
// the chart, so the chart coordinate stays at 0.1 or 1 rad and the result is
// exact up to rounding; without re-centring, dexp^-1 would be evaluated at
// 10^4 rad, past its singularities at 2 pi k. The axis (0.6, 0.8, 0) makes
// t w exact in double at t = 10, so exp((6000, 8000, 0)) is the exact answer
// up to its own rounding (sin and cos of 10^4 are correctly rounded).
TEST(RuntimeRkmk, ConstantSpinOfThousandsOfTurnsIsExactToRounding) {
  const Vec3 w = {600.0, 800.0, 0.0};
  const Mat3 exact = SO3::exp({6000.0, 8000.0, 0.0});
  for (Trivialization side : {Trivialization::left, Trivialization::right}) {
    for (double h : {1e-3, 1e-4}) {
      const auto r = integrate_rkmk4<SO3>(
          side, [&](double, const Mat3&, double* xi) { write(w, xi); }, SO3::identity(), 0.0, 10.0, h, 0.0,
          NoGroupObserver{});
      ASSERT_EQ(r.status, Status::ok);
      EXPECT_EQ(r.t, 10.0);
      EXPECT_EQ(r.stats.steps, static_cast<long>(std::lround(10.0 / h)));
      const double e = frobenius_distance(r.g, exact);
      const double orthogonality = frobenius_distance(r.g * lie::transpose<3>(r.g), SO3::identity());
      std::printf("spin 1000 rad/s, 10 s, %s, h=%g: error %.2e, |R R^T - I| %.2e\n",
                  side == Trivialization::left ? "left" : "right", h, e, orthogonality);
      // Rounding can at worst accumulate linearly, a few units of 1e-16 per
      // step; the method itself adds nothing for a constant velocity.
      const double bound = 4e-16 * static_cast<double>(r.stats.steps);
      EXPECT_LT(e, bound);
      EXPECT_LT(orthogonality, bound);
    }
  }
}

TEST(RuntimeRkmk, So3TumblingConvergesAtOrderFour) {
  const Tumbling m;
  auto run = [&](Trivialization side, auto xi, double h) {
    const auto r = integrate_rkmk4<SO3>(side, xi, m.R(0.0), 0.0, kT, h, 0.0, NoGroupObserver{});
    EXPECT_EQ(r.status, Status::ok);
    return frobenius_distance(r.g, m.R(kT));
  };
  // Body velocities, given as functions of time only.
  expect_fourth_order(
      "SO3 left, xi(t)",
      [&](double h) {
        return run(
            Trivialization::left, [&](double t, const Mat3&, double* xi) { write(m.body(t), xi); }, h);
      },
      kSteps);
  // Body velocities computed from the state: xi = R^T w_s(t).
  expect_fourth_order(
      "SO3 left, xi(t, R) = R^T w_s",
      [&](double h) {
        return run(
            Trivialization::left,
            [&](double t, const Mat3& R, double* xi) { write(lie::transpose<3>(R) * m.spatial(t), xi); }, h);
      },
      kSteps);
  expect_fourth_order(
      "SO3 right, xi(t)",
      [&](double h) {
        return run(
            Trivialization::right, [&](double t, const Mat3&, double* xi) { write(m.spatial(t), xi); }, h);
      },
      kSteps);
  expect_fourth_order(
      "SO3 right, xi(t, R) = R w_b",
      [&](double h) {
        return run(
            Trivialization::right, [&](double t, const Mat3& R, double* xi) { write(R * m.body(t), xi); }, h);
      },
      kSteps);
}

// A fast top: 100 rad/s spin with nutation, 1 s (16 turns). The order is
// measured at steps of 0.02 to 0.1 rad of spin per step.
TEST(RuntimeRkmk, FastSpinningTopConvergesAtOrderFour) {
  Tumbling m;
  m.spin = 100.0;
  expect_fourth_order("SO3 left, 100 rad/s top",
                      [&](double h) {
                        const auto r = integrate_rkmk4<SO3>(
                            Trivialization::left, [&](double t, const Mat3&, double* xi) { write(m.body(t), xi); },
                            m.R(0.0), 0.0, 1.0, h, 0.0, NoGroupObserver{});
                        EXPECT_EQ(r.status, Status::ok);
                        return frobenius_distance(r.g, m.R(1.0));
                      },
                      {1e-3, 5e-4, 2.5e-4});
}

// ------------------------------------------------------------------ SE(3), SO(3) x R^3

double se3_error(const SE3::Element& g, double t, const Tumbling& m) {
  const Vec3 dp = g.p - position(t);
  return std::sqrt(frobenius_distance(g.R, m.R(t)) * frobenius_distance(g.R, m.R(t)) + lie::dot(dp, dp));
}

TEST(RuntimeRkmk, Se3ConvergesAtOrderFour) {
  const Tumbling m;
  const SE3::Element g0 = {m.R(0.0), position(0.0)};
  auto run = [&](Trivialization side, auto xi, double h) {
    const auto r = integrate_rkmk4<SE3>(side, xi, g0, 0.0, kT, h, 0.0, NoGroupObserver{});
    EXPECT_EQ(r.status, Status::ok);
    return se3_error(r.g, kT, m);
  };
  // Body twist: (w_b, R^T p').
  expect_fourth_order(
      "SE3 left, body twist",
      [&](double h) {
        return run(
            Trivialization::left,
            [&](double t, const SE3::Element& g, double* xi) {
              write6(m.body(t), lie::transpose<3>(g.R) * velocity(t), xi);
            },
            h);
      },
      kSteps);
  // Spatial twist: (w_s, p' - w_s x p) = (w_s, p' + p x w_s), from time only.
  expect_fourth_order(
      "SE3 right, spatial twist",
      [&](double h) {
        return run(
            Trivialization::right,
            [&](double t, const SE3::Element&, double* xi) {
              write6(m.spatial(t), velocity(t) - lie::cross(m.spatial(t), position(t)), xi);
            },
            h);
      },
      kSteps);
}

TEST(RuntimeRkmk, So3xR3ConvergesAtOrderFour) {
  const Tumbling m;
  const SO3xR3::Element g0 = {m.R(0.0), position(0.0)};
  auto run = [&](Trivialization side, auto xi, double h) {
    const auto r = integrate_rkmk4<SO3xR3>(side, xi, g0, 0.0, kT, h, 0.0, NoGroupObserver{});
    EXPECT_EQ(r.status, Status::ok);
    return se3_error({r.g.R, r.g.p}, kT, m);
  };
  // Direct product: the linear velocity is p' in both trivializations.
  expect_fourth_order(
      "SO3xR3 left",
      [&](double h) {
        return run(
            Trivialization::left,
            [&](double t, const SO3xR3::Element&, double* xi) { write6(m.body(t), velocity(t), xi); }, h);
      },
      kSteps);
  expect_fourth_order(
      "SO3xR3 right",
      [&](double h) {
        return run(
            Trivialization::right,
            [&](double t, const SO3xR3::Element&, double* xi) { write6(m.spatial(t), velocity(t), xi); }, h);
      },
      kSteps);
}

// ------------------------------------------------------------------ SE(2)

// theta(t) = 2t + sin t, p(t) = (cos 1.5t + t, sin t - 0.3 t^2).
TEST(RuntimeRkmk, Se2ConvergesAtOrderFour) {
  auto theta = [](double t) { return 2 * t + std::sin(t); };
  auto dtheta = [](double t) { return 2 + std::cos(t); };
  auto p = [](double t) { return std::array<double, 2>{std::cos(1.5 * t) + t, std::sin(t) - 0.3 * t * t}; };
  auto dp = [](double t) { return std::array<double, 2>{-1.5 * std::sin(1.5 * t) + 1, std::cos(t) - 0.6 * t}; };
  const SE2::Element g0 = {theta(0), p(0)[0], p(0)[1]};
  auto error = [&](const SE2::Element& g) {
    const auto q = p(kT);
    // Compare angles on the circle-free representation: theta is unwrapped.
    return std::sqrt((g.theta - theta(kT)) * (g.theta - theta(kT)) + (g.x - q[0]) * (g.x - q[0]) +
                     (g.y - q[1]) * (g.y - q[1]));
  };
  expect_fourth_order(
      "SE2 left, body twist",
      [&](double h) {
        const auto r = integrate_rkmk4<SE2>(
            Trivialization::left,
            [&](double t, const SE2::Element& g, double* xi) {
              const auto v = dp(t);
              const double c = std::cos(g.theta), s = std::sin(g.theta);
              xi[0] = dtheta(t);
              xi[1] = c * v[0] + s * v[1];  // R^T p'
              xi[2] = -s * v[0] + c * v[1];
            },
            g0, 0.0, kT, h, 0.0, NoGroupObserver{});
        EXPECT_EQ(r.status, Status::ok);
        return error(r.g);
      },
      kSteps);
  expect_fourth_order(
      "SE2 right, spatial twist",
      [&](double h) {
        const auto r = integrate_rkmk4<SE2>(
            Trivialization::right,
            [&](double t, const SE2::Element&, double* xi) {
              const auto v = dp(t), q = p(t);
              xi[0] = dtheta(t);
              xi[1] = v[0] + dtheta(t) * q[1];  // p' - w J p
              xi[2] = v[1] - dtheta(t) * q[0];
            },
            g0, 0.0, kT, h, 0.0, NoGroupObserver{});
        EXPECT_EQ(r.status, Status::ok);
        return error(r.g);
      },
      kSteps);
}

// ------------------------------------------------------------------ R^k

// On R^k the method is classic RK4: it reproduces integrate_rk4 (to rounding)
// on the Riccati equation x' = x^2 cos t, x(0) = 1/2.
TEST(RuntimeRkmk, OnRnItIsClassicRk4) {
  using R1 = lie::Rn<1>;
  auto rhs = [](double t, const double* x, double* f) { f[0] = x[0] * x[0] * std::cos(t); };
  for (double h : {0.1, 0.05}) {
    const auto a = integrate_rkmk4<R1>(
        Trivialization::left, [&](double t, const R1::Element& x, double* xi) { rhs(t, x.data(), xi); },
        R1::Element{0.5}, 0.0, 2.0, h, 0.0, NoGroupObserver{});
    const auto b = hamel::runtime::integrate_rk4(rhs, {0.5}, 0.0, 2.0, h, 0.0, hamel::runtime::NoObserver{});
    ASSERT_EQ(a.status, Status::ok);
    EXPECT_NEAR(a.g[0], b.x[0], 1e-15);
    EXPECT_EQ(a.stats.rhs_evals, b.stats.rhs_evals);
    EXPECT_EQ(a.stats.steps, b.stats.steps);
  }
}

// ------------------------------------------------------------------ sampling, stats, failures

// Samples between steps come from g_n exp(eta(s)) with a cubic Hermite eta;
// they must be fourth-order accurate too. t0 and t_end are excluded so that
// only interpolated samples are judged.
TEST(RuntimeRkmk, SamplesAreFourthOrderAccurate) {
  const Tumbling m;
  for (Trivialization side : {Trivialization::left, Trivialization::right}) {
    expect_fourth_order(
        side == Trivialization::left ? "SO3 left samples" : "SO3 right samples",
        [&](double h) {
          double worst = 0.0;
          int samples = 0;
          double last_t = -1.0;
          const auto r = integrate_rkmk4<SO3>(
              side,
              [&](double t, const Mat3&, double* xi) {
                write(side == Trivialization::left ? m.body(t) : m.spatial(t), xi);
              },
              m.R(0.0), 0.0, 2.0, h, 0.0317,
              [&](double t, const Mat3& R) {
                EXPECT_GT(t, last_t);
                last_t = t;
                if (t > 0.0 && t < 2.0) worst = std::fmax(worst, frobenius_distance(R, m.R(t)));
                ++samples;
              });
          EXPECT_EQ(r.status, Status::ok);
          EXPECT_EQ(samples, 1 + 63 + 1);  // t0, 0.0317 k for k = 1..63, t_end
          return worst;
        },
        kSteps);
  }
}

TEST(RuntimeRkmk, CountsStepsAndVelocityEvaluations) {
  int observed = 0;
  const auto r = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0.1, 0.2, 0.3}, xi);
      },
      SO3::identity(), 0.0, 1.0, 0.1, 0.0, [&](double, const Mat3&) { ++observed; });
  ASSERT_EQ(r.status, Status::ok);
  EXPECT_EQ(r.stats.steps, 10);
  EXPECT_EQ(r.stats.rhs_evals, 40);  // 4 per step: the end velocity is the next step's first stage
  EXPECT_EQ(observed, 11);           // t0 and every step
  // Backwards in time undoes the motion.
  const auto back = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0.1, 0.2, 0.3}, xi);
      },
      r.g, 1.0, 0.0, 0.1, 0.0, NoGroupObserver{});
  ASSERT_EQ(back.status, Status::ok);
  EXPECT_LT(frobenius_distance(back.g, SO3::identity()), 1e-14);  // 20 steps of rounding
}

TEST(RuntimeRkmk, ReportsFailuresInsteadOfReturningNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The velocity is undefined after t = 0.5: stop with the last finite state.
  const auto r = integrate_rkmk4<SE3>(
      Trivialization::left,
      [&](double t, const SE3::Element&, double* xi) {
        for (int i = 0; i < 6; ++i) xi[i] = t <= 0.5 ? 0.3 * (i + 1) : nan;
      },
      SE3::identity(), 0.0, 2.0, 0.01, 0.0, NoGroupObserver{});
  EXPECT_EQ(r.status, Status::non_finite_state);
  EXPECT_TRUE(SE3::is_finite(r.g));
  EXPECT_GE(r.t, 0.48);
  EXPECT_LE(r.t, 0.51);

  const auto bad_start = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0, 0, 1}, xi);
      },
      Mat3{nan, 0, 0, 0, 1, 0, 0, 0, 1}, 0.0, 1.0, 0.1, 0.0, NoGroupObserver{});
  EXPECT_EQ(bad_start.status, Status::non_finite_state);
  EXPECT_EQ(bad_start.stats.steps, 0);

  const auto infinite_velocity = integrate_rkmk4<SO3>(
      Trivialization::right,
      [](double t, const Mat3&, double* xi) {
        write({0, t < 0.3 ? 1.0 : 1.0 / 0.0, 0}, xi);
      },
      SO3::identity(), 0.0, 1.0, 0.1, 0.0, NoGroupObserver{});
  EXPECT_EQ(infinite_velocity.status, Status::non_finite_state);
  EXPECT_TRUE(SO3::is_finite(infinite_velocity.g));

  const auto no_step = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0, 0, 1}, xi);
      },
      SO3::identity(), 0.0, 1.0, 0.0, 0.0, NoGroupObserver{});
  EXPECT_EQ(no_step.status, Status::invalid_argument);

  const auto too_many = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0, 0, 1}, xi);
      },
      SO3::identity(), 0.0, 1e6, 1e-12, 0.0, NoGroupObserver{});
  EXPECT_EQ(too_many.status, Status::too_many_steps);

  int observed = 0;
  const auto empty = integrate_rkmk4<SO3>(
      Trivialization::left,
      [](double, const Mat3&, double* xi) {
        write({0, 0, 1}, xi);
      },
      SO3::identity(), 1.0, 1.0, 0.1, 0.0, [&](double, const Mat3&) { ++observed; });
  EXPECT_EQ(empty.status, Status::ok);
  EXPECT_EQ(observed, 1);
}

}  // namespace
