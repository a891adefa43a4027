// The planar four-bar linkage of models/four_bar.yaml, written out by hand with Eigen and nothing of hamel: the loop
// closure g(q), its Jacobian G, the loop closed for a crank angle (intersection of two circles), the velocities on the
// loop, the energy, and the Euler-Lagrange equations with Lagrange multipliers (KKT):
//
//   [ M(q)  G^T ] [ q'' ]   [ -h(q, q') ]        M = sum_i m_i J_i^T J_i + diag(I_i),  I_i = m_i l_i^2 / 12,
//   [ G     0   ] [ lam ] = [ -G' q'    ],       h = sum_i m_i J_i^T (J_i' q') + dV/dq,
//
// J_i the Jacobian of rod i's centre of mass (p_1 = l1/2 e(theta1), p_2 = l1 e(theta1) + l2/2 e(theta2),
// p_3 = (d, 0) + l3/2 e(theta3), e(a) = (cos a, sin a)), V = g sum_i m_i y_i.
#pragma once

#include <Eigen/Dense>

#include <cmath>

namespace four_bar_reference {

struct Parameters {
  double l1 = 0.2, l2 = 0.6, l3 = 0.45, d = 0.5, m1 = 0.4, m2 = 1.2, m3 = 0.9, g = 9.81;  // the model's defaults
  /// In the order of the model's parameters, as the emitted kernels read them.
  Eigen::Matrix<double, 8, 1> array() const {
    Eigen::Matrix<double, 8, 1> p;
    p << l1, l2, l3, d, m1, m2, m3, g;
    return p;
  }
};

using Vector3 = Eigen::Vector3d;
using Vector2 = Eigen::Vector2d;
using Jacobian = Eigen::Matrix<double, 2, 3>;

/// g(q): the coupler's tip minus the rocker's tip.
inline Vector2 loop(const Parameters& p, const Vector3& q) {
  return {p.l1 * std::cos(q[0]) + p.l2 * std::cos(q[1]) - p.d - p.l3 * std::cos(q[2]),
          p.l1 * std::sin(q[0]) + p.l2 * std::sin(q[1]) - p.l3 * std::sin(q[2])};
}

inline Jacobian loop_jacobian(const Parameters& p, const Vector3& q) {
  Jacobian G;
  G << -p.l1 * std::sin(q[0]), -p.l2 * std::sin(q[1]), p.l3 * std::sin(q[2]),  //
      p.l1 * std::cos(q[0]), p.l2 * std::cos(q[1]), -p.l3 * std::cos(q[2]);
  return G;
}

/// The loop closed for crank angle theta1 on the branch of the model's initial state (the coupler turned
/// counter-clockwise from the diagonal A-D): theta2 from the triangle A, B, D (law of cosines), theta3 from B - D.
inline Vector3 closed(const Parameters& p, double theta1) {
  const Vector2 A(p.l1 * std::cos(theta1), p.l1 * std::sin(theta1)), D(p.d, 0.0);
  const Vector2 AD = D - A;
  const double r = AD.norm();
  const double alpha = std::acos((p.l2 * p.l2 + r * r - p.l3 * p.l3) / (2 * p.l2 * r));
  const double theta2 = std::atan2(AD[1], AD[0]) + alpha;
  const Vector2 B = A + p.l2 * Vector2(std::cos(theta2), std::sin(theta2));
  return {theta1, theta2, std::atan2(B[1] - D[1], B[0] - D[0])};
}

/// q' on the loop (G q' = 0) with crank rate w.
inline Vector3 velocities(const Parameters& p, const Vector3& q, double w) {
  const Jacobian G = loop_jacobian(p, q);
  const Eigen::Matrix2d Gs = G.rightCols<2>();
  const Vector2 rest = Gs.fullPivLu().solve(-G.col(0) * w);
  return {w, rest[0], rest[1]};
}

/// The centres of mass' Jacobians J_i (2 x 3) and their rates times q' (J_i' q').
inline void centres(const Parameters& p, const Vector3& q, const Vector3& v, Jacobian J[3], Vector2 Jdot_v[3]) {
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]), c2 = std::cos(q[1]), s2 = std::sin(q[1]);
  const double c3 = std::cos(q[2]), s3 = std::sin(q[2]);
  J[0] << -p.l1 / 2 * s1, 0, 0, p.l1 / 2 * c1, 0, 0;
  J[1] << -p.l1 * s1, -p.l2 / 2 * s2, 0, p.l1 * c1, p.l2 / 2 * c2, 0;
  J[2] << 0, 0, -p.l3 / 2 * s3, 0, 0, p.l3 / 2 * c3;
  Jdot_v[0] = -p.l1 / 2 * v[0] * v[0] * Vector2(c1, s1);
  Jdot_v[1] = -p.l1 * v[0] * v[0] * Vector2(c1, s1) - p.l2 / 2 * v[1] * v[1] * Vector2(c2, s2);
  Jdot_v[2] = -p.l3 / 2 * v[2] * v[2] * Vector2(c3, s3);
}

