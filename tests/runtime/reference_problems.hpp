// SPDX-License-Identifier: MIT
// Problems and fits the runtime's integrator tests share (kepler_orbit.hpp holds the Kepler orbit and its exact
// solution).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace hamel_test {

/// Arenstorf's periodic orbit of the restricted three-body problem (Hairer, Norsett & Wanner I, Sect. II.0): it
/// closes after arenstorf_period but passes close to the moon, where steps must shrink by orders of magnitude.
inline void arenstorf_rhs(double /*t*/, const double* y, double* f) {
  constexpr double mu = 0.012277471;
  constexpr double mu1 = 1.0 - mu;
  const double d1 = std::pow((y[0] + mu) * (y[0] + mu) + y[1] * y[1], 1.5);
  const double d2 = std::pow((y[0] - mu1) * (y[0] - mu1) + y[1] * y[1], 1.5);
  f[0] = y[2];
  f[1] = y[3];
  f[2] = y[0] + 2 * y[3] - mu1 * (y[0] + mu) / d1 - mu * (y[0] - mu1) / d2;
  f[3] = y[1] - 2 * y[2] - mu1 * y[1] / d1 - mu * y[1] / d2;
}
inline const std::array<double, 4> arenstorf_start = {0.994, 0.0, 0.0, -2.00158510637908252240537862224};
inline constexpr double arenstorf_period = 17.0652165601579625588917206249;

/// Least-squares slope of log(y) against log(x): an observed order of convergence.
inline double fitted_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += std::log(x[i]);
    my += std::log(y[i]);
  }
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(x.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (std::log(x[i]) - mx) * (std::log(y[i]) - my);
    sxx += (std::log(x[i]) - mx) * (std::log(x[i]) - mx);
  }
  return sxy / sxx;
}

}  // namespace hamel_test
