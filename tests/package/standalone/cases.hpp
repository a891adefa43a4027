// SPDX-License-Identifier: MIT
// The initial states, inputs and steps the standalone driver integrates with the emitted rk4_step and
// package_builds_standalone_test integrates with the generator's GraphEvaluator; plain arrays so that the
// driver needs nothing beyond the emitted packages.
#pragma once

namespace hamel_package_cases {

constexpr int steps = 200;
constexpr double h = 0.005;

// chaplygin_sleigh: x, y, theta, v, omega; inputs tau, F (held over every step).
constexpr double sleigh_x0[5] = {0.1, -0.2, 0.3, 1.0, 0.5};
constexpr double sleigh_in[2] = {0.05, 0.2};

// satellite_se3 (--fold all): phi1..3, then the locked velocities and rotor rates (12 in all).
constexpr double satellite_x0[12] = {0.1, 0.2, 0.3, 0.05, -0.02, 0.03, 0.01, 0.0, -0.01, 5.0, -3.0, 2.0};

}  // namespace hamel_package_cases
