// Side-by-side timing of a hamel-emitted floating-base tree and the same robot in MuJoCo (docs/benchmarks.md,
// "Shipped models against MuJoCo"), in one Google Benchmark binary: mj_forward (contacts and limits disabled,
// gravity as the MJCF states it), MuJoCo's finite-difference derivatives mjd_transitionFD (centred), and the
// package's rhs and jacobian. Built and run by tools/mujoco-bench.sh with -DPKG=<namespace> and
// -DPKG_HEADER="<name>.hpp".
//
//   bench MODEL.xml check [STATES]   agreement: hamel's rhs against mj_forward at STATES random states (default
//                                     20); prints the largest relative difference of (ẇ, v̇, q̈) and exits 1
//                                     above 1e-9
//   bench MODEL.xml [benchmark flags]   ns per call
//
// State mapping, as tools/scaling/harness.cpp and tests/import: hamel x = (q, [Γ], w, v, q̇) with (w, v) the base
// frame's body twist and Γ = Rᵀ g (present when the package's state has gravity_x); MuJoCo's free joint qpos =
// (p, quat), qvel = (R v, w); back: ẇ = qacc_ang, v̇ = Rᵀ qacc_lin − w × v. Joints and inputs are matched by name
// (hamel input = MuJoCo actuator of the same name or, as `hamel import` names them, u_<actuator>; ctrl = input).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include PKG_HEADER

namespace {

mjModel* g_model = nullptr;
mjData* g_data = nullptr;
std::vector<double> g_x, g_in, g_A, g_B;

constexpr int n_joints = PKG::n_coordinates;  // then Γ if the state holds it
bool gravity_state() {
  for (int i = 0; i < PKG::n_coordinates; ++i)
    if (std::strcmp(PKG::state_names[i], "gravity_x") == 0) return true;
  return false;
}

void quat_to_R(const double* q, double R[3][3]) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0][0] = 1 - 2 * (y * y + z * z), R[0][1] = 2 * (x * y - w * z), R[0][2] = 2 * (x * z + w * y);
  R[1][0] = 2 * (x * y + w * z), R[1][1] = 1 - 2 * (x * x + z * z), R[1][2] = 2 * (y * z - w * x);
  R[2][0] = 2 * (x * z - w * y), R[2][1] = 2 * (y * z + w * x), R[2][2] = 1 - 2 * (x * x + y * y);
}

