// models/quadrotor_slung_load.yaml against a Newton–Euler model written here from the physics, in inertial
// coordinates, sharing nothing with hamel's derivation: the frame's pose (R, p), its angular velocity ω in its own
// frame and its velocity v in the world; the load's position p_L and velocity v_L in the world; the cable as a
// tension T along n = (p_L − p_A)/|p_L − p_A| between the attachment point p_A = p + R r_A and the load, with T from
// the constraint |p_L − p_A| = l differentiated twice (every acceleration is affine in T):
//   m a = R (0, 0, f) + m g + T n,   I ω̇ = τ − ω × I ω + r_A × Rᵀ T n,   m_L a_L = m_L g − T n.
// The generated rhs (state (θ, φ, Γ, ξ, θ̇, φ̇), Γ gravity in the frame) is integrated with the frame's pose
// reconstructed alongside (Ṙ = R [ω]×, ṗ = R v_b), both with DOP853 at 1e-13, for 10 s along a path where a torque
// about body y tumbles the frame through pitch 90° (where the ZYX Euler angles of a hand-written model are
// singular); R, p and the load's position must agree to 1e-10, Γ with Rᵀ g. At hover (f = (m + m_L) g) the
// eigenvalues of `hamel linearize` agree with those of the reference's Jacobian (central differences in long
// double) to 1e-9.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <hamel/runtime/dop853.hpp>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using Real = long double;
using V3 = Eigen::Matrix<Real, 3, 1>;
using M3 = Eigen::Matrix<Real, 3, 3>;
using VX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
using MX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;

// The model file's default parameters.
constexpr Real m = 1.5L, mL = 0.3L, l = 1.0L, d = 0.05L, g = 9.81L;
const V3 inertia(0.029L, 0.029L, 0.055L);
const V3 gravity(0, 0, -g);
const V3 r_A(0, 0, -d);

M3 hat(const V3& a) {
  M3 h;
  h << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return h;
}

// Reference state y = (R row-major 9, p 3, ω 3, v 3, p_L 3, v_L 3) = 24.
VX reference_rhs(const VX& y, Real f, const V3& tau) {
  M3 R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = y[3 * i + j];
  const V3 w = y.segment<3>(12), v = y.segment<3>(15), pL = y.segment<3>(18), vL = y.segment<3>(21);
  const V3 pA = y.segment<3>(9) + R * r_A;
  const V3 vA = v + R * w.cross(r_A);
  const V3 e = pL - pA;
  const V3 n = e / e.norm();
  const M3 I = inertia.asDiagonal();
  // Accelerations as a0 + T a1.
  const V3 a0 = R * V3(0, 0, f) / m + gravity, a1 = n / m;
  const V3 alpha0 = I.inverse() * (tau - w.cross(I * w)), alpha1 = I.inverse() * r_A.cross(R.transpose() * n);
  const V3 aL0 = gravity, aL1 = -n / mL;
  const V3 aA0 = a0 + R * (alpha0.cross(r_A) + w.cross(w.cross(r_A))), aA1 = a1 + R * alpha1.cross(r_A);
  // (p_L − p_A)·(a_L − a_A) + |v_L − v_A|² = 0.
  const Real T = -(e.dot(aL0 - aA0) + (vL - vA).squaredNorm()) / e.dot(aL1 - aA1);
  VX dy(24);
  const M3 dR = R * hat(w);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) dy[3 * i + j] = dR(i, j);
  dy.segment<3>(9) = v;
  dy.segment<3>(12) = alpha0 + T * alpha1;
  dy.segment<3>(15) = a0 + T * a1;
  dy.segment<3>(18) = vL;
  dy.segment<3>(21) = aL0 + T * aL1;
  return dy;
}

M3 Rx(Real a) {
  M3 r;
  r << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return r;
}
M3 Ry(Real a) {
  M3 r;
  r << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return r;
}

// The inputs along a path, a flip: a torque about body y tumbles the frame for 1.6 s (through pitch 90 degrees and
// upside down), then an attitude controller (a proportional-derivative law on R and ω, as a flight controller would
// run it) turns it upright again; the thrust holds the weight along body z as far as the tilt allows. `spatial`
// adds roll and yaw torques during the flip. Both models evaluate the same law on their own pose.
void inputs(double t, const M3& R, const V3& w, bool spatial, double* in) {
  const double up = static_cast<double>(R(2, 2));
  in[0] = static_cast<double>((m + mL) * g) * (0.6 + 0.4 * up) + 0.3 * std::sin(1.3 * t);
  if (t < 1.6) {
    in[1] = spatial ? 0.002 : 0.0;
    in[2] = 0.06;
    in[3] = spatial ? 0.001 : 0.0;
    return;
  }
  // e_R = ½ vee(Rᵀ − R) for the upright R_d = I (Lee, Leok & McClamroch 2010).
  const V3 e(static_cast<double>(R(2, 1) - R(1, 2)) / 2, static_cast<double>(R(0, 2) - R(2, 0)) / 2,
             static_cast<double>(R(1, 0) - R(0, 1)) / 2);
  for (int k = 0; k < 3; ++k) in[1 + k] = static_cast<double>(-0.4L * e[k] - 0.12L * w[k]);
}

