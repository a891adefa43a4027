// Group elements of the runtime's Lie groups as plain poses (rotation, planar angle, translation), and the
// dispatch from a model's group name to the runtime's group type, shared by `phase` and `simulate`.
#pragma once

#include "model/input_error.hpp"

#include <hamel/runtime/lie/rn.hpp>
#include <hamel/runtime/lie/se2.hpp>
#include <hamel/runtime/lie/se3.hpp>
#include <hamel/runtime/lie/so3.hpp>
#include <hamel/runtime/lie/so3xr3.hpp>

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace hamel {

/// One group element at time t, in the representation the group suggests.
struct GroupPose {
  double t = 0;
  std::optional<std::array<double, 9>> R;  ///< rotation, row-major (SO3, SE3, SO3xR3)
  std::optional<double> theta;             ///< planar angle (SE2), not wrapped
  std::vector<double> p;                   ///< translation (SE3, SO3xR3: 3; SE2: x, y; Rk: k)
};

inline GroupPose pose_of(double t, const runtime::lie::Mat3& R) {
  GroupPose p;
  p.t = t;
  p.R = R;
  return p;
}
inline GroupPose pose_of(double t, const runtime::lie::SE3::Element& g) {
  GroupPose p = pose_of(t, g.R);
  p.p.assign(g.p.begin(), g.p.end());
  return p;
}
inline GroupPose pose_of(double t, const runtime::lie::SO3xR3::Element& g) {
  GroupPose p = pose_of(t, g.R);
  p.p.assign(g.p.begin(), g.p.end());
  return p;
}
inline GroupPose pose_of(double t, const runtime::lie::SE2::Element& g) {
  GroupPose p;
  p.t = t;
  p.theta = g.theta;
  p.p = {g.x, g.y};
  return p;
}
template <std::size_t K>
GroupPose pose_of(double t, const std::array<double, K>& g) {
  GroupPose p;
  p.t = t;
  p.p.assign(g.begin(), g.end());
  return p;
}

/// Column names of a pose: R00..R22, then theta, x, y (SE2) or px, py, pz / p1..pk.
inline std::vector<std::string> pose_columns(const GroupPose& pose) {
  std::vector<std::string> c;
  if (pose.R)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c.push_back("R" + std::to_string(i) + std::to_string(j));
  if (pose.theta) return {"theta", "x", "y"};
  for (std::size_t k = 0; k < pose.p.size(); ++k)
    c.push_back(pose.p.size() <= 3 ? std::string("p") + "xyz"[k] : "p" + std::to_string(k + 1));
  return c;
}

/// The pose's values in pose_columns order.
inline std::vector<double> pose_values(const GroupPose& pose) {
  std::vector<double> v;
  if (pose.R) v.assign(pose.R->begin(), pose.R->end());
  if (pose.theta) v.push_back(*pose.theta);
  v.insert(v.end(), pose.p.begin(), pose.p.end());
  return v;
}

/// The rotation vector w with exp(w) = R nearest to `previous`: the principal logarithm θn (θ ≤ π) moved
/// along its axis by a whole number of turns, (θ + 2πk) n (every logarithm of R is of this form).
inline std::array<double, 3> rotation_vector_near(const std::array<double, 9>& R,
                                                  const std::array<double, 3>& previous) {
  constexpr double two_pi = 6.283185307179586476925286766559;
  const runtime::lie::Vec3 w = runtime::lie::SO3::log(R);
  double theta = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  std::array<double, 3> n{};
  if (theta > 1e-12) {
    for (int i = 0; i < 3; ++i) n[static_cast<std::size_t>(i)] = w[static_cast<std::size_t>(i)] / theta;
  } else {  // R = I: any axis; whole turns about the previous one's
    const double r = std::sqrt(previous[0] * previous[0] + previous[1] * previous[1] + previous[2] * previous[2]);
    if (r == 0) return {w[0], w[1], w[2]};
    for (std::size_t i = 0; i < 3; ++i) n[i] = previous[i] / r;
  }
  const double along = previous[0] * n[0] + previous[1] * n[1] + previous[2] * n[2];
  theta += two_pi * std::round((along - theta) / two_pi);
  return {theta * n[0], theta * n[1], theta * n[2]};
}

/// The rotation vectors of a trajectory's rotations (poses with R), continuous from one sample to the next
/// (not wrapped at |w| = π), starting from the principal logarithm of the first.
inline std::vector<std::array<double, 3>> unwrapped_rotation_vectors(const std::vector<GroupPose>& poses) {
  std::vector<std::array<double, 3>> out;
  std::array<double, 3> previous{};
  for (const GroupPose& p : poses) {
    previous = rotation_vector_near(*p.R, previous);
    out.push_back(previous);
  }
  return out;
}

template <class G>
struct GroupTag {
  using type = G;
};

/// Calls f(GroupTag<G>{}) with the runtime group type of `group`; throws InputError for groups the
/// runtime has no reconstruction for.
template <class F>
auto with_group(const std::string& group, F&& f) {
  namespace lie = runtime::lie;
  if (group == "SO3") return f(GroupTag<lie::SO3>{});
  if (group == "SE3") return f(GroupTag<lie::SE3>{});
  if (group == "SO3xR3") return f(GroupTag<lie::SO3xR3>{});
  if (group == "SE2") return f(GroupTag<lie::SE2>{});
  if (group == "R1") return f(GroupTag<lie::Rn<1>>{});
  if (group == "R2") return f(GroupTag<lie::Rn<2>>{});
  if (group == "R3") return f(GroupTag<lie::Rn<3>>{});
  throw InputError("reconstruction on " + group +
                   " is not available; the runtime has SO3, SE3, SO3xR3, SE2 and R1..R3");
}

}  // namespace hamel
