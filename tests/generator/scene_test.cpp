// Scenes: the kernels a scene keeps are the only ones emitted (a reconstruction-only scene has no mass
// matrix or dynamics in its files), pruned kernels give the same numbers as the full set, scene defaults
// drive `simulate`, and scene errors name file:line and key.
#include "scene/scene.hpp"
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace {

namespace fs = std::filesystem;

using hamel::test::source_dir;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hamel_scene_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

TEST(Scene, ReconstructionOnlyEmitsNoMassMatrixOrDynamics) {
  const fs::path out = scratch("reconstruction");
  const std::string cmd = std::string(HAMEL_BINARY) + " emit " + source_dir() +
                          "/scenes/satellite_reconstruction.yaml -o " + out.string() + " 2> /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string header = slurp(out / "satellite_reconstruction.hpp");
  const std::string source = slurp(out / "satellite_reconstruction.cpp");
  EXPECT_NE(header.find("void group_velocity("), std::string::npos);
  for (const char* absent : {"void mass_matrix(", "void forcing(", "void rhs(", "void jacobian(", "void energy("}) {
    EXPECT_EQ(header.find(absent), std::string::npos) << absent;
    EXPECT_EQ(source.find(absent), std::string::npos) << absent;
  }
  EXPECT_NE(header.find("// Scene satellite_reconstruction on satellite_se3"), std::string::npos);
}

TEST(Scene, PrunedKernelsAgreeWithTheFullSet) {
  const hamel::Scene scene = hamel::load_scene(source_dir() + "/scenes/satellite_dynamics.yaml");
  const hamel::Model loaded = hamel::load_model(scene.model_path);
  std::map<std::string, double> all;
  std::vector<double> p;
  for (const auto& q : loaded.parameters) all[q.symbol.get_name()] = q.default_value, p.push_back(q.default_value);
  const hamel::Model model = hamel::fold_parameters(loaded, all);
  const hamel::Derivation d = hamel::derive(model, hamel::DeriveSettings{scene.form});
  const hamel::KernelSet full = hamel::build_kernels(model, d);
  const hamel::KernelSet pruned = hamel::build_kernels(model, d, hamel::scene_kernels(scene));
  EXPECT_LT(pruned.kernels.size(), full.kernels.size());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const hamel::Kernel& k : pruned.kernels) {
    hamel::GraphEvaluator a(pruned.graph, k.outputs), b(full.graph, full.get(k.name).outputs);
    const std::size_t n = full.get("rhs").outputs.size();
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> x(n), ya(k.outputs.size()), yb(k.outputs.size());
      for (double& v : x) v = u(rng);
      a.evaluate(0.0, x.data(), p.data(), nullptr, ya.data());
      b.evaluate(0.0, x.data(), p.data(), nullptr, yb.data());
      for (std::size_t i = 0; i < ya.size(); ++i) EXPECT_NEAR(ya[i], yb[i], 1e-12 * (1 + std::fabs(yb[i]))) << k.name;
    }
  }
}

TEST(Scene, SimulateTakesHorizonIntegratorAndInitialStateFromTheScene) {
  const fs::path out = scratch("simulate.csv");
  const std::string cmd = std::string(HAMEL_BINARY) + " simulate " + source_dir() +
                          "/scenes/satellite_dynamics.yaml --out " + out.string() + " 2> /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  std::string header, line, last;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_NE(header.find("R00"), std::string::npos);  // rkmk4 reconstructs the pose
  EXPECT_NE(line.find(",10,"), std::string::npos);   // phi1_dot = 10 from `initial`
  while (std::getline(in, line)) last = line;
  EXPECT_EQ(last.substr(0, last.find(',')), "10");  // t_end = 10
}

TEST(Scene, ErrorsNameFileLineAndKey) {
  const fs::path dir = scratch("bad");
  fs::create_directories(dir);
  const fs::path bad = dir / "bad_scene.yaml";
  std::ofstream(bad) << "scene: s\nmodel: " << source_dir() << "/models/double_pendulum.yaml\ncompute: [dynamics, "
                     << "teleport]\n";
  const fs::path err = dir / "err.txt";
  const std::string cmd =
      std::string(HAMEL_BINARY) + " emit " + bad.string() + " -o " + (dir / "out").string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  const std::string message = slurp(err);
  EXPECT_NE(message.find("bad_scene.yaml:3:"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown task 'teleport'"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
