// Side-by-side benchmark of one model's kernels printed whole (emit --split 0) and split (emit --split N):
// the two packages are the same model under the names WHOLE and SPLIT (tools/split-bench.sh). Before timing,
// every kernel of both packages is evaluated at random states and must agree bit for bit (the split kernels
// perform the same operations in the same order); then Google Benchmark times each kernel of each package.
#include WHOLE_HEADER
#include SPLIT_HEADER

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

std::vector<double> random_state(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(-0.8, 0.8);
  std::vector<double> x(static_cast<std::size_t>(n));
  for (double& v : x) v = u(rng);
  return x;
}

int check_identical() {
  std::mt19937 rng(11);
  int failures = 0;
  for (int s = 0; s < 20; ++s) {
    const std::vector<double> x = random_state(rng, WHOLE::n_state);
    const std::vector<double> in(static_cast<std::size_t>(WHOLE::n_inputs) + 1, 0.1);
    for (int k = 0; k < WHOLE::n_kernels; ++k) {
      const auto& a = WHOLE::kernel_table[k];
      const auto& b = SPLIT::kernel_table[k];
      std::vector<double> oa(static_cast<std::size_t>(a.n_out) + 1), ob(static_cast<std::size_t>(b.n_out) + 1);
      a.function(0.0, x.data(), WHOLE::default_parameters, in.data(), oa.data());
      b.function(0.0, x.data(), SPLIT::default_parameters, in.data(), ob.data());
      if (a.n_out != b.n_out || std::strcmp(a.name, b.name) != 0 ||
          std::memcmp(oa.data(), ob.data(), sizeof(double) * static_cast<std::size_t>(a.n_out)) != 0) {
        std::fprintf(stderr, "split-bench: kernel %s differs between whole and split at state %d\n", a.name, s);
        ++failures;
      }
    }
  }
  return failures;
}

void run_kernel(benchmark::State& state, WHOLE::kernel_function f, int n_state, int n_inputs, int n_out,
                const double* p) {
  std::mt19937 rng(5);
  const std::vector<double> x = random_state(rng, n_state);
  const std::vector<double> in(static_cast<std::size_t>(n_inputs) + 1, 0.1);
  std::vector<double> out(static_cast<std::size_t>(n_out) + 1);
  for (auto _ : state) {
    f(0.0, x.data(), p, in.data(), out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (check_identical() != 0) return 1;
  std::printf("split-bench: every kernel bit-identical whole and split on 20 random states\n");
  for (int k = 0; k < WHOLE::n_kernels; ++k) {
    const auto& a = WHOLE::kernel_table[k];
    const auto& b = SPLIT::kernel_table[k];
    benchmark::RegisterBenchmark((std::string(a.name) + "/whole").c_str(), run_kernel, a.function,
                                 WHOLE::n_state, WHOLE::n_inputs, a.n_out, WHOLE::default_parameters);
    benchmark::RegisterBenchmark((std::string(b.name) + "/split").c_str(), run_kernel, b.function,
                                 SPLIT::n_state, SPLIT::n_inputs, b.n_out, SPLIT::default_parameters);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
