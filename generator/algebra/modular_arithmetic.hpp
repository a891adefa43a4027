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

}  // namespace hamel::modular
