// models/satellite_thrusters.yaml (a bus with six thrusters, a reaction wheel and a two-link arm on a floating
// SE(3) base) against the momentum balance of the whole spacecraft, written here in inertial coordinates from the
// geometry of the model file and sharing nothing with hamel's derivation. The emitted kernels (every parameter
// symbolic) are compiled as firmware compiles them.
//
// The reference: with the bus pose (R, p) and the state (r, ω, v, ṙ), forward kinematics by hand gives every
// body's rotation R_i, centre of mass c_i and velocities (ω_i, ċ_i) in the world, hence the total linear momentum
// P = Σ m_i ċ_i and the angular momentum about the inertial origin L = Σ (c_i × m_i ċ_i + R_i I_i R_iᵀ ω_i).
// Newton and Euler for the whole spacecraft: Ṗ = Σ_k F_k and L̇ = Σ_k r_k × F_k over the thrusters k (world force
// F_k = R f_k d_k at r_k = p + R ρ_k); the joint torques are internal. For each joint j, Euler for the subtree S_j
// about the joint's origin o_j (a moving point) along its axis a_j: a_j · (L̇_{S_j,o_j} + ȯ_j × P_{S_j}) = τ_j,
// since the parent's reaction has no moment about a_j. These 6 + 3 equations fix all nine accelerations.
//  - At 20 random states, parameters and inputs: the time derivatives are taken exactly, by dual numbers along the
//    tangent (Ṙ = R[ω]×, ṗ = R v, ṙ, and (ω̇, v̇, r̈) from the emitted rhs); all nine equations to 1e-12 relative.
//  - Along a 10 s manoeuvre with time-varying thrusts and joint torques, the bus pose reconstructed with the
//    runtime's RKMK4 on SE(3) × R^n (integrate_rkmk4_coupled, the integrals ∫ΣF dt and ∫Σ r × F dt carried in the
//    vector part): P(t) − P(0) and L(t) − L(0) equal the integrated thrust and moment to 1e-11 relative; with the
//    thrusters off (the arm and the wheel still driven) P and L are conserved to 1e-12 relative.
#include <hamel/runtime/lie/rkmk_coupled.hpp>
#include <hamel/runtime/lie/se3.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "satellite_thrusters.hpp"

