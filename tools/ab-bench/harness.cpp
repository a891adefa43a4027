// Side-by-side benchmark of one model's kernels emitted two ways, A and B (tools/ab-bench.sh): two packages
// of the same model under the names A and B. Before timing, every kernel of both packages is evaluated at
// random states and must agree: bit for bit when TOLERANCE is 0 (e.g. split against whole kernels, which
// perform the same operations in the same order), otherwise to TOLERANCE relative to the kernel's largest
// output. Then Google Benchmark times each kernel of each package.
#include A_HEADER
#include B_HEADER

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
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

int check_agreement() {
  std::mt19937 rng(11);
  int failures = 0;
  double worst = 0;
  for (int s = 0; s < 20; ++s) {
    const std::vector<double> x = random_state(rng, A::n_state);
    const std::vector<double> in(static_cast<std::size_t>(A::n_inputs) + 1, 0.1);
    for (int k = 0; k < A::n_kernels; ++k) {
      const auto& a = A::kernel_table[k];
      const auto& b = B::kernel_table[k];
      std::vector<double> oa(static_cast<std::size_t>(a.n_out) + 1), ob(static_cast<std::size_t>(b.n_out) + 1);
      a.function(0.0, x.data(), A::default_parameters, in.data(), oa.data());
      b.function(0.0, x.data(), B::default_parameters, in.data(), ob.data());
      bool agree = a.n_out == b.n_out && std::strcmp(a.name, b.name) == 0;
      if (agree && TOLERANCE == 0) {
        agree = std::memcmp(oa.data(), ob.data(), sizeof(double) * static_cast<std::size_t>(a.n_out)) == 0;
      } else if (agree) {
        double scale = 1e-300, difference = 0;
        for (int i = 0; i < a.n_out; ++i) {
          scale = std::max(scale, std::fabs(oa[static_cast<std::size_t>(i)]));
          difference =
              std::max(difference, std::fabs(oa[static_cast<std::size_t>(i)] - ob[static_cast<std::size_t>(i)]));
        }
        worst = std::max(worst, difference / scale);
        agree = difference <= TOLERANCE * scale;
      }
      if (!agree) {
        std::fprintf(stderr, "ab-bench: kernel %s differs between " A_LABEL " and " B_LABEL " at state %d\n", a.name,
                     s);
        ++failures;
      }
    }
  }
  if (failures == 0 && TOLERANCE == 0)
    std::printf("ab-bench: every kernel bit-identical " A_LABEL " and " B_LABEL " on 20 random states\n");
  else if (failures == 0)
    std::printf("ab-bench: every kernel agrees " A_LABEL " and " B_LABEL
                " on 20 random states, largest relative difference %.1e\n",
                worst);
  return failures;
}

template <class Function>
void run_kernel(benchmark::State& state, Function f, int n_state, int n_inputs, int n_out, const double* p) {
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
  if (check_agreement() != 0) return 1;
  for (int k = 0; k < A::n_kernels; ++k) {
    const auto& a = A::kernel_table[k];
    const auto& b = B::kernel_table[k];
    benchmark::RegisterBenchmark((std::string(a.name) + "/" A_LABEL).c_str(), run_kernel<A::kernel_function>,
                                 a.function, A::n_state, A::n_inputs, a.n_out, A::default_parameters);
    benchmark::RegisterBenchmark((std::string(b.name) + "/" B_LABEL).c_str(), run_kernel<B::kernel_function>,
                                 b.function, B::n_state, B::n_inputs, b.n_out, B::default_parameters);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
