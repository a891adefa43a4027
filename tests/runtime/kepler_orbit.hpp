// SPDX-License-Identifier: MIT
// Analytic Kepler orbit (mu = 1, semi-major axis 1): a nonlinear reference solution.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace hamel_test {

/// Orbital period for mu = 1 and semi-major axis 1.
inline constexpr double kepler_period = 6.283185307179586476925286766559;

/// Right-hand side of the planar two-body problem, state (x, y, vx, vy).
inline void kepler_rhs(double /*t*/, const double* s, double* f) {
  const double r2 = s[0] * s[0] + s[1] * s[1];
  const double inv_r3 = 1.0 / (r2 * std::sqrt(r2));
  f[0] = s[2];
  f[1] = s[3];
  f[2] = -s[0] * inv_r3;
  f[3] = -s[1] * inv_r3;
}

/// Exact state at time t of the orbit with eccentricity e that is at periapsis
/// on the positive x axis at t = 0, from Kepler's equation E - e sin E = t
/// solved by Newton's method.
inline std::array<double, 4> kepler_state(double t, double e) {
  double E = t + e * std::sin(t);
  for (int i = 0; i < 50; ++i) {
    const double dE = (E - e * std::sin(E) - t) / (1.0 - e * std::cos(E));
    E -= dE;
    if (std::fabs(dE) < 1e-16 * (1.0 + std::fabs(E))) {
      break;
    }
  }
  const double b = std::sqrt(1.0 - e * e);
  const double E_dot = 1.0 / (1.0 - e * std::cos(E));
  return {std::cos(E) - e, b * std::sin(E), -std::sin(E) * E_dot, b * std::cos(E) * E_dot};
}

/// Largest absolute component difference between a state and the exact orbit.
inline double kepler_error(double t, const double* s, double e) {
  const std::array<double, 4> exact = kepler_state(t, e);
  double err = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    err = std::fmax(err, std::fabs(s[i] - exact[i]));
  }
  return err;
}

}  // namespace hamel_test
