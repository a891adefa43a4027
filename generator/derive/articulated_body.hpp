// The articulated-body algorithm (Featherstone, Rigid Body Dynamics Algorithms, 2008, §7.3 and Table 7.1) over
// a kinematic tree's body-frame recursion (derive/kinematic_tree.cpp): the accelerations u̇ of `--dynamics aba`
// as a program of named intermediates, O(n), M never formed. Spatial algebra in derive/spatial_algebra.hpp.
#pragma once

#include "derive/hamel_equations.hpp"
#include "derive/spatial_algebra.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace hamel {

// The body-frame recursion of derive_tree: parents, joint poses, axes and inertias in each body's frame,
// and the twists V_i and momenta h_i = 𝕀_i V_i.
struct BodyFrames {
  const std::vector<int>& parent;
  const std::vector<spatial::Link>& link;
  const std::vector<spatial::Vec6>& axis;
  const std::vector<spatial::Mat6>& inertia;
  const std::vector<spatial::Vec6>& V;
  const std::vector<spatial::Vec6>& h;
};

// The articulated-body algorithm (Featherstone, Rigid Body Dynamics Algorithms, Table 7.1) in the bodies'
// frames: u̇ without forming M, O(n). Bias accelerations c_i = ad_{V_i} S_i ṙ_i and bias wrenches
// p_i = −ad*_{V_i} 𝕀_i V_i as in derive_tree's f; the floating base is the root "joint" with the directions
// `base` (its acceleration S_0 ξ̇, no bias term: left trivialization). On a fixed base (m = 0) the root
// does not move; gravity enters as its upward acceleration a_0 = −g (as in f), carried outward in the last
// pass. A joint's armature adds to D_i, its springs and damper to τ_i (joint_force).
// `b` is the body-frame recursion at u̇ = 0; the accelerations and pivots go to eq.recursive_accelerations and
// eq.recursive_pivots.
void articulated_body(spatial::Namer& name, const BodyFrames& b, const std::vector<spatial::Vec6>& base,
                      const spatial::Vec6& root_acceleration, const std::vector<GiNaC::realsymbol>& rates,
                      const std::vector<GiNaC::ex>& joint_force, const std::vector<GiNaC::ex>& armature,
                      HamelEquations& eq);

}  // namespace hamel