namespace {

namespace sat = satellite_thrusters;
// State (phiw, q1, q2, wx, wy, wz, vx, vy, vz, phiw_dot, q1_dot, q2_dot); inputs (f1..f6, tau_w, tau1, tau2).
static_assert(sat::n_state == 12 && sat::n_inputs == 9 && sat::n_coordinates == 3);

// A dual number a + b ε (ε² = 0): derivatives along a tangent, exact to rounding.
struct Dual {
  double a = 0, b = 0;
  Dual() = default;
  Dual(double x, double dx = 0) : a(x), b(dx) {}  // NOLINT: implicit from double on purpose
};
Dual operator+(Dual x, Dual y) { return {x.a + y.a, x.b + y.b}; }
Dual operator-(Dual x, Dual y) { return {x.a - y.a, x.b - y.b}; }
Dual operator-(Dual x) { return {-x.a, -x.b}; }
Dual operator*(Dual x, Dual y) { return {x.a * y.a, x.a * y.b + x.b * y.a}; }
Dual sin(Dual x) { return {std::sin(x.a), std::cos(x.a) * x.b}; }
Dual cos(Dual x) { return {std::cos(x.a), -std::sin(x.a) * x.b}; }

template <class T>
using V3 = std::array<T, 3>;
template <class T>
using M3 = std::array<T, 9>;  // row-major

template <class T>
V3<T> operator+(const V3<T>& x, const V3<T>& y) {
  return {x[0] + y[0], x[1] + y[1], x[2] + y[2]};
}
template <class T>
V3<T> operator-(const V3<T>& x, const V3<T>& y) {
  return {x[0] - y[0], x[1] - y[1], x[2] - y[2]};
}
template <class T>
V3<T> scale(T s, const V3<T>& x) {
  return {s * x[0], s * x[1], s * x[2]};
}
template <class T>
V3<T> cross(const V3<T>& x, const V3<T>& y) {
  return {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
}
template <class T>
T dot(const V3<T>& x, const V3<T>& y) {
  return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
}
template <class T>
V3<T> mul(const M3<T>& m, const V3<T>& x) {
  return {m[0] * x[0] + m[1] * x[1] + m[2] * x[2], m[3] * x[0] + m[4] * x[1] + m[5] * x[2],
          m[6] * x[0] + m[7] * x[1] + m[8] * x[2]};
}
template <class T>
V3<T> mul_transposed(const M3<T>& m, const V3<T>& x) {
  return {m[0] * x[0] + m[3] * x[1] + m[6] * x[2], m[1] * x[0] + m[4] * x[1] + m[7] * x[2],
          m[2] * x[0] + m[5] * x[1] + m[8] * x[2]};
}
template <class T>
M3<T> mul(const M3<T>& a, const M3<T>& b) {
  M3<T> c;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
  return c;
}
template <class T>
M3<T> rot_z(T q) {
  using std::cos, std::sin;
  const T c = cos(q), s = sin(q);
  return {c, -s, T(0), s, c, T(0), T(0), T(0), T(1)};
}
template <class T>
M3<T> rot_y(T q) {
  using std::cos, std::sin;
  const T c = cos(q), s = sin(q);
  return {c, T(0), s, T(0), T(1), T(0), -s, T(0), c};
}
template <class T>
V3<T> lift(const V3<double>& x) {
  return {T(x[0]), T(x[1]), T(x[2])};
}

// The model file's parameters, by name (the values come from the caller: defaults or perturbed).
struct Params {
  double m0, c0x, c0y, c0z, I0x, I0y, I0z, I0xy, mw, Jw, Jwt, hw, bx, by, bz, l1, m1, J1a, I1, l2, m2, J2a, I2;
};
Params params_from(const double* p) {
  auto get = [&](const std::string& name) {
    for (int k = 0; k < sat::n_parameters; ++k)
      if (name == sat::parameter_names[k]) return p[k];
    ADD_FAILURE() << "no parameter " << name;
    return 0.0;
  };
  return {get("m0"), get("c0x"), get("c0y"), get("c0z"), get("I0x"), get("I0y"), get("I0z"), get("I0xy"),
          get("mw"), get("Jw"),  get("Jwt"), get("hw"),  get("bx"),  get("by"),  get("bz"),  get("l1"),
          get("m1"), get("J1a"), get("I1"),  get("l2"),  get("m2"),  get("J2a"), get("I2")};
}

// One body of the reference: mass, inertia about the centre of mass in the body frame (row-major), and in the
// world its rotation, centre of mass and their rates.
template <class T>
struct Body {
  double mass;
  M3<double> inertia;
  M3<T> R;
  V3<T> c, c_dot, omega;
};

template <class T>
struct Spacecraft {
  std::array<Body<T>, 4> body;  // bus, wheel, upper arm, forearm
  V3<T> joint_origin[3], joint_origin_dot[3], joint_axis[3];
};

// Forward kinematics by hand. State: bus pose (R, p), joint angles (phiw, q1, q2), the bus's body twist (ω, v) and
// the joint rates.
template <class T>
Spacecraft<T> kinematics(const Params& k, const M3<T>& R, const V3<T>& p, const V3<T>& q, const V3<T>& w_body,
                         const V3<T>& v_body, const V3<T>& q_dot) {
  Spacecraft<T> s;
  const V3<T> w0 = mul(R, w_body), v0 = mul(R, v_body);  // world angular velocity, velocity of the bus origin
  auto point_velocity = [&](const V3<T>& x) { return v0 + cross(w0, x - p); };  // a point fixed on the bus
  const V3<T> ez{T(0), T(0), T(1)}, ey{T(0), T(1), T(0)};
  // Bus.
  const V3<T> c0 = p + mul(R, lift<T>({k.c0x, k.c0y, k.c0z}));
  s.body[0] = {k.m0, {k.I0x, k.I0xy, 0, k.I0xy, k.I0y, 0, 0, 0, k.I0z}, R, c0, point_velocity(c0), w0};
  // Wheel: about the bus z axis through (0, 0, -hw).
  const V3<T> ow = p + mul(R, lift<T>({0, 0, -k.hw}));
  const V3<T> aw = mul(R, ez);
  s.body[1] = {k.mw,
               {k.Jwt, 0, 0, 0, k.Jwt, 0, 0, 0, k.Jw},
               mul(R, rot_z(q[0])),
               ow,
               point_velocity(ow),
               w0 + scale(q_dot[0], aw)};
  // Upper arm: about the bus z axis through (bx, 0, bz).
  const V3<T> o1 = p + mul(R, lift<T>({k.bx, 0, k.bz}));
  const V3<T> a1 = mul(R, ez);
  const M3<T> R1 = mul(R, rot_z(q[1]));
  const V3<T> w1 = w0 + scale(q_dot[1], a1), o1_dot = point_velocity(o1);
  const V3<T> c1 = o1 + mul(R1, lift<T>({k.l1 / 2, 0, 0}));
  s.body[2] = {k.m1, {k.J1a, 0, 0, 0, k.I1, 0, 0, 0, k.I1}, R1, c1, o1_dot + cross(w1, c1 - o1), w1};
  // Forearm: about the upper arm's y axis through its point (l1, 0, 0).
  const V3<T> o2 = o1 + mul(R1, lift<T>({k.l1, 0, 0}));
  const V3<T> a2 = mul(R1, ey);
  const M3<T> R2 = mul(R1, rot_y(q[2]));
  const V3<T> w2 = w1 + scale(q_dot[2], a2), o2_dot = o1_dot + cross(w1, o2 - o1);
  const V3<T> c2 = o2 + mul(R2, lift<T>({k.l2 / 2, 0, 0}));
  s.body[3] = {k.m2, {k.J2a, 0, 0, 0, k.I2, 0, 0, 0, k.I2}, R2, c2, o2_dot + cross(w2, c2 - o2), w2};
  s.joint_origin[0] = ow, s.joint_origin[1] = o1, s.joint_origin[2] = o2;
  s.joint_origin_dot[0] = point_velocity(ow), s.joint_origin_dot[1] = o1_dot, s.joint_origin_dot[2] = o2_dot;
  s.joint_axis[0] = aw, s.joint_axis[1] = a1, s.joint_axis[2] = a2;
  return s;
}

// Linear momentum and angular momentum about the point o of the bodies in `which`.
template <class T>
void momenta(const Spacecraft<T>& s, const std::vector<int>& which, const V3<T>& o, V3<T>& P, V3<T>& L) {
  P = {T(0), T(0), T(0)};
  L = P;
  for (int i : which) {
    const Body<T>& b = s.body[static_cast<std::size_t>(i)];
    const V3<T> mv = scale(T(b.mass), b.c_dot);
    P = P + mv;
    // The spin R I Rᵀ ω.
    const V3<T> body_w = mul_transposed(b.R, b.omega);
    M3<T> I;
    for (int e = 0; e < 9; ++e) I[static_cast<std::size_t>(e)] = T(b.inertia[static_cast<std::size_t>(e)]);
    L = L + cross(b.c - o, mv) + mul(b.R, mul(I, body_w));
  }
}

// The thrusters: point in the bus frame and unit direction, as in the model file; inputs f1..f6 in order.
struct Thruster {
  V3<double> point, direction;
};
std::array<Thruster, 6> thrusters(const Params& k) {
  return {{{{-k.bx, k.by, 0}, {1, 0, 0}},
           {{-k.bx, -k.by, 0}, {1, 0, 0}},
           {{k.bx, 0, -k.bz}, {0, 0, 1}},
           {{-k.bx, 0, -k.bz}, {0, 0, 1}},
           {{0, k.by, -k.bz}, {0, 0, 1}},
           {{0, -k.by, -k.bz}, {0, 0, 1}}}};
}

// Σ F and Σ r × F (about the inertial origin) of the thrusters in the world.
void thrust(const Params& k, const M3<double>& R, const V3<double>& p, const double* in, V3<double>& F, V3<double>& M) {
  F = {0, 0, 0};
  M = {0, 0, 0};
  const auto all = thrusters(k);
  for (std::size_t j = 0; j < all.size(); ++j) {
    const V3<double> f = scale(in[j], mul(R, all[j].direction));
    F = F + f;
    M = M + cross(p + mul(R, all[j].point), f);
  }
}

M3<double> random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  double q[4];
  double norm = 0;
  for (double& c : q) c = n(rng), norm += c * c;
  norm = std::sqrt(norm);
  const double w = q[0] / norm, x = q[1] / norm, y = q[2] / norm, z = q[3] / norm;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

double norm(const V3<double>& x) { return std::sqrt(dot(x, x)); }

// The nine balance equations at one state, pose (R, p), parameters and inputs; returns the largest residual
// relative to the size of the terms it balances.
double balance_residual(const double* x, const M3<double>& R, const V3<double>& p, const double* params,
                        const double* in) {
  double dx[sat::n_state];
  sat::rhs(0.0, x, params, in, dx);
  const Params k = params_from(params);
  // The state and its rate as duals: value + ε · (d/dt).
  const V3<double> w{x[3], x[4], x[5]}, v{x[6], x[7], x[8]};
  M3<Dual> Rd;
  const M3<double> R_dot = [&] {
    M3<double> hat_w{0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
    return mul(R, hat_w);
  }();
  for (int e = 0; e < 9; ++e)
    Rd[static_cast<std::size_t>(e)] = Dual(R[static_cast<std::size_t>(e)], R_dot[static_cast<std::size_t>(e)]);
  const V3<double> p_dot = mul(R, v);
  const V3<Dual> pd{Dual(p[0], p_dot[0]), Dual(p[1], p_dot[1]), Dual(p[2], p_dot[2])};
  auto dual3 = [&](int at) {
    return V3<Dual>{Dual(x[at], dx[at]), Dual(x[at + 1], dx[at + 1]), Dual(x[at + 2], dx[at + 2])};
  };
  const Spacecraft<Dual> s = kinematics(k, Rd, pd, dual3(0), dual3(3), dual3(6), dual3(9));
  auto d = [](const V3<Dual>& a) { return V3<double>{a[0].b, a[1].b, a[2].b}; };
  auto val = [](const V3<Dual>& a) { return V3<double>{a[0].a, a[1].a, a[2].a}; };
  const V3<Dual> origin{Dual(0), Dual(0), Dual(0)};
  V3<Dual> P, L;
  momenta(s, {0, 1, 2, 3}, origin, P, L);
  V3<double> F, M;
  thrust(k, R, p, in, F, M);
  double worst = 0;
  const double scale_p = norm(F) + 1e-3 * norm(val(P)), scale_l = norm(M) + 1e-3 * norm(val(L));
  worst = std::max(worst, norm(d(P) - F) / scale_p);
  worst = std::max(worst, norm(d(L) - M) / scale_l);
  // Each joint's subtree about the joint origin along its axis; τ from the inputs (tau_w, tau1, tau2).
  const std::vector<int> subtree[3] = {{1}, {2, 3}, {3}};
  for (int j = 0; j < 3; ++j) {
    // L about the moving point o_j: the Dual carries d/dt of Σ (c − o) × m ċ + spin, with o moving as well.
    V3<Dual> Pj, Lj;
    momenta(s, subtree[j], s.joint_origin[j], Pj, Lj);
    const V3<double> a = val(s.joint_axis[j]);
    const double lhs = dot(a, d(Lj) + cross(val(s.joint_origin_dot[j]), val(Pj)));
    const double tau = in[6 + j];
    worst = std::max(worst, std::fabs(lhs - tau) / (std::fabs(tau) + 1e-3 * norm(val(Lj)) + 1e-12));
  }
  return worst;
}

TEST(SatelliteThrusters, AccelerationsSatisfyTheMomentumBalanceAtRandomStates) {
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> u(-1, 1), angle(-M_PI, M_PI), factor(0.8, 1.25), thrust_range(0, 20);
  double worst = 0;
  for (int trial = 0; trial < 20; ++trial) {
    double x[sat::n_state];
    for (int i = 0; i < 3; ++i) x[i] = angle(rng);
    for (int i = 3; i < 9; ++i) x[i] = 0.5 * u(rng);
    for (int i = 9; i < 12; ++i) x[i] = 2 * u(rng);
    const M3<double> R = random_rotation(rng);
    const V3<double> p{10 * u(rng), 10 * u(rng), 10 * u(rng)};
    double params[sat::n_parameters];
    for (int i = 0; i < sat::n_parameters; ++i) params[i] = sat::default_parameters[i] * (trial ? factor(rng) : 1);
    double in[sat::n_inputs];
    for (int i = 0; i < 6; ++i) in[i] = thrust_range(rng);
    for (int i = 6; i < 9; ++i) in[i] = 3 * u(rng);
    worst = std::max(worst, balance_residual(x, R, p, params, in));
  }
  std::printf("momentum and joint balances at 20 random states: worst relative residual %.2e\n", worst);
  EXPECT_LE(worst, 1e-12);
}

// Inputs along the manoeuvre: thrusts pulsing out of phase (so the pairs turn the bus), or off; the arm and the
// wheel driven throughout.
void inputs_at(double t, bool thrusters_on, double* in) {
  for (int j = 0; j < 6; ++j) in[j] = thrusters_on ? 6.0 * (1 + std::sin(0.9 * t + 1.1 * j)) : 0.0;
  in[6] = 0.05 * std::cos(0.5 * t);
  in[7] = 2.0 * std::sin(0.8 * t);
  in[8] = -1.5 * std::sin(1.3 * t + 0.4);
}

struct Drift {
  double P = 0, L = 0, P_size = 0, L_size = 0;
};

// RKMK4 on SE(3) × R^(12 + 6): the state, and the integrals of Σ F and Σ r × F along the reconstructed pose.
Drift manoeuvre(bool thrusters_on, double h) {
  using hamel::runtime::lie::SE3;
  const Params k = params_from(sat::default_parameters);
  constexpr std::size_t n = sat::n_state + 6;
  std::vector<double> x0(n, 0.0);
  const double start[sat::n_state] = {0.2, 0.3, 0.8, 0.02, -0.01, 0.05, 0.1, -0.05, 0.02, 20.0, 0.1, -0.2};
  std::copy(start, start + sat::n_state, x0.begin());
  auto f = [&](double t, const double* x, const SE3::Element& g, double* dx) {
    double in[sat::n_inputs];
    inputs_at(t, thrusters_on, in);
    sat::rhs(t, x, sat::default_parameters, in, dx);
    V3<double> F, M;
    thrust(k, g.R, g.p, in, F, M);
    for (int i = 0; i < 3; ++i)
      dx[sat::n_state + i] = F[static_cast<std::size_t>(i)], dx[sat::n_state + 3 + i] = M[static_cast<std::size_t>(i)];
  };
  auto xi = [](double, const double* x, double* out) { std::copy(x + 3, x + 9, out); };
  auto momentum_at = [&](const double* x, const SE3::Element& g, V3<double>& P, V3<double>& L) {
    const Spacecraft<double> s = kinematics<double>(k, g.R, g.p, {x[0], x[1], x[2]}, {x[3], x[4], x[5]},
                                                    {x[6], x[7], x[8]}, {x[9], x[10], x[11]});
    momenta(s, {0, 1, 2, 3}, V3<double>{0, 0, 0}, P, L);
  };
  V3<double> P0{}, L0{};
  Drift drift;
  bool first = true;
  auto observe = [&](double, const double* x, const SE3::Element& g) {
    V3<double> P, L;
    momentum_at(x, g, P, L);
    if (first) P0 = P, L0 = L, first = false;
    const double* integral = x + sat::n_state;  // ∫ Σ F dt, then ∫ Σ r × F dt
    const V3<double> dP = P - P0 - V3<double>{integral[0], integral[1], integral[2]};
    const V3<double> dL = L - L0 - V3<double>{integral[3], integral[4], integral[5]};
    drift.P = std::max(drift.P, norm(dP));
    drift.L = std::max(drift.L, norm(dL));
    drift.P_size = std::max({drift.P_size, norm(P), norm(P0)});
    drift.L_size = std::max({drift.L_size, norm(L), norm(L0)});
  };
  std::vector<double> x = x0, work(hamel::runtime::lie::RkmkCoupledWorkspace::doubles(n));
  const auto result = hamel::runtime::lie::integrate_rkmk4_coupled<SE3>(hamel::runtime::lie::Trivialization::left, f,
                                                                        xi, SE3::identity(), x.data(), n, 0.0, 10.0, h,
                                                                        0.05, observe, {work.data(), work.size()});
  EXPECT_EQ(result.status, hamel::runtime::Status::ok);
  std::printf("thrusters %s, RKMK4 h = %g, 10 s: |P - P0 - int F| %.2e of %.2e, |L - L0 - int r x F| %.2e of %.2e\n",
              thrusters_on ? "on " : "off", h, drift.P, drift.P_size, drift.L, drift.L_size);
  return drift;
}

TEST(SatelliteThrusters, ManoeuvreFollowsTheMomentumBalanceAlongTheReconstructedPose) {
  const Drift on = manoeuvre(true, 1e-3);
  EXPECT_LE(on.P / on.P_size, 1e-11);
  EXPECT_LE(on.L / on.L_size, 1e-11);
  EXPECT_GT(on.P_size, 100.0) << "the thrusters must change the momentum";
}

TEST(SatelliteThrusters, MomentumIsConservedWithTheThrustersOff) {
  const Drift off = manoeuvre(false, 1e-3);
  EXPECT_LE(off.P / off.P_size, 1e-12);
  EXPECT_LE(off.L / off.L_size, 1e-12);
}

}  // namespace
