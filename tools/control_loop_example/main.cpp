// SPDX-License-Identifier: MIT
// A fixed-rate (1 kHz) attitude control loop for the satellite with three reaction wheels, built on the
// generated package satellite_wheels_controlled alone (see README.md). Every tick it reads the state,
// evaluates the generated kernels (group_velocity for the base angular velocity, rhs for the wheel
// accelerations it reports) and advances the plant by one emitted rk4_step with the wheel torques held;
// the attitude quaternion is propagated from the base angular velocity. Nothing is allocated: all arrays
// live on the stack with sizes from the package's ABI constants.
//
// Usage: control_loop [seconds] (default 10). Prints a line per simulated second and a summary; exits 0
// when the attitude error ends below 1e-3 rad, 1 otherwise.
#include "satellite_wheels_controlled.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace {

namespace sat = satellite_wheels_controlled;
using real = sat::real;

// Rotation as a unit quaternion (w, x, y, z); body-fixed angular velocity w: q' = q (0, w) / 2.
struct Quaternion {
  real w, x, y, z;
};

Quaternion multiply(const Quaternion& a, const Quaternion& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// exp of the rotation vector v (angle |v| about v / |v|).
Quaternion rotation(const real v[3]) {
  const real angle = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const real half = angle / real(2);
  // sin(a/2)/a, with its series near zero.
  const real s = angle < real(1e-4) ? real(0.5) - angle * angle / real(48) : std::sin(half) / angle;
  return {std::cos(half), s * v[0], s * v[1], s * v[2]};
}

Quaternion normalized(const Quaternion& q) {
  const real n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// Attitude error (rotation vector of the shortest rotation from the target, here the identity, to q).
void attitude_error(const Quaternion& q, real e[3]) {
  const real sign = q.w < 0 ? real(-1) : real(1);
  const real vec = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  const real angle = real(2) * std::atan2(vec, sign * q.w);
  const real scale = vec > real(0) ? sign * angle / vec : real(2);
  e[0] = scale * q.x;
  e[1] = scale * q.y;
  e[2] = scale * q.z;
}

real norm3(const real v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Indices into the state and kernel outputs (the package's layout, README.md): the rotor rates phi_i_dot
// are the last three states; group_velocity gives (wx, wy, wz, vx, vy, vz).
constexpr int first_rotor_rate = sat::n_state - 3;
static_assert(sat::n_inputs == 3, "the wheel torques tau1..tau3");
static_assert(sat::n_out_group_velocity == 6, "xi = (w, v)");

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  constexpr int rate_hz = 1000;
  const real h = real(1) / real(rate_hz);
  const long ticks = static_cast<long>(seconds * rate_hz + 0.5);

  // PD on the attitude error through the wheels: the base feels -tau_i about e_i, so tau = Kp e + Kd w
  // drives e to zero; |tau_i| <= tau_max. Gains for about 25 kg m^2: natural frequency 2 rad/s, damping 0.9.
  const real kp = real(100), kd = real(90), tau_max = real(5);

  // Initial state: at rest, rotors still; attitude 0.2 rad about (1, 2, -1) / sqrt(6).
  real x[sat::n_state] = {};
  const real axis_scale = real(0.2) / std::sqrt(real(6));
  const real initial_rotation[3] = {axis_scale, real(2) * axis_scale, -axis_scale};
  Quaternion q = rotation(initial_rotation);
  const real* p = sat::default_parameters;

  real xi[sat::n_out_group_velocity];
  real xi_next[sat::n_out_group_velocity];
  real x_dot[sat::n_out_rhs];
  real tau[sat::n_inputs] = {};
  real e[3];
  sat::group_velocity(0, x, p, tau, xi);

  double worst_tick_us = 0, total_us = 0, settle_time = -1;
  real peak_tau = 0, peak_wheel_acceleration = 0, peak_wheel_rate = 0;
  std::printf("# t[s] attitude_error[rad] |w|[rad/s] wheel_rates[rad/s] tau[N m]\n");
  for (long k = 0; k <= ticks; ++k) {
    const real t = static_cast<real>(k) * h;
    attitude_error(q, e);
    const real error = norm3(e);
    if (error >= real(1e-3)) settle_time = -1;
    if (error < real(1e-3) && settle_time < 0) settle_time = static_cast<double>(t);
    if (k % rate_hz == 0)
      std::printf("%5.1f %.3e %.3e % .3f % .3f % .3f % .3f % .3f % .3f\n", static_cast<double>(t),
                  static_cast<double>(error), static_cast<double>(norm3(xi)), static_cast<double>(x[first_rotor_rate]),
                  static_cast<double>(x[first_rotor_rate + 1]), static_cast<double>(x[first_rotor_rate + 2]),
                  static_cast<double>(tau[0]), static_cast<double>(tau[1]), static_cast<double>(tau[2]));
    if (k == ticks) break;

    // One tick: controller, model, one integrator step (timed: the budget is 1000 us).
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 3; ++i) {
      const real demand = kp * e[i] + kd * xi[i];
      tau[i] = demand > tau_max ? tau_max : (demand < -tau_max ? -tau_max : demand);
    }
    sat::rhs(t, x, p, tau, x_dot);
    sat::rk4_step(t, h, x, p, tau);
    sat::group_velocity(t + h, x, p, tau, xi_next);
    real turn[3];
    for (int i = 0; i < 3; ++i) turn[i] = h * (xi[i] + xi_next[i]) / real(2);
    q = normalized(multiply(q, rotation(turn)));
    for (int i = 0; i < sat::n_out_group_velocity; ++i) xi[i] = xi_next[i];
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();

    total_us += us;
    if (us > worst_tick_us) worst_tick_us = us;
    for (int i = 0; i < 3; ++i) {
      peak_tau = std::fmax(peak_tau, std::fabs(tau[i]));
      peak_wheel_acceleration = std::fmax(peak_wheel_acceleration, std::fabs(x_dot[first_rotor_rate + i]));
      peak_wheel_rate = std::fmax(peak_wheel_rate, std::fabs(x[first_rotor_rate + i]));
    }
  }
  attitude_error(q, e);
  const double final_error = static_cast<double>(norm3(e));
  std::printf("ticks %ld at %d Hz, real = %s\n", ticks, rate_hz, sizeof(real) == 4 ? "float" : "double");
  std::printf("final attitude error %.3e rad, |w| %.3e rad/s\n", final_error, static_cast<double>(norm3(xi)));
  std::printf("settled below 1e-3 rad at t = %.3f s\n", settle_time);
  std::printf("peak |tau| %.3f N m, peak wheel acceleration %.3f rad/s^2, peak wheel rate %.3f rad/s\n",
              static_cast<double>(peak_tau), static_cast<double>(peak_wheel_acceleration),
              static_cast<double>(peak_wheel_rate));
  std::printf("compute per tick: mean %.2f us, worst %.2f us (budget %d us)\n", total_us / (ticks > 0 ? ticks : 1),
              worst_tick_us, 1000000 / rate_hz);
  return final_error < 1e-3 ? 0 : 1;
}
