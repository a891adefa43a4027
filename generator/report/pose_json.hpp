// A group element as JSON, as `hamel phase` and `hamel gait` print it: "R" (3x3, SO3/SE3/SO3xR3) and "p", or
// "theta", "x", "y" on SE2.
#pragma once

#include "numeric/group_pose.hpp"

#include <nlohmann/json.hpp>

namespace hamel {

inline nlohmann::json pose_json(const GroupPose& p) {
  nlohmann::json j = nlohmann::json::object();
  if (p.R) {
    const auto& R = *p.R;
    j["R"] = {{R[0], R[1], R[2]}, {R[3], R[4], R[5]}, {R[6], R[7], R[8]}};
  }
  if (p.theta) {
    j["theta"] = *p.theta;
    j["x"] = p.p.at(0);
    j["y"] = p.p.at(1);
  } else if (!p.p.empty()) {
    j["p"] = p.p;
  }
  return j;
}

}  // namespace hamel
