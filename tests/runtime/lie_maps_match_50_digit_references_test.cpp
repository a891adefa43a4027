// SPDX-License-Identifier: MIT
// exp, log, dexp and dexp^-1 on SO(3), SE(3) and SE(2) agree with 50-digit
// references to 1e-14 relative (Frobenius norm) at rotation angles 10^-k and
// pi - 10^-k, k = 1..12, where naive closed forms lose all their digits.
//
// The references share nothing with the code under test: hat and vee are
// written out again here, ad is built column by column from matrix
// commutators [hat x, hat e_j], exp(hat x) and dexp = sum ad^k/(k+1)! are
// summed as power series at 50 digits, and dexp^-1 is the 50-digit inverse of
// that series.
//
// The logarithm needs a fair reference. Its input is a double matrix R_d, the
// 50-digit exp(x) rounded to doubles, which is orthogonal only to about 1e-16.
// Comparing log(R_d) with x would charge the rounding of R_d to the logarithm,
// so the reference is the 50-digit logarithm of the rotation nearest to R_d (its
// orthogonal polar factor), and for SE(3) and SE(2) the translation part is
// dexp_SO3(w)^-1 p (resp. its SE(2) analogue) of the rounded p, again at 50
// digits. Near pi that is the only fair choice: the logarithm there is well
// conditioned only on rotations, and the code has to recover the axis from R_d
// without dividing by sin(theta).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "hamel/runtime/lie/matrix.hpp"
#include "hamel/runtime/lie/se2.hpp"
#include "hamel/runtime/lie/se3.hpp"
#include "hamel/runtime/lie/so3.hpp"
#include "lie_reference.hpp"

namespace {

namespace lie = hamel::runtime::lie;
using lie::Mat3;
using lie::Mat4;
using lie::Mat6;
using lie::SE2;
using lie::SE3;
using lie::SO3;
using lie::Vec3;
using lie::Vec6;
using lie_ref::Mat;

constexpr double kTolerance = 1e-14;
constexpr double kPi = 3.14159265358979323846;

// Unit axes in general position (not along coordinate axes, so that every
// matrix entry is exercised).
Vec3 axis(int k) {
  static const std::array<Vec3, 5> raw = {
      {{1.0, 2.0, 3.0}, {-0.3, 0.8, 0.52}, {0.9, -0.1, -0.4}, {0.05, -0.7, 0.2}, {-0.6, -0.25, 0.9}}};
  const Vec3& a = raw[static_cast<std::size_t>(k) % raw.size()];
  const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / n, a[1] / n, a[2] / n};
}

// Angles 10^-k and pi - 10^-k, k = 1..12: where closed forms in sin and cos cancel.
double angle(bool near_pi, int k) { return near_pi ? kPi - std::pow(10.0, -k) : std::pow(10.0, -k); }

// Worst errors per (quantity, region, k), printed as a table at the end.
class Table {
 public:
  void record(const std::string& name, bool near_pi, int k, double e) {
    const auto i = static_cast<std::size_t>(std::find(names_.begin(), names_.end(), name) - names_.begin());
    if (i == names_.size()) {
      names_.push_back(name);
      worst_.push_back({});
    }
    double& w = worst_[i][near_pi ? 1 : 0][static_cast<std::size_t>(k)];
    w = std::max(w, e);
    EXPECT_LE(e, kTolerance) << name << (near_pi ? " at pi - 10^-" : " at 10^-") << k;
  }
  void print(const char* group) const {
    for (int region = 0; region < 2; ++region) {
      std::printf("%s, theta = %s, worst relative error:\n   k", group, region ? "pi - 10^-k" : "10^-k");
      for (const auto& n : names_) std::printf(" %11s", n.c_str());
      std::printf("\n");
      for (std::size_t k = 1; k <= 12; ++k) {
        std::printf("  %2zu", k);
        for (const auto& w : worst_) std::printf(" %11.2e", w[static_cast<std::size_t>(region)][k]);
        std::printf("\n");
      }
    }
  }

 private:
  std::vector<std::string> names_;
  std::vector<std::array<std::array<double, 13>, 2>> worst_;
};

// ||M - I||_F / ||I||_F for an n x n row-major matrix.
template <std::size_t N>
double identity_defect(const std::array<double, N * N>& m) {
  double s = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < N; ++j) {
      const double d = m[i * N + j] - (i == j ? 1.0 : 0.0);
      s += d * d;
    }
  }
  return std::sqrt(s / N);
}

