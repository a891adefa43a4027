// SPDX-License-Identifier: MIT
// Scalar coefficient functions of the closed-form exp, dexp and dexp^-1 on
// SO(3), SE(3) and SE(2), accurate to a few ulps for every angle.
//
// All of them are even, analytic functions of the rotation angle theta >= 0
// (poles only where noted), so each is written as a power series in t = theta^2
// near 0 and as a closed form farther out. The closed forms subtract nearly
// equal numbers at small theta: (theta - sin theta)/theta^3 evaluated in double
// keeps only log10(theta^2 / 6 / 2^-53) digits, and the SE(3) derivative terms
// lose twice as many. Where the switch lies is chosen per coefficient with the
// following model (u = 2^-53, the unit roundoff; 1 ulp = 2u relative):
//
//   closed form: relative rounding error ~ u * kappa_c(theta), where kappa_c is
//     the condition number of its cancelling sum (sum of |terms| / |result|);
//     each term carries about one rounding error of libm's sin/cos (< 1 ulp).
//   series, N terms: relative error ~ u * kappa_s(theta) + truncation, with
//     kappa_s = sum |c_k| t^k / |f|, and truncation = |c_N t^N| / |f| (the
//     first omitted term; the tails decrease geometrically or faster).
//
// The switch theta_0 is placed where the closed form has stopped being worse
// than the series (kappa_c(theta_0) at most kappa_s(theta_0), or at most 1/2
// when the series has positive terms and kappa_s = 1), and N is the smallest
// count whose truncation at theta_0 is below u/8. Each function documents its
// numbers. The resulting accuracy is not taken on trust: the runtime tests
// compare every function with a 120-digit evaluation of its closed form on a
// grid that straddles every switch (worst errors 0.8 to 2.8 ulp).
//
// Names: a(theta) = sin(theta)/theta, b = (1 - cos theta)/theta^2,
// c = (theta - sin theta)/theta^3, eta = (1 - (theta/2) cot(theta/2))/theta^2,
// and "_d" denotes (1/theta) d/dtheta of the function (needed by SE(3), where
// the translational block of dexp is the directional derivative of the
// rotational one). In those terms, on so(3) with W = hat(w), theta = |w|:
//   exp(W)     = I + a W + b W^2
//   dexp_w     = I + b W + c W^2          (also the V matrix of SE(3) exp)
//   dexp_w^-1  = I - W/2 + eta W^2
#pragma once

#include <cmath>
#include <cstddef>

