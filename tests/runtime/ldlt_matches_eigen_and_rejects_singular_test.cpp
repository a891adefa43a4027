// SPDX-License-Identifier: MIT
// ldlt_solve agrees with Eigen's Cholesky and LU solvers on random symmetric
// positive definite systems and refuses singular, indefinite and non-finite ones.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "hamel/runtime/ldlt.hpp"

namespace {

using hamel::runtime::ldlt_solve;
using hamel::runtime::Status;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Well-conditioned SPD matrix: B B^T is positive semidefinite, the shift makes it definite.
RowMatrix random_spd(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RowMatrix B(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) B(i, j) = u(rng);
  return B * B.transpose() + n * RowMatrix::Identity(n, n);
}

Eigen::VectorXd random_vector(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

Status solve(RowMatrix M, Eigen::VectorXd& b) { return ldlt_solve(M.data(), b.data(), static_cast<int>(M.rows())); }

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

TEST(RuntimeLdlt, MatchesEigenOnRandomSpdMatrices) {
  std::mt19937 rng(20240521);
  double worst = 0.0;
  for (int n = 1; n <= 12; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      const RowMatrix M = random_spd(n, rng);
      const Eigen::VectorXd b = random_vector(n, rng);
      Eigen::VectorXd x = b;
      ASSERT_EQ(solve(M, x), Status::ok) << "n = " << n;
      const Eigen::VectorXd x_llt = M.llt().solve(b);
      const Eigen::VectorXd x_lu = M.partialPivLu().solve(b);
      EXPECT_LT(relative_difference(x, x_llt), 1e-12) << "n = " << n;
      EXPECT_LT(relative_difference(x, x_lu), 1e-12) << "n = " << n;
      worst = std::fmax(worst, relative_difference(x, x_llt));
    }
  }
  std::printf("worst relative difference to Eigen LLT: %.2e\n", worst);
}

// Mass matrices mix units (kg next to kg m^2 of a tiny part); scaling must not
// be mistaken for singularity, and the answer must still be accurate.
TEST(RuntimeLdlt, BadlyScaledButDefiniteMatrixIsSolved) {
  std::mt19937 rng(7);
  const int n = 6;
  Eigen::VectorXd scale(n);
  scale << 1e3, 1.0, 1e-3, 10.0, 1e-2, 1e2;
  const RowMatrix M = scale.asDiagonal() * random_spd(n, rng) * scale.asDiagonal();
  const Eigen::VectorXd b = random_vector(n, rng);
  Eigen::VectorXd x = b;
  ASSERT_EQ(solve(M, x), Status::ok);
  EXPECT_LT(relative_difference(x, M.partialPivLu().solve(b)), 1e-9);
  EXPECT_LT((M * x - b).norm() / b.norm(), 1e-12);
}

TEST(RuntimeLdlt, ReadsOnlyTheLowerTriangle) {
  std::mt19937 rng(11);
  const int n = 5;
  const RowMatrix M = random_spd(n, rng);
  RowMatrix lower_only = M;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) lower_only(i, j) = std::numeric_limits<double>::quiet_NaN();
  const Eigen::VectorXd b = random_vector(n, rng);
  Eigen::VectorXd x = b;
  ASSERT_EQ(solve(lower_only, x), Status::ok);
  EXPECT_LT(relative_difference(x, M.llt().solve(b)), 1e-12);
}

TEST(RuntimeLdlt, RankDeficientMatricesAreSingular) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 2; n <= 12; ++n) {
    RowMatrix B(n, n - 1);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n - 1; ++j) B(i, j) = u(rng);
    Eigen::VectorXd b = random_vector(n, rng);
    EXPECT_EQ(solve(B * B.transpose(), b), Status::singular_mass_matrix) << "n = " << n;
  }
  Eigen::VectorXd b = Eigen::VectorXd::Ones(3);
  EXPECT_EQ(solve(RowMatrix::Zero(3, 3), b), Status::singular_mass_matrix);
  // A massless coordinate: its row and column vanish in an otherwise definite matrix.
  RowMatrix massless = random_spd(5, rng);
  massless.row(2).setZero();
  massless.col(2).setZero();
  Eigen::VectorXd b5 = Eigen::VectorXd::Ones(5);
  EXPECT_EQ(solve(massless, b5), Status::singular_mass_matrix);
}

TEST(RuntimeLdlt, IndefiniteMatricesAreRejected) {
  std::mt19937 rng(5);
  for (int n = 2; n <= 12; ++n) {
    // Q diag(1, ..., 1, -1) Q^T with a random orthogonal Q: positive diagonal
    // entries are typical, so only the factorisation can tell.
    const Eigen::HouseholderQR<RowMatrix> qr(random_spd(n, rng));
    const RowMatrix Q = qr.householderQ();
    Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
    d(n - 1) = -1.0;
    Eigen::VectorXd b = random_vector(n, rng);
    EXPECT_EQ(solve(Q * d.asDiagonal() * Q.transpose(), b), Status::singular_mass_matrix) << "n = " << n;
  }
  std::array<double, 4> M = {1.0, 2.0, 2.0, 1.0};  // eigenvalues 3 and -1
  std::array<double, 2> b = {1.0, 1.0};
  EXPECT_EQ(ldlt_solve<2>(M, b), Status::singular_mass_matrix);
  std::array<double, 1> m1 = {-2.0};
  std::array<double, 1> b1 = {1.0};
  EXPECT_EQ(ldlt_solve<1>(m1, b1), Status::singular_mass_matrix);
}

TEST(RuntimeLdlt, NonFiniteEntriesAreRejected) {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()};
  for (const double v : bad) {
    for (const int where : {0, 3, 4}) {  // diagonal, off-diagonal (lower), last diagonal
      std::array<double, 9> M = {4, 1, 0, 1, 3, 0, 0, 1, 2};
      M[3] = 1;
      M[static_cast<std::size_t>(where == 4 ? 8 : where)] = v;
      std::array<double, 3> b = {1, 2, 3};
      EXPECT_EQ(ldlt_solve<3>(M, b), Status::singular_mass_matrix) << v << " at " << where;
    }
  }
}

TEST(RuntimeLdlt, FixedSizeOverloadSolvesAKnownSystem) {
  // [[4, 2, 0], [2, 5, 3], [0, 3, 10]] x = b with x = (1, -2, 3) by construction.
  std::array<double, 9> M = {4, 2, 0, 2, 5, 3, 0, 3, 10};
  std::array<double, 3> b = {4 * 1 + 2 * -2, 2 * 1 + 5 * -2 + 3 * 3, 3 * -2 + 10 * 3};
  ASSERT_EQ(ldlt_solve<3>(M, b), Status::ok);
  EXPECT_NEAR(b[0], 1.0, 1e-15);
  EXPECT_NEAR(b[1], -2.0, 1e-15);
  EXPECT_NEAR(b[2], 3.0, 1e-15);
}

TEST(RuntimeLdlt, EmptySystemIsTriviallySolved) { EXPECT_EQ(ldlt_solve(nullptr, nullptr, 0), Status::ok); }

}  // namespace
