// SPDX-License-Identifier: MIT
// The group policies follow the documented conventions, checked against
// definitions in plain double arithmetic rather than against each other:
// hat/vee, ad as the matrix commutator, Ad as conjugation, compose and inverse
// as matrix products, exp as the matrix exponential series, dexp as the
// right-trivialized derivative of exp (by finite differences) and dexp(-x) as
// the left-trivialized one, and log as the principal inverse of exp, including
// at exactly pi and for SE(2) angles of many turns.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/rn.hpp"
#include "hamel/runtime/lie/se2.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "hamel/runtime/lie/so3xr3.hpp"

namespace {

namespace lie = hamel::runtime::lie;
using lie::Mat3;
using lie::Mat4;
using lie::Mat6;
using lie::SE2;
using lie::SE3;
using lie::SO3;
using lie::SO3xR3;
using lie::Vec3;
using lie::Vec6;
using lie::operator*;  // std::array operators live in the lie namespace, out of ADL's reach

constexpr double kPi = 3.14159265358979323846;

// Homogeneous-matrix view of each group, so that the checks below can be
// written once: hat, vee and the matrix of an element. SO3xR3 is embedded as
// the block-diagonal 7 x 7 matrix diag(R, [[I, p], [0, 1]]), which is how a
// direct product of matrix groups is represented.
template <class G>
struct View;

template <>
struct View<SO3> {
  static constexpr std::size_t n = 3;
  static Mat3 hat(const Vec3& x) { return SO3::hat(x); }
  static Vec3 vee(const Mat3& m) { return SO3::vee(m); }
  static Mat3 matrix(const Mat3& R) { return R; }
};

template <>
struct View<SE3> {
  static constexpr std::size_t n = 4;
  static Mat4 hat(const Vec6& x) { return SE3::hat(x); }
  static Vec6 vee(const Mat4& m) { return SE3::vee(m); }
  static Mat4 matrix(const SE3::Element& g) { return SE3::matrix(g); }
};

template <>
struct View<SE2> {
  static constexpr std::size_t n = 3;
  static Mat3 hat(const Vec3& x) { return SE2::hat(x); }
  static Vec3 vee(const Mat3& m) { return SE2::vee(m); }
  static Mat3 matrix(const SE2::Element& g) { return SE2::matrix(g); }
};

template <>
struct View<SO3xR3> {
  static constexpr std::size_t n = 7;
  using M = lie::SquareMatrix<7>;
  static M hat(const Vec6& x) {
    M m{};
    const Mat3 W = SO3::hat({x[0], x[1], x[2]});
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) m[i * 7 + j] = W[i * 3 + j];
      m[(3 + i) * 7 + 6] = x[3 + i];
    }
    return m;
  }
  static Vec6 vee(const M& m) {
    return {0.5 * (m[2 * 7 + 1] - m[1 * 7 + 2]),
            0.5 * (m[0 * 7 + 2] - m[2 * 7 + 0]),
            0.5 * (m[1 * 7 + 0] - m[0 * 7 + 1]),
            m[3 * 7 + 6],
            m[4 * 7 + 6],
            m[5 * 7 + 6]};
  }
  static M matrix(const SO3xR3::Element& g) {
    M m{};
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) m[i * 7 + j] = g.R[i * 3 + j];
      m[(3 + i) * 7 + 3 + i] = 1.0;
      m[(3 + i) * 7 + 6] = g.p[i];
    }
    m[6 * 7 + 6] = 1.0;
    return m;
  }
};

template <std::size_t N>
double max_abs_diff(const std::array<double, N>& a, const std::array<double, N>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < N; ++i) d = std::fmax(d, std::fabs(a[i] - b[i]));
  return d;
}

template <std::size_t K>
lie::SquareMatrix<K> sub(const lie::SquareMatrix<K>& a, const lie::SquareMatrix<K>& b) {
  lie::SquareMatrix<K> c;
  for (std::size_t i = 0; i < K * K; ++i) c[i] = a[i] - b[i];
  return c;
}