namespace hamel::runtime::lie::coefficients {

namespace detail {

/// Evaluates c[0] + c[1] t + ... + c[n-1] t^(n-1) by Horner's rule.
template <std::size_t N>
constexpr double horner(const double (&c)[N], double t) {
  double r = c[N - 1];
  for (std::size_t k = N - 1; k-- > 0;) r = r * t + c[k];
  return r;
}

}  // namespace detail

// Taylor coefficients, as polynomials in t = theta^2. Each literal is the exact
// rational value rounded to the nearest double (17 significant digits round
// trip); tests/runtime/lie_coefficients_are_accurate_test.cpp checks every one
// against exact rational arithmetic (CLN).

/// (theta - sin theta)/theta^3 = sum_k (-1)^k t^k / (2k+3)!, k = 0..10.
inline constexpr double kSinDefectSeries[] = {
    0.16666666666666666,    -0.0083333333333333332,  0.00019841269841269841, -2.7557319223985893e-06,
    2.505210838544172e-08,  -1.6059043836821613e-10, 7.6471637318198164e-13, -2.8114572543455206e-15,
    8.2206352466243295e-18, -1.9572941063391263e-20, 3.8681701706306841e-23,
};

/// (1/theta) d/dtheta of the above = sum_{k>=1} (-1)^k 2k t^(k-1) / (2k+3)!, k = 1..14.
inline constexpr double kSinDefectDerivativeSeries[] = {
    -0.016666666666666666,   0.00079365079365079365, -1.6534391534391536e-05, 2.0041686708353376e-07,
    -1.6059043836821615e-09, 9.1765964781837793e-12, -3.936040156083729e-14,  1.3153016394598927e-16,
    -3.5231293914104271e-19, 7.7363403412613678e-22, -1.4183290625645841e-24, 2.204085567310931e-27,
    -2.9405903504764064e-30, 3.4051501163498504e-33,
};

/// eta = sum_{n>=1} (-1)^(n+1) B_2n t^(n-1) / (2n)!, n = 1..23 (B_2n Bernoulli
/// numbers; all terms are positive).
inline constexpr double kDexpinvSeries[] = {
    0.083333333333333329,   0.0013888888888888889,  3.3068783068783071e-05, 8.2671957671957675e-07,
    2.08767569878681e-08,   5.2841901386874932e-10, 1.3382536530684679e-11, 3.3896802963225827e-13,
    8.5860620562778452e-15, 2.1748686985580619e-16, 5.5090028283602295e-18, 1.3954464685812522e-19,
    3.5347070396294673e-21, 8.9535174270375463e-23, 2.2679524523376829e-24, 5.7447906688722025e-26,
    1.455172475614865e-27,  3.6859949406653103e-29, 9.3367342570950451e-31, 2.36502241570063e-32,
    5.9906717624821341e-34, 1.5174548844682903e-35, 3.8437581254541886e-37,
};

/// (1/theta) d eta/dtheta = sum_{n>=2} 2(n-1) (-1)^(n+1) B_2n t^(n-2) / (2n)!,
/// n = 2..26 (all terms positive).
inline constexpr double kDexpinvDerivativeSeries[] = {
    0.0027777777777777779,  0.00013227513227513228, 4.9603174603174603e-06, 1.670140559029448e-07,
    5.2841901386874934e-09, 1.6059043836821613e-10, 4.7455524148516162e-12, 1.3737699290044552e-13,
    3.914763657404511e-15,  1.1018005656720459e-16, 3.0699822308787551e-18, 8.4832968951107215e-20,
    2.3279145310297621e-21, 6.3502668665455129e-23, 1.7234372006616606e-24, 4.6565519219675679e-26,
    1.2532382798262054e-27, 3.3612243325542163e-29, 8.9870851796623931e-31, 2.3962687049928537e-32,
    6.3733105147668194e-34, 1.6912535751998429e-35, 4.4787224134174783e-37, 1.1837985812163269e-38,
    3.1235383709103717e-40,
};

// Switch points (see each function for the derivation).
inline constexpr double kSincSwitch = 1e-4;
inline constexpr double kSinDefectSwitch = 1.9;
inline constexpr double kSinDefectDerivativeSwitch = 3.3;
inline constexpr double kDexpinvSwitch = 2.65;

/// a(theta) = sin(theta)/theta.
///
/// The quotient itself is accurate to about 1 ulp for every theta > 0 (no
/// cancellation); the series 1 - t/6 is used below 1e-4 only to avoid 0/0 and
/// the underflow of tiny theta. Its truncation there is t^2/120 < 1e-18, far
/// below u. Measured worst error: 0.8 ulp.
inline double sinc(double theta) {
  if (theta < kSincSwitch) return 1.0 - theta * theta / 6.0;
  return std::sin(theta) / theta;
}

/// b(theta) = (1 - cos theta)/theta^2, written as (1/2) a(theta/2)^2.
///
/// The half-angle identity 1 - cos theta = 2 sin^2(theta/2) removes the
/// cancellation completely, so no switch is needed: the error is that of
/// sinc plus two roundings, for every theta. (Evaluated naively, 1 - cos theta
/// is 100 % wrong at theta = 1e-8.) Measured worst error: 1.5 ulp.
inline double versine_ratio(double theta) {
  const double s = sinc(0.5 * theta);
  return 0.5 * s * s;
}

/// c(theta) = (theta - sin theta)/theta^3.
///
/// Closed form: only sin theta carries an error (half an ulp of sin theta), and
/// the subtraction magnifies it by kappa_c = sin theta/(theta - sin theta),
/// which drops to 1 at theta = 1.895. The series alternates with
/// kappa_s = (sinh theta - theta)/(theta - sin theta) = 1.43 there.
/// theta_0 = 1.9; the first omitted term of the 11-term series is
/// t^11/25! = 0.006 u relative at theta_0. Measured worst error: 1.6 ulp.
inline double sin_defect_ratio(double theta) {
  const double t = theta * theta;
  if (theta < kSinDefectSwitch) return detail::horner(kSinDefectSeries, t);
  return (theta - std::sin(theta)) / (t * theta);
}

/// c_d(theta) = (1/theta) dc/dtheta = (3 sin theta - theta cos theta - 2 theta)/theta^5.
///
/// The numerator is O(theta^5) made of O(theta) terms: kappa_c =
/// (3|sin| + theta|cos| + 2 theta)/|numerator| is 3.6 at theta = 3, 2.7 at 3.3
/// and 1.9 at 3.8, while the alternating series has kappa_s = 2.4 at 3, 2.8 at
/// 3.3 and 4.0 at 3.8; the two cross at theta_0 = 3.3. The first omitted term
/// of the 14-term series is below 0.006 u relative there. Measured worst
/// error: 1.6 ulp.
inline double sin_defect_ratio_d(double theta) {
  const double t = theta * theta;
  if (theta < kSinDefectDerivativeSwitch) return detail::horner(kSinDefectDerivativeSeries, t);
  return (3.0 * std::sin(theta) - theta * std::cos(theta) - 2.0 * theta) / (t * t * theta);
}

/// eta(theta) = (1 - (theta/2) cot(theta/2))/theta^2, the W^2 coefficient of
/// dexp^-1 on so(3). Poles at theta = 2 pi k, k >= 1.
///
/// Closed form: p = (theta/2) cot(theta/2) is evaluated as
/// cos(theta/2)/a(theta/2) to about 2 ulps, and 1 - p magnifies that by
/// kappa_c = p/(1 - p): 1.8 at theta = 2, 0.5 at 2.65, 0 at pi. The series has
/// only positive terms (kappa_s = 1), so it is never worse; it converges like
/// (theta/2pi)^2k, which makes it long near pi. theta_0 = 2.65 is where
/// kappa_c = 1/2, i.e. where the closed form has become as good as the
/// series; 23 terms keep the truncation below 0.03 u there. Measured worst
/// error: 1.5 ulp.
/// (Evaluated naively with theta sin theta/(2(1 - cos theta)), the error is
/// 1e-4 relative at theta = 1e-3.)
inline double dexpinv_ratio(double theta) {
  const double t = theta * theta;
  if (theta < kDexpinvSwitch) return detail::horner(kDexpinvSeries, t);
  const double half = 0.5 * theta;
  return (1.0 - std::cos(half) / sinc(half)) / t;
}

/// eta_d(theta) = (1/theta) d eta/dtheta; poles at theta = 2 pi k, k >= 1.
///
/// The closed form (1/t)((1/a(theta/2)^2 - 1)/t - eta) cancels badly over a
/// wide range: kappa_c is still 3 at theta = 4 and drops to 1.5 only at 5.3.
/// The series has positive terms but would need ~45 of them at 5.3. In
/// between, the half-angle identity
///     eta_d(theta) = eta_d(theta/2)/16 + c(theta/2) / (64 cos^2(theta/4)),
/// (differentiate eta(theta) = eta(theta/2)/4 + tan(theta/4)/(4 theta)) adds two
/// positive terms and so loses nothing. Hence: the 25-term series below
/// theta_0 = 2.65 (truncation 0.03 u there), one half-angle step on
/// [2.65, 5.3), the closed form from 5.3 on (kappa_c <= 1.5). Measured worst
/// error: 2.8 ulp (near 2 pi, in the closed form).
inline double dexpinv_ratio_d(double theta) {
  const double t = theta * theta;
  if (theta < kDexpinvSwitch) return detail::horner(kDexpinvDerivativeSeries, t);
  if (theta < 2.0 * kDexpinvSwitch) {
    const double half = 0.5 * theta;
    const double q = std::cos(0.25 * theta);
    return detail::horner(kDexpinvDerivativeSeries, half * half) / 16.0 + sin_defect_ratio(half) / (64.0 * q * q);
  }
  const double s = sinc(0.5 * theta);
  return ((1.0 / (s * s) - 1.0) / t - dexpinv_ratio(theta)) / t;
}

/// b_d(theta) = (1/theta) db/dtheta = (theta sin theta - 2(1 - cos theta))/theta^4.
///
/// Since eta = (1 - a/(2b))/theta^2, this equals -2 b eta exactly: a product of
/// two accurate factors, so it needs no switch of its own. Measured worst
/// error: 2.4 ulp.
inline double versine_ratio_d(double theta) { return -2.0 * versine_ratio(theta) * dexpinv_ratio(theta); }

}  // namespace hamel::runtime::lie::coefficients
