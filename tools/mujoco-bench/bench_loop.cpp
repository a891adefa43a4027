// Side-by-side timing of a hamel-emitted closed-loop tree on a fixed base (model key `loops`) and the same linkage in
// MuJoCo, closed there by one <equality><connect> (docs/benchmarks.md, "Shipped and imported robots against
// MuJoCo"), in one Google Benchmark binary as bench.cpp: mj_forward, mjd_transitionFD (centred) and the package's
// rhs and jacobian. Built and run by tools/mujoco-bench.sh with -DPKG=<namespace> and -DPKG_HEADER="<name>.hpp".
//
//   bench_loop MODEL.xml check [STATES]   agreement at STATES random states on the loop (default 20); prints the
//                                          largest relative difference and exits 1 above 1e-8
//   bench_loop MODEL.xml [benchmark flags]   ns per call
//
// MuJoCo's equality constraints are soft (solref, solimp): mj_forward's qacc is not the rigid loop's, so the check
// does what tests/loops/slider_crank_matches_mujoco_test.cpp does. At a state on the loop it solves
//
//   [ M(q)  Jᵀ ] [ q'' ]   [ qfrc_passive − qfrc_bias ]
//   [ J     0  ] [ lam ] = [ −J' q'                   ]
//
// with MuJoCo's mass matrix (mj_fullM of qM) and forces from mj_forward, J the difference of mj_jac at the connect's
// two anchors (MuJoCo's compiled anchors, eq_data), J' q' by fourth-order central differences of the anchors' gap
// along q + s q'; rows of J that vanish (a planar loop's normal) are left out. hamel's rhs must give q' (the
// kinematics) and the independent joints' q''. It also prints, for information, how far mj_forward's soft qacc is
// from the rigid one. States on the loop: a random perturbation of qpos0 (which closes the loop) closed by Newton's
// method on MuJoCo's gap (minimum-norm steps), velocities in the null space of J with random independent rates.
//
// State mapping: hamel x = (q by joint name, u_I) with u_I the rates <joint>_dot of the independent joints; MuJoCo's
// qpos and qvel by joint name (hinges and slides only); no inputs. Timing: mj_forward with the equality constraint on
// (MuJoCo's constraint solver runs, as it does for a MuJoCo user), contacts and limits off.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <Eigen/Dense>
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

constexpr int n = PKG::n_coordinates;
constexpr int m = PKG::n_independent;
static_assert(PKG::n_inputs == 0, "bench_loop: linkages without inputs (MuJoCo actuators) only");

mjModel* g_model = nullptr;
mjData* g_data = nullptr;
std::vector<double> g_x, g_in, g_A, g_B;
int g_dof[n];          // MuJoCo's qpos (= qvel) address of hamel's coordinate i
int g_independent[m];  // the coordinate whose rate is hamel's u_I k
std::vector<double> g_qpos0;

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "bench_loop: %s\n", what.c_str());
  std::exit(2);
}

void map_joints() {
  if (g_model->nq != n || g_model->nv != n) fail("MuJoCo's nq, nv differ from hamel's coordinates");
  if (g_model->neq != 1 || g_model->eq_type[0] != mjEQ_CONNECT) fail("expected one <equality><connect>");
  for (int i = 0; i < n; ++i) {
    const int j = mj_name2id(g_model, mjOBJ_JOINT, PKG::state_names[i]);
    if (j < 0) fail(std::string("no MuJoCo joint ") + PKG::state_names[i]);
    g_dof[i] = g_model->jnt_dofadr[j];
    if (g_model->jnt_qposadr[j] != g_dof[i]) fail("qpos and qvel addresses differ");
  }
  for (int k = 0; k < m; ++k) {
    g_independent[k] = -1;
    for (int i = 0; i < n; ++i)
      if (std::string(PKG::state_names[n + k]) == std::string(PKG::state_names[i]) + "_dot") g_independent[k] = i;
    if (g_independent[k] < 0) fail(std::string("the velocity ") + PKG::state_names[n + k] + " is no joint's rate");
  }
  g_qpos0.assign(g_model->qpos0, g_model->qpos0 + n);
}

// In hamel's coordinate order: q, and MuJoCo's qpos from it.
void set_qpos(const Eigen::VectorXd& q) {
  for (int i = 0; i < n; ++i) g_data->qpos[g_dof[i]] = q[i];
}