// A matrix Lie algebra for the references: hat from coordinates (an n x 1
// column) to a matrix, and vee back.
struct RefAlgebra {
  std::size_t dim;
  std::function<Mat(const Mat&)> hat;
  std::function<Mat(const Mat&)> vee;
};

// ad_x from its definition: column j is vee([hat x, hat e_j]).
Mat ad_from_commutators(const RefAlgebra& g, const Mat& x) {
  const Mat X = g.hat(x);
  Mat ad(g.dim, g.dim);
  for (std::size_t j = 0; j < g.dim; ++j) {
    Mat e(g.dim, 1);
    e(j, 0) = lie_ref::num(1.0);
    const Mat E = g.hat(e);
    const Mat column = g.vee(X * E - E * X);
    for (std::size_t i = 0; i < g.dim; ++i) ad(i, j) = column(i, 0);
  }
  return ad;
}

const RefAlgebra& so3_algebra() {
  static const RefAlgebra g{3, [](const Mat& w) { return lie_ref::hat_so3(w); },
                            [](const Mat& W) {
                              Mat w(3, 1);
                              w(0, 0) = W(2, 1);
                              w(1, 0) = W(0, 2);
                              w(2, 0) = W(1, 0);
                              return w;
                            }};
  return g;
}

const RefAlgebra& se3_algebra() {
  static const RefAlgebra g{6,
                            [](const Mat& x) {
                              Mat w(3, 1);
                              for (std::size_t i = 0; i < 3; ++i) w(i, 0) = x(i, 0);
                              const Mat W = lie_ref::hat_so3(w);
                              Mat X(4, 4);
                              for (std::size_t i = 0; i < 3; ++i) {
                                for (std::size_t j = 0; j < 3; ++j) X(i, j) = W(i, j);
                                X(i, 3) = x(3 + i, 0);
                              }
                              return X;
                            },
                            [](const Mat& X) {
                              Mat x(6, 1);
                              x(0, 0) = X(2, 1);
                              x(1, 0) = X(0, 2);
                              x(2, 0) = X(1, 0);
                              for (std::size_t i = 0; i < 3; ++i) x(3 + i, 0) = X(i, 3);
                              return x;
                            }};
  return g;
}

const RefAlgebra& se2_algebra() {
  static const RefAlgebra g{3,
                            [](const Mat& x) {
                              Mat X(3, 3);
                              X(0, 1) = -x(0, 0);
                              X(1, 0) = x(0, 0);
                              X(0, 2) = x(1, 0);
                              X(1, 2) = x(2, 0);
                              return X;
                            },
                            [](const Mat& X) {
                              Mat x(3, 1);
                              x(0, 0) = X(1, 0);
                              x(1, 0) = X(0, 2);
                              x(2, 0) = X(1, 2);
                              return x;
                            }};
  return g;
}

// ---------------------------------------------------------------- SO(3)

TEST(RuntimeLieReference, So3MapsAreAccurateNearZeroAndNearPi) {
  lie_ref::set_digits(50);
  Table table;
  for (int near_pi = 0; near_pi < 2; ++near_pi) {
    for (int k = 1; k <= 12; ++k) {
      for (int a = 0; a < 2; ++a) {
        const double theta = angle(near_pi, k);
        const Vec3 n = axis(k + 2 * a);
        const Vec3 w = {theta * n[0], theta * n[1], theta * n[2]};
        const Mat w_ref = lie_ref::vec({w[0], w[1], w[2]});

        const Mat R = lie_ref::exp(so3_algebra().hat(w_ref));
        table.record("exp", near_pi, k, lie_ref::relative_error(SO3::exp(w).data(), R));

        const Mat D = lie_ref::dexp(ad_from_commutators(so3_algebra(), w_ref));
        const Mat3 D_c = SO3::dexp(w), Di_c = SO3::dexpinv(w);
        table.record("dexp", near_pi, k, lie_ref::relative_error(D_c.data(), D));
        table.record("dexpinv", near_pi, k, lie_ref::relative_error(Di_c.data(), lie_ref::inverse(D)));
        table.record("dexp*inv-I", near_pi, k, identity_defect<3>(lie::mat_mul<3>(D_c, Di_c)));

        Mat3 R_d;
        const std::vector<double> rounded = lie_ref::round(R);
        std::copy(rounded.begin(), rounded.end(), R_d.begin());
        const Vec3 w_c = SO3::log(R_d);
        const Mat log_ref = lie_ref::log_rotation(lie_ref::polar(lie_ref::from_doubles(R_d.data(), 3, 3)));
        table.record("log", near_pi, k, lie_ref::relative_error(w_c.data(), log_ref));
        table.record("exp(log)", near_pi, k,
                     lie_ref::relative_error(SO3::exp(w_c).data(), lie_ref::from_doubles(R_d.data(), 3, 3)));
      }
    }
  }
  table.print("SO(3)");
}