struct Sample {
  double t;
  M3 R;
  V3 p, pL, gamma;
};

std::vector<Sample> integrate_hamel(const std::vector<double>& x0, bool spatial) {
  const hamel::Model model = hamel::load_model(hamel::test::source("models/quadrotor_slung_load.yaml"));
  const hamel::Derivation derivation = hamel::derive(model);
  const hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs"});
  hamel::GraphEvaluator rhs(kernels.graph, kernels.get("rhs").outputs);
  std::vector<double> p;
  for (const hamel::Parameter& q : model.parameters) p.push_back(q.default_value);
  const int n = 13;  // (θ, φ, Γ, ξ, θ̇, φ̇)
  std::vector<double> y = x0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) y.push_back(i == j ? 1.0 : 0.0);
  for (int i = 0; i < 3; ++i) y.push_back(0.0);
  auto f = [&](double t, const double* x, double* dx) {
    double in[4];
    M3 pose;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) pose(i, j) = x[n + 3 * i + j];
    inputs(t, pose, V3(x[5], x[6], x[7]), spatial, in);
    rhs.evaluate(t, x, p.data(), in, dx);
    const double *w = x + 5, *v = x + 8, *R = x + n;
    for (int i = 0; i < 3; ++i) {
      const double* r = R + 3 * i;
      dx[n + 3 * i + 0] = r[1] * w[2] - r[2] * w[1];
      dx[n + 3 * i + 1] = r[2] * w[0] - r[0] * w[2];
      dx[n + 3 * i + 2] = r[0] * w[1] - r[1] * w[0];
      dx[n + 9 + i] = r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    }
  };
  std::vector<Sample> out;
  hamel::runtime::Dop853Options opt;
  opt.rtol = opt.atol = 1e-13;
  const auto result = hamel::runtime::integrate_dop853(f, y, 0.0, 10.0, opt, 0.002, [&](double t, const double* x) {
    Sample s{t, M3::Zero(), V3::Zero(), V3::Zero(), V3(x[2], x[3], x[4])};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) s.R(i, j) = x[n + 3 * i + j];
      s.p[i] = x[n + 9 + i];
    }
    s.pL = s.p + s.R * (r_A + Ry(x[0]) * Rx(x[1]) * V3(0, 0, -l));
    out.push_back(s);
  });
  EXPECT_EQ(result.status, hamel::runtime::Status::ok);
  return out;
}

std::vector<Sample> integrate_reference(const VX& y0, bool spatial) {
  std::vector<double> y(y0.data(), y0.data() + y0.size());
  for (double& v : y) v = static_cast<double>(v);
  std::vector<double> start(24);
  for (int k = 0; k < 24; ++k) start[static_cast<std::size_t>(k)] = static_cast<double>(y0[k]);
  auto f = [&](double t, const double* x, double* dx) {
    double in[4];
    VX yy(24);
    for (int k = 0; k < 24; ++k) yy[k] = x[k];
    M3 pose;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) pose(i, j) = yy[3 * i + j];
    inputs(t, pose, yy.segment<3>(12), spatial, in);
    const VX dy = reference_rhs(yy, in[0], V3(in[1], in[2], in[3]));
    for (int k = 0; k < 24; ++k) dx[k] = static_cast<double>(dy[k]);
  };
  std::vector<Sample> out;
  hamel::runtime::Dop853Options opt;
  opt.rtol = opt.atol = 1e-13;
  const auto result = hamel::runtime::integrate_dop853(f, start, 0.0, 10.0, opt, 0.002, [&](double t, const double* x) {
    Sample s{t, M3::Zero(), V3::Zero(), V3::Zero(), V3::Zero()};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) s.R(i, j) = x[3 * i + j];
      s.p[i] = x[9 + i];
      s.pL[i] = x[18 + i];
    }
    out.push_back(s);
  });
  EXPECT_EQ(result.status, hamel::runtime::Status::ok);
  return out;
}

