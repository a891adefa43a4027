// SPDX-License-Identifier: MIT
// The DOP853 coefficients, typed in from dop853.f, satisfy the Runge-Kutta
// order conditions: all 200 rooted-tree conditions up to order 8 for the
// solution, up to order 5 and 3 for the two embedded error estimators (and
// not beyond, else they would estimate nothing), and up to order 7 for the
// continuous extension at several points of the step. The conditions are
// checked to 1e-12, so a typo that moves a coefficient by about 1e-10 or more
// fails them (tried on coefficients of a, er, bhh and d while writing this);
// the last test shows one such case.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "hamel/runtime/dop853.hpp"

namespace {

namespace k = hamel::runtime::detail::dop853;
constexpr int S = k::kStages;
using Vec = std::array<double, S>;
using Matrix = std::array<Vec, S>;

// A rooted tree, stored by the indices of its subtrees in the list built by
// all_trees(), in nondecreasing order (which makes the representation unique).
struct Tree {
  int order = 1;
  double gamma = 1.0;  // gamma(t) = |t| * prod gamma(subtrees); the exact solution's weight is 1 / gamma
  std::vector<int> children;
};

// All rooted trees with at most max_order nodes, ordered by number of nodes.
std::vector<Tree> all_trees(int max_order) {
  std::vector<Tree> trees = {Tree{}};
  for (int order = 2; order <= max_order; ++order) {
    // Multisets of existing trees (smaller than `order`) whose orders sum to order - 1.
    const std::size_t known = trees.size();
    std::vector<int> picked;
    std::function<void(int, std::size_t)> choose = [&](int remaining, std::size_t from) {
      if (remaining == 0) {
        Tree t;
        t.order = order;
        t.gamma = order;
        for (int c : picked) t.gamma *= trees[static_cast<std::size_t>(c)].gamma;
        t.children = picked;
        trees.push_back(t);
        return;
      }
      for (std::size_t i = from; i < known; ++i) {
        if (trees[i].order <= remaining) {
          picked.push_back(static_cast<int>(i));
          choose(remaining - trees[i].order, i);
          picked.pop_back();
        }
      }
    };
    choose(order - 1, 0);
  }
  return trees;
}

// Stage weights Phi_i(t): 1 for the single node, and for t = [t1, ..., tm]
// the product over subtrees of sum_j a_ij Phi_j(t_k).
std::vector<Vec> stage_weights(const std::vector<Tree>& trees, const Matrix& a) {
  std::vector<Vec> phi(trees.size());
  for (std::size_t t = 0; t < trees.size(); ++t) {
    phi[t].fill(1.0);
    for (int child : trees[t].children) {
      for (int i = 0; i < S; ++i) {
        double s = 0.0;
        for (int j = 0; j < S; ++j)
          s += a[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] *
               phi[static_cast<std::size_t>(child)][static_cast<std::size_t>(j)];
        phi[t][static_cast<std::size_t>(i)] *= s;
      }
    }
  }
  return phi;
}

Matrix tableau() {
  Matrix a{};
  for (int i = 0; i < S; ++i)
    for (int j = 0; j < S; ++j) a[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = k::a[i][j];
  return a;
}

double dot(const Vec& w, const Vec& phi) {
  double s = 0.0;
  for (int i = 0; i < S; ++i) s += w[static_cast<std::size_t>(i)] * phi[static_cast<std::size_t>(i)];
  return s;
}

// Largest |sum_i w_i Phi_i(t) - scale^|t| / gamma(t)| over the trees of one order.
double worst_residual(const std::vector<Tree>& trees, const std::vector<Vec>& phi, const Vec& w, int order,
                      double scale = 1.0) {
  double worst = 0.0;
  for (std::size_t t = 0; t < trees.size(); ++t) {
    if (trees[t].order == order) {
      worst = std::fmax(worst, std::fabs(dot(w, phi[t]) - std::pow(scale, order) / trees[t].gamma));
    }
  }
  return worst;
}

// The weights are O(1..500) with alternating signs; sums of such terms in
// double precision are good to a few 1e-14, while the exact values 1/gamma go
// down to 1/40320. 1e-12 separates rounding from a wrong coefficient.
constexpr double kTolerance = 1e-12;

Vec weights_b() {
  Vec b{};
  for (int i = 0; i < k::kStepStages; ++i) b[static_cast<std::size_t>(i)] = k::b[i];
  return b;
}

TEST(RuntimeDop853Tableau, TreeEnumerationIsComplete) {
  // Number of rooted trees with n nodes (OEIS A000081): 1, 1, 2, 4, 9, 20, 48, 115.
  const std::vector<Tree> trees = all_trees(8);
  const int expected[] = {1, 1, 2, 4, 9, 20, 48, 115};
  for (int order = 1; order <= 8; ++order) {
    EXPECT_EQ(std::count_if(trees.begin(), trees.end(), [&](const Tree& t) { return t.order == order; }),
              expected[order - 1])
        << "order " << order;
  }
  // Spot checks of gamma: the tall tree of order 8 has 8!, the bushy one 8.
  double max_gamma = 0.0;
  double min_gamma = 1e300;
  for (const Tree& t : trees) {
    if (t.order == 8) {
      max_gamma = std::fmax(max_gamma, t.gamma);
      min_gamma = std::fmin(min_gamma, t.gamma);
    }
  }
  EXPECT_EQ(max_gamma, 40320.0);
  EXPECT_EQ(min_gamma, 8.0);
}

TEST(RuntimeDop853Tableau, NodesAreRowSumsAndTheMatrixIsExplicit) {
  for (int i = 0; i < S; ++i) {
    double row = 0.0;
    for (int j = 0; j < S; ++j) {
      if (j >= i) {
        EXPECT_EQ(k::a[i][j], 0.0) << "a[" << i << "][" << j << "] on or above the diagonal";
      }
      row += k::a[i][j];
    }
    EXPECT_NEAR(row, k::c[i], 1e-14) << "row " << i;
  }
  // Stage 12 is evaluated at t + h: it must be the FSAL stage.
  EXPECT_EQ(k::c[k::kStepStages], 1.0);
}

TEST(RuntimeDop853Tableau, SolutionWeightsHaveOrderEight) {
  const std::vector<Tree> trees = all_trees(8);
  const std::vector<Vec> phi = stage_weights(trees, tableau());
  const Vec b = weights_b();
  for (int order = 1; order <= 8; ++order) {
    const double r = worst_residual(trees, phi, b, order);
    std::printf("b: order %d worst residual %.2e\n", order, r);
    EXPECT_LT(r, kTolerance) << "order " << order;
  }
}

// b - er are the weights of the embedded fifth-order solution: order 5 exactly.
TEST(RuntimeDop853Tableau, FifthOrderEstimatorHasOrderFiveAndNoMore) {
  const std::vector<Tree> trees = all_trees(6);
  const std::vector<Vec> phi = stage_weights(trees, tableau());
  Vec w = weights_b();
  for (int i = 0; i < k::kStepStages; ++i) w[static_cast<std::size_t>(i)] -= k::er[i];
  for (int order = 1; order <= 5; ++order) {
    EXPECT_LT(worst_residual(trees, phi, w, order), kTolerance) << "order " << order;
  }
  const double r6 = worst_residual(trees, phi, w, 6);
  std::printf("fifth-order estimator: worst order-6 residual %.2e\n", r6);
  EXPECT_GT(r6, 1e-6);
}

// The third-order weights use stages 0, 8 and 11 only.
TEST(RuntimeDop853Tableau, ThirdOrderEstimatorHasOrderThreeAndNoMore) {
  const std::vector<Tree> trees = all_trees(4);
  const std::vector<Vec> phi = stage_weights(trees, tableau());
  Vec w{};
  w[0] = k::bhh0;
  w[8] = k::bhh8;
  w[11] = k::bhh11;
  for (int order = 1; order <= 3; ++order) {
    EXPECT_LT(worst_residual(trees, phi, w, order), kTolerance) << "order " << order;
  }
  const double r4 = worst_residual(trees, phi, w, 4);
  std::printf("third-order estimator: worst order-4 residual %.2e\n", r4);
  EXPECT_GT(r4, 1e-6);
}

// The dense output x + theta (r1 + (1-theta) (r2 + theta (r3 + (1-theta) (r4 +
// theta (r5 + (1-theta) (r6 + theta r7)))))) is linear in the stages: with
// r1 = h b.f, r2 = h (e0 - b).f, r3 = h (2b - e0 - e12).f and r4..r7 = h d.f it
// is x + h sum_i b_i(theta) f_i. Continuous order 7 means
// sum_i b_i(theta) Phi_i(t) = theta^|t| / gamma(t) for all trees up to order 7.
Vec dense_weights(double theta) {
  Vec b = weights_b();
  Vec r[8]{};
  for (int i = 0; i < S; ++i) {
    const auto u = static_cast<std::size_t>(i);
    r[1][u] = b[u];
    r[2][u] = (i == 0 ? 1.0 : 0.0) - b[u];
    r[3][u] = 2 * b[u] - (i == 0 ? 1.0 : 0.0) - (i == k::kStepStages ? 1.0 : 0.0);
    for (int m = 0; m < 4; ++m) r[4 + m][u] = k::d[m][i];
  }
  const double s = theta;
  const double s1 = 1.0 - theta;
  Vec w{};
  for (std::size_t u = 0; u < static_cast<std::size_t>(S); ++u) {
    const double tail = r[4][u] + s * (r[5][u] + s1 * (r[6][u] + s * r[7][u]));
    w[u] = s * (r[1][u] + s1 * (r[2][u] + s * (r[3][u] + s1 * tail)));
  }
  return w;
}

TEST(RuntimeDop853Tableau, ContinuousExtensionHasOrderSeven) {
  const std::vector<Tree> trees = all_trees(8);
  const std::vector<Vec> phi = stage_weights(trees, tableau());
  for (const double theta : {0.1, 0.37, 0.5, 0.81, 1.0}) {
    const Vec w = dense_weights(theta);
    for (int order = 1; order <= 7; ++order) {
      EXPECT_LT(worst_residual(trees, phi, w, order, theta), kTolerance) << "theta " << theta << " order " << order;
    }
    // Order 8 holds only at theta = 1, where the extension is the step itself.
    const double r8 = worst_residual(trees, phi, w, 8, theta);
    std::printf("dense output theta=%.2f: worst order-8 residual %.2e\n", theta, r8);
    if (theta == 1.0) {
      EXPECT_LT(r8, kTolerance);
    } else {
      EXPECT_GT(r8, 1e-9);
    }
  }
}

// The checks above have teeth: a relative change of 1e-11 (2.8e-10 absolute)
// in one coefficient of stage 8, with c kept consistent, is caught.
TEST(RuntimeDop853Tableau, APerturbedCoefficientIsDetected) {
  Matrix a = tableau();
  a[8][5] *= 1.0 + 1e-11;
  // Keep c consistent so that only the higher conditions can notice.
  a[8][0] -= k::a[8][5] * 1e-11;
  const std::vector<Tree> trees = all_trees(8);
  const std::vector<Vec> phi = stage_weights(trees, a);
  double worst = 0.0;
  for (int order = 1; order <= 8; ++order) worst = std::fmax(worst, worst_residual(trees, phi, weights_b(), order));
  std::printf("perturbed tableau: worst residual %.2e\n", worst);
  EXPECT_GT(worst, kTolerance);
}

}  // namespace