// ---------------------------------------------------------------- SE(3)

// Linear parts: one with a large component along the axis (so that the
// (w . v) terms of dexp matter), one nearly orthogonal to it.
Vec3 linear_part(int k) { return (k % 2) ? Vec3{0.4, -1.1, 0.7} : Vec3{2.0, 0.3, -0.9}; }

TEST(RuntimeLieReference, Se3MapsAreAccurateNearZeroAndNearPi) {
  lie_ref::set_digits(50);
  Table table;
  for (int near_pi = 0; near_pi < 2; ++near_pi) {
    for (int k = 1; k <= 12; ++k) {
      for (int a = 0; a < 2; ++a) {
        const double theta = angle(near_pi, k);
        const Vec3 n = axis(k + 2 * a + 1);
        const Vec3 v = linear_part(k + a);
        const Vec6 x = {theta * n[0], theta * n[1], theta * n[2], v[0], v[1], v[2]};
        const Mat x_ref = lie_ref::vec(std::vector<double>(x.begin(), x.end()));

        const Mat G = lie_ref::exp(se3_algebra().hat(x_ref));
        table.record("exp", near_pi, k, lie_ref::relative_error(SE3::matrix(SE3::exp(x)).data(), G));

        const Mat D = lie_ref::dexp(ad_from_commutators(se3_algebra(), x_ref));
        const Mat6 D_c = SE3::dexp(x), Di_c = SE3::dexpinv(x);
        table.record("dexp", near_pi, k, lie_ref::relative_error(D_c.data(), D));
        table.record("dexpinv", near_pi, k, lie_ref::relative_error(Di_c.data(), lie_ref::inverse(D)));
        table.record("dexp*inv-I", near_pi, k, identity_defect<6>(lie::mat_mul<6>(D_c, Di_c)));

        // log: the rounded element; the reference rotation is the polar factor
        // of its R, and v_ref = dexp_SO3(w_ref)^-1 p.
        const std::vector<double> rounded = lie_ref::round(G);
        SE3::Element g_d;
        for (std::size_t i = 0; i < 3; ++i) {
          for (std::size_t j = 0; j < 3; ++j) g_d.R[i * 3 + j] = rounded[i * 4 + j];
          g_d.p[i] = rounded[i * 4 + 3];
        }
        const Vec6 x_c = SE3::log(g_d);
        const Mat w_ref = lie_ref::log_rotation(lie_ref::polar(lie_ref::from_doubles(g_d.R.data(), 3, 3)));
        const Mat v_ref = lie_ref::inverse(lie_ref::dexp(ad_from_commutators(so3_algebra(), w_ref))) *
                          lie_ref::vec({g_d.p[0], g_d.p[1], g_d.p[2]});
        Mat log_ref(6, 1);
        for (std::size_t i = 0; i < 3; ++i) {
          log_ref(i, 0) = w_ref(i, 0);
          log_ref(3 + i, 0) = v_ref(i, 0);
        }
        table.record("log", near_pi, k, lie_ref::relative_error(x_c.data(), log_ref));
        table.record("exp(log)", near_pi, k,
                     lie_ref::relative_error(SE3::matrix(SE3::exp(x_c)).data(),
                                             lie_ref::from_doubles(SE3::matrix(g_d).data(), 4, 4)));
      }
    }
  }
  table.print("SE(3)");
}