// Both models from the load swung out by (θ, φ) and the frame turning at ω, joint rates zero (so the load's velocity
// follows from the frame's twist), over 10 s of the flip: R, and p and the load's position relative to the distance
// flown, to 1e-10; Γ = Rᵀ g along hamel's reconstructed pose. Returns the largest sin(pitch) of the path.
double compare(Real phi, Real theta, const V3& w, bool spatial) {
  const V3 vb(0.3L, -0.1L, 0.2L);
  const std::vector<double> x0 = {static_cast<double>(theta),
                                  static_cast<double>(phi),
                                  0,
                                  0,
                                  -9.81,  // θ, φ, Γ
                                  static_cast<double>(w[0]),
                                  static_cast<double>(w[1]),
                                  static_cast<double>(w[2]),
                                  0.3,
                                  -0.1,
                                  0.2,
                                  0,
                                  0};  // ξ, θ̇, φ̇
  VX y0 = VX::Zero(24);
  y0[0] = y0[4] = y0[8] = 1;
  y0.segment<3>(12) = w;
  y0.segment<3>(15) = vb;  // R = I: world and body velocities coincide
  const V3 cable = r_A + Ry(theta) * Rx(phi) * V3(0, 0, -l);
  y0.segment<3>(18) = cable;
  y0.segment<3>(21) = vb + w.cross(cable);
  const std::vector<Sample> h = integrate_hamel(x0, spatial), r = integrate_reference(y0, spatial);
  EXPECT_EQ(h.size(), r.size());
  double worst_R = 0, worst_p = 0, worst_load = 0, worst_gamma = 0, pitch = 0, distance = 1;
  for (std::size_t k = 0; k < h.size() && k < r.size(); ++k) {
    worst_R = std::max(worst_R, static_cast<double>((h[k].R - r[k].R).norm()));
    worst_p = std::max(worst_p, static_cast<double>((h[k].p - r[k].p).norm()));
    worst_load = std::max(worst_load, static_cast<double>((h[k].pL - r[k].pL).norm()));
    worst_gamma = std::max(worst_gamma, static_cast<double>((h[k].gamma - h[k].R.transpose() * gravity).norm() / g));
    pitch = std::max(pitch, static_cast<double>(-r[k].R(2, 0)));  // sin of the ZYX pitch angle
    distance = std::max(distance, static_cast<double>(r[k].pL.norm()));
  }
  std::printf(
      "%s, 10 s: |R - R_ref| %.1e, |p - p_ref| %.1e m, load %.1e m (farthest %.0f m), |Gamma - R^T g|/g %.1e; "
      "largest sin(pitch) %.9f\n",
      spatial ? "spatial" : "planar", worst_R, worst_p, worst_load, distance, worst_gamma, pitch);
  EXPECT_LE(worst_R, 1e-10);
  EXPECT_LE(worst_p / distance, 1e-10);
  EXPECT_LE(worst_load / distance, 1e-10);
  EXPECT_LE(worst_gamma, 1e-10);
  return pitch;
}

// In the frame's x-z plane (the load swung back, no roll or yaw), the flip passes exactly through pitch 90°.
TEST(QuadrotorSlungLoad, FlipsThroughPitchNinetyDegreesAsTheNewtonEulerModel) {
  EXPECT_GT(compare(0, -0.2L, V3(0, 0.1L, 0), false), 1 - 1e-5) << "the path must pass pitch 90 degrees";
}

// Out of the plane: the load swung sideways, the frame turning about all three axes, roll and yaw torques.
TEST(QuadrotorSlungLoad, FliesASpatialPathAsTheNewtonEulerModel) {
  EXPECT_GT(compare(0.3L, -0.2L, V3(0.02L, 0.1L, 0.05L), true), 0.99) << "a flip";
}

