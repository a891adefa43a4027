// SPDX-License-Identifier: MIT
// lu_factor / lu_solve reproduce hand-computed solutions, need their pivoting,
// rebuild P A from the factors, agree with Eigen's partial-pivoting LU on
// random systems, and refuse singular and non-finite matrices.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "hamel/runtime/lu.hpp"

namespace {

using hamel::runtime::lu_factor;
using hamel::runtime::lu_solve;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A zero in the leading position makes elimination without row exchanges
// impossible. b = A (1, 2, 3, 4) worked out by hand: 0+2+6+12, 1+0+3+0,
// 2+2+0+4, 1+2+3+4.
TEST(RuntimeLu, SolvesAHandComputedSystemThatNeedsRowExchanges) {
  std::vector<double> A = {0, 1, 2, 3,  //
                           1, 0, 1, 0,  //
                           2, 1, 0, 1,  //
                           1, 1, 1, 1};
  std::vector<double> b = {20, 4, 8, 10};
  std::vector<int> pivots(4, -1);
  ASSERT_TRUE(lu_factor(A.data(), pivots.data(), 4));
  EXPECT_EQ(pivots[0], 2);  // the largest entry of the first column is the 2 in row 2
  lu_solve(A.data(), pivots.data(), b.data(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(b[i], i + 1.0, 1e-14) << i;
  }
}

// Without pivoting, [[1e-20, 1], [1, 1]] x = (1, 2) gives x0 = 0 (the 1 - 1e20
// swamps everything); the exact solution is x0 = 1 / (1 - 1e-20), x1 = (1 - 2e-20)
// / (1 - 1e-20), i.e. 1 and 1 to double precision.
TEST(RuntimeLu, PartialPivotingSavesATinyLeadingPivot) {
  std::vector<double> A = {1e-20, 1, 1, 1};
  std::vector<double> b = {1, 2};
  int pivots[2];
  ASSERT_TRUE(lu_factor(A.data(), pivots, 2));
  lu_solve(A.data(), pivots, b.data(), 2);
  EXPECT_NEAR(b[0], 1.0, 1e-15);
  EXPECT_NEAR(b[1], 1.0, 1e-15);
}

RowMatrix random_matrix(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RowMatrix M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) M(i, j) = u(rng);
  return M;
}

// The stored factors must satisfy P A = L U, with the swaps replayed in order.
TEST(RuntimeLu, FactorsRebuildThePermutedMatrix) {
  std::mt19937 rng(7);
  for (int n = 1; n <= 9; ++n) {
    const RowMatrix A = random_matrix(n, rng);
    RowMatrix F = A;
    std::vector<int> pivots(static_cast<std::size_t>(n));
    ASSERT_TRUE(lu_factor(F.data(), pivots.data(), n));
    RowMatrix L = RowMatrix::Identity(n, n);
    RowMatrix U = RowMatrix::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        if (j < i) {
          L(i, j) = F(i, j);
          EXPECT_LE(std::fabs(F(i, j)), 1.0) << "multiplier beyond 1: pivoting not partial";
        } else {
          U(i, j) = F(i, j);
        }
      }
    }
    RowMatrix PA = A;
    for (int k = 0; k < n; ++k) PA.row(k).swap(PA.row(pivots[static_cast<std::size_t>(k)]));
    EXPECT_LT((PA - L * U).cwiseAbs().maxCoeff(), 1e-14 * n) << "n = " << n;
  }
}

TEST(RuntimeLu, MatchesEigenOnRandomSystems) {
  std::mt19937 rng(20240607);
  double worst = 0.0;
  for (int n : {1, 2, 3, 5, 8, 13, 30, 150}) {
    for (int trial = 0; trial < 5; ++trial) {
      const RowMatrix A = random_matrix(n, rng);
      Eigen::VectorXd b = Eigen::VectorXd::Random(n);
      const Eigen::VectorXd expected = A.partialPivLu().solve(b);
      RowMatrix F = A;
      std::vector<int> pivots(static_cast<std::size_t>(n));
      ASSERT_TRUE(lu_factor(F.data(), pivots.data(), n)) << "n = " << n;
      lu_solve(F.data(), pivots.data(), b.data(), n);
      // Judged by the residual, which does not depend on the conditioning of
      // the random matrix, and by the agreement with Eigen.
      const Eigen::VectorXd rhs = A * expected;
      const double residual = (A * b - rhs).norm() / (A.norm() * b.norm());
      EXPECT_LT(residual, 1e-14) << "n = " << n;
      const double difference = (b - expected).norm() / expected.norm();
      EXPECT_LT(difference, 1e-10) << "n = " << n;
      worst = std::fmax(worst, difference);
    }
  }
  std::printf("worst relative difference to Eigen PartialPivLU: %.2e\n", worst);
}

TEST(RuntimeLu, RefusesSingularMatrices) {
  // Exactly singular: the second row is twice the first.
  std::vector<double> exact = {1, 2, 2, 4};
  int pivots[3];
  EXPECT_FALSE(lu_factor(exact.data(), pivots, 2));
  // Singular up to rounding: row 2 = 0.1 row 0 + 0.7 row 1, formed in floating
  // point, so elimination leaves a rounding-sized last pivot rather than 0.
  std::vector<double> rounded = {1, 2, 3, 4, 5, 6, 0.1 * 1 + 0.7 * 4, 0.1 * 2 + 0.7 * 5, 0.1 * 3 + 0.7 * 6};
  std::vector<double> copy = rounded;
  EXPECT_FALSE(lu_factor(rounded.data(), pivots, 3));
  // relative_pivot_tolerance = 0 only rejects exact zeros, and this one is not.
  EXPECT_TRUE(lu_factor(copy.data(), pivots, 3, 0.0));
  std::vector<double> zero(9, 0.0);
  EXPECT_FALSE(lu_factor(zero.data(), pivots, 3, 0.0));
}

TEST(RuntimeLu, RefusesNonFiniteEntries) {
  int pivots[2];
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<double> A = {1, 0, 0, bad};
    EXPECT_FALSE(lu_factor(A.data(), pivots, 2)) << bad;
  }
  // Finite entries whose elimination overflows: the multiplier is -1 and the
  // trailing pivot 1.5e308 + 1.5e308 is infinite, which must be refused too.
  std::vector<double> overflow = {1, 1.5e308, -1, 1.5e308};
  EXPECT_FALSE(lu_factor(overflow.data(), pivots, 2, 0.0));
}

TEST(RuntimeLu, EmptyMatrixIsTriviallyFactored) {
  EXPECT_TRUE(lu_factor(nullptr, nullptr, 0));
  lu_solve(nullptr, nullptr, nullptr, 0);
}

}  // namespace
