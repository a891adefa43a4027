// An independent model of kinematic trees with a floating base, with Eigen in long double, written from the
// physics and not from the generator (model key `tree`):
//  - spatial vectors V = (ω, v) (angular first) in each body's own frame; the pose of a child relative to its
//    parent g = (rotation, offset) · exp(q S), S = (axis, 0) revolute, (0, axis) prismatic;
//  - the body twists V_i = Ad_{g_pi⁻¹} V_p + S_i q̇_i, the base twist V_0 = B ξ with B the 6×m basis of the
//    group's algebra inside se(3) (SE3: identity; SE2: (w, vx, vy) ↦ (0, 0, w, vx, vy, 0); SO3: angular;
//    R3: linear);
//  - recursive Newton–Euler (Featherstone's RNEA in body frames, Luh–Walker–Paul): accelerations
//    A_i = Ad_{g_pi⁻¹} A_p + S_i q̈_i + ad_{V_i} S_i q̇_i, body wrenches F_i = 𝕀_i A_i − ad_{V_i}ᵀ 𝕀_i V_i
//    (the Euler–Poincaré equation d/dt(𝕀V) − ad*_V 𝕀V = F, i.e. l̇ + ω×l + v×p = τ, ṗ + ω×p = f), summed
//    from the leaves to the base with F_p += Ad_{g_pi⁻¹}ᵀ F_i; joint force S_iᵀ F_i, base wrench F_0;
//  - the mass matrix column by column from RNEA at zero velocity and unit accelerations, the bias from RNEA
//    at zero acceleration; both projected on the group with blockdiag(B, I): Bᵀ F_0 = 0 (free base) and
//    S_iᵀ F_i = Q_i, solved for (ξ̇, q̈);
//  - kinetic energy ½ Σ V_iᵀ 𝕀_i V_i, body momentum ∂T/∂V_0 = Σ Ad_{g_0i⁻¹}ᵀ 𝕀_i V_i about the base-frame
//    origin, total mass and centre of mass in the base frame;
//  - random trees (random parents, axes, rotations, offsets, masses, centres of mass, positive definite
//    inertias that satisfy the triangle inequality) and their YAML model text: decimals with 6 places and
//    rotations/axes as exact rationals (from integer quaternions), so the file and the reference hold the
//    same numbers.
#pragma once

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace tree_ref {

using Real = long double;
using V3 = Eigen::Matrix<Real, 3, 1>;
using M3 = Eigen::Matrix<Real, 3, 3>;
using V6 = Eigen::Matrix<Real, 6, 1>;
using M6 = Eigen::Matrix<Real, 6, 6>;
using VX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
using MX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;

struct Inertial {
  Real mass = 1;
  V3 com = V3::Zero();
  M3 inertia = M3::Identity();  ///< about the centre of mass
  // Texts for the YAML file (empty: printed from the values).
  std::string mass_text;
};

struct Body {
  int parent = -1;  ///< −1: the base
  bool prismatic = false;
  V3 axis = V3::UnitZ();
  V3 offset = V3::Zero();
  M3 rotation = M3::Identity();
  bool has_rotation = false;
  std::string axis_text, rotation_text;  ///< exact rationals for the YAML file (empty: from the values)
  Inertial inertial;
};

struct Tree {
  std::string group = "SE3";  ///< SE3, SE2, SO3, R3
  Inertial base;
  std::vector<Body> bodies;
  int n() const { return static_cast<int>(bodies.size()); }
};

inline M3 hat(const V3& a) {
  M3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

/// Columns: the group's basis inside se(3), angular before linear.
inline MX basis(const std::string& group) {
  if (group == "SE3") return MX::Identity(6, 6);
  MX B;
  if (group == "SE2") {
    B = MX::Zero(6, 3);
    B(2, 0) = B(3, 1) = B(4, 2) = 1;
  } else if (group == "SO3") {
    B = MX::Zero(6, 3);
    B(0, 0) = B(1, 1) = B(2, 2) = 1;
  } else if (group == "R3") {
    B = MX::Zero(6, 3);
    B(3, 0) = B(4, 1) = B(5, 2) = 1;
  } else {
    throw std::runtime_error("tree_ref: no basis for group " + group);
  }
  return B;
}

inline std::vector<std::string> group_velocity_names(const std::string& group) {
  if (group == "SE3") return {"wx", "wy", "wz", "vx", "vy", "vz"};
  if (group == "SE2") return {"w", "vx", "vy"};
  if (group == "SO3") return {"wx", "wy", "wz"};
  if (group == "R3") return {"vx", "vy", "vz"};
  throw std::runtime_error("tree_ref: no names for group " + group);
}

/// Spatial inertia about the frame origin: T = ½ Vᵀ 𝕀 V = ½ m |v + ω × c|² + ½ ωᵀ Θ ω.
inline M6 spatial_inertia(const Inertial& b) {
  const M3 C = hat(b.com);
  M6 I;
  I.block<3, 3>(0, 0) = b.inertia - b.mass * C * C;
  I.block<3, 3>(0, 3) = b.mass * C;
  I.block<3, 3>(3, 0) = -b.mass * C;
  I.block<3, 3>(3, 3) = b.mass * M3::Identity();
  return I;
}

struct Pose {
  M3 R = M3::Identity();
  V3 p = V3::Zero();
  Pose operator*(const Pose& o) const { return {R * o.R, p + R * o.p}; }
};

inline M3 rodrigues(const V3& axis, Real angle) {
  const M3 K = hat(axis);
  return M3::Identity() + std::sin(angle) * K + (1 - std::cos(angle)) * K * K;
}

/// g_parent,child(q) = (rotation, offset) · exp(q S).
inline Pose joint_pose(const Body& b, Real q) {
  Pose e;
  if (b.prismatic)
    e.p = q * b.axis;
  else
    e.R = rodrigues(b.axis, q);
  return Pose{b.rotation, b.offset} * e;
}

/// Ad_{g⁻¹} for g = (R, p): twists of the parent frame into the child frame.
inline M6 Ad_inverse(const Pose& g) {
  M6 X = M6::Zero();
  const M3 Rt = g.R.transpose();
  X.block<3, 3>(0, 0) = Rt;
  X.block<3, 3>(3, 0) = -Rt * hat(g.p);
  X.block<3, 3>(3, 3) = Rt;
  return X;
}

inline M6 ad(const V6& V) {
  M6 a = M6::Zero();
  const M3 w = hat(V.head<3>());
  a.block<3, 3>(0, 0) = w;
  a.block<3, 3>(3, 0) = hat(V.tail<3>());
  a.block<3, 3>(3, 3) = w;
  return a;
}

inline V6 joint_screw(const Body& b) {
  V6 S = V6::Zero();
  if (b.prismatic)
    S.tail<3>() = b.axis;
  else
    S.head<3>() = b.axis;
  return S;
}

/// Poses of every body relative to the base frame.
inline std::vector<Pose> base_poses(const Tree& t, const VX& q) {
  std::vector<Pose> g(t.bodies.size());
  for (int i = 0; i < t.n(); ++i) {
    const Body& b = t.bodies[static_cast<std::size_t>(i)];
    const Pose gp = b.parent < 0 ? Pose{} : g[static_cast<std::size_t>(b.parent)];
    g[static_cast<std::size_t>(i)] = gp * joint_pose(b, q[i]);
  }
  return g;
}

/// A force `force` at the point `point` and a torque `torque` applied to body `body` (−1: the base), all resolved in
/// the body's frame.
struct Wrench {
  int body = -1;
  V3 point = V3::Zero(), force = V3::Zero(), torque = V3::Zero();
};

/// What acts on the bodies besides the joints: gravity (the gravitational acceleration resolved in the base's frame;
/// each body's weight m g, at its centre of mass, resolved in its own frame by its pose relative to the base) and
/// applied wrenches. Written as forces on the bodies, not as an acceleration of the base.
struct Loads {
  V3 gravity = V3::Zero();
  std::vector<Wrench> wrenches;
};

/// The wrench about body k's origin (its frame) of its weight and its applied wrenches (k = −1: the base).
inline V6 applied(const Tree& t, const Loads& loads, int k, const M3& R_base_body) {
  const Inertial& in = k < 0 ? t.base : t.bodies[static_cast<std::size_t>(k)].inertial;
  const V3 weight = in.mass * (R_base_body.transpose() * loads.gravity);
  V6 w;
  w << in.com.cross(weight), weight;
  for (const Wrench& a : loads.wrenches)
    if (a.body == k) {
      w.head<3>() += a.torque + a.point.cross(a.force);
      w.tail<3>() += a.force;
    }
  return w;
}

/// RNEA: (F_0, S_iᵀ F_i) for the base twist and acceleration nu0, a0 (6-D) and joint rates/accelerations, with the
/// weights and applied wrenches of `loads` taken off each body's Newton–Euler wrench.
inline VX rnea(const Tree& t, const VX& q, const V6& V0, const V6& A0, const VX& qd, const VX& qdd,
               const Loads& loads = {}) {
  const std::size_t n = t.bodies.size();
  std::vector<V6> V(n), A(n), F(n);
  std::vector<M6> X(n);
  std::vector<Pose> g(n);  // relative to the base
  for (std::size_t i = 0; i < n; ++i) {
    const Body& b = t.bodies[i];
    const Pose joint = joint_pose(b, q[static_cast<int>(i)]);
    g[i] = (b.parent < 0 ? Pose{} : g[static_cast<std::size_t>(b.parent)]) * joint;
    X[i] = Ad_inverse(joint);
    const V6 Vp = b.parent < 0 ? V0 : V[static_cast<std::size_t>(b.parent)];
    const V6 Ap = b.parent < 0 ? A0 : A[static_cast<std::size_t>(b.parent)];
    const V6 S = joint_screw(b);
    V[i] = X[i] * Vp + S * qd[static_cast<int>(i)];
    A[i] = X[i] * Ap + S * qdd[static_cast<int>(i)] + ad(V[i]) * S * qd[static_cast<int>(i)];
    const M6 I = spatial_inertia(b.inertial);
    F[i] = I * A[i] - ad(V[i]).transpose() * (I * V[i]) - applied(t, loads, static_cast<int>(i), g[i].R);
  }
  const M6 I0 = spatial_inertia(t.base);
  V6 F0 = I0 * A0 - ad(V0).transpose() * (I0 * V0) - applied(t, loads, -1, M3::Identity());
  VX out(6 + static_cast<int>(n));
  for (std::size_t k = n; k-- > 0;) {
    const Body& b = t.bodies[k];
    out[6 + static_cast<int>(k)] = joint_screw(b).dot(F[k]);
    const V6 Fp = X[k].transpose() * F[k];
    if (b.parent < 0)
      F0 += Fp;
    else
      F[static_cast<std::size_t>(b.parent)] += Fp;
  }
  out.head<6>() = F0;
  return out;
}

/// blockdiag(B, I_n): reduced velocities (ξ, q̇) to (V_0, q̇).
inline MX reduced_basis(const Tree& t) {
  const MX B = basis(t.group);
  MX P = MX::Zero(6 + t.n(), B.cols() + t.n());
  P.topLeftCorner(6, B.cols()) = B;
  P.bottomRightCorner(t.n(), t.n()).setIdentity();
  return P;
}

/// Mass matrix in (ξ, q̇) from RNEA with unit accelerations at zero velocity.
inline MX mass_matrix(const Tree& t, const VX& q) {
  const MX P = reduced_basis(t);
  const int N = 6 + t.n();
  MX H(N, N);
  const VX zero = VX::Zero(t.n());
  for (int k = 0; k < N; ++k) {
    VX e = VX::Zero(N);
    e[k] = 1;
    H.col(k) = rnea(t, q, V6::Zero(), e.head<6>(), zero, e.tail(t.n()));
  }
  return P.transpose() * H * P;
}

/// (ξ̇, q̈) for the state (q, ξ, q̇), joint forces Q and `loads` (free base: no wrench on it but its loads).
inline VX accelerations(const Tree& t, const VX& q, const VX& xi, const VX& qd, const VX& Q, const Loads& loads = {}) {
  const MX P = reduced_basis(t);
  const MX B = basis(t.group);
  const V6 V0 = B * xi;
  const VX bias = P.transpose() * rnea(t, q, V0, V6::Zero(), qd, VX::Zero(t.n()), loads);
  VX rhs = -bias;
  rhs.tail(t.n()) += Q;
  const MX H = mass_matrix(t, q);
  return H.ldlt().solve(rhs);
}

/// q̈ of a tree whose base is the world (fixed: no motion), under joint forces Q and `loads` (gravity resolved in the
/// world = base frame): the joint rows of RNEA, M from unit joint accelerations.
inline VX fixed_base_accelerations(const Tree& t, const VX& q, const VX& qd, const VX& Q, const Loads& loads = {}) {
  const int n = t.n();
  MX H(n, n);
  const VX zero = VX::Zero(n);
  for (int k = 0; k < n; ++k) {
    VX e = VX::Zero(n);
    e[k] = 1;
    H.col(k) = rnea(t, q, V6::Zero(), V6::Zero(), zero, e).tail(n);
  }
  const VX rhs = Q - rnea(t, q, V6::Zero(), V6::Zero(), qd, zero, loads).tail(n);
  return H.ldlt().solve(rhs);
}

/// Body twists V_i for the state.
inline std::vector<V6> twists(const Tree& t, const VX& q, const V6& V0, const VX& qd) {
  std::vector<V6> V(t.bodies.size());
  for (std::size_t i = 0; i < t.bodies.size(); ++i) {
    const Body& b = t.bodies[i];
    const V6 Vp = b.parent < 0 ? V0 : V[static_cast<std::size_t>(b.parent)];
    V[i] = Ad_inverse(joint_pose(b, q[static_cast<int>(i)])) * Vp + joint_screw(b) * qd[static_cast<int>(i)];
  }
  return V;
}

inline Real kinetic_energy(const Tree& t, const VX& q, const VX& xi, const VX& qd) {
  const V6 V0 = basis(t.group) * xi;
  Real T = V0.dot(spatial_inertia(t.base) * V0) / 2;
  const std::vector<V6> V = twists(t, q, V0, qd);
  for (std::size_t i = 0; i < V.size(); ++i) T += V[i].dot(spatial_inertia(t.bodies[i].inertial) * V[i]) / 2;
  return T;
}

/// ∂T/∂V_0: the spatial momentum of the whole tree in the base frame, about its origin (angular, linear).
inline V6 body_momentum(const Tree& t, const VX& q, const VX& xi, const VX& qd) {
  const V6 V0 = basis(t.group) * xi;
  V6 h = spatial_inertia(t.base) * V0;
  const std::vector<V6> V = twists(t, q, V0, qd);
  const std::vector<Pose> g = base_poses(t, q);
  for (std::size_t i = 0; i < V.size(); ++i)
    h += Ad_inverse(g[i]).transpose() * (spatial_inertia(t.bodies[i].inertial) * V[i]);
  return h;
}

inline Real total_mass(const Tree& t) {
  Real m = t.base.mass;
  for (const Body& b : t.bodies) m += b.inertial.mass;
  return m;
}

/// Centre of mass of the whole tree in the base frame.
inline V3 centre_of_mass(const Tree& t, const VX& q) {
  V3 s = t.base.mass * t.base.com;
  const std::vector<Pose> g = base_poses(t, q);
  for (std::size_t i = 0; i < g.size(); ++i)
    s += t.bodies[i].inertial.mass * (g[i].p + g[i].R * t.bodies[i].inertial.com);
  return s / total_mass(t);
}

// ---------------------------------------------------------------------------------------------------
// Random trees and their model text.

/// A decimal with 6 places: the text goes to the file, the value (parsed from the same text) to the reference.
inline Real decimal(std::mt19937_64& rng, Real lo, Real hi, std::string* text = nullptr) {
  std::uniform_real_distribution<double> u(static_cast<double>(lo), static_cast<double>(hi));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", u(rng));
  if (text) *text = buf;
  return std::strtold(buf, nullptr);
}

inline std::string number_text(Real v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6Lf", v);
  return buf;
}

/// A rotation with rational entries from an integer quaternion (a, b, c, d): exactly orthogonal.
struct RationalRotation {
  long num[3][3];
  long den;
  M3 value() const {
    M3 R;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R(i, j) = static_cast<Real>(num[i][j]) / static_cast<Real>(den);
    return R;
  }
  std::string text() const {
    std::ostringstream s;
    s << "[";
    for (int i = 0; i < 3; ++i) {
      s << (i ? ", [" : "[");
      for (int j = 0; j < 3; ++j) s << (j ? ", " : "") << num[i][j] << "/" << den;
      s << "]";
    }
    s << "]";
    return s.str();
  }
  std::string column_text(int j) const {
    std::ostringstream s;
    s << "[" << num[0][j] << "/" << den << ", " << num[1][j] << "/" << den << ", " << num[2][j] << "/" << den << "]";
    return s.str();
  }
};

inline RationalRotation rational_rotation(long a, long b, long c, long d) {
  RationalRotation r;
  r.den = a * a + b * b + c * c + d * d;
  const long m[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                        {2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b)},
                        {2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.num[i][j] = m[i][j];
  return r;
}

inline RationalRotation random_rotation(std::mt19937_64& rng, bool about_z_only) {
  std::uniform_int_distribution<long> u(-5, 5);
  long a, b, c, d;
  do {
    a = u(rng);
    b = about_z_only ? 0 : u(rng);
    c = about_z_only ? 0 : u(rng);
    d = u(rng);
  } while (a * a + b * b + c * c + d * d == 0);
  return rational_rotation(a, b, c, d);
}

/// Principal moments λ = (b + c, a + c, a + b) of point masses' second moments a, b, c > 0 (so the triangle
/// inequality holds), turned by a random rotation.
inline M3 random_inertia(std::mt19937_64& rng, Real scale, bool planar_principal) {
  const Real a = decimal(rng, 0.05, 1) * scale, b = decimal(rng, 0.05, 1) * scale, c = decimal(rng, 0.05, 1) * scale;
  const V3 lambda(b + c, a + c, a + b);
  const M3 Q = random_rotation(rng, planar_principal).value();
  M3 I = Q * lambda.asDiagonal() * Q.transpose();
  // Round to the 6 decimals the file carries (symmetric by construction).
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) I(i, j) = I(j, i) = std::strtold(number_text(I(i, j)).c_str(), nullptr);
  return I;
}

struct RandomSettings {
  std::string group = "SE3";
  int n = 3;
  bool rotations = true;  ///< give `rotation` on about half of the joints
  bool prismatic = true;  ///< about a third of the joints prismatic
  bool chain = false;     ///< a serial chain (parent of body k is body k−1) instead of random parents
};

/// A random tree: parent of body k uniform among the base and bodies 0..k−1 (or k−1 for a chain).
inline Tree random_tree(std::mt19937_64& rng, const RandomSettings& s) {
  const bool planar = s.group == "SE2";
  Tree t;
  t.group = s.group;
  t.base.mass = decimal(rng, 5, 20, &t.base.mass_text);
  for (int k = 0; k < 3; ++k) t.base.com[k] = decimal(rng, -0.3, 0.3);
  t.base.inertia = random_inertia(rng, 3, false);
  std::uniform_real_distribution<double> coin(0, 1);
  for (int i = 0; i < s.n; ++i) {
    Body b;
    std::uniform_int_distribution<int> parent(-1, i - 1);
    b.parent = s.chain ? i - 1 : parent(rng);
    b.prismatic = s.prismatic && coin(rng) < 0.35;
    // Axis: a column of a random rational rotation (exactly unit). Planar: z for revolute, in-plane for
    // prismatic joints.
    const RationalRotation ra = random_rotation(rng, planar);
    const int column = planar ? (b.prismatic ? 0 : 2) : 2;
    b.axis = ra.value().col(column);
    b.axis_text = ra.column_text(column);
    if (planar && !b.prismatic && coin(rng) < 0.5) {  // −z now and then
      b.axis = -b.axis;
      b.axis_text = "[0, 0, -1]";
    }
    for (int k = 0; k < 3; ++k) b.offset[k] = decimal(rng, -0.8, 0.8);
    if (s.rotations && coin(rng) < 0.5) {
      const RationalRotation rr = random_rotation(rng, planar);
      b.rotation = rr.value();
      b.rotation_text = rr.text();
      b.has_rotation = true;
    }
    b.inertial.mass = decimal(rng, 0.5, 4, &b.inertial.mass_text);
    for (int k = 0; k < 3; ++k) b.inertial.com[k] = decimal(rng, -0.4, 0.4);
    b.inertial.inertia = random_inertia(rng, 0.2, false);
    t.bodies.push_back(b);
  }
  return t;
}

inline std::string vector_text(const V3& v) {
  return "[" + number_text(v[0]) + ", " + number_text(v[1]) + ", " + number_text(v[2]) + "]";
}

inline std::string matrix_text(const M3& m) {
  std::string s = "[";
  for (int i = 0; i < 3; ++i) s += (i ? ", " : "") + vector_text(m.row(i).transpose());
  return s + "]";
}

/// Extra top-level text (forces, inputs, potential, parameters) goes verbatim after the tree. When
/// `mass_parameters` is set, the masses are parameters m0 (base), m1..mn with the reference's values.
inline std::string yaml(const Tree& t, const std::string& name, const std::string& extra = "",
                        bool mass_parameters = false) {
  std::ostringstream s;
  auto mass = [&](const Inertial& in, int k) {
    if (mass_parameters) return "m" + std::to_string(k);
    return in.mass_text.empty() ? number_text(in.mass) : in.mass_text;
  };
  s << "schema: 1\nname: " << name << "\n";
  s << "description: random kinematic tree written by tests/tree/tree_reference.hpp\n";
  if (mass_parameters) {
    s << "parameters:\n";
    s << "  m0: " << number_text(t.base.mass) << "\n";
    for (int i = 0; i < t.n(); ++i)
      s << "  m" << i + 1 << ": " << number_text(t.bodies[static_cast<std::size_t>(i)].inertial.mass) << "\n";
  }
  s << "group: " << t.group << "\ntrivialization: left\ngroup_velocity: [";
  const auto names = group_velocity_names(t.group);
  for (std::size_t k = 0; k < names.size(); ++k) s << (k ? ", " : "") << names[k];
  s << "]\nconnection: mechanical\ntree:\n  base:\n    name: base\n";
  s << "    mass: " << mass(t.base, 0) << "\n    com: " << vector_text(t.base.com)
    << "\n    inertia: " << matrix_text(t.base.inertia) << "\n  bodies:\n";
  for (int i = 0; i < t.n(); ++i) {
    const Body& b = t.bodies[static_cast<std::size_t>(i)];
    s << "    - name: b" << i + 1
      << "\n      parent: " << (b.parent < 0 ? std::string("base") : "b" + std::to_string(b.parent + 1))
      << "\n      joint:\n        name: q" << i + 1 << "\n        type: " << (b.prismatic ? "prismatic" : "revolute")
      << "\n        axis: " << (b.axis_text.empty() ? vector_text(b.axis) : b.axis_text)
      << "\n        offset: " << vector_text(b.offset) << "\n";
    if (b.has_rotation)
      s << "        rotation: " << (b.rotation_text.empty() ? matrix_text(b.rotation) : b.rotation_text) << "\n";
    s << "      mass: " << mass(b.inertial, i + 1) << "\n      com: " << vector_text(b.inertial.com)
      << "\n      inertia: " << matrix_text(b.inertial.inertia) << "\n";
  }
  s << extra;
  return s.str();
}

}  // namespace tree_ref
