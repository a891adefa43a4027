// A kinematic tree as the rigid-body algorithms of rbd/ see it, split as Pinocchio splits ModelTpl and DataTpl:
// TreeModel holds the structure and what is fixed for an evaluation of the recursions (joint placements at the
// configuration, axes, inertias, the base's directions, gravity, applied wrenches), and each algorithm returns its
// own data (twists, wrenches, composite or articulated inertias), every value a named intermediate of the
// derivation's program.
//
// Body 0 is the base: floating (it moves in the directions `base` of se(3), the group's velocity ξ) or fixed to the
// world (no directions). Body i ≥ 1 hangs on parent[i] < i by a one-degree-of-freedom joint with coordinate r^{i−1}.
//
// Two frame conventions (Pinocchio's LOCAL and WORLD): every quantity of body i in its own frame, passed between
// parent and child by the joint's pose (Frame::local: the body-frame recursions of rhs and energy), or every
// quantity in one common frame, the base's frame at the current instant (the world on a fixed base), where the
// recursions need no transforms (Frame::world: the mass matrix, the connection, the Jacobian's derivatives).
//
// The algorithms, one per file: forward_kinematics (poses, axes and inertias in the common frame), crba (composite
// inertias, mass matrix), rnea (inverse dynamics), aba (articulated-body factor and solve), ldlt (the base's block and
// every other dense solve) and rnea_derivatives (∂ID/∂x, Carpentier & Mansard 2018).
#pragma once

#include "rbd/spatial.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace hamel::rbd {

using Ex = GiNaC::ex;

enum class Frame { local, world };

/// A rigid body's inertial data in its own frame: mass, centre of mass, rotational inertia about the centre of mass.
struct BodyInertia {
  Ex mass = 0;
  Vec3<Ex> com{0, 0, 0};
  Mat3<Ex> rotational{{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
};

/// 𝕀 about the body frame's origin: m, h = m c, J = Θ − m [c]×² (momentum 𝕀 V = (Θ ω + c × p, p),
/// p = m (v + ω × c)); entries expanded as sums of products of the data.
Inertia<Ex> spatial_inertia(const BodyInertia& body);

struct TreeModel {
  std::vector<int> parent;           ///< parent of body i; −1 for the base
  std::vector<Link<Ex>> link;        ///< body i's pose in its parent's frame at the configuration (i ≥ 1)
  std::vector<Vec6<Ex>> axis;        ///< S_i: the joint's motion in body i's frame (i ≥ 1; zero for the base)
  std::vector<BodyInertia> body;     ///< inertial data of body i, in its frame
  std::vector<Inertia<Ex>> inertia;  ///< spatial_inertia(body[i])
  std::vector<Ex> armature;          ///< a_i added to the joint's diagonal of M (i ≥ 1; 0 for the base)
  std::vector<Vec6<Ex>> base;        ///< the directions e_α the base moves in (empty: fixed base)
  Vec6<Ex> root_acceleration;        ///< gravity as the base's upward acceleration (0, −g), in the base's frame
                                     ///< (Featherstone): every body's wrench then carries its weight
  std::vector<Vec6<Ex>> external;    ///< the wrench applied to body i, in its frame (Pinocchio's fext); zeros if none

  std::size_t size() const { return parent.size(); }
  bool fixed_base() const { return base.empty(); }
  /// Whether some body has an applied wrench.
  bool has_external() const;
};

/// Every body's pose (R, p), joint axis s_i and inertia in the common frame, named in a program
/// (forward_kinematics), and the composite inertias of the subtrees (crba: composite_inertias).
struct CommonFrame {
  std::vector<Mat3<Ex>> R;
  std::vector<Vec3<Ex>> p;
  std::vector<Vec6<Ex>> axis;  ///< s_i (i ≥ 1; zero for the base)
  std::vector<Inertia<Ex>> inertia;
  std::vector<Inertia<Ex>> composite;  ///< 𝕀ᶜ_i = Σ over i's subtree (a fixed base's is not formed)
};

/// What the recursions read of body i in one frame convention: motion passed from the parent's frame into the
/// body's, forces passed back, the joint axis, the inertia and the applied wrench, in the convention's frame.
class FrameView {
 public:
  /// Frame::local: the bodies' own frames.
  explicit FrameView(const TreeModel& model);
  /// Frame::world: the common frame (applied wrenches moved into it once, named).
  FrameView(const TreeModel& model, const CommonFrame& frame, const Namer<Ex>& name);

  Frame convention() const { return convention_; }
  const TreeModel& model() const { return model_; }
  std::size_t size() const { return model_.size(); }
  int parent(std::size_t i) const { return model_.parent[i]; }
  Vec6<Ex> motion_from_parent(std::size_t i, const Vec6<Ex>& v) const {
    return convention_ == Frame::local ? model_.link[i].to_child(v) : v;
  }
  Vec6<Ex> force_to_parent(std::size_t i, const Vec6<Ex>& f) const {
    return convention_ == Frame::local ? model_.link[i].to_parent(f) : f;
  }
  const Vec6<Ex>& axis(std::size_t i) const { return convention_ == Frame::local ? model_.axis[i] : frame_->axis[i]; }
  const Inertia<Ex>& inertia(std::size_t i) const {
    return convention_ == Frame::local ? model_.inertia[i] : frame_->inertia[i];
  }
  const Vec6<Ex>& external(std::size_t i) const { return external_[i]; }

 private:
  const TreeModel& model_;
  const CommonFrame* frame_ = nullptr;
  Frame convention_;
  std::vector<Vec6<Ex>> external_;
};

/// A tree's dynamics as the kernels use them (derive_tree builds it, emit/equations_of_motion.cpp solves and
/// differentiates with it): the model, its common frame, and the symbols of the state in the derivation's program.
struct TreeDynamics {
  TreeModel model;
  CommonFrame frame;
  std::vector<Ex> base_velocity;  ///< ξ^α (m)
  std::vector<Ex> coordinates;    ///< r^I (n)
  std::vector<Ex> gravity_state;  ///< Γ (3) when the state carries gravity in the base's frame, else empty: then
                                  ///< root_acceleration = (0, −Γ) and the state is (r, Γ, ξ, ṙ)
  std::vector<Ex> rates;          ///< ṙ^I (n)
  std::vector<Ex> accelerations;  ///< the m + n symbols standing for u̇
  std::vector<Ex> joint_force;    ///< τ_I(r, u, t, inputs): applied joint forces, springs, dampers (n)
  /// Q (m + n: base directions, then joints): the generalized forces of the applied wrenches (Jᵀ f_ext) plus, on
  /// the joints, τ_I(r, u, t, inputs) (applied joint forces, springs, dampers). ID = M u̇ − f + (what Q leaves out
  /// of f) is differentiated with Q taken symbolically (rbd/rnea_derivatives.hpp).
  std::vector<Ex> generalized_force;
  /// The outward pass in the bodies' frames at u̇ = 0 (rnea_motion with FrameView(model)), named in the derivation's
  /// program: twists v_i, momenta h_i and joint-axis rates ψ_i, what forward_dynamics reads (index 0 the base).
  std::vector<Vec6<Ex>> local_twist, local_momentum, local_axis_rate;
};

}  // namespace hamel::rbd