// The connect's anchors in the world at q, their gap and (optionally) its Jacobian in hamel's coordinate order.
Eigen::Vector3d gap(const Eigen::VectorXd& q, Eigen::MatrixXd* J = nullptr) {
  set_qpos(q);
  mj_kinematics(g_model, g_data);
  mj_comPos(g_model, g_data);
  Eigen::Vector3d p[2];
  const int body[2] = {g_model->eq_obj1id[0], g_model->eq_obj2id[0]};
  for (int k = 0; k < 2; ++k) {
    const double* a = g_model->eq_data + 3 * k;
    const double* R = g_data->xmat + 9 * body[k];
    for (int r = 0; r < 3; ++r)
      p[k][r] = g_data->xpos[3 * body[k] + r] + R[3 * r] * a[0] + R[3 * r + 1] * a[1] + R[3 * r + 2] * a[2];
  }
  if (J) {
    J->setZero(3, n);
    std::vector<double> jacp(3 * static_cast<std::size_t>(n));
    for (int k = 0; k < 2; ++k) {
      mj_jac(g_model, g_data, jacp.data(), nullptr, p[k].data(), body[k]);
      for (int r = 0; r < 3; ++r)
        for (int i = 0; i < n; ++i) (*J)(r, i) += (k == 0 ? 1 : -1) * jacp[static_cast<std::size_t>(r * n + g_dof[i])];
    }
  }
  return p[0] - p[1];
}

// The rows of J that do not vanish identically at q (the planar loop's normal does).
Eigen::MatrixXd rows_of(const Eigen::MatrixXd& J, std::vector<int>* rows) {
  rows->clear();
  for (int r = 0; r < 3; ++r)
    if (J.row(r).norm() > 1e-9) rows->push_back(r);
  Eigen::MatrixXd Jr(static_cast<int>(rows->size()), n);
  for (std::size_t r = 0; r < rows->size(); ++r) Jr.row(static_cast<int>(r)) = J.row((*rows)[r]);
  return Jr;
}

// A random state on the loop: hamel's x and MuJoCo's qpos, qvel for it; returns MuJoCo's velocity in hamel's
// coordinate order.
Eigen::VectorXd random_state(std::mt19937_64& rng, std::vector<double>& x, std::vector<double>& in) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (int attempt = 0; attempt < 100; ++attempt) {
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) {
      const bool slide = g_model->jnt_type[g_model->dof_jntid[g_dof[i]]] == mjJNT_SLIDE;
      q[i] = g_qpos0[static_cast<std::size_t>(g_dof[i])] + (slide ? 0.05 : 1.0) * u(rng);
    }
    Eigen::MatrixXd J;
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector3d g = gap(q, &J);
      if (g.norm() < 1e-15) break;
      q -= J.completeOrthogonalDecomposition().solve(g);
    }
    if (gap(q, &J).norm() > 1e-14) continue;
    std::vector<int> rows;
    const Eigen::MatrixXd Jr = rows_of(J, &rows);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Jr);
    lu.setThreshold(1e-10);
    const Eigen::MatrixXd N = lu.kernel();
    if (N.cols() != m) continue;
    Eigen::MatrixXd NI(m, m);
    for (int k = 0; k < m; ++k) NI.row(k) = N.row(g_independent[k]);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(NI);
    if (svd.singularValues()(m - 1) < 1e-3 * svd.singularValues()(0)) continue;  // near the partition's singularity
    Eigen::VectorXd uI(m);
    for (int k = 0; k < m; ++k) uI[k] = 5 * u(rng);
    const Eigen::VectorXd v = N * NI.fullPivLu().solve(uI);
    x.assign(PKG::n_state, 0.0);
    for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = q[i];
    for (int k = 0; k < m; ++k) x[static_cast<std::size_t>(n + k)] = uI[k];
    in.assign(PKG::n_inputs, 0.0);
    mj_resetData(g_model, g_data);
    set_qpos(q);
    for (int i = 0; i < n; ++i) g_data->qvel[g_dof[i]] = v[i];
    return v;
  }
  fail("no state on the loop found in 100 attempts");
}

