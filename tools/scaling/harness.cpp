// Scaling benchmark harness (tools/scaling): MuJoCo and, when compiled with -DHAMEL_PKG=<namespace>
// -DHAMEL_HEADER="<name>.hpp", a hamel-emitted package of the same floating-base tree.
//
//   harness check MODEL.xml STATES.txt   for every line of STATES.txt
//                                         (quat_w quat_x quat_y quat_z px py pz q_1..q_n w(3) v(3) qdot_1..qdot_n)
//                                         prints "mujoco a_1..a_m" (mj_forward), "mujoco_core a_1..a_m" (the
//                                         dynamics core alone, see mujoco_core) and, with a package,
//                                         "hamel a_1..a_m": the accelerations (w_dot, v_dot, q_ddot) in hamel's
//                                         coordinates.
//   harness bench MODEL.xml [google-benchmark flags]
//                                         ns per call of mj_forward, of MuJoCo's dynamics core and of the
//                                         package's rhs and mass_matrix.
//
// State mapping. hamel: x = (q, w, v, q_dot), (w, v) the base frame's body twist (angular, then the linear
// velocity of the base origin, resolved in the base frame). MuJoCo freejoint: qpos = (p, quat), qvel =
// (world linear velocity of the body origin, body-frame angular velocity). So qvel_lin = R v, qvel_ang = w,
// and back: w_dot = qacc_ang, v_dot = R^T qacc_lin - w x v.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#ifdef HAMEL_PKG
#include HAMEL_HEADER
#endif

namespace {

struct Mj {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  int n = 0;                 // hinge joints
  std::vector<int> qposadr;  // of q1..qn (by name: MuJoCo numbers joints depth-first)
  std::vector<int> dofadr;
};

Mj load(const char* path) {
  Mj s;
  char err[1000] = "";
  s.m = mj_loadXML(path, nullptr, err, sizeof err);
  if (!s.m) {
    std::fprintf(stderr, "harness: cannot load %s: %s\n", path, err);
    std::exit(2);
  }
  s.d = mj_makeData(s.m);
  s.n = s.m->njnt - 1;
  for (int i = 1; i <= s.n; ++i) {
    const std::string name = "q" + std::to_string(i);
    const int j = mj_name2id(s.m, mjOBJ_JOINT, name.c_str());
    if (j < 0) {
      std::fprintf(stderr, "harness: no joint %s\n", name.c_str());
      std::exit(2);
    }
    s.qposadr.push_back(s.m->jnt_qposadr[j]);
    s.dofadr.push_back(s.m->jnt_dofadr[j]);
  }
  return s;
}

void quat_to_R(const double* q, double* R) {  // row-major
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  // One row of R per line.
  // clang-format off
  R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - w * z);     R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z);     R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y);     R[7] = 2 * (y * z + w * x);     R[8] = 1 - 2 * (x * x + y * y);
  // clang-format on
}

// s: quat(4) p(3) then the hamel state x = (q(n), w(3), v(3), qdot(n)).
void set_state(Mj& s, const double* pose, const double* x) {
  const int n = s.n;
  double R[9];
  quat_to_R(pose, R);
  double* qpos = s.d->qpos;
  double* qvel = s.d->qvel;
  qpos[0] = pose[4];
  qpos[1] = pose[5];
  qpos[2] = pose[6];
  for (int k = 0; k < 4; ++k) qpos[3 + k] = pose[k];
  const double* w = x + n;
  const double* v = x + n + 3;
  for (int i = 0; i < 3; ++i) qvel[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
  for (int i = 0; i < 3; ++i) qvel[3 + i] = w[i];
  for (int i = 0; i < n; ++i) {
    qpos[s.qposadr[i]] = x[i];
    qvel[s.dofadr[i]] = x[n + 6 + i];
  }
}

// accelerations (w_dot, v_dot, q_ddot) from MuJoCo's qacc after mj_forward
void mujoco_acc(const Mj& s, const double* pose, const double* x, double* a) {
  const int n = s.n;
  double R[9];
  quat_to_R(pose, R);
  const double* qacc = s.d->qacc;
  const double* w = x + n;
  const double* v = x + n + 3;
  const double wxv[3] = {w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0]};
  for (int i = 0; i < 3; ++i) a[i] = qacc[3 + i];
  for (int i = 0; i < 3; ++i) a[3 + i] = R[i] * qacc[0] + R[3 + i] * qacc[1] + R[6 + i] * qacc[2] - wxv[i];
  for (int i = 0; i < n; ++i) a[6 + i] = qacc[s.dofadr[i]];
}

// MuJoCo's dynamics core only, without the rest of mj_forward's pipeline (collision, constraints, sensors,
// actuation, checks): kinematics, composite rigid bodies, M = L^T D L, bias forces by RNE, qacc = -M^-1 c.
void mujoco_core(const Mj& s, double* qacc, double* work) {
  mj_kinematics(s.m, s.d);
  mj_comPos(s.m, s.d);
  mj_crb(s.m, s.d);
  mj_factorM(s.m, s.d);
  mj_comVel(s.m, s.d);
  mj_rne(s.m, s.d, 0, work);
  for (int i = 0; i < s.m->nv; ++i) work[i] = -work[i];
  mj_solveM(s.m, s.d, qacc, work, 1);
}

