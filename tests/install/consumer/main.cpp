// x' = -x from 1 to t = 1 with the installed runtime's RK4: exit 0 when x(1) = e^-1 to 1e-9.
#include <hamel/runtime/rk4.hpp>

#include <cmath>
#include <cstdio>

int main() {
  auto f = [](double, const double* y, double* dy) { dy[0] = -y[0]; };
  double last = 0;
  const auto r =
      hamel::runtime::integrate_rk4(f, {1.0}, 0.0, 1.0, 0.01, 0.0, [&](double, const double* y) { last = y[0]; });
  const double err = std::fabs(last - std::exp(-1.0));
  std::printf("%.3e\n", err);
  return r.status == hamel::runtime::Status::ok && err < 1e-9 ? 0 : 1;
}
