// The phase of a kinematic tree (hamel phase on a `tree` model): the recursive ep derivation gives L and K
// as blocks of the mass matrix and the connection is solved numerically in the graph (L A = K, phase.cpp).
// Checked against the general bundle path on the same system: the tree's kinetic energy inlined into one
// expression (tree_kinetic_energy), the momentum form (HEMomCons), whose A = L⁻¹K is formed symbolically
// (bundle_connection.cpp). A free-floating SE(2) base with a two-link arm, a shifted loop of the joint
// angles (a centred loop has no net phase by symmetry), zero momentum and the base at rest.
#include "derive/derivation.hpp"
#include "derive/kinematic_tree.hpp"
#include "model/load_model.hpp"
#include "numeric/phase.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace {

const char* kModel = R"(name: two_link_swimmer
group: SE2
group_velocity: [w, vx, vy]
tree:
  base: {name: head, mass: 2, com: [0.05, 0.02, 0], inertia: [[0, 0, 0], [0, 0, 0], [0, 0, 0.05]]}
  bodies:
    - name: l1
      parent: head
      joint: {name: q1, type: revolute, axis: [0, 0, 1], offset: [0.3, 0.05, 0]}
      mass: 1.2
      com: [0.2, 0, 0]
      inertia: [[0, 0, 0], [0, 0, 0], [0, 0, 0.02]]
    - name: l2
      parent: l1
      joint: {name: q2, type: revolute, axis: [0, 0, 1], offset: [0.4, 0, 0]}
      mass: 0.8
      com: [0.15, 0.01, 0]
      inertia: [[0, 0, 0], [0, 0, 0], [0, 0, 0.01]]
)";

TEST(TreePhase, NumericConnectionMatchesSymbolicConnection) {
  const hamel::Model tree = hamel::load_model_from_text(kModel, "two_link_swimmer.yaml");
  const hamel::Model expanded = hamel::with_inlined_tree(tree);

  const hamel::Derivation recursive = hamel::derive(tree, hamel::DeriveSettings{"ep"});
  ASSERT_FALSE(recursive.bundle->connection_derived);
  const hamel::Derivation symbolic = hamel::derive(expanded, hamel::DeriveSettings{"momentum"});
  ASSERT_TRUE(symbolic.bundle->connection_derived);

  for (const hamel::PhaseMomentum momentum : {hamel::PhaseMomentum::zero, hamel::PhaseMomentum::rest}) {
    hamel::PhaseRequest req;
    req.path = {GiNaC::ex(0.6) + GiNaC::numeric(1, 2) * GiNaC::sin(2 * GiNaC::Pi * tree.time),
                GiNaC::numeric(7, 10) * GiNaC::cos(2 * GiNaC::Pi * tree.time)};
    req.cycles = 3;
    req.momentum = momentum;
    const hamel::PhaseResult a = hamel::compute_phase(tree, recursive, {}, req);
    // The expanded model has its own symbol for t: the path is the same expression in it.
    req.path = {req.path[0].subs(GiNaC::lst{tree.time}, GiNaC::lst{expanded.time}),
                req.path[1].subs(GiNaC::lst{tree.time}, GiNaC::lst{expanded.time})};
    const hamel::PhaseResult b = hamel::compute_phase(expanded, symbolic, {}, req);
    ASSERT_EQ(a.cycles.size(), 3u);
    ASSERT_EQ(b.cycles.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(*a.cycles[k].theta, *b.cycles[k].theta, 1e-13) << "cycle " << k;
      EXPECT_NEAR(a.cycles[k].p[0], b.cycles[k].p[0], 1e-13) << "cycle " << k;
      EXPECT_NEAR(a.cycles[k].p[1], b.cycles[k].p[1], 1e-13) << "cycle " << k;
    }
    // A genuine phase; with zero momentum the rotation of SE(2) adds up cycle by cycle.
    EXPECT_GT(std::abs(*a.cycles[0].theta), 1e-3);
    if (momentum == hamel::PhaseMomentum::zero) {
      EXPECT_NEAR(*a.cycles[2].theta, 3 * *a.cycles[0].theta, 1e-9);
    }
  }
}

}  // namespace
