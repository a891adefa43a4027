// The emitted double pendulum's rhs integrated with the installed runtime's RK4, against the package's own
// rk4_step: the same method, so the two agree to rounding; exit 0 when they do.
#include "double_pendulum.hpp"

#include <hamel/runtime/rk4.hpp>

#include <cmath>
#include <cstdio>

int main() {
  namespace dp = double_pendulum;
  const auto f = [](double t, const double* x, double* dx) { dp::rhs(t, x, dp::default_parameters, nullptr, dx); };
  double last[dp::n_state] = {};
  const auto r =
      hamel::runtime::integrate_rk4(f, {0.5, -0.3, 0.0, 0.0}, 0.0, 1.0, 0.01, 0.0, [&](double, const double* x) {
        for (int i = 0; i < dp::n_state; ++i) last[i] = x[i];
      });
  double x[dp::n_state] = {0.5, -0.3, 0.0, 0.0};
  for (int k = 0; k < 100; ++k) dp::rk4_step(k * 0.01, 0.01, x, dp::default_parameters, nullptr);
  double worst = 0;
  for (int i = 0; i < dp::n_state; ++i) worst = std::fmax(worst, std::fabs(x[i] - last[i]));
  std::printf("runtime rk4 vs package rk4_step: %.3e\n", worst);
  return r.status == hamel::runtime::Status::ok && worst < 1e-12 ? 0 : 1;
}
