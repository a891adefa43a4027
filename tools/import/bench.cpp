// Side-by-side timing of an imported robot (docs/import.md): MuJoCo's mj_forward on the MJCF file (contacts
// and limits disabled, gravity off: what the import kept) against the hamel-emitted rhs of the same robot, in
// one Google Benchmark binary. Built and run by tools/import-bench.sh with -DPKG=<namespace> and
// -DPKG_HEADER="<name>.hpp". The state is random (fixed seed); both compute the same accelerations
// (tests/import checks them to 1e-10).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <cstdio>
#include <random>
#include <vector>

#include PKG_HEADER

namespace {

mjModel* g_model = nullptr;
mjData* g_data = nullptr;
std::vector<double> g_x, g_in;

void BM_mujoco_forward(benchmark::State& st) {
  for (auto _ : st) {
    mj_forward(g_model, g_data);
    benchmark::DoNotOptimize(g_data->qacc);
    benchmark::ClobberMemory();
  }
}

void BM_hamel_rhs(benchmark::State& st) {
  static double out[PKG::n_state];
  for (auto _ : st) {
    PKG::rhs(0.0, g_x.data(), PKG::default_parameters, g_in.data(), out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}

void BM_hamel_mass_matrix(benchmark::State& st) {
  static double out[PKG::n_out_mass_matrix];
  for (auto _ : st) {
    PKG::mass_matrix(0.0, g_x.data(), PKG::default_parameters, g_in.data(), out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}

BENCHMARK(BM_mujoco_forward);
BENCHMARK(BM_hamel_rhs);
BENCHMARK(BM_hamel_mass_matrix);

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench MODEL.xml [benchmark flags]\n");
    return 2;
  }
  char err[1000] = "";
  g_model = mj_loadXML(argv[1], nullptr, err, sizeof err);
  if (!g_model) {
    std::fprintf(stderr, "bench: %s\n", err);
    return 2;
  }
  g_model->opt.disableflags |= mjDSBL_CONSTRAINT;
  g_model->opt.gravity[0] = g_model->opt.gravity[1] = g_model->opt.gravity[2] = 0;
  g_data = mj_makeData(g_model);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < g_model->nq; ++i) g_data->qpos[i] = u(rng);
  for (int i = 0; i < g_model->nv; ++i) g_data->qvel[i] = u(rng);
  for (int i = 0; i < g_model->nu; ++i) g_data->ctrl[i] = u(rng);
  mj_normalizeQuat(g_model, g_data->qpos);
  for (int i = 0; i < PKG::n_state; ++i) g_x.push_back(u(rng));
  for (int i = 0; i < PKG::n_inputs; ++i) g_in.push_back(u(rng));
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
