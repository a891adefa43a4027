#include "compiled_models.hpp"

#include "chaplygin_sleigh.hpp"
#include "double_pendulum.hpp"
#include "free_rigid_body.hpp"
#include "planar_swimmer.hpp"
#include "rolling_ball.hpp"
#include "rolling_ball_bundle.hpp"
#include "rolling_disk.hpp"
#include "satellite_se3.hpp"
#include "satellite_so3xr3.hpp"
#include "space_robot.hpp"

#include <cstdlib>
#include <stdexcept>

namespace hamel::test {

#define HAMEL_ENTRY(NS, RESIDUAL)                                                                                 \
  CompiledModel {                                                                                                 \
#NS, "models/" #NS ".yaml", NS::n_coordinates, NS::n_independent, NS::n_parameters, NS::n_inputs,             \
        NS::n_constraints, NS::n_hamel, NS::default_parameters, NS::kinematics, NS::mass_matrix, NS::forcing,     \
        NS::hamel_coefficients, NS::rhs, NS::energy, RESIDUAL, "", 0, nullptr, nullptr, nullptr, NS::input_names, \
        NS::constraint_names                                                                                      \
  }

// Bundle models: their group velocity, connection (null without shape) and locked inertia kernels, and
// the --fold they were emitted with (tests/kernels/CMakeLists.txt).
#define HAMEL_BUNDLE_ENTRY(NS, RESIDUAL, FOLD, N_GROUP, CONNECTION)                                           \
  CompiledModel {                                                                                             \
#NS, "models/" #NS ".yaml", NS::n_coordinates, NS::n_independent, NS::n_parameters, NS::n_inputs,         \
        NS::n_constraints, NS::n_hamel, NS::default_parameters, NS::kinematics, NS::mass_matrix, NS::forcing, \
        NS::hamel_coefficients, NS::rhs, NS::energy, RESIDUAL, FOLD, N_GROUP, NS::group_velocity, CONNECTION, \
        NS::locked_inertia, NS::input_names, NS::constraint_names                                             \
  }

const std::vector<CompiledModel>& compiled_models() {
  static const std::vector<CompiledModel> models = {
      HAMEL_ENTRY(chaplygin_sleigh, chaplygin_sleigh::constraint_residual),
      HAMEL_ENTRY(rolling_disk, rolling_disk::constraint_residual),
      HAMEL_ENTRY(rolling_ball, rolling_ball::constraint_residual),
      HAMEL_ENTRY(double_pendulum, nullptr),
      HAMEL_BUNDLE_ENTRY(free_rigid_body, nullptr, "", 3, nullptr),
      HAMEL_BUNDLE_ENTRY(rolling_ball_bundle, nullptr, "", 3, rolling_ball_bundle::connection),
      HAMEL_BUNDLE_ENTRY(satellite_se3, nullptr, "all", 6, satellite_se3::connection),
      HAMEL_BUNDLE_ENTRY(satellite_so3xr3, nullptr, "all", 6, satellite_so3xr3::connection),
      // Kinematic trees (recursive ep form, intermediate symbols).
      HAMEL_BUNDLE_ENTRY(planar_swimmer, nullptr, "all", 3, planar_swimmer::connection),
      HAMEL_BUNDLE_ENTRY(space_robot, nullptr, "all", 6, space_robot::connection),
  };
  return models;
}

const CompiledModel& compiled_model(const std::string& name) {
  for (const CompiledModel& m : compiled_models())
    if (m.name == name) return m;
  throw std::invalid_argument("no compiled model " + name);
}

std::string source_path(const std::string& relative) {
  const char* root = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(root ? root : HAMEL_SOURCE_DIR_DEFAULT) + "/" + relative;
}

}  // namespace hamel::test