// exp of a matrix by its power series in double; fine for the moderate norms
// used here (terms decay below 1e-17 relative well before 40 terms).
template <std::size_t K>
lie::SquareMatrix<K> series_exp(const lie::SquareMatrix<K>& X) {
  lie::SquareMatrix<K> sum = lie::identity_matrix<K>(), term = sum;
  for (int k = 1; k < 60; ++k) {
    term = lie::mat_mul<K>(term, X);
    for (double& v : term) v /= k;
    for (std::size_t i = 0; i < K * K; ++i) sum[i] += term[i];
  }
  return sum;
}

// A few algebra elements in general position, with rotation angles from small
// to beyond pi.
template <class G>
std::array<typename G::Vector, 4> samples() {
  std::array<typename G::Vector, 4> s{};
  const double raw[4][6] = {{0.3, -0.2, 0.5, 1.0, -2.0, 0.7},
                            {-1.1, 0.9, 1.7, 0.2, 0.4, -1.5},
                            {3.6, 1.5, -1.2, -0.8, 0.3, 0.6},
                            {1e-3, -2e-3, 5e-4, 0.9, 1.1, -0.4}};
  for (std::size_t i = 0; i < 4; ++i) {
    for (std::size_t j = 0; j < G::dim; ++j) s[i][j] = raw[i][j];
  }
  return s;
}

template <class G>
void check_conventions(const char* name) {
  using V = View<G>;
  constexpr std::size_t n = V::n;
  const auto xs = samples<G>();
  double worst_fd = 0.0;
  for (const auto& x : xs) {
    for (const auto& y : xs) {
      // hat/vee round trip and ad as the commutator.
      EXPECT_LT(max_abs_diff(V::vee(V::hat(x)), x), 1e-15) << name;
      const auto X = V::hat(x), Y = V::hat(y);
      const auto bracket = V::vee(sub<n>(lie::mat_mul<n>(X, Y), lie::mat_mul<n>(Y, X)));
      EXPECT_LT(max_abs_diff(lie::mat_vec<G::dim>(G::ad(x), y), bracket), 1e-14) << name << ": ad";

      // exp is the matrix exponential; compose and inverse are matrix products.
      const auto gx = G::exp(x), gy = G::exp(y);
      EXPECT_LT(max_abs_diff(V::matrix(gx), series_exp<n>(X)), 1e-13) << name << ": exp";
      EXPECT_LT(max_abs_diff(V::matrix(G::compose(gx, gy)), lie::mat_mul<n>(V::matrix(gx), V::matrix(gy))), 1e-14)
          << name << ": compose";
      EXPECT_LT(max_abs_diff(lie::mat_mul<n>(V::matrix(G::inverse(gx)), V::matrix(gx)), lie::identity_matrix<n>()),
                1e-14)
          << name << ": inverse";

      // Ad is conjugation, and Ad(exp x) = exp(ad x).
      const auto conj = V::vee(lie::mat_mul<n>(lie::mat_mul<n>(V::matrix(gx), Y), V::matrix(G::inverse(gx))));
      EXPECT_LT(max_abs_diff(lie::mat_vec<G::dim>(G::Ad(gx), y), conj), 1e-13) << name << ": Ad";
      EXPECT_LT(max_abs_diff(G::Ad(gx), series_exp<G::dim>(G::ad(x))), 1e-13) << name << ": Ad exp = exp ad";

      // dexp by a fourth-order central difference of s -> exp(x + s y):
      // right: (d/ds exp(x + s y)) exp(x)^-1 = hat(dexp(x) y);
      // left:  exp(x)^-1 (d/ds exp(x + s y)) = hat(dexp(-x) y).
      // Step 1e-3: truncation ~h^4 = 1e-12, rounding ~1e-16/h = 1e-13.
      const double h = 1e-3;
      typename G::Vector xm2, xm1, xp1, xp2, minus_x;
      for (std::size_t i = 0; i < G::dim; ++i) {
        xm2[i] = x[i] - 2 * h * y[i];
        xm1[i] = x[i] - h * y[i];
        xp1[i] = x[i] + h * y[i];
        xp2[i] = x[i] + 2 * h * y[i];
        minus_x[i] = -x[i];
      }
      lie::SquareMatrix<n> derivative;
      const auto m2 = V::matrix(G::exp(xm2)), m1 = V::matrix(G::exp(xm1));
      const auto p1 = V::matrix(G::exp(xp1)), p2 = V::matrix(G::exp(xp2));
      for (std::size_t i = 0; i < n * n; ++i) derivative[i] = (m2[i] - 8 * m1[i] + 8 * p1[i] - p2[i]) / (12 * h);
      const auto inv = V::matrix(G::inverse(gx));
      const auto right = V::vee(lie::mat_mul<n>(derivative, inv));
      const auto left = V::vee(lie::mat_mul<n>(inv, derivative));
      const double e_right = max_abs_diff(lie::mat_vec<G::dim>(G::dexp(x), y), right);
      const double e_left = max_abs_diff(lie::mat_vec<G::dim>(G::dexp(minus_x), y), left);
      worst_fd = std::fmax(worst_fd, std::fmax(e_right, e_left));
      EXPECT_LT(e_right, 1e-9) << name << ": right-trivialized dexp";
      EXPECT_LT(e_left, 1e-9) << name << ": left-trivialized dexp(-x)";

      // dexp^-1 inverts dexp.
      EXPECT_LT(max_abs_diff(lie::mat_mul<G::dim>(G::dexp(x), G::dexpinv(x)), lie::identity_matrix<G::dim>()), 1e-14)
          << name << ": dexpinv";
    }
  }
  std::printf("%s: worst finite-difference mismatch of dexp %.2e\n", name, worst_fd);
}

