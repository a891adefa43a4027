// Residues modulo the Mersenne prime 2^61 − 1: one of the number types hamel evaluates expressions in (with double,
// algebra/operations.hpp, and 50-digit floats, algebra/high_precision.hpp), the one of the randomized exact zero
// tests (Schwartz–Zippel): algebra/identity_test on GiNaC expressions, emit/zero_test on the IR. Both compute with
// Residue (evaluate_in's rules below) and draw their random points with RandomPoint, keyed by what a value stands
// for (a symbol's name, a node's structural key), so a point does not depend on the order in which a test visits
// an expression.
#pragma once

#include "algebra/operations.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string_view>

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

/// A residue, with +, −, × and negation modulo p: evaluate_in's number type for the zero tests.
struct Residue {
  u64 value = 0;
  friend Residue operator+(Residue a, Residue b) { return {add_mod(a.value, b.value)}; }
  friend Residue operator-(Residue a, Residue b) { return {sub_mod(a.value, b.value)}; }
  friend Residue operator*(Residue a, Residue b) { return {mul_mod(a.value, b.value)}; }
  friend Residue operator-(Residue a) { return {sub_mod(0, a.value)}; }
  bool is_zero() const { return value == 0; }
};

/// Thrown where a value has no residue at this point: a division by 0, the square root of a non-square.
struct Pole {};

inline Residue divide(Residue a, Residue b) {
  if (b.value == 0) throw Pole{};
  return {mul_mod(a.value, inverse_of_nonzero(b.value))};
}

/// a^k for an integer k (a negative k divides: Pole at a = 0).
inline Residue power(Residue a, long k) {
  const u64 r = pow_mod(a.value, k < 0 ? 0 - static_cast<u64>(k) : static_cast<u64>(k));
  return k < 0 ? divide({1}, {r}) : Residue{r};
}

/// The square root of a modulo p ≡ 3 (mod 4): a^((p+1)/4) when a is a square (Pole otherwise). One root of each
/// value, multiplicatively: read as x^(1/2), the identities of the algebraic extension by √x hold.
inline Residue square_root(Residue a) {
  if (a.value == 0) return a;
  const u64 r = pow_mod(a.value, (prime + 1) / 4);
  if (mul_mod(r, r) != a.value) throw Pole{};
  return {r};
}

/// op(a, b) for +, −, ×, / and negation (Pole for a division by 0); the other operations need more than two
/// residues (sin and cos a circle point, other functions a free variable) and are the callers' (throws
/// std::logic_error).
inline Residue arithmetic(Op op, Residue a, Residue b) {
  return evaluate_in<Residue>(
      op, a, b, divide, [](Residue, Residue) -> Residue { throw std::logic_error("residues: pow is the caller's"); },
      [](Op, Residue) -> Residue { throw std::logic_error("residues: functions are the caller's"); });
}

/// The key of a name (FNV-1a): what a symbol's random residue is drawn for.
inline u64 key_of(std::string_view name) {
  u64 h = 1469598103934665603ULL;
  for (char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return h;
}

/// A random point: a residue in [1, p − 1] for every key, a function of (seed, key) only (splitmix64), so the
/// same in every run and whatever order the keys are asked in.
class RandomPoint {
 public:
  explicit RandomPoint(u64 seed) : seed_(seed) {}
  Residue residue(u64 key) const {
    u64 z = seed_ ^ (key * 0x9e3779b97f4a7c15ULL);
    for (int round = 0; round < 2; ++round) {
      z += 0x9e3779b97f4a7c15ULL;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      z ^= z >> 31;
    }
    return {1 + z % (prime - 1)};
  }
  /// A random point of the circle (Circle::at of a residue drawn for a key derived from `key`).
  Circle circle(u64 key) const { return Circle::at(residue(key ^ 0x5bd1e9955bd1e995ULL).value); }

 private:
  u64 seed_;
};

}  // namespace hamel::modular
