// SPDX-License-Identifier: MIT
// Every scalar coefficient of coefficients.hpp is accurate to a few ulps at
// every angle, in particular on both sides of each series/closed-form switch,
// and the series literals are the correctly rounded exact rationals.
//
// References: the closed forms evaluated at 120 digits. Their cancellation at
// small theta costs at most 4 * 16 = 64 digits at theta = 1e-16 (the SE(3)
// derivative coefficients are O(theta^4) differences of O(1) terms), which
// leaves over 50 correct digits; the references therefore share nothing with
// the series the code uses.
#include <gtest/gtest.h>

#include <cln/integer.h>
#include <cln/rational.h>
#include <cln/real.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "hamel/runtime/lie/coefficients.hpp"
#include "lie_reference.hpp"

namespace {

namespace co = hamel::runtime::lie::coefficients;
using lie_ref::num;
using lie_ref::Real;

constexpr double kUlp = std::numeric_limits<double>::epsilon();  // 2^-52
constexpr double kPi = 3.14159265358979323846;

// 120-digit closed forms.
Real ref_sinc(const Real& t) { return cln::sin(t) / t; }
Real ref_versine(const Real& t) { return (num(1.0) - cln::cos(t)) / (t * t); }
Real ref_sin_defect(const Real& t) { return (t - cln::sin(t)) / (t * t * t); }
Real ref_sin_defect_d(const Real& t) { return (3 * cln::sin(t) - t * cln::cos(t) - 2 * t) / (t * t * t * t * t); }
Real ref_dexpinv(const Real& t) {
  const Real h = t / 2;
  return (num(1.0) - h * cln::cos(h) / cln::sin(h)) / (t * t);
}
Real ref_versine_d(const Real& t) { return (t * cln::sin(t) - 2 * (num(1.0) - cln::cos(t))) / (t * t * t * t); }
// eta = 1/t^2 - cot(t/2)/(2t); differentiate and divide by t.
Real ref_dexpinv_d(const Real& t) {
  const Real h = t / 2, s = cln::sin(h), c = cln::cos(h);
  return -2 / (t * t * t * t) + c / s / (2 * t * t * t) + 1 / (4 * t * t * s * s);
}

// The values at theta = 0 (the constant series terms).
struct Coefficient {
  const char* name;
  double (*code)(double);
  Real (*reference)(const Real&);
  long limit_num, limit_den;  // value at theta = 0
};

const std::vector<Coefficient>& coefficients() {
  static const std::vector<Coefficient> all = {
      {"sinc", co::sinc, ref_sinc, 1, 1},
      {"versine_ratio", co::versine_ratio, ref_versine, 1, 2},
      {"sin_defect_ratio", co::sin_defect_ratio, ref_sin_defect, 1, 6},
      {"sin_defect_ratio_d", co::sin_defect_ratio_d, ref_sin_defect_d, -1, 60},
      {"dexpinv_ratio", co::dexpinv_ratio, ref_dexpinv, 1, 12},
      {"dexpinv_ratio_d", co::dexpinv_ratio_d, ref_dexpinv_d, 1, 360},
      {"versine_ratio_d", co::versine_ratio_d, ref_versine_d, -1, 12},
  };
  return all;
}

// Angles: a logarithmic sweep from 1e-16 to 1, a fine linear sweep up to 6.2
// (below the poles at 2 pi), and a neighbourhood of every switch point, down to
// the adjacent doubles.
std::vector<double> sweep() {
  std::vector<double> th;
  for (int i = 0; i <= 320; ++i) th.push_back(std::pow(10.0, -16.0 + i * 0.05));
  for (double x = 0.003; x < 6.2; x += 0.00731) th.push_back(x);
  for (double s : {co::kSincSwitch, co::kSinDefectSwitch, co::kSinDefectDerivativeSwitch, co::kDexpinvSwitch,
                   2.0 * co::kDexpinvSwitch}) {
    double lo = s, hi = s;
    for (int i = 0; i < 4; ++i) {
      lo = std::nextafter(lo, 0.0);
      hi = std::nextafter(hi, 10.0);
      th.push_back(lo);
      th.push_back(hi);
    }
    th.push_back(s);
    for (double d : {1e-12, 1e-8, 1e-4, 1e-2}) {
      th.push_back(s * (1 - d));
      th.push_back(s * (1 + d));
    }
  }
  return th;
}

TEST(RuntimeLieCoefficients, AccurateToAFewUlpsAtEveryAngle) {
  lie_ref::set_digits(120);
  const std::vector<double> angles = sweep();
  for (const Coefficient& c : coefficients()) {
    double worst = 0.0, worst_at = 0.0;
    for (double theta : angles) {
      const Real ref = c.reference(num(theta));
      const double got = c.code(theta);
      const double e = lie_ref::to_double(cln::abs((num(got) - ref) / ref)) / kUlp;
      if (e > worst) {
        worst = e;
        worst_at = theta;
      }
    }
    std::printf("%-20s worst error %.2f ulp at theta = %.17g (%zu angles in [1e-16, 6.2))\n", c.name, worst, worst_at,
                angles.size());
    EXPECT_LE(worst, 4.0) << c.name << " at theta = " << worst_at;
  }
}

// Beyond 2 pi only the closed forms are used; they must stay accurate away
// from the poles of eta and eta_d at 2 pi k.
TEST(RuntimeLieCoefficients, AccurateBeyondTwoPi) {
  lie_ref::set_digits(120);
  for (const Coefficient& c : coefficients()) {
    double worst = 0.0;
    for (double theta : {7.0, 10.0, 11.5, 30.0, 100.0, 1000.5}) {
      const Real ref = c.reference(num(theta));
      worst = std::max(worst, lie_ref::to_double(cln::abs((num(c.code(theta)) - ref) / ref)) / kUlp);
    }
    std::printf("%-20s worst error %.2f ulp for theta in [7, 1000.5]\n", c.name, worst);
    EXPECT_LE(worst, 16.0) << c.name;
  }
}

// theta = 0 and angles whose square underflows give the limits exactly.
TEST(RuntimeLieCoefficients, ExactLimitsAtZeroAndTinyAngles) {
  lie_ref::set_digits(50);
  for (const Coefficient& c : coefficients()) {
    const double limit = static_cast<double>(c.limit_num) / static_cast<double>(c.limit_den);
    for (double theta : {0.0, 1e-300, std::numeric_limits<double>::denorm_min(), 1e-160}) {
      EXPECT_EQ(c.code(theta), limit) << c.name << " at theta = " << theta;
    }
  }
}

// Each series literal is the exact coefficient rounded to the nearest double:
// |literal - exact| <= half an ulp of the literal.
template <std::size_t N>
void expect_correctly_rounded(const char* name, const double (&literals)[N], Real (*exact)(long k)) {
  for (std::size_t k = 0; k < N; ++k) {
    const Real x = exact(static_cast<long>(k));
    const double lit = literals[k];
    const double half_ulp = 0.5 * (std::nextafter(std::fabs(lit), 1.0 / 0.0) - std::fabs(lit));
    const double err = lie_ref::to_double(cln::abs(num(lit) - x));
    EXPECT_LE(err, half_ulp) << name << "[" << k << "] = " << lit;
  }
}

// The Bernoulli number B_n as an exact rational (Akiyama-Tanigawa algorithm).
cln::cl_RA bernoulli(long n) {
  std::vector<cln::cl_RA> a(static_cast<std::size_t>(n) + 1);
  for (long m = 0; m <= n; ++m) {
    a[static_cast<std::size_t>(m)] = cln::cl_RA(1) / (m + 1);
    for (long j = m; j >= 1; --j) {
      a[static_cast<std::size_t>(j) - 1] = j * (a[static_cast<std::size_t>(j) - 1] - a[static_cast<std::size_t>(j)]);
    }
  }
  return n == 1 ? -a[0] : a[0];  // B_1 = -1/2 in the convention used here
}

Real exact_float(const cln::cl_RA& r) { return cln::cl_float(r, lie_ref::format()); }
cln::cl_RA sign(long k) { return (k % 2) ? cln::cl_RA(-1) : cln::cl_RA(1); }

TEST(RuntimeLieCoefficients, SeriesLiteralsAreCorrectlyRounded) {
  lie_ref::set_digits(60);
  // Sanity of the Bernoulli numbers themselves.
  ASSERT_EQ(bernoulli(2), cln::cl_RA(1) / 6);
  ASSERT_EQ(bernoulli(12), cln::cl_RA(-691) / 2730);
  expect_correctly_rounded("kSinDefectSeries", co::kSinDefectSeries,
                           [](long k) { return exact_float(sign(k) / cln::factorial(2 * k + 3)); });
  expect_correctly_rounded("kSinDefectDerivativeSeries", co::kSinDefectDerivativeSeries, [](long k) {
    const long j = k + 1;  // coefficient of t^(j-1)
    return exact_float(sign(j) * 2 * j / cln::factorial(2 * j + 3));
  });
  expect_correctly_rounded("kDexpinvSeries", co::kDexpinvSeries, [](long k) {
    const long n = k + 1;  // coefficient of t^(n-1)
    return exact_float(-sign(n) * bernoulli(2 * n) / cln::factorial(2 * n));
  });
  expect_correctly_rounded("kDexpinvDerivativeSeries", co::kDexpinvDerivativeSeries, [](long k) {
    const long n = k + 2;  // coefficient of t^(n-2)
    return exact_float(-sign(n) * 2 * (n - 1) * bernoulli(2 * n) / cln::factorial(2 * n));
  });
}

}  // namespace
