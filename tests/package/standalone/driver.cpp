// SPDX-License-Identifier: MIT
// Links the emitted packages of two models into one binary (two namespaces) and advances each with its
// emitted rk4_step; prints the sizes and final states for package_builds_standalone_test. Built with
// -fno-exceptions -fno-rtti -Wall -Wextra -Werror -pedantic and nothing but the packages and <cstdio>.
#include "cases.hpp"
#include "chaplygin_sleigh.hpp"
#include "satellite_se3.hpp"

#include <cmath>
#include <cstdio>

namespace {

template <class Real, int N>
void print_state(const char* model, const Real (&x)[N]) {
  for (int i = 0; i < N; ++i) std::printf("%s %d %.17g\n", model, i, static_cast<double>(x[i]));
}

}  // namespace

int main() {
  namespace c = hamel_package_cases;
  std::printf("sizeof_real %d %d\n", static_cast<int>(sizeof(chaplygin_sleigh::real)),
              static_cast<int>(sizeof(satellite_se3::real)));
  std::printf("n_state %d %d\n", chaplygin_sleigh::n_state, satellite_se3::n_state);
  std::printf("n_kernels %d %d\n", chaplygin_sleigh::n_kernels, satellite_se3::n_kernels);

  chaplygin_sleigh::real sleigh[chaplygin_sleigh::n_state];
  for (int i = 0; i < chaplygin_sleigh::n_state; ++i) sleigh[i] = static_cast<chaplygin_sleigh::real>(c::sleigh_x0[i]);
  chaplygin_sleigh::real in[chaplygin_sleigh::n_inputs];
  for (int i = 0; i < chaplygin_sleigh::n_inputs; ++i) in[i] = static_cast<chaplygin_sleigh::real>(c::sleigh_in[i]);

  satellite_se3::real satellite[satellite_se3::n_state];
  for (int i = 0; i < satellite_se3::n_state; ++i) satellite[i] = static_cast<satellite_se3::real>(c::satellite_x0[i]);

  const auto h_sleigh = static_cast<chaplygin_sleigh::real>(c::h);
  const auto h_satellite = static_cast<satellite_se3::real>(c::h);
  for (int k = 0; k < c::steps; ++k) {
    chaplygin_sleigh::rk4_step(static_cast<chaplygin_sleigh::real>(k) * h_sleigh, h_sleigh, sleigh,
                               chaplygin_sleigh::default_parameters, in);
    satellite_se3::rk4_step(static_cast<satellite_se3::real>(k) * h_satellite, h_satellite, satellite,
                            satellite_se3::default_parameters, nullptr);
  }
  print_state("chaplygin_sleigh", sleigh);
  print_state("satellite_se3", satellite);

  // Every kernel through the table (the generic dispatch a firmware might use): finite outputs.
  satellite_se3::real out[satellite_se3::n_out_max];
  int finite = 1;
  for (const auto& k : satellite_se3::kernel_table) {
    k.function(0, satellite, satellite_se3::default_parameters, nullptr, out);
    for (int i = 0; i < k.n_out; ++i) finite = finite && std::isfinite(static_cast<double>(out[i]));
  }
  std::printf("finite %d\n", finite);
  return 0;
}
