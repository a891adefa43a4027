// hamel's emitted rhs, jacobian and mass_matrix against DART and MuJoCo on the same floating robot, in one
// Google Benchmark binary (docs/benchmarks.md, "Against DART and MuJoCo"). Built by tools/peer-bench.sh with
// -DPKG=<namespace> -DPKG_NAME="<name>" -DPKG_HEADER="<name>.hpp" and linked with peers.o.
//
//   bench MODEL.xml [--zero-armature] check [STATES]
//       agreement at STATES random states (default 20): u̇ of hamel's rhs against DART's and MuJoCo's forward
//       dynamics, hamel's mass_matrix against theirs (in hamel's u), and the u̇ rows of hamel's jacobian
//       against centred differences (h = 1e-6) of each peer's forward dynamics. Prints one line of largest
//       differences, relative to max(1, largest entry); exits 1 when u̇ or M differ by more than 1e-9.
//   bench MODEL.xml [--zero-armature] [benchmark flags]
//       ns per call. Every timed loop switches between two random states on each call (the peers cache what
//       depends on positions only), and the peers' calls include storing the state in the library.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "peers.hpp"
#include PKG_HEADER

namespace {

peer::Layout package_layout() {
  peer::Layout L;
  L.n_state = PKG::n_state;
  L.n_coordinates = PKG::n_coordinates;
  L.n_inputs = PKG::n_inputs;
  for (int i = 0; i < PKG::n_state; ++i) L.state_names.emplace_back(PKG::state_names[i]);
  for (int i = 0; i < PKG::n_inputs; ++i) L.input_names.emplace_back(PKG::input_names[i]);
  L.gravity = std::find(L.state_names.begin(), L.state_names.begin() + L.n_coordinates, "gravity_x") !=
              L.state_names.begin() + L.n_coordinates;
  if (PKG::n_out_mass_matrix != L.n_velocities() * L.n_velocities()) {
    std::fprintf(stderr, "peer-bench: the package's mass matrix is not n_velocities²\n");
    std::exit(2);
  }
  return L;
}

std::unique_ptr<peer::Mujoco> g_mujoco;
std::unique_ptr<peer::Dart> g_dart;
peer::State g_states[2];
peer::Layout g_layout;

double rel(const std::vector<double>& a, const std::vector<double>& b) {
  double err = 0, scale = 1;
  for (std::size_t k = 0; k < a.size(); ++k) {
    err = std::max(err, std::abs(a[k] - b[k]));
    scale = std::max(scale, std::abs(b[k]));
  }
  return err / scale;
}

std::vector<double> peer_udot(peer::Peer& p, const peer::State& s) {
  std::vector<double> a(static_cast<std::size_t>(g_layout.n_velocities()));
  p.set(s);
  p.forward();
  p.accelerations(a.data());
  return a;
}

// ∂u̇/∂x by centred differences of the peer's forward dynamics through hamel's coordinates, row-major
// n_velocities × n_state.
std::vector<double> peer_jacobian(peer::Peer& p, const peer::State& s) {
  const int nv = g_layout.n_velocities(), ns = g_layout.n_state;
  const double h = 1e-6;
  std::vector<double> J(static_cast<std::size_t>(nv * ns));
  for (int c = 0; c < ns; ++c) {
    peer::State sp = s, sm = s;
    sp.x[static_cast<std::size_t>(c)] += h;
    sm.x[static_cast<std::size_t>(c)] -= h;
    const auto ap = peer_udot(p, sp), am = peer_udot(p, sm);
    for (int r = 0; r < nv; ++r)
      J[static_cast<std::size_t>(r * ns + c)] =
          (ap[static_cast<std::size_t>(r)] - am[static_cast<std::size_t>(r)]) / (2 * h);
  }
  return J;
}

int check(int states) {
  const int nv = g_layout.n_velocities(), ns = g_layout.n_state, nc = g_layout.n_coordinates;
  std::mt19937_64 rng(2026);
  double rhs_dart = 0, rhs_mj = 0, rhs_smooth = 0, M_dart = 0, M_mj = 0, J_dart = 0, J_mj = 0;
  std::vector<double> out(PKG::n_state), Mh(PKG::n_out_mass_matrix), Jh(PKG::n_out_jacobian);
  std::vector<double> udot(static_cast<std::size_t>(nv)), Mp(static_cast<std::size_t>(nv * nv));
  for (int k = 0; k < states; ++k) {
    const peer::State s = peer::random_state(g_layout, g_mujoco->gravity(), rng);
    PKG::rhs(0.0, s.x.data(), PKG::default_parameters, s.in.data(), out.data());
    const std::vector<double> uh(out.begin() + nc, out.end());
    rhs_dart = std::max(rhs_dart, rel(peer_udot(*g_dart, s), uh));
    rhs_mj = std::max(rhs_mj, rel(peer_udot(*g_mujoco, s), uh));
    g_mujoco->set(s);
    g_mujoco->smooth();
    g_mujoco->smooth_accelerations(udot.data());
    rhs_smooth = std::max(rhs_smooth, rel(udot, uh));

    PKG::mass_matrix(0.0, s.x.data(), PKG::default_parameters, s.in.data(), Mh.data());
    g_dart->set(s);
    g_dart->mass_matrix();
    g_dart->mass_matrix_hamel(Mp.data());
    M_dart = std::max(M_dart, rel(Mp, Mh));
    g_mujoco->set(s);
    g_mujoco->mass_matrix();
    g_mujoco->mass_matrix_hamel(Mp.data());
    M_mj = std::max(M_mj, rel(Mp, Mh));

    if (k < 3) {  // the differences cost 2 n_state forward dynamics each
      PKG::jacobian(0.0, s.x.data(), PKG::default_parameters, s.in.data(), Jh.data());
      const std::vector<double> Jrows(Jh.begin() + nc * ns, Jh.end());
      J_dart = std::max(J_dart, rel(peer_jacobian(*g_dart, s), Jrows));
      J_mj = std::max(J_mj, rel(peer_jacobian(*g_mujoco, s), Jrows));
    }
  }
  std::printf(
      "%s: %d states: rhs vs DART %.1e, vs mj_forward %.1e, vs MuJoCo smooth %.1e; mass matrix vs DART %.1e, "
      "vs MuJoCo %.1e; jacobian vs centred differences of DART %.1e, of MuJoCo %.1e\n",
      PKG_NAME, states, rhs_dart, rhs_mj, rhs_smooth, M_dart, M_mj, J_dart, J_mj);
  const double worst = std::max({rhs_dart, rhs_mj, rhs_smooth, M_dart, M_mj});
  return worst <= 1e-9 && std::max(J_dart, J_mj) <= 1e-5 ? 0 : 1;
}

template <void (*K)(PKG::real, const PKG::real*, const PKG::real*, const PKG::real*, PKG::real*), int N_OUT>
void BM_hamel(benchmark::State& st) {
  static double out[N_OUT];
  int k = 0;
  for (auto _ : st) {
    K(0.0, g_states[k].x.data(), PKG::default_parameters, g_states[k].in.data(), out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
    k ^= 1;
  }
}

template <class P, void (P::*F)()>
void BM_peer(benchmark::State& st, P* p) {
  p->set(g_states[0]);
  p->save(0);
  p->set(g_states[1]);
  p->save(1);
  int k = 0;
  for (auto _ : st) {
    p->restore(k);
    (p->*F)();
    benchmark::ClobberMemory();
    k ^= 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench MODEL.xml [--zero-armature] [check [STATES] | benchmark flags]\n");
    return 2;
  }
  const char* xml = argv[1];
  int arg = 2;
  bool zero_armature = false;
  if (argc > arg && std::strcmp(argv[arg], "--zero-armature") == 0) zero_armature = true, ++arg;
  g_layout = package_layout();
  g_mujoco = std::make_unique<peer::Mujoco>(xml, g_layout, zero_armature);
  g_dart = std::make_unique<peer::Dart>(xml, g_layout, zero_armature);
  if (argc > arg && std::strcmp(argv[arg], "check") == 0) return check(argc > arg + 1 ? std::atoi(argv[arg + 1]) : 20);
  std::mt19937_64 rng(1);
  g_states[0] = peer::random_state(g_layout, g_mujoco->gravity(), rng);
  g_states[1] = peer::random_state(g_layout, g_mujoco->gravity(), rng);
  using peer::Dart;
  using peer::Mujoco;
  benchmark::RegisterBenchmark("hamel_rhs", BM_hamel<PKG::rhs, PKG::n_out_rhs>);
  benchmark::RegisterBenchmark("hamel_jacobian", BM_hamel<PKG::jacobian, PKG::n_out_jacobian>);
  benchmark::RegisterBenchmark("hamel_mass_matrix", BM_hamel<PKG::mass_matrix, PKG::n_out_mass_matrix>);
  benchmark::RegisterBenchmark("dart_forward", BM_peer<Dart, &Dart::forward>, g_dart.get());
  benchmark::RegisterBenchmark("dart_jacobian_fd", BM_peer<Dart, &Dart::jacobian_fd>, g_dart.get());
  benchmark::RegisterBenchmark("dart_mass_matrix", BM_peer<Dart, &Dart::mass_matrix>, g_dart.get());
  benchmark::RegisterBenchmark("mujoco_forward", BM_peer<Mujoco, &Mujoco::forward>, g_mujoco.get());
  benchmark::RegisterBenchmark("mujoco_smooth", BM_peer<Mujoco, &Mujoco::smooth>, g_mujoco.get());
  benchmark::RegisterBenchmark("mujoco_jacobian_fd", BM_peer<Mujoco, &Mujoco::jacobian_fd>, g_mujoco.get());
  benchmark::RegisterBenchmark("mujoco_transitionFD", BM_peer<Mujoco, &Mujoco::transition_fd>, g_mujoco.get());
  benchmark::RegisterBenchmark("mujoco_mass_matrix", BM_peer<Mujoco, &Mujoco::mass_matrix>, g_mujoco.get());
  std::vector<char*> bargv{argv[0]};
  for (int i = arg; i < argc; ++i) bargv.push_back(argv[i]);
  int bargc = static_cast<int>(bargv.size());
  benchmark::Initialize(&bargc, bargv.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