// The eigenvalues of hamel linearize at hover against the reference's Jacobian at hover (central differences,
// long double); zero eigenvalues are left out of the comparison, together with the ~6e-5 that central differences
// make of the reference's nilpotent chains (tilt -> velocity -> position: a zero of multiplicity four perturbed
// by 1e-17 splits by its fourth root).
TEST(QuadrotorSlungLoad, HoverEigenvaluesOfLinearizeMatchTheReference) {
  const Real hover = (m + mL) * g;
  char command[512];
  std::snprintf(command, sizeof command, "%s linearize %s --input f=%.17g --json 2>/dev/null", HAMEL_BINARY,
                hamel::test::source("models/quadrotor_slung_load.yaml").c_str(), static_cast<double>(hover));
  const hamel::test::Outcome run = hamel::test::run(command);
  ASSERT_EQ(run.status, 0) << run.out;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  std::vector<std::complex<double>> generated;
  for (const auto& e : j.at("eigenvalues")) {
    const std::complex<double> z(e.at(0).get<double>(), e.at(1).get<double>());
    if (std::abs(z) > 1e-3) generated.push_back(z);
  }
  // The reference's state holds R (9) and the load's position (3) and velocity (3) in full; its motion stays on the
  // manifold where R is a rotation and the cable has length l. Linearized at hover, the dynamics on that manifold:
  // local coordinates z = (rotation vector θ, p, ω, v, the cable's angles α about x and β about y and their rates),
  // the embedding y(z) and its tangent map T = ∂y/∂z, and the restricted map T⁺ J T (the tangent space of an
  // invariant manifold at an equilibrium is invariant under J).
  const auto embed = [](const VX& z) {
    const V3 th = z.segment<3>(0);
    const Real angle = th.norm();
    M3 R = M3::Identity();
    if (angle > 0) R = Eigen::AngleAxis<Real>(angle, th / angle).toRotationMatrix();
    const V3 w = z.segment<3>(6), v = z.segment<3>(9);
    const Real a = z[12], b = z[13], ad = z[14], bd = z[15];
    const V3 c = r_A + Rx(a) * Ry(b) * V3(0, 0, -l);
    M3 dRx, dRy;  // derivatives of Rx and Ry by their angles
    dRx << 0, 0, 0, 0, -std::sin(a), -std::cos(a), 0, std::cos(a), -std::sin(a);
    dRy << -std::sin(b), 0, std::cos(b), 0, 0, 0, -std::cos(b), 0, -std::sin(b);
    const V3 c_rate = (dRx * Ry(b) * ad + Rx(a) * dRy * bd) * V3(0, 0, -l);
    VX y(24);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) y[3 * i + j] = R(i, j);
    y.segment<3>(9) = z.segment<3>(3);
    y.segment<3>(12) = w;
    y.segment<3>(15) = v;
    y.segment<3>(18) = z.segment<3>(3) + R * c;
    y.segment<3>(21) = v + R * (w.cross(c) + c_rate);
    return y;
  };
  const VX z0 = VX::Zero(16);
  const Real h = 1e-6L;
  MX T(24, 16), J(24, 24);
  for (int k = 0; k < 16; ++k) {
    VX zp = z0, zm = z0;
    zp[k] += h;
    zm[k] -= h;
    T.col(k) = (embed(zp) - embed(zm)) / (2 * h);
  }
  const VX y0 = embed(z0);
  for (int k = 0; k < 24; ++k) {
    VX yp = y0, ym = y0;
    yp[k] += h;
    ym[k] -= h;
    J.col(k) = (reference_rhs(yp, hover, V3::Zero()) - reference_rhs(ym, hover, V3::Zero())) / (2 * h);
  }
  const MX restricted = (T.transpose() * T).inverse() * T.transpose() * J * T;
  const Eigen::MatrixXd Jd = restricted.cast<double>();
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(Jd);
  std::vector<std::complex<double>> reference;
  for (int k = 0; k < 16; ++k)
    if (std::abs(solver.eigenvalues()[k]) > 1e-3) reference.push_back(solver.eigenvalues()[k]);
  const auto order = [](const std::complex<double>& a, const std::complex<double>& b) {
    return a.imag() != b.imag() ? a.imag() < b.imag() : a.real() < b.real();
  };
  std::sort(generated.begin(), generated.end(), order);
  std::sort(reference.begin(), reference.end(), order);
  ASSERT_EQ(generated.size(), reference.size());
  double worst = 0;
  for (std::size_t k = 0; k < generated.size(); ++k) {
    worst = std::max(worst, std::abs(generated[k] - reference[k]));
    std::printf("  eigenvalue %zu: hamel %.12f%+.12fi, reference %.12f%+.12fi\n", k, generated[k].real(),
                generated[k].imag(), reference[k].real(), reference[k].imag());
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_EQ(generated.size(), 4u) << "the load's two pendulum modes, coupled with the frame's roll and pitch";
}

}  // namespace

// The hover thrust given as an expression of the parameters (as simulate's --input takes it): linearize evaluates it at
// the run's parameters, reports it as the point's input (JSON input_values), and at hover nothing accelerates. With
// --param m=2 the same expression holds the heavier frame: the thrust follows the parameter.
TEST(QuadrotorSlungLoad, LinearizeTakesTheHoverThrustAsAnExpressionOfTheParameters) {
  const std::string model = hamel::test::source("models/quadrotor_slung_load.yaml");
  for (const double mass : {static_cast<double>(m), 2.0}) {
    const std::string command = std::string(HAMEL_BINARY) + " linearize " + model +
                                " --param m=" + std::to_string(mass) + " --input 'f=(m+mL)*g' --json 2>/dev/null";
    const hamel::test::Outcome run = hamel::test::run(command);
    ASSERT_EQ(run.status, 0) << command;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    const double f = j.at("input_values").at("f").get<double>();
    EXPECT_NEAR(f, (mass + static_cast<double>(mL)) * static_cast<double>(g), 1e-12) << command;
    EXPECT_EQ(j.at("input_values").at("tx").get<double>(), 0.0);
    double worst = 0;
    for (const auto& c : j.at("residual")) worst = std::max(worst, std::abs(c.get<double>()));
    EXPECT_LE(worst, 1e-12) << "x' at hover: " << j.at("residual").dump();
  }
}
