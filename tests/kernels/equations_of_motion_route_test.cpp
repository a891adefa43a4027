// The route by which rhs computes u̇ is chosen in one place (emit/equations_of_motion.hpp): by the derivation (a
// tree or not, a constant mass matrix), the tree's size and --dynamics, the same for every verb. These cases pin the
// decision and that the kernels and `derive` follow it; that each route gives the right accelerations is checked
// against independent references elsewhere (tests/tree: Newton–Euler, MuJoCo, the LDLᵀ against the recursion).
#include "derive/derivation.hpp"
#include "emit/equations_of_motion.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace {

using hamel::AccelerationRoute;

// A planar chain of `links` rods on revolute joints, hinged to the world.
std::string fixed_chain(int links) {
  std::string text = "schema: 1\nname: chain_" + std::to_string(links) +
                     "\nparameters:\n  g: 9.81\ntree:\n  base: world\n  gravity: [0, -g, 0]\n  bodies:\n";
  for (int i = 1; i <= links; ++i)
    text +=
        "    - name: link" + std::to_string(i) +
        "\n      parent: " + (i == 1 ? std::string("world") : "link" + std::to_string(i - 1)) +
        "\n      joint: {name: q" + std::to_string(i) + ", type: revolute, axis: [0, 0, 1], offset: [" +
        (i == 1 ? "0" : "0.5") +
        ", 0, 0]}\n      mass: 1\n      com: [0.25, 0, 0]\n      inertia: [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.02]]\n";
  return text;
}

AccelerationRoute route(const hamel::Model& model, const std::string& dynamics = "") {
  return hamel::acceleration_route(model, hamel::derive(model), dynamics);
}

std::string rhs_summary(const hamel::Model& model, const std::string& dynamics) {
  const hamel::Derivation d = hamel::derive(model);
  return hamel::build_kernels(model, d, {"rhs"}, {dynamics}).get("rhs").summary;
}

TEST(EquationsOfMotion, TreesTakeTheRecursionFromTheirDefaultSize) {
  // Fixed base: the articulated-body algorithm from 5 bodies (tree_dynamics_default).
  const hamel::Model four = hamel::load_model_from_text(fixed_chain(4), "chain_4.yaml");
  const hamel::Model five = hamel::load_model_from_text(fixed_chain(5), "chain_5.yaml");
  EXPECT_EQ(route(four), AccelerationRoute::ldlt);
  EXPECT_EQ(route(five), AccelerationRoute::articulated);
  EXPECT_EQ(route(four, "aba"), AccelerationRoute::articulated);
  EXPECT_EQ(route(five, "ldlt"), AccelerationRoute::ldlt);
  // The kernels follow the route.
  EXPECT_NE(rhs_summary(five, "").find("articulated-body algorithm"), std::string::npos);
  EXPECT_NE(rhs_summary(five, "ldlt").find("LDL^T"), std::string::npos);
  EXPECT_NE(rhs_summary(four, "").find("LDL^T"), std::string::npos);
}

TEST(EquationsOfMotion, AConstantMassMatrixIsInvertedAtGenerationTime) {
  const hamel::Model loaded = hamel::load_model(hamel::test::source("models/free_rigid_body.yaml"));
  EXPECT_EQ(route(loaded), AccelerationRoute::ldlt);  // M holds the symbolic inertias
  std::map<std::string, double> defaults;
  for (const auto& p : loaded.parameters) defaults[p.symbol.get_name()] = p.default_value;
  const hamel::Model folded = hamel::fold_parameters(loaded, defaults);
  EXPECT_EQ(route(folded), AccelerationRoute::constant_inverse);
  const hamel::Derivation d = hamel::derive(folded);
  const hamel::KernelSet k = hamel::build_kernels(folded, d, {"rhs"});
  EXPECT_NE(k.get("rhs").summary.find("inverted at generation time"), std::string::npos);
  EXPECT_TRUE(k.rhs_pivots.empty());  // nothing is factored at run time
}

TEST(EquationsOfMotion, AnOptionThatDoesNotApplyIsAnInputError) {
  const hamel::Model pendulum = hamel::load_model(hamel::test::source("models/double_pendulum.yaml"));
  const hamel::Model loop = hamel::load_model(hamel::test::source("models/four_bar_tree.yaml"));
  const auto message = [](const hamel::Model& model, const std::string& dynamics) -> std::string {
    try {
      route(model, dynamics);
    } catch (const hamel::InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(pendulum, "aba").find("not a tree"), std::string::npos);
  EXPECT_EQ(message(pendulum, "ldlt"), "");
  EXPECT_NE(message(loop, "ldlt").find("closed loops"), std::string::npos);
  EXPECT_NE(message(pendulum, "fast").find("expected aba or ldlt, got 'fast'"), std::string::npos);
}

// Every verb goes through the same choice: derive prints u̇ exactly when rhs computes it by the recursion, and refuses
// what emit refuses.
TEST(EquationsOfMotion, DeriveShowsTheRouteOfTheKernels) {
  const std::string hamel = HAMEL_BINARY;
  const std::string model = hamel::test::source("models/space_robot.yaml");
  const auto accelerations = [&](const std::string& options) {
    const hamel::test::Outcome o = hamel::test::run(hamel + " derive " + model + " --json " + options + " 2>/dev/null");
    EXPECT_EQ(o.status, 0) << o.out;
    const nlohmann::json j = nlohmann::json::parse(o.out);
    return j.contains("accelerations") ? j["accelerations"].size() : 0;
  };
  EXPECT_EQ(accelerations(""), 13u);  // 6 base directions, 7 joints
  EXPECT_EQ(accelerations("--dynamics ldlt"), 0u);
  const std::string pendulum = hamel::test::source("models/double_pendulum.yaml");
  for (const char* verb : {"derive", "emit -o /nonexistent/never"}) {
    const hamel::test::Outcome o =
        hamel::test::run(hamel + " " + verb + " " + pendulum + " --dynamics aba 2>&1 >/dev/null");
    EXPECT_EQ(o.status, 2) << verb;
    EXPECT_NE(o.out.find("--dynamics aba applies to kinematic tree models"), std::string::npos) << o.out;
  }
}

}  // namespace
