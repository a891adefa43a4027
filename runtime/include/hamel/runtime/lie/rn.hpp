// SPDX-License-Identifier: MIT
// The additive group R^k, so that vector-valued unknowns fit the same interface.
#pragma once

#include <array>
#include <cstddef>

#include "hamel/runtime/lie/matrix.hpp"

namespace hamel::runtime::lie {

/// R^k under addition as a group policy: exp and log are the identity, dexp,
/// dexp^-1 and Ad the identity matrix, ad zero. The Munthe-Kaas method on Rn<k>
/// is the classic Runge-Kutta method.
template <std::size_t K>
struct Rn {
  static constexpr std::size_t dim = K;
  using Vector = std::array<double, K>;
  using Matrix = SquareMatrix<K>;
  using Element = std::array<double, K>;

  static Element identity() { return Element{}; }
  static Element exp(const Vector& x) { return x; }
  static Vector log(const Element& g) { return g; }
  static Matrix dexp(const Vector&) { return identity_matrix<K>(); }
  static Matrix dexpinv(const Vector&) { return identity_matrix<K>(); }
  static Matrix ad(const Vector&) { return Matrix{}; }
  static Matrix Ad(const Element&) { return identity_matrix<K>(); }

  static Element compose(const Element& a, const Element& b) {
    Element c;
    for (std::size_t i = 0; i < K; ++i) c[i] = a[i] + b[i];
    return c;
  }

  static Element inverse(const Element& g) {
    Element c;
    for (std::size_t i = 0; i < K; ++i) c[i] = -g[i];
    return c;
  }

  static bool is_finite(const Element& g) { return all_finite(g); }
};

}  // namespace hamel::runtime::lie
