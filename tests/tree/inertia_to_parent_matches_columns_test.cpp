// rbd::inertia_to_parent (the articulated-body algorithm's X 𝕀 Xᵀ by 3×3 blocks, rbd/spatial.hpp)
// against the same congruence formed column by column from the twist and wrench maps it must agree with,
// Link::to_child and Link::to_parent: column k of X 𝕀 Xᵀ is to_parent(𝕀 to_child(e_k)). Random rotations
// (general, and about each coordinate axis, where the blocks drop R's zeros or, with Link::about set, turn by the
// double angle), random offsets and random symmetric 𝕀, in exact rational arithmetic: the two must be equal, not
// close.
#include "algebra/intermediates.hpp"
#include "rbd/spatial.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace {

using namespace hamel::rbd;
using Mat3 = Mat3<GiNaC::ex>;
using Mat6 = Mat6<GiNaC::ex>;
using Vec6 = Vec6<GiNaC::ex>;
using GiNaC::ex;
using GiNaC::numeric;

// A rotation with rational entries (Cayley transform of a rational skew matrix): exact, orthonormal.
Mat3 cayley(const numeric& a, const numeric& b, const numeric& c) {
  const numeric n = 1 + a * a + b * b + c * c;
  return {{{(1 + a * a - b * b - c * c) / n, 2 * (a * b - c) / n, 2 * (a * c + b) / n},
           {2 * (a * b + c) / n, (1 - a * a + b * b - c * c) / n, 2 * (b * c - a) / n},
           {2 * (a * c - b) / n, 2 * (b * c + a) / n, (1 - a * a - b * b + c * c) / n}}};
}

TEST(InertiaToParent, EqualsTheCongruenceFormedColumnByColumn) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> small(-9, 9);
  const auto r = [&] { return numeric(small(rng), 7); };
  for (int trial = 0; trial < 12; ++trial) {
    Link<ex> l;
    const int axis = trial % 4;  // 0..2: about that coordinate axis, 3: general
    const numeric t = r();
    l.R = cayley(axis == 0 || axis == 3 ? t : numeric(0), axis == 1 || axis == 3 ? r() : numeric(0),
                 axis == 2 || axis == 3 ? r() : numeric(0));
    l.p = {r(), r(), r()};
    Mat6 I;
    for (std::size_t a = 0; a < 6; ++a)
      for (std::size_t b = a; b < 6; ++b) I[a][b] = I[b][a] = r();
    // About a coordinate axis: by R's entries, then by the double angle (Link::about).
    for (const int about : axis < 3 ? std::vector<int>{-1, axis} : std::vector<int>{-1}) {
      l.about = about;
      hamel::Intermediates tape;
      const Namer<ex> name([&tape](const ex& e) { return tape.define(e); });
      const Mat6 blocks = inertia_to_parent(l, I, name);
      for (int k = 0; k < 6; ++k) {
        const Vec6 column = l.to_parent(times(I, l.to_child(unit6<ex>(k))));
        for (std::size_t row = 0; row < 6; ++row) {
          const ex difference = tape.inline_all(blocks[row][static_cast<std::size_t>(k)]) - column[row];
          EXPECT_TRUE(difference.expand().is_zero())
              << "trial " << trial << " about " << about << " entry (" << row << ", " << k << ")";
        }
      }
    }
  }
}

// The double angle where it matters: a rotation by a symbol θ about each coordinate axis (cos θ and sin θ named, as
// rbd::joint_pose has them), where only cos² θ + sin² θ = 1 makes the turned blocks equal the congruence.
TEST(InertiaToParent, TurnsByTheDoubleAngleAboutACoordinateAxis) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> small(-9, 9);
  const auto r = [&] { return numeric(small(rng), 7); };
  const GiNaC::realsymbol c("c"), s("s");
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t k = static_cast<std::size_t>(axis), i = (k + 1) % 3, j = (k + 2) % 3;
    Link<ex> l;
    l.R = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
    l.R[k][k] = 1;
    l.R[i][i] = l.R[j][j] = c;
    l.R[j][i] = s;
    l.R[i][j] = -s;
    l.p = {r(), r(), r()};
    l.about = axis;
    Mat6 I;
    for (std::size_t a = 0; a < 6; ++a)
      for (std::size_t b = a; b < 6; ++b) I[a][b] = I[b][a] = r();
    hamel::Intermediates tape;
    const Namer<ex> name([&tape](const ex& e) { return tape.define(e); });
    const Mat6 blocks = inertia_to_parent(l, I, name);
    for (int col = 0; col < 6; ++col) {
      const Vec6 column = l.to_parent(times(I, l.to_child(unit6<ex>(col))));
      for (std::size_t row = 0; row < 6; ++row) {
        const ex difference = (tape.inline_all(blocks[row][static_cast<std::size_t>(col)]) - column[row]).expand();
        EXPECT_TRUE(difference.subs(GiNaC::pow(s, 2) == 1 - GiNaC::pow(c, 2)).expand().is_zero())
            << "axis " << axis << " entry (" << row << ", " << col << ")";
      }
    }
  }
}

}  // namespace
