#include "compiled_models.hpp"

#include "chaplygin_sleigh.hpp"
#include "double_pendulum.hpp"
#include "rolling_ball.hpp"
#include "rolling_disk.hpp"

#include <cstdlib>
#include <stdexcept>

namespace hamel::test {

#define HAMEL_ENTRY(NS, RESIDUAL)                                                                             \
  CompiledModel {                                                                                             \
#NS, "models/" #NS ".yaml", NS::n_coordinates, NS::n_independent, NS::n_parameters, NS::n_inputs,         \
        NS::n_constraints, NS::n_hamel, NS::default_parameters, NS::kinematics, NS::mass_matrix, NS::forcing, \
        NS::hamel_coefficients, NS::rhs, NS::energy, RESIDUAL                                                 \
  }

const std::vector<CompiledModel>& compiled_models() {
  static const std::vector<CompiledModel> models = {
      HAMEL_ENTRY(chaplygin_sleigh, chaplygin_sleigh::constraint_residual),
      HAMEL_ENTRY(rolling_disk, rolling_disk::constraint_residual),
      HAMEL_ENTRY(rolling_ball, rolling_ball::constraint_residual),
      HAMEL_ENTRY(double_pendulum, nullptr),
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
