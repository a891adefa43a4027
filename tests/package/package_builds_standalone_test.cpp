// The generated package as firmware would use it: `hamel emit` writes chaplygin_sleigh and satellite_se3
// (--fold all) into a scratch folder; tests/package/standalone, a plain CMake project that only
// add_subdirectory's the two packages, builds them into one driver binary (two namespaces) with g++ and
// clang++, -fno-exceptions -fno-rtti -Wall -Wextra -Werror -pedantic, for float and double; the driver's
// 200 emitted rk4_step calls must match RK4 on the generator's own graph evaluation (GraphEvaluator with
// runtime::integrate_rk4). Also: emission is byte-identical, and the package needs nothing but <cmath>.
#include "package_support.hpp"
#include "standalone/cases.hpp"

#include "derive/derivation.hpp"
#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"

#include <hamel/runtime/rk4.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

namespace hamel::package_test {
namespace {

namespace c = hamel_package_cases;

// RK4 on the generator's evaluation of the rhs graph, in double, from x0 with the inputs held.
std::vector<double> reference(const std::string& model_file, bool fold_all, std::vector<double> x0,
                              std::vector<double> inputs) {
  Model model = load_model(source(model_file));
  std::vector<double> p;
  for (const auto& par : model.parameters) p.push_back(par.default_value);
  if (fold_all) {
    std::map<std::string, double> values;
    for (const auto& par : model.parameters) values[par.symbol.get_name()] = par.default_value;
    model = fold_parameters(model, values);
  }
  const Derivation derivation = derive(model);
  const KernelSet kernels = build_kernels(model, derivation);
  GraphEvaluator rhs(kernels.graph, kernels.get("rhs").outputs);
  auto f = [&](double t, const double* x, double* dx) { rhs.evaluate(t, x, p.data(), inputs.data(), dx); };
  const auto result =
      runtime::integrate_rk4(f, std::move(x0), 0.0, c::steps * c::h, c::h, 0.0, [](double, const double*) {});
  EXPECT_EQ(result.status, runtime::Status::ok);
  return result.x;
}

struct Reference {
  std::vector<double> sleigh, satellite;
};

const Reference& references() {
  static const Reference r{reference("models/chaplygin_sleigh.yaml", false,
                                     std::vector<double>(std::begin(c::sleigh_x0), std::end(c::sleigh_x0)),
                                     std::vector<double>(std::begin(c::sleigh_in), std::end(c::sleigh_in))),
                           reference("models/satellite_se3.yaml", true,
                                     std::vector<double>(std::begin(c::satellite_x0), std::end(c::satellite_x0)), {})};
  return r;
}

// Emits the two packages into `root` (chaplygin_sleigh/, satellite_se3/), with `flags` added.
void emit_packages(const fs::path& root, const std::string& flags = "") {
  const Outcome a = emit(source("models/chaplygin_sleigh.yaml"), flags, root / "chaplygin_sleigh");
  ASSERT_EQ(a.status, 0) << a.out;
  const Outcome b = emit(source("models/satellite_se3.yaml"), "--fold all " + flags, root / "satellite_se3");
  ASSERT_EQ(b.status, 0) << b.out;
}

// Compiler, scalar type and the flags of emit (--split 5 prints every kernel longer than five statements as
// functions of five, passing values in a stack array: the path the longest kernels of large models take).
class StandalonePackage : public ::testing::TestWithParam<std::tuple<std::string, std::string, std::string>> {};

TEST_P(StandalonePackage, BuildsWithStrictFlagsAndItsRk4StepMatchesTheGenerator) {
  const auto& [compiler, real, flags] = GetParam();
  const std::string cxx = compiler == "gcc" ? HAMEL_GXX : HAMEL_CLANGXX;
  if (cxx.empty()) GTEST_SKIP() << "no " << compiler << " C++ compiler found at configure time";
  Scratch dir(compiler + "_" + real + (flags.empty() ? "" : "_split"));
  emit_packages(dir.path() / "packages", flags);
  if (HasFatalFailure()) return;
  const Outcome built = cmake_build(source("tests/package/standalone"), dir.path() / "build", cxx, strict_flags,
                                    {{"PACKAGE_ROOT", (dir.path() / "packages").string()},
                                     {"HAMEL_CHAPLYGIN_SLEIGH_REAL", real},
                                     {"HAMEL_SATELLITE_SE3_REAL", real}});
  ASSERT_EQ(built.status, 0) << built.out;
  EXPECT_EQ(built.out.find("warning"), std::string::npos) << built.out;

  const Outcome ran = run(quote((dir.path() / "build" / "driver").string()));
  ASSERT_EQ(ran.status, 0) << ran.out;
  std::istringstream lines(ran.out);
  std::string key;
  std::map<std::string, std::vector<double>> state;
  int sizeof_a = 0, sizeof_b = 0, finite = 0;
  while (lines >> key) {
    if (key == "sizeof_real") {
      lines >> sizeof_a >> sizeof_b;
    } else if (key == "finite") {
      lines >> finite;
    } else if (key == "chaplygin_sleigh" || key == "satellite_se3") {
      int i = 0;
      double v = 0;
      lines >> i >> v;
      state[key].push_back(v);
    } else {
      std::string rest;
      std::getline(lines, rest);
    }
  }
  const int expected_size = real == "float" ? 4 : 8;
  EXPECT_EQ(sizeof_a, expected_size);
  EXPECT_EQ(sizeof_b, expected_size);
  EXPECT_EQ(finite, 1) << "a kernel of the table gave a non-finite output";

  // float: 200 steps in single precision; double: agreement to rounding.
  const double tolerance = real == "float" ? 2e-5 : 1e-12;
  const auto compare = [&](const std::string& model, const std::vector<double>& expected) {
    const std::vector<double>& got = state[model];
    ASSERT_EQ(got.size(), expected.size()) << model;
    double worst = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
      const double error = std::fabs(got[i] - expected[i]) / std::max(1.0, std::fabs(expected[i]));
      worst = std::max(worst, error);
      EXPECT_LE(error, tolerance) << model << " state " << i << ": " << got[i] << " vs " << expected[i];
    }
    std::printf("%s %s %s: worst relative difference to the generator %.3g\n", compiler.c_str(), real.c_str(),
                model.c_str(), worst);
  };
  compare("chaplygin_sleigh", references().sleigh);
  compare("satellite_se3", references().satellite);
}

std::string case_name(const ::testing::TestParamInfo<StandalonePackage::ParamType>& info) {
  return std::get<0>(info.param) + "_" + std::get<1>(info.param) + (std::get<2>(info.param).empty() ? "" : "_split");
}

INSTANTIATE_TEST_SUITE_P(CompilersAndScalars, StandalonePackage,
                         ::testing::Combine(::testing::Values("gcc", "clang"), ::testing::Values("float", "double"),
                                            ::testing::Values("")),
                         case_name);
INSTANTIATE_TEST_SUITE_P(SplitKernels, StandalonePackage,
                         ::testing::Values(StandalonePackage::ParamType{"gcc", "double", "--split 5"},
                                           StandalonePackage::ParamType{"clang", "float", "--split 5"}),
                         case_name);

TEST(EmittedPackage, ReEmissionIsByteIdentical) {
  Scratch a("identical_a"), b("identical_b");
  emit_packages(a.path());
  emit_packages(b.path());
  if (HasFatalFailure()) return;
  for (const char* model : {"chaplygin_sleigh", "satellite_se3"}) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(a.path() / model)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names,
              (std::vector<std::string>{".hamel-manifest", "CMakeLists.txt", "README.md", std::string(model) + ".cpp",
                                        std::string(model) + ".h", std::string(model) + ".hpp"}));
    for (const std::string& name : names) {
      const std::string x = slurp(a.path() / model / name);
      EXPECT_FALSE(x.empty()) << name;
      EXPECT_EQ(x, slurp(b.path() / model / name)) << model << "/" << name << " differs between two emissions";
    }
  }
}

