// The C++ side of tools/python-bench.sh: the loop a C++ caller writes over N states, kernel(t, x_i, p, in_i, out_i),
// timed per state, for rhs and jacobian of the package PKG (compiled with its header; linked with its static library,
// built with the same flags as the Python module's shared library). Reads the states and inputs bench.py drew. Two
// loops: into one output array reused by every pass, and into a new (uninitialized) array per pass, as a Python call
// that returns its result does.
//   bench_<PKG> states.bin inputs.bin N passes  ->  lines "<kernel> <reused|new> <ns per state>" (best pass, CPU time)
#include PKG_HEADER

#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

namespace {

// CPU time of the process (user and system, page faults included), so that time the shared machine gives to other
// processes is not counted; bench.py measures Python the same way (time.process_time).
double cpu_ns() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) * 1e9 + static_cast<double>(now.tv_nsec);
}

std::vector<double> read_doubles(const char* path, std::size_t count) {
  std::vector<double> v(count);
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(count * sizeof(double)));
  if (!in && count > 0) {
    std::fprintf(stderr, "bench: cannot read %zu doubles from %s\n", count, path);
    std::exit(2);
  }
  return v;
}

template <class Kernel>
double best_ns_per_state(Kernel kernel, int m, const std::vector<double>& x, const std::vector<double>& in, long n,
                         int passes, bool new_array) {
  const std::size_t size = static_cast<std::size_t>(n) * static_cast<std::size_t>(m);
  std::vector<double> reused(size);
  const double* in0 = in.empty() ? nullptr : in.data();
  double best = 1e300, sink = 0;
  for (int pass = 0; pass < passes; ++pass) {
    const double start = cpu_ns();
    double* out = new_array ? new double[size] : reused.data();
    for (long i = 0; i < n; ++i)
      kernel(0.0, x.data() + i * PKG::n_state, PKG::default_parameters, in0 ? in0 + i * PKG::n_inputs : nullptr,
             out + i * m);
    sink += out[static_cast<std::size_t>(pass % m)];
    if (new_array) delete[] out;
    best = std::min(best, (cpu_ns() - start) / static_cast<double>(n));
  }
  if (sink == 12345.678) std::puts("");  // keeps the outputs observable
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s states.bin inputs.bin N passes\n", argv[0]);
    return 2;
  }
  const long n = std::atol(argv[3]);
  const int passes = std::atoi(argv[4]);
  const auto x = read_doubles(argv[1], static_cast<std::size_t>(n * PKG::n_state));
  const auto in = read_doubles(argv[2], static_cast<std::size_t>(n * PKG::n_inputs));
  // Lambdas, so that each loop calls its kernel directly, as a caller's loop would.
  const auto rhs = [](double t, const double* s, const double* p, const double* u, double* out) {
    PKG::rhs(t, s, p, u, out);
  };
  const auto jacobian = [](double t, const double* s, const double* p, const double* u, double* out) {
    PKG::jacobian(t, s, p, u, out);
  };
  for (const bool new_array : {false, true}) {
    const char* how = new_array ? "new" : "reused";
    std::printf("rhs %s %.3f\n", how, best_ns_per_state(rhs, PKG::n_out_rhs, x, in, n, passes, new_array));
    std::printf("jacobian %s %.3f\n", how,
                best_ns_per_state(jacobian, PKG::n_out_jacobian, x, in, n, passes, new_array));
  }
  return 0;
}