TEST(RuntimeLieConventions, So3) { check_conventions<SO3>("SO3"); }
TEST(RuntimeLieConventions, Se3) { check_conventions<SE3>("SE3"); }
TEST(RuntimeLieConventions, Se2) { check_conventions<SE2>("SE2"); }
TEST(RuntimeLieConventions, So3xR3) { check_conventions<SO3xR3>("SO3xR3"); }

TEST(RuntimeLieConventions, So3xR3IsTheDirectProduct) {
  const Vec6 x = {0.3, -0.2, 0.5, 1.0, -2.0, 0.7};
  const SO3xR3::Element g = SO3xR3::exp(x);
  EXPECT_EQ(g.R, SO3::exp({0.3, -0.2, 0.5}));
  EXPECT_EQ(g.p, (Vec3{1.0, -2.0, 0.7}));  // the translation is not rotated
  const SO3xR3::Element gg = SO3xR3::compose(g, g);
  EXPECT_EQ(gg.p, (Vec3{2.0, -4.0, 1.4}));
  const Mat6 D = SO3xR3::dexp(x);
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(D[(3 + i) * 6 + j], 0.0);
      EXPECT_EQ(D[i * 6 + 3 + j], 0.0);
      EXPECT_EQ(D[(3 + i) * 6 + 3 + j], i == j ? 1.0 : 0.0);
    }
  }
  const Vec6 back = SO3xR3::log(g);
  EXPECT_LT(max_abs_diff(back, x), 1e-15);
}

TEST(RuntimeLieConventions, RnIsAddition) {
  using R4 = lie::Rn<4>;
  const R4::Element a = {1.0, 2.0, 3.0, 4.0}, b = {0.5, -1.0, 2.0, 0.0};
  EXPECT_EQ(R4::compose(a, b), (R4::Element{1.5, 1.0, 5.0, 4.0}));
  EXPECT_EQ(R4::compose(a, R4::inverse(a)), R4::identity());
  EXPECT_EQ(R4::exp(a), a);
  EXPECT_EQ(R4::dexpinv(a), lie::identity_matrix<4>());
  EXPECT_EQ(R4::ad(a), lie::SquareMatrix<4>{});
}