// The rigid loop's accelerations (hamel's coordinate order) at the state in g_data, with velocity v; leaves
// mj_forward's results (MuJoCo's soft qacc) in g_data.
Eigen::VectorXd rigid_accelerations(const Eigen::VectorXd& v) {
  Eigen::VectorXd q(n);
  for (int i = 0; i < n; ++i) q[i] = g_data->qpos[g_dof[i]];
  Eigen::MatrixXd J;
  gap(q, &J);
  const double h = 1e-3;  // J' v = d²/ds² gap(q + s v) at s = 0
  const Eigen::Vector3d Jdv =
      (-gap(q + 2 * h * v) + 16 * gap(q + h * v) - 30 * gap(q) + 16 * gap(q - h * v) - gap(q - 2 * h * v)) /
      (12 * h * h);
  set_qpos(q);
  mj_forward(g_model, g_data);
  Eigen::MatrixXd Mfull(n, n);
  mj_fullM(g_model, Mfull.data(), g_data->qM);  // symmetric: row- or column-major alike
  std::vector<int> rows;
  const Eigen::MatrixXd Jr = rows_of(J, &rows);
  const int k = static_cast<int>(rows.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + k, n + k);
  Eigen::VectorXd b(n + k);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) K(i, j) = Mfull(g_dof[i], g_dof[j]);
    const int d = g_dof[i];
    b[i] = g_data->qfrc_passive[d] - g_data->qfrc_bias[d];
  }
  K.block(n, 0, k, n) = Jr;
  K.block(0, n, n, k) = Jr.transpose();
  for (int r = 0; r < k; ++r) b[n + r] = -Jdv[rows[static_cast<std::size_t>(r)]];
  return K.fullPivLu().solve(b).head(n);
}

int check(int states) {
  std::mt19937_64 rng(2026);
  double worst = 0, soft = 0;
  std::vector<double> x, in, out(PKG::n_state);
  for (int s = 0; s < states; ++s) {
    const Eigen::VectorXd v = random_state(rng, x, in);
    const Eigen::VectorXd a = rigid_accelerations(v);
    PKG::rhs(0.0, x.data(), PKG::default_parameters, in.data(), out.data());
    double err = 0, soft_err = 0;
    for (int i = 0; i < n; ++i) {
      err = std::max(err, std::abs(out[static_cast<std::size_t>(i)] - v[i]) / std::max(1.0, v.norm()));
      soft_err = std::max(soft_err, std::abs(g_data->qacc[g_dof[i]] - a[i]) / std::max(1.0, a.norm()));
    }
    for (int k = 0; k < m; ++k)
      err =
          std::max(err, std::abs(out[static_cast<std::size_t>(n + k)] - a[g_independent[k]]) / std::max(1.0, a.norm()));
    worst = std::max(worst, err);
    soft = std::max(soft, soft_err);
  }
  std::printf(
      "%s: mj_forward's soft-constraint qacc vs the rigid loop: %.1e; hamel rhs vs MuJoCo's M, bias and the "
      "loop's multipliers at %d random states on the loop: max relative difference %.1e\n",
      PKG_NAME, soft, states, worst);
  return worst <= 1e-8 ? 0 : 1;  // J' v by finite differences: ~1e-10
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
    std::fprintf(stderr, "usage: bench_loop MODEL.xml [check [STATES] | benchmark flags]\n");
    return 2;
  }
  char err[1000] = "";
  g_model = mj_loadXML(argv[1], nullptr, err, sizeof err);
  if (!g_model) fail(err);
  // Contacts and limits off (hamel has neither); the equality constraint stays on: mj_forward runs MuJoCo's
  // constraint solver for it, which is what a MuJoCo user of the linkage pays.
  g_model->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_LIMIT;
  g_data = mj_makeData(g_model);
  map_joints();
  if (argc >= 3 && std::strcmp(argv[2], "check") == 0) return check(argc >= 4 ? std::atoi(argv[3]) : 20);
  std::mt19937_64 rng(1);
  random_state(rng, g_x, g_in);
  mj_forward(g_model, g_data);
  const int nv = g_model->nv, na = g_model->na;
  g_A.resize(static_cast<std::size_t>((2 * nv + na) * (2 * nv + na)));
  g_B.resize(static_cast<std::size_t>((2 * nv + na) * std::max(1, g_model->nu)));
  argv[1] = argv[0];
  --argc;
  ++argv;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
