// An independent model of the satellite of models/satellite_se3.yaml and satellite_so3xr3.yaml (base
// with three reaction wheels, rotor i spinning about the base axis e_i through its own centre of mass
// d_i), built from the physical parameters with Eigen, not from the generator: total mass M, centre of
// mass c in F_b, the locked inertia Θ_c about c (parallel-axis theorem), the rotor axial inertia J; and
// the base rotation under conservation of angular momentum about the (fixed) total centre of mass,
// integrated as a unit quaternion with classic RK4 and renormalisation.
//
// Since the rotors are axisymmetric and spin about axes through their own centres of mass, rotor motion
// moves no mass relative to the base: the total angular momentum about c in the inertial frame is
// h = R (Θ_c ω + J φ̇) (ω the body angular velocity, J φ̇ = (J φ̇_1, J φ̇_2, J φ̇_3) in the body frame), and
// the total linear momentum is M ṗ_c with p_c the inertial position of c.
#pragma once

#include "model/model.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace satellite {

struct Physical {
  double M = 0;
  Eigen::Vector3d c;        ///< total centre of mass in F_b
  Eigen::Matrix3d Theta_c;  ///< locked inertia about c, F_b axes
  double J = 0;             ///< rotor axial inertia
  /// Linear momentum of the rotors' relative motion per unit φ̇_i (all zero: each rotor's centre of
  /// mass is on its own spin axis, so its velocity (d_i × e_i) + e_i × d_i vanishes).
  std::array<Eigen::Vector3d, 3> rotor_linear_momentum;
};

inline Eigen::Matrix3d parallel_axis(double m, const Eigen::Vector3d& r) {
  return m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
}

inline Physical physical(const hamel::Model& model) {
  std::map<std::string, double> v;
  for (const auto& p : model.parameters) v[p.symbol.get_name()] = p.default_value;
  const double m0 = v.at("m0"), mr = v.at("mr"), J = v.at("J"), Jt = v.at("Jt");
  const Eigen::Vector3d c0(v.at("c0x"), v.at("c0y"), v.at("c0z"));
  std::array<Eigen::Vector3d, 3> d;
  for (int i = 0; i < 3; ++i) {
    const std::string k = std::to_string(i + 1);
    d[static_cast<std::size_t>(i)] = Eigen::Vector3d(v.at("d" + k + "x"), v.at("d" + k + "y"), v.at("d" + k + "z"));
  }
  Physical s;
  s.M = m0 + 3 * mr;
  s.J = J;
  s.c = (m0 * c0 + mr * (d[0] + d[1] + d[2])) / s.M;
  s.Theta_c = Eigen::Vector3d(v.at("T0x"), v.at("T0y"), v.at("T0z")).asDiagonal();
  s.Theta_c += parallel_axis(m0, c0 - s.c);
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d diag = Eigen::Vector3d::Constant(Jt);
    diag[i] = J;
    const Eigen::Vector3d& di = d[static_cast<std::size_t>(i)];
    s.Theta_c += Eigen::Matrix3d(diag.asDiagonal()) + parallel_axis(mr, di - s.c);
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i);
    // The relative twist (e_i, d_i × e_i) moves the rotor's centre of mass with (d_i × e_i) + e_i × d_i.
    s.rotor_linear_momentum[static_cast<std::size_t>(i)] = mr * (di.cross(e) + e.cross(di));
  }
  return s;
}

/// The paper's Sec. 6c path r(t) = (π(cos 2πt − 1), π sin 2πt, π/2 sin 4πt) and its rate.
inline Eigen::Vector3d path_rate(double t) {
  const double pi = M_PI, w = 2 * pi * pi;
  return {-w * std::sin(2 * pi * t), w * std::cos(2 * pi * t), w * std::cos(4 * pi * t)};
}

inline Eigen::Matrix3d rotation(const Eigen::Vector4d& q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

/// q̇ = ½ q ⊗ (0, ω) with ω = omega(t, R) the body angular velocity; classic RK4 with `steps_per_unit`
/// steps per unit time, renormalised after every step; R at t = 1, 2, ..., cycles.
inline std::vector<Eigen::Matrix3d> rotations_per_cycle(
    const std::function<Eigen::Vector3d(double, const Eigen::Matrix3d&)>& omega, int cycles, int steps_per_unit) {
  auto rate = [&](double t, const Eigen::Vector4d& q) {
    const Eigen::Vector3d w = omega(t, rotation(q));
    // (q0, qv) ⊗ (0, w) = (−qv·w, q0 w + qv × w)
    Eigen::Vector4d out;
    const Eigen::Vector3d qv = q.tail<3>();
    out[0] = -qv.dot(w);
    out.tail<3>() = q[0] * w + qv.cross(w);
    return Eigen::Vector4d(0.5 * out);
  };
  std::vector<Eigen::Matrix3d> out;
  Eigen::Vector4d q(1, 0, 0, 0);
  const double h = 1.0 / steps_per_unit;
  for (int k = 0; k < cycles; ++k) {
    for (int i = 0; i < steps_per_unit; ++i) {
      const double t = k + i * h;
      const Eigen::Vector4d k1 = rate(t, q);
      const Eigen::Vector4d k2 = rate(t + h / 2, q + h / 2 * k1);
      const Eigen::Vector4d k3 = rate(t + h / 2, q + h / 2 * k2);
      const Eigen::Vector4d k4 = rate(t + h, q + h * k3);
      q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      q.normalize();
    }
    out.push_back(rotation(q));
  }
  return out;
}

}  // namespace satellite
