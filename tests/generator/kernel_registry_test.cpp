// One kernel registry (emit/kernel_registry.hpp) serves build_kernels, emit --kernels and scenes: every kernel
// build_kernels makes, for general-coordinate, bundle and tree models and for every kernel named on request,
// is registered and carries the registry's summary; every scene task names registered kernels; kernels the
// registry builds only on request are not built by default; names are unique.
#include "emit/kernel_registry.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "scene/scene.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>
#include <string>

namespace hamel {
namespace {

std::string source(const std::string& relative) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/" + relative;
}

void check_registered(const KernelSet& set, const std::set<std::string>& only) {
  std::vector<const Kernel*> all;
  for (const Kernel& k : set.kernels) all.push_back(&k);
  if (set.prepared)
    for (const Kernel& k : set.prepared->kernels) all.push_back(&k);
  for (const Kernel* k : all) {
    ASSERT_TRUE(is_kernel_name(k->name)) << k->name;
    const KernelSpec& spec = kernel_spec(k->name);
    EXPECT_EQ(k->summary.rfind(spec.summary, 0), 0u) << k->name << ": " << k->summary;
    if (only.empty()) {
      EXPECT_TRUE(spec.by_default) << k->name << " built without being named";
    }
  }
}

TEST(KernelRegistry, EveryBuiltKernelIsRegistered) {
  for (const char* file :
       {"models/double_pendulum.yaml", "models/satellite_se3.yaml", "models/rolling_ball_bundle.yaml",
        "models/space_robot.yaml", "models/chaplygin_sleigh.yaml", "models/four_bar.yaml"}) {
    SCOPED_TRACE(file);
    const Model model = load_model(source(file));
    const Derivation derivation = derive(model);
    check_registered(build_kernels(model, derivation), {});
    check_registered(build_kernels(model, derivation, {"rhs", "linearization", "rhs_prepared"}),
                     {"rhs", "linearization", "rhs_prepared"});
  }
  const Model sleigh = load_model(source("models/chaplygin_sleigh.yaml"));
  const KernelSet by = build_kernels(sleigh, derive(sleigh), {"input_jacobian", "parameter_jacobian"});
  ASSERT_EQ(by.kernels.size(), 2u);
  check_registered(by, {"input_jacobian", "parameter_jacobian"});
  const Model pendulum = load_model(source("models/double_pendulum.yaml"));
  const KernelSet riemann = build_kernels(pendulum, derive(pendulum), {"riemann_linearization"});
  ASSERT_EQ(riemann.kernels.size(), 1u);
  check_registered(riemann, {"riemann_linearization"});
}

TEST(KernelRegistry, OnRequestKernelsAreNotBuiltByDefault) {
  const Model model = load_model(source("models/double_pendulum.yaml"));
  const KernelSet set = build_kernels(model, derive(model));
  for (const Kernel& k : set.kernels) EXPECT_NE(k.name, "linearization");
  for (const Kernel& k : set.kernels) EXPECT_NE(k.name, "riemann_linearization");
  const Model sleigh = load_model(source("models/chaplygin_sleigh.yaml"));  // inputs and parameters
  for (const Kernel& k : build_kernels(sleigh, derive(sleigh)).kernels) {
    EXPECT_NE(k.name, "input_jacobian");
    EXPECT_NE(k.name, "parameter_jacobian");
  }
}

TEST(KernelRegistry, SceneTasksNameRegisteredKernelsAndNamesAreUnique) {
  for (const auto& [task, kernels] : scene_tasks())
    for (const std::string& k : kernels) EXPECT_TRUE(is_kernel_name(k)) << "task " << task << ": " << k;
  std::set<std::string> names;
  for (const KernelSpec& k : kernel_registry()) EXPECT_TRUE(names.insert(k.name).second) << k.name;
  EXPECT_THROW(kernel_spec("no_such_kernel"), std::logic_error);
  EXPECT_NE(kernel_names().find("riemann_linearization"), std::string::npos);
}

}  // namespace
}  // namespace hamel
