// The jacobian kernel (d(x')/dx, built symbolically for the implicit integrators) against central finite
// differences of the rhs kernel, for every shipped model at random states.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

namespace {

using hamel::test::source_dir;

TEST(JacobianKernel, MatchesCentralDifferencesOfTheRightHandSide) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-0.8, 0.8);
  int models = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source_dir() + "/models")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const hamel::Model loaded = hamel::load_model(entry.path().string());
    std::map<std::string, double> all;
    std::vector<double> p;
    for (const auto& q : loaded.parameters) all[q.symbol.get_name()] = q.default_value, p.push_back(q.default_value);
    const hamel::Model model = hamel::fold_parameters(loaded, all);
    const hamel::Derivation d = hamel::derive(model);
    const hamel::KernelSet k = hamel::build_kernels(model, d);
    hamel::GraphEvaluator rhs(k.graph, k.get("rhs").outputs), jac(k.graph, k.get("jacobian").outputs);
    const std::size_t n = k.get("rhs").outputs.size();
    ASSERT_EQ(k.get("jacobian").outputs.size(), n * n);
    std::vector<double> in(model.inputs.size(), 0.3);
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> x(n), J(n * n), fp(n), fm(n);
      for (double& v : x) v = uniform(rng);
      const double t = 0.1 * trial;
      jac.evaluate(t, x.data(), p.data(), in.data(), J.data());
      double scale = 1e-300, worst = 0;
      for (std::size_t c = 0; c < n; ++c) {
        const double h = 1e-5 * std::max(1.0, std::fabs(x[c]));
        std::vector<double> xp = x, xm = x;
        xp[c] += h;
        xm[c] -= h;
        rhs.evaluate(t, xp.data(), p.data(), in.data(), fp.data());
        rhs.evaluate(t, xm.data(), p.data(), in.data(), fm.data());
        for (std::size_t r = 0; r < n; ++r) {
          const double fd = (fp[r] - fm[r]) / (2 * h);
          scale = std::max(scale, std::fabs(fd));
          worst = std::max(worst, std::fabs(fd - J[r * n + c]));
        }
      }
      // Central differences are O(h²) ≈ 1e-10 relative here; a wrong entry is O(1).
      EXPECT_LT(worst / scale, 1e-7);
    }
    ++models;
  }
  EXPECT_GE(models, 8);
}

}  // namespace
