// Stiff test problems shared by the runtime's tests.
#pragma once

#include <cmath>

namespace hamel::runtime_test {

// Prothero-Robinson: x' = lambda (x - phi(t)) + phi'(t) with phi = sin has the
// solution x = phi for x(0) = 0, whatever lambda; lambda = -1e6 makes it stiff.
constexpr double kLambda = -1e6;
inline void prothero_robinson_rhs(double t, const double* x, double* f) {
  f[0] = kLambda * (x[0] - std::sin(t)) + std::cos(t);
}
inline void prothero_robinson_jac(double, const double*, double* J) { J[0] = kLambda; }

// Van der Pol oscillator x'' - mu (1 - x^2) x' + x = 0 as a first-order system, mu = 1000.
constexpr double kMu = 1000.0;
inline void van_der_pol_rhs(double, const double* y, double* f) {
  f[0] = y[1];
  f[1] = kMu * (1 - y[0] * y[0]) * y[1] - y[0];
}
inline void van_der_pol_jac(double, const double* y, double* J) {
  J[0] = 0.0;
  J[1] = 1.0;
  J[2] = -2 * kMu * y[0] * y[1] - 1.0;
  J[3] = kMu * (1 - y[0] * y[0]);
}

}  // namespace hamel::runtime_test