// Rotations by exactly pi (where log has two valid answers, +-w) and rotations
// in general position: log inverts exp and returns |w| <= pi.
TEST(RuntimeLieConventions, So3LogIsPrincipal) {
  const Mat3 half_turns[] = {
      {1, 0, 0, 0, -1, 0, 0, 0, -1},
      {-1, 0, 0, 0, 1, 0, 0, 0, -1},
      {-1, 0, 0, 0, -1, 0, 0, 0, 1},
      {0, 1, 0, 1, 0, 0, 0, 0, -1},  // about (1, 1, 0)/sqrt 2
  };
  for (const Mat3& R : half_turns) {
    const Vec3 w = SO3::log(R);
    EXPECT_NEAR(lie::norm(w), kPi, 1e-15);
    EXPECT_LT(max_abs_diff(SO3::exp(w), R), 1e-15);
  }
  // Angles beyond pi come back as 2 pi - theta about the opposite axis.
  for (double theta : {0.5, 2.0, 3.0, 3.5, 5.0, 6.2, 7.0, 100.0}) {
    const Vec3 n = {0.48, -0.6, 0.64};
    const Vec3 w = SO3::log(SO3::exp(theta * n));
    const double principal = std::remainder(theta, 2 * kPi);
    EXPECT_LT(max_abs_diff(w, principal * n), 1e-13) << theta;
  }
}

// log inverts exp on the whole open ball |w| < pi (both switch branches of
// SO3::log), for SO(3) and SE(3): 4000 pseudo-random rotation vectors with
// angles uniform in [0, 3.14] and translations in [-2, 2]^3. The logarithm is
// well conditioned there, so the round trip must be exact to rounding.
TEST(RuntimeLieConventions, LogInvertsExpOnTheOpenBall) {
  unsigned long long state = 12345;
  auto uniform = [&state]() {  // 53-bit LCG output in [0, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  double worst_so3 = 0.0, worst_se3 = 0.0;
  for (int i = 0; i < 4000; ++i) {
    Vec3 n = {2 * uniform() - 1, 2 * uniform() - 1, 2 * uniform() - 1};
    n = (1.0 / lie::norm(n)) * n;
    const Vec3 w = (3.14 * uniform()) * n;
    worst_so3 = std::fmax(worst_so3, max_abs_diff(SO3::log(SO3::exp(w)), w));
    const Vec6 x = {w[0], w[1], w[2], 4 * uniform() - 2, 4 * uniform() - 2, 4 * uniform() - 2};
    worst_se3 = std::fmax(worst_se3, max_abs_diff(SE3::log(SE3::exp(x)), x));
  }
  std::printf("log(exp(x)) - x: worst %.2e on SO(3), %.2e on SE(3)\n", worst_so3, worst_se3);
  EXPECT_LT(worst_so3, 4e-15);
  EXPECT_LT(worst_se3, 1e-14);
}

// The SE(2) angle is kept unwrapped by compose and reduced exactly by log,
// even after a thousand turns.
TEST(RuntimeLieConventions, Se2AngleCountsTurnsAndLogReducesIt) {
  SE2::Element g = SE2::identity();
  const SE2::Element step = SE2::exp({2 * kPi / 8 + 1e-3, 0.0, 0.0});
  for (int i = 0; i < 8000; ++i) g = SE2::compose(g, step);
  EXPECT_NEAR(g.theta, 8000 * (2 * kPi / 8 + 1e-3), 1e-9);
  // Reference: the stored angle reduced mod 2 pi in long double, whose 2 pi is
  // good to 1e-19, so a thousand turns cost 1e-16.
  const long double total = g.theta;
  const long double two_pi = 6.283185307179586476925286766559L;
  const double principal = static_cast<double>(total - two_pi * std::nearbyint(total / two_pi));
  EXPECT_NEAR(SE2::log(g)[0], principal, 1e-12);
  EXPECT_NEAR(SE2::log(g)[0], 8.0 - 2 * kPi, 1e-9);  // 1000 turns plus 8 rad
}

}  // namespace
