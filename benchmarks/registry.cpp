#include "registry.hpp"

#include <benchmark/benchmark.h>

#include <memory>

namespace hamel_bench {

namespace {

std::vector<KernelEntry>& entries() {
  static std::vector<KernelEntry> list;
  return list;
}

struct Arguments {
  kernel_function f;
  std::vector<double> x, p, in, out;
};

}  // namespace

const std::vector<KernelEntry>& kernels() { return entries(); }

void add_kernel(const std::string& package, const std::string& kernel, kernel_function f, int n_state, int n_parameters,
                int n_inputs, int n_out, int n_temporaries, const double* default_parameters) {
  auto a = std::make_shared<Arguments>();
  a->f = f;
  // A generic state away from singular configurations: x_i in [-0.45, 0.45], the same for every package.
  unsigned seed = 12345;
  for (int i = 0; i < n_state; ++i) {
    seed = seed * 1103515245u + 12345u;
    a->x.push_back(0.9 * static_cast<double>((seed >> 8) % 10007) / 10007.0 - 0.45);
  }
  if (default_parameters) a->p.assign(default_parameters, default_parameters + n_parameters);
  a->in.assign(static_cast<std::size_t>(n_inputs), 0.1);
  a->out.assign(static_cast<std::size_t>(n_out > 0 ? n_out : 1), 0.0);
  entries().push_back({package, kernel, n_temporaries});
  benchmark::RegisterBenchmark((package + "/" + kernel).c_str(), [a](benchmark::State& state) {
    for (auto _ : state) {
      a->f(0.1, a->x.data(), a->p.data(), a->in.data(), a->out.data());
      benchmark::DoNotOptimize(a->out.data());
      benchmark::ClobberMemory();
    }
  })->Unit(benchmark::kNanosecond);
}

}  // namespace hamel_bench