// The diagonal of dexp's lower-left block (and dexp^-1's), q (W V + V W)_ii + s (W^2)_ii, is small when w and v
// lie close to one coordinate axis: (W^2)_ii = -(w_j^2 + w_k^2) and (W V + V W)_ii = -2 (w_j v_j + w_k v_k).
// Formed as w_i^2 - |w|^2 and 2 w_i v_i - 2 w . v, it loses about log10(|w|^2 / (w_j^2 + w_k^2)) digits, which a
// Frobenius-norm error does not see. Entry by entry, relative to the 50-digit value:
TEST(RuntimeLieReference, Se3DexpBlockDiagonalKeepsItsDigitsNearAnAxis) {
  lie_ref::set_digits(50);
  for (std::size_t i = 0; i < 3; ++i) {
    for (double theta : {0.5, 2.0}) {
      Vec6 x{};
      x[i] = theta;
      x[(i + 1) % 3] = 3e-7;
      x[(i + 2) % 3] = -2e-7;
      x[3 + i] = 0.8;
      x[3 + (i + 1) % 3] = 4e-7;
      x[3 + (i + 2) % 3] = 1e-7;
      const Mat D =
          lie_ref::dexp(ad_from_commutators(se3_algebra(), lie_ref::vec(std::vector<double>(x.begin(), x.end()))));
      const Mat Di = lie_ref::inverse(D);
      const Mat6 D_c = SE3::dexp(x), Di_c = SE3::dexpinv(x);
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t row = 3 + k, col = k;
        const double ref = lie_ref::to_double(D(row, col)), ref_inv = lie_ref::to_double(Di(row, col));
        EXPECT_LE(std::abs(D_c[row * 6 + col] - ref), 1e-13 * std::abs(ref))
            << "dexp(" << row << ", " << col << "), axis " << i << ", theta " << theta;
        EXPECT_LE(std::abs(Di_c[row * 6 + col] - ref_inv), 1e-13 * std::abs(ref_inv))
            << "dexp^-1(" << row << ", " << col << "), axis " << i << ", theta " << theta;
      }
    }
  }
}

// ---------------------------------------------------------------- SE(2)

TEST(RuntimeLieReference, Se2MapsAreAccurateNearZeroAndNearPi) {
  lie_ref::set_digits(50);
  Table table;
  for (int near_pi = 0; near_pi < 2; ++near_pi) {
    for (int k = 1; k <= 12; ++k) {
      for (int sign = -1; sign <= 1; sign += 2) {
        const double w = sign * angle(near_pi, k);
        const Vec3 x = {w, 0.7 * sign, -1.3};
        const Mat x_ref = lie_ref::vec({x[0], x[1], x[2]});

        const Mat G = lie_ref::exp(se2_algebra().hat(x_ref));
        const SE2::Element g_c = SE2::exp(x);
        table.record("exp", near_pi, k, lie_ref::relative_error(SE2::matrix(g_c).data(), G));

        const Mat D = lie_ref::dexp(ad_from_commutators(se2_algebra(), x_ref));
        const Mat3 D_c = SE2::dexp(x), Di_c = SE2::dexpinv(x);
        table.record("dexp", near_pi, k, lie_ref::relative_error(D_c.data(), D));
        table.record("dexpinv", near_pi, k, lie_ref::relative_error(Di_c.data(), lie_ref::inverse(D)));
        table.record("dexp*inv-I", near_pi, k, identity_defect<3>(lie::mat_mul<3>(D_c, Di_c)));

        // log of {w, rounded translation}: the angle is exact, so the reference
        // is (w, V(w)^-1 p) with V(w) = sum (w J)^k/(k+1)! at 50 digits.
        const SE2::Element g_d = {w, lie_ref::to_double(G(0, 2)), lie_ref::to_double(G(1, 2))};
        const Vec3 x_c = SE2::log(g_d);
        Mat wJ(2, 2);
        wJ(0, 1) = lie_ref::num(-w);
        wJ(1, 0) = lie_ref::num(w);
        const Mat v_ref = lie_ref::inverse(lie_ref::dexp(wJ)) * lie_ref::vec({g_d.x, g_d.y});
        Mat log_ref(3, 1);
        log_ref(0, 0) = lie_ref::num(w);
        log_ref(1, 0) = v_ref(0, 0);
        log_ref(2, 0) = v_ref(1, 0);
        table.record("log", near_pi, k, lie_ref::relative_error(x_c.data(), log_ref));
        table.record("exp(log)", near_pi, k,
                     lie_ref::relative_error(SE2::matrix(SE2::exp(x_c)).data(),
                                             lie_ref::from_doubles(SE2::matrix(g_d).data(), 3, 3)));
      }
    }
  }
  table.print("SE(2)");
}

}  // namespace