inline Eigen::Matrix3d mass_matrix(const Parameters& p, const Vector3& q) {
  Jacobian J[3];
  Vector2 Jdot_v[3];
  centres(p, q, Vector3::Zero(), J, Jdot_v);
  const double m[3] = {p.m1, p.m2, p.m3}, l[3] = {p.l1, p.l2, p.l3};
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    M += m[i] * J[i].transpose() * J[i];
    M(i, i) += m[i] * l[i] * l[i] / 12;
  }
  return M;
}

inline double energy(const Parameters& p, const Vector3& q, const Vector3& v) {
  const double V =
      p.g * (p.m1 * p.l1 / 2 * std::sin(q[0]) + p.m2 * (p.l1 * std::sin(q[0]) + p.l2 / 2 * std::sin(q[1])) +
             p.m3 * p.l3 / 2 * std::sin(q[2]));
  return 0.5 * v.dot(mass_matrix(p, q) * v) + V;
}

/// q'' from the Euler-Lagrange equations with multipliers for the loop (the KKT system above).
inline Vector3 accelerations(const Parameters& p, const Vector3& q, const Vector3& v) {
  Jacobian J[3];
  Vector2 Jdot_v[3];
  centres(p, q, v, J, Jdot_v);
  const double m[3] = {p.m1, p.m2, p.m3};
  Vector3 h(p.g * (p.m1 * p.l1 / 2 + p.m2 * p.l1) * std::cos(q[0]), p.g * p.m2 * p.l2 / 2 * std::cos(q[1]),
            p.g * p.m3 * p.l3 / 2 * std::cos(q[2]));
  for (int i = 0; i < 3; ++i) h += m[i] * J[i].transpose() * Jdot_v[i];
  const Jacobian G = loop_jacobian(p, q);
  const Vector2 Gdot_v(
      -p.l1 * std::cos(q[0]) * v[0] * v[0] - p.l2 * std::cos(q[1]) * v[1] * v[1] + p.l3 * std::cos(q[2]) * v[2] * v[2],
      -p.l1 * std::sin(q[0]) * v[0] * v[0] - p.l2 * std::sin(q[1]) * v[1] * v[1] + p.l3 * std::sin(q[2]) * v[2] * v[2]);
  Eigen::Matrix<double, 5, 5> K = Eigen::Matrix<double, 5, 5>::Zero();
  K.topLeftCorner<3, 3>() = mass_matrix(p, q);
  K.topRightCorner<3, 2>() = G.transpose();
  K.bottomLeftCorner<2, 3>() = G;
  Eigen::Matrix<double, 5, 1> b;
  b << -h, -Gdot_v;
  return K.fullPivLu().solve(b).head<3>();
}

}  // namespace four_bar_reference
