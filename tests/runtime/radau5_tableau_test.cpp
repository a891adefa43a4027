// SPDX-License-Identifier: MIT
// The Radau IIA coefficients of radau5.hpp are the 3-stage collocation method
// of order 5: nodes are row sums, the collocation conditions C(3) and the
// quadrature conditions B(5) hold (B(6) does not), the method is stiffly
// accurate, its stability function is the (2,3) Pade approximant of e^z
// (hence L-stable), gamma0 is the real eigenvalue of A, and the embedded
// error estimator has order 3 exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>

#include "hamel/runtime/radau5.hpp"

namespace {

namespace k = hamel::runtime::detail::radau5;

TEST(RuntimeRadau5Tableau, NodesAreTheRadauPoints) {
  // c1, c2 are the roots of 10 c^2 - 8 c + 1 (the Radau IIA nodes besides 1).
  for (const double c : {k::c1, k::c2}) EXPECT_NEAR(10 * c * c - 8 * c + 1, 0.0, 1e-15) << c;
  EXPECT_EQ(k::c[2], 1.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(k::a[i][0] + k::a[i][1] + k::a[i][2], k::c[i], 1e-15) << "row " << i;
  }
}

// Stage order 3: sum_j a_ij c_j^(q-1) = c_i^q / q for q = 1, 2, 3, i.e. each
// stage integrates quadratics exactly (the collocation conditions C(3)).
TEST(RuntimeRadau5Tableau, CollocationConditionsHold) {
  for (int i = 0; i < 3; ++i) {
    for (int q = 1; q <= 3; ++q) {
      double s = 0.0;
      for (int j = 0; j < 3; ++j) s += k::a[i][j] * std::pow(k::c[j], q - 1);
      EXPECT_NEAR(s, std::pow(k::c[i], q) / q, 1e-15) << "row " << i << ", q " << q;
    }
  }
}

// With C(3), order 5 needs B(5): the weights (the last row, as the method is
// stiffly accurate) integrate polynomials of degree 4 exactly; degree 5 fails,
// so the order is not higher.
TEST(RuntimeRadau5Tableau, QuadratureHasOrderFiveExactly) {
  for (int q = 1; q <= 6; ++q) {
    double s = 0.0;
    for (int j = 0; j < 3; ++j) s += k::a[2][j] * std::pow(k::c[j], q - 1);
    if (q <= 5) {
      EXPECT_NEAR(s, 1.0 / q, 1e-15) << "q " << q;
    } else {
      std::printf("B(6) residual %.3e\n", s - 1.0 / q);
      EXPECT_GT(std::fabs(s - 1.0 / q), 1e-4);
    }
  }
}

// R(z) = 1 + z b^T (I - z A)^-1 1 against the (2,3) Pade approximant of e^z,
// (1 + 2z/5 + z^2/20) / (1 - 3z/5 + 3z^2/20 - z^3/60), the known stability
// function of 3-stage Radau IIA; it vanishes at infinity (L-stability).
std::complex<double> stability(std::complex<double> z) {
  // Solve (I - z A) g = 1 by Cramer's rule (3 x 3).
  std::complex<double> m[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = (i == j ? 1.0 : 0.0) - z * k::a[i][j];
  auto det = [](std::complex<double> x[3][3]) {
    return x[0][0] * (x[1][1] * x[2][2] - x[1][2] * x[2][1]) - x[0][1] * (x[1][0] * x[2][2] - x[1][2] * x[2][0]) +
           x[0][2] * (x[1][0] * x[2][1] - x[1][1] * x[2][0]);
  };
  const std::complex<double> d = det(m);
  std::complex<double> r = 1.0;
  for (int col = 0; col < 3; ++col) {
    std::complex<double> mc[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) mc[i][j] = j == col ? 1.0 : m[i][j];
    r += z * k::a[2][col] * det(mc) / d;
  }
  return r;
}

TEST(RuntimeRadau5Tableau, StabilityFunctionIsThePadeApproximant) {
  for (const std::complex<double> z :
       {std::complex<double>(-1, 0), std::complex<double>(-10, 0), std::complex<double>(0.5, 0),
        std::complex<double>(-3, 7), std::complex<double>(0, 2)}) {
    const std::complex<double> pade =
        (1.0 + 2.0 * z / 5.0 + z * z / 20.0) / (1.0 - 3.0 * z / 5.0 + 3.0 * z * z / 20.0 - z * z * z / 60.0);
    EXPECT_LT(std::abs(stability(z) - pade), 1e-14 * std::abs(pade) + 1e-15) << z;
  }
  // A-stable along the imaginary axis, and L-stable.
  for (double y = 0.1; y < 1e4; y *= 3) EXPECT_LE(std::abs(stability({0, y})), 1.0 + 1e-13) << y;
  EXPECT_LT(std::abs(stability({-1e8, 0})), 1e-7);
}

TEST(RuntimeRadau5Tableau, Gamma0IsTheRealEigenvalueOfA) {
  double m[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = k::a[i][j] - (i == j ? k::gamma0 : 0.0);
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  EXPECT_NEAR(det, 0.0, 1e-16);
  EXPECT_NEAR(k::gamma0, (6.0 + std::cbrt(81.0) - std::cbrt(9.0)) / 30.0, 1e-16);
}

// The estimate gamma0 (h f(t, x) + dd . Z), with Z = h A F, is the difference
// between the Radau solution and y + h (gamma0 f0 + sum_j bhat_j F_j), bhat =
// b + gamma0 A^T dd. That embedded formula (with node 0 added) must integrate
// polynomials of degree 2 exactly but not degree 3: an O(h^4) estimate. In
// terms of dd: delta_q1 + sum_j (dd^T A)_j c_j^(q-1) = 0 exactly for q <= 3.
TEST(RuntimeRadau5Tableau, ErrorEstimatorHasOrderThreeExactly) {
  double ddA[3] = {0, 0, 0};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) ddA[j] += k::dd[i] * k::a[i][j];
  for (int q = 1; q <= 4; ++q) {
    double s = q == 1 ? 1.0 : 0.0;
    for (int j = 0; j < 3; ++j) s += ddA[j] * std::pow(k::c[j], q - 1);
    if (q <= 3) {
      EXPECT_NEAR(s, 0.0, 1e-14) << "q " << q;
    } else {
      std::printf("estimator degree-3 residual %.3e\n", s);
      EXPECT_GT(std::fabs(s), 1e-3);
    }
  }
}

}  // namespace