// A random state of both: hamel's x and inputs, and MuJoCo's qpos, qvel and ctrl for the same motion.
void random_state(std::mt19937_64& rng, std::vector<double>& x, std::vector<double>& in) {
  std::uniform_real_distribution<double> u(-1, 1);
  const int G = gravity_state() ? 3 : 0, n = n_joints - G;
  x.assign(PKG::n_state, 0.0);
  in.assign(PKG::n_inputs, 0.0);
  double quat[4], norm = 0;
  for (double& c : quat) c = u(rng), norm += c * c;
  for (double& c : quat) c /= std::sqrt(norm);
  double R[3][3];
  quat_to_R(quat, R);
  for (int i = 0; i < n; ++i) x[i] = 1.5 * u(rng);
  for (int i = 0; i < G; ++i) {
    const double* g = g_model->opt.gravity;
    x[n + i] = R[0][i] * g[0] + R[1][i] * g[1] + R[2][i] * g[2];
  }
  for (int i = n + G; i < PKG::n_state; ++i) x[i] = u(rng);
  for (double& c : in) c = u(rng);
  mj_resetData(g_model, g_data);
  for (int k = 0; k < 3; ++k) g_data->qpos[k] = u(rng);
  for (int k = 0; k < 4; ++k) g_data->qpos[3 + k] = quat[k];
  const double *w = x.data() + n + G, *v = w + 3;
  for (int i = 0; i < 3; ++i) {
    g_data->qvel[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
    g_data->qvel[3 + i] = w[i];
  }
  for (int i = 0; i < n; ++i) {
    const int j = mj_name2id(g_model, mjOBJ_JOINT, PKG::state_names[i]);
    if (j < 0) {
      std::fprintf(stderr, "bench: no MuJoCo joint %s\n", PKG::state_names[i]);
      std::exit(2);
    }
    g_data->qpos[g_model->jnt_qposadr[j]] = x[i];
    g_data->qvel[g_model->jnt_dofadr[j]] = x[n + G + 6 + i];
  }
  for (int k = 0; k < PKG::n_inputs; ++k) {
    // The input of the same name, or `hamel import`'s u_<actuator>.
    int a = mj_name2id(g_model, mjOBJ_ACTUATOR, PKG::input_names[k]);
    if (a < 0 && std::strncmp(PKG::input_names[k], "u_", 2) == 0)
      a = mj_name2id(g_model, mjOBJ_ACTUATOR, PKG::input_names[k] + 2);
    if (a < 0) {
      std::fprintf(stderr, "bench: no MuJoCo actuator %s\n", PKG::input_names[k]);
      std::exit(2);
    }
    g_data->ctrl[a] = in[k];
  }
}

int check(int states) {
  std::mt19937_64 rng(2026);
  const int G = gravity_state() ? 3 : 0, n = n_joints - G;
  double worst = 0;
  std::vector<double> x, in, out(PKG::n_state);
  for (int s = 0; s < states; ++s) {
    random_state(rng, x, in);
    mj_forward(g_model, g_data);
    PKG::rhs(0.0, x.data(), PKG::default_parameters, in.data(), out.data());
    double R[3][3];
    quat_to_R(g_data->qpos + 3, R);
    const double *w = x.data() + n + G, *v = w + 3, *qacc = g_data->qacc;
    const double wxv[3] = {w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0]};
    std::vector<double> ref;
    for (int i = 0; i < 3; ++i) ref.push_back(qacc[3 + i]);
    for (int i = 0; i < 3; ++i) ref.push_back(R[0][i] * qacc[0] + R[1][i] * qacc[1] + R[2][i] * qacc[2] - wxv[i]);
    for (int i = 0; i < n; ++i)
      ref.push_back(qacc[g_model->jnt_dofadr[mj_name2id(g_model, mjOBJ_JOINT, PKG::state_names[i])]]);
    double err = 0, scale = 1;
    for (std::size_t k = 0; k < ref.size(); ++k) {
      err = std::max(err, std::abs(out[static_cast<std::size_t>(n + G) + k] - ref[k]));
      scale = std::max(scale, std::abs(ref[k]));
    }
    worst = std::max(worst, err / scale);
  }
  std::printf("%s: hamel rhs vs mj_forward at %d random states: max relative difference %.1e\n", PKG_NAME, states,
              worst);
  return worst <= 1e-9 ? 0 : 1;
}

void BM_mujoco_forward(benchmark::State& st) {
  for (auto _ : st) {
    mj_forward(g_model, g_data);
    benchmark::DoNotOptimize(g_data->qacc);
    benchmark::ClobberMemory();
  }
}

void BM_mujoco_transitionFD(benchmark::State& st) {
  for (auto _ : st) {
    mjd_transitionFD(g_model, g_data, 1e-6, 1, g_A.data(), g_B.data(), nullptr, nullptr);
    benchmark::DoNotOptimize(g_A.data());
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

void BM_hamel_jacobian(benchmark::State& st) {
  static double out[PKG::n_out_jacobian];
  for (auto _ : st) {
    PKG::jacobian(0.0, g_x.data(), PKG::default_parameters, g_in.data(), out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}

BENCHMARK(BM_mujoco_forward);
BENCHMARK(BM_mujoco_transitionFD);
BENCHMARK(BM_hamel_rhs);
BENCHMARK(BM_hamel_jacobian);

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench MODEL.xml [check [STATES] | benchmark flags]\n");
    return 2;
  }
  char err[1000] = "";
  g_model = mj_loadXML(argv[1], nullptr, err, sizeof err);
  if (!g_model) {
    std::fprintf(stderr, "bench: %s\n", err);
    return 2;
  }
  g_model->opt.disableflags |= mjDSBL_CONSTRAINT;  // contacts and limits: hamel has neither
  g_data = mj_makeData(g_model);
  if (argc >= 3 && std::strcmp(argv[2], "check") == 0) return check(argc >= 4 ? std::atoi(argv[3]) : 20);
  std::mt19937_64 rng(1);
  random_state(rng, g_x, g_in);
  const int nv = g_model->nv, na = g_model->na;
  g_A.resize(static_cast<std::size_t>((2 * nv + na) * (2 * nv + na)));
  g_B.resize(static_cast<std::size_t>((2 * nv + na) * g_model->nu));
  argv[1] = argv[0];
  --argc;
  ++argv;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
