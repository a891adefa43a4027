// SPDX-License-Identifier: MIT
// hamel::runtime::rk4_step is the text every emitted package prints as its rk4_step (the generator's build reads it out
// of rk4.hpp). One step is the classical RK4 step: exact for x' = a cubic in t (Simpson's rule, so its stages are taken
// at t, t + h/2 and t + h, with p and in passed to each), and the degree-4 Taylor polynomial of exp(hA) for a linear
// system x' = A x; in float as in double.
#include <gtest/gtest.h>

#include <cmath>

#include "hamel/runtime/rk4.hpp"

namespace {

// x' = t^3 - p[0] t + in[0].
template <class real>
void cubic(real t, const real*, const real* p, const real* in, real* out) {
  out[0] = t * t * t - p[0] * t + in[0];
}
template <class real>
real cubic_integral(real a, real b, real p, real in) {
  const auto F = [&](real t) { return t * t * t * t / 4 - p * t * t / 2 + in * t; };
  return F(b) - F(a);
}

// The oscillator x0' = x1, x1' = -p[0] x0.
void oscillator(double, const double* x, const double* p, const double*, double* out) {
  out[0] = x[1];
  out[1] = -p[0] * x[0];
}

TEST(RuntimeRk4Step, IsExactForACubicInTime) {
  const double p = 2.0, in = 0.25, t = 0.5, h = 0.1;
  double x = 1.5;
  hamel::runtime::rk4_step<double, 1, cubic<double>>(t, h, &x, &p, &in);
  EXPECT_NEAR(x, 1.5 + cubic_integral(t, t + h, p, in), 1e-15);

  const float pf = 2.0f, inf = 0.25f;
  float xf = 1.5f;
  hamel::runtime::rk4_step<float, 1, cubic<float>>(0.5f, 0.1f, &xf, &pf, &inf);
  EXPECT_NEAR(xf, 1.5f + cubic_integral(0.5f, 0.6f, pf, inf), 1e-6f);
}

TEST(RuntimeRk4Step, IsTheTaylorPolynomialOfTheExponentialForALinearSystem) {
  const double w2 = 3.0, h = 0.2;
  double x[2] = {0.7, -0.4};
  hamel::runtime::rk4_step<double, 2, oscillator>(0.0, h, x, &w2, nullptr);
  // sum_k (hA)^k x0 / k! for k <= 4, with A = [[0, 1], [-w2, 0]]: A^2 = -w2 I.
  const double x0 = 0.7, v0 = -0.4, a = h * h * w2;
  const double c = 1 - a / 2 + a * a / 24, s = h * (1 - a / 6);  // even and odd parts
  EXPECT_NEAR(x[0], c * x0 + s * v0, 1e-15);
  EXPECT_NEAR(x[1], c * v0 - w2 * s * x0, 1e-15);
}

}  // namespace