std::vector<std::vector<double>> read_states(const char* path) {
  std::vector<std::vector<double>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::vector<double> r;
    double v;
    while (ls >> v) r.push_back(v);
    if (!r.empty()) rows.push_back(r);
  }
  return rows;
}

int check(const char* xml, const char* states) {
  Mj s = load(xml);
  const int n = s.n, m = 6 + n;
  for (const auto& r : read_states(states)) {
    if (static_cast<int>(r.size()) != 7 + 2 * n + 6) {
      std::fprintf(stderr, "harness: state line has %zu numbers, expected %d\n", r.size(), 7 + 2 * n + 6);
      return 2;
    }
    const double* pose = r.data();
    const double* x = r.data() + 7;
    set_state(s, pose, x);
    mj_forward(s.m, s.d);
    std::vector<double> a(m);
    mujoco_acc(s, pose, x, a.data());
    std::printf("mujoco");
    for (double v : a) std::printf(" %.17g", v);
    std::printf("\n");
    std::vector<double> qacc(s.m->nv), work(s.m->nv);
    mujoco_core(s, qacc.data(), work.data());
    std::copy(qacc.begin(), qacc.end(), s.d->qacc);
    mujoco_acc(s, pose, x, a.data());
    std::printf("mujoco_core");
    for (double v : a) std::printf(" %.17g", v);
    std::printf("\n");
#ifdef HAMEL_PKG
    if (HAMEL_PKG::n_state != 2 * n + 6) {
      std::fprintf(stderr, "harness: package n_state %d, MuJoCo model has %d joints\n", HAMEL_PKG::n_state, n);
      return 2;
    }
    std::vector<double> out(HAMEL_PKG::n_out_rhs);
    HAMEL_PKG::rhs(0.0, x, HAMEL_PKG::default_parameters, nullptr, out.data());
    std::printf("hamel");
    for (int i = n; i < 2 * n + 6; ++i) std::printf(" %.17g", out[i]);
    std::printf("\n");
#endif
  }
  return 0;
}

// one fixed pseudo-random state for the timings
std::vector<double> bench_state(int n) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> r(7 + 2 * n + 6);
  double qn = 0;
  for (int k = 0; k < 4; ++k) {
    r[k] = u(rng);
    qn += r[k] * r[k];
  }
  for (int k = 0; k < 4; ++k) r[k] /= std::sqrt(qn);
  for (size_t k = 4; k < r.size(); ++k) r[k] = u(rng);
  return r;
}

Mj* g_mj = nullptr;

void BM_mujoco_forward(benchmark::State& st) {
  Mj& s = *g_mj;
  const auto r = bench_state(s.n);
  set_state(s, r.data(), r.data() + 7);
  for (auto _ : st) {
    mj_forward(s.m, s.d);
    benchmark::DoNotOptimize(s.d->qacc);
    benchmark::ClobberMemory();
  }
}

void BM_mujoco_core(benchmark::State& st) {
  Mj& s = *g_mj;
  const auto r = bench_state(s.n);
  set_state(s, r.data(), r.data() + 7);
  std::vector<double> qacc(s.m->nv), work(s.m->nv);
  for (auto _ : st) {
    mujoco_core(s, qacc.data(), work.data());
    benchmark::DoNotOptimize(qacc.data());
    benchmark::ClobberMemory();
  }
}

#ifdef HAMEL_PKG
template <void (*K)(HAMEL_PKG::real, const HAMEL_PKG::real*, const HAMEL_PKG::real*, const HAMEL_PKG::real*,
                    HAMEL_PKG::real*),
          int N_OUT>
void BM_hamel(benchmark::State& st) {
  const auto r = bench_state(g_mj->n);
  const double* x = r.data() + 7;
  static double out[N_OUT];
  for (auto _ : st) {
    K(0.0, x, HAMEL_PKG::default_parameters, nullptr, out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}
#endif

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && std::strcmp(argv[1], "check") == 0) return check(argv[2], argv[3]);
  if (argc >= 3 && std::strcmp(argv[1], "bench") == 0) {
    static Mj s = load(argv[2]);
    g_mj = &s;
    benchmark::RegisterBenchmark("mujoco_forward", BM_mujoco_forward);
    benchmark::RegisterBenchmark("mujoco_core", BM_mujoco_core);
#ifdef HAMEL_PKG
    benchmark::RegisterBenchmark("hamel_rhs", BM_hamel<HAMEL_PKG::rhs, HAMEL_PKG::n_out_rhs>);
    benchmark::RegisterBenchmark("hamel_mass_matrix", BM_hamel<HAMEL_PKG::mass_matrix, HAMEL_PKG::n_out_mass_matrix>);
#endif
    int bargc = argc - 2;
    std::vector<char*> bargv(argv + 2, argv + argc);
    bargv[0] = argv[0];
    benchmark::Initialize(&bargc, bargv.data());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
  }
  std::fprintf(stderr, "usage: %s check MODEL.xml STATES.txt | bench MODEL.xml [benchmark flags]\n", argv[0]);
  return 2;
}