TEST(EmittedPackage, IsSelfContainedAndMitLicensed) {
  Scratch dir("self_contained");
  emit_packages(dir.path());
  if (HasFatalFailure()) return;
  for (const char* model : {"chaplygin_sleigh", "satellite_se3"}) {
    for (const auto& e : fs::directory_iterator(dir.path() / model)) {
      const std::string text = slurp(e.path());
      EXPECT_NE(text.find("SPDX-License-Identifier: MIT"), std::string::npos) << e.path();
      // Source and headers (C++ and C) include only each other and <cmath>.
      std::istringstream lines(text);
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("#include", 0) == 0) {
          EXPECT_TRUE(line == "#include <cmath>" || line == "#include \"" + std::string(model) + ".hpp\"" ||
                      line == "#include \"" + std::string(model) + ".h\"")
              << e.path() << ": " << line;
        }
      }
      if (e.path().extension() != ".cpp" && e.path().extension() != ".hpp") continue;
      std::string code;  // without comments
      std::istringstream all(text);
      for (std::string line; std::getline(all, line);) {
        if (line.rfind("/*", 0) == 0) continue;
        code += line.substr(0, line.find("//")) + "\n";
      }
      for (const char* banned : {"new ", "malloc", "throw", "try", "typeid", "dynamic_cast", "std::vector", "static "})
        EXPECT_EQ(code.find(banned), std::string::npos) << e.path() << " uses " << banned;
    }
    const std::string header = slurp(dir.path() / model / (std::string(model) + ".hpp"));
    for (const char* abi :
         {"constexpr int n_state", "constexpr int n_parameters", "constexpr int n_inputs", "constexpr int n_out_rhs",
          "constexpr int n_out_max", "constexpr int n_temporaries_rhs", "constexpr int rk4_stack_reals",
          "kernel_table[n_kernels]", "void rk4_step(real t, real h, real* x, const real* p, const real* in);"})
      EXPECT_NE(header.find(abi), std::string::npos) << model << ": " << abi;
  }
}

}  // namespace
}  // namespace hamel::package_test
