// The benchmark registry: every emitted kernel of every package, timed with the same pseudo-random
// state, default parameters and small inputs.
#pragma once

#include <string>
#include <vector>

namespace hamel_bench {

using kernel_function = void (*)(double t, const double* x, const double* p, const double* in, double* out);

/// Registers `package/kernel` with Google Benchmark.
void add_kernel(const std::string& package, const std::string& kernel, kernel_function f, int n_state, int n_parameters,
                int n_inputs, int n_out, int n_temporaries, const double* default_parameters);

struct KernelEntry {
  std::string package, kernel;
  int n_temporaries;
};

/// Everything registered, in registration order.
const std::vector<KernelEntry>& kernels();

}  // namespace hamel_bench
