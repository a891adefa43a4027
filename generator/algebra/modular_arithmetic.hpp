// Arithmetic modulo the Mersenne prime 2^61 − 1, for the randomized exact zero tests (Schwartz–Zippel) of
// algebra/identity_test and emit/zero_test.
#pragma once

#include <cmath>
#include <cstdint>

namespace hamel::modular {

using u64 = std::uint64_t;
__extension__ typedef unsigned __int128 u128;  // GCC and Clang; the product of two residues needs 122 bits
constexpr u64 prime = (u64{1} << 61) - 1;

inline u64 add_mod(u64 a, u64 b) {
  const u64 s = a + b;
  return s >= prime ? s - prime : s;
}
inline u64 sub_mod(u64 a, u64 b) { return a >= b ? a - b : a + prime - b; }
inline u64 mul_mod(u64 a, u64 b) {
  const u128 p = static_cast<u128>(a) * b;
  const u64 lo = static_cast<u64>(p & prime), hi = static_cast<u64>(p >> 61);  // 2^61 ≡ 1
  return add_mod(lo, hi);
}
inline u64 pow_mod(u64 a, u64 k) {
  u64 r = 1;
  for (; k; k >>= 1, a = mul_mod(a, a))
    if (k & 1) r = mul_mod(r, a);
  return r;
}
/// a⁻¹ for a ≠ 0 (Fermat).
inline u64 inverse_of_nonzero(u64 a) { return pow_mod(a, prime - 2); }

/// The residue of a finite double, read as the rational m · 2^e it is exactly.
inline u64 residue_of_double(double v) {
  int exponent = 0;
  const double mantissa = std::frexp(std::fabs(v), &exponent);  // |v| = mantissa · 2^exponent, mantissa in [0.5, 1)
  const auto m = static_cast<u64>(std::ldexp(mantissa, 53));
  exponent -= 53;
  const u64 power = exponent >= 0 ? pow_mod(2, static_cast<u64>(exponent))
                                  : inverse_of_nonzero(pow_mod(2, static_cast<u64>(-exponent)));
  const u64 r = mul_mod(m % prime, power);
  return v < 0 ? sub_mod(0, r) : r;
}

/// A point of the unit circle c² + s² = 1 over Z/pZ, c + i s multiplied as complex numbers: what the zero tests
/// read sin and cos of an angle as, so that sin² + cos² = 1 and the addition theorems hold exactly (the angle
/// k θ is the point to the power k).
struct Circle {
  u64 c = 1, s = 0;
  Circle operator*(const Circle& o) const {
    return {sub_mod(mul_mod(c, o.c), mul_mod(s, o.s)), add_mod(mul_mod(c, o.s), mul_mod(s, o.c))};
  }
  /// z^k; for k < 0 the conjugate's power (z⁻¹ = z̄ on the circle).
  Circle power(long k) const {
    Circle z = k < 0 ? Circle{c, sub_mod(0, s)} : *this, r;
    for (unsigned long n = k < 0 ? 0UL - static_cast<unsigned long>(k) : static_cast<unsigned long>(k); n;
         n >>= 1, z = z * z)
      if (n & 1) r = r * z;
    return r;
  }
  /// The point ((1 − τ²), 2τ) / (1 + τ²) for any residue τ (1 + τ² ≠ 0 because p ≡ 3 mod 4).
  static Circle at(u64 tau) {
    const u64 tau2 = mul_mod(tau, tau), den = inverse_of_nonzero(add_mod(1, tau2));
    return {mul_mod(sub_mod(1, tau2), den), mul_mod(mul_mod(2, tau), den)};
  }
};

}  // namespace hamel::modular
