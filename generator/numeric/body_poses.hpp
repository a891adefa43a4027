// Where a model's rigid bodies are: each body's frame in the world at a configuration, from the model's own
// kinematics, for `hamel animate`. A kinematic tree composes its joints' placements, g_i = g_parent · (rotation,
// offset) · exp(q_i S_i) (docs/model-format.md, "Pose of a body"), from the base: the world on a fixed base, the
// group element g(t) of the reconstruction on a floating one. A model in general coordinates with `bodies` has each
// pose (R(q, t), p(q, t)) written out. Bundle models whose bodies are given by twists (or T by `kinetic`) do not
// say where their bodies are: only the group frame is known.
#pragma once

#include "model/model.hpp"

#include <array>
#include <string>
#include <vector>

namespace hamel {

/// A rigid placement x ↦ R x + p (R row-major).
struct Placement {
  std::array<double, 9> R{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> p{0, 0, 0};
};

/// a · b: b's frame given in a's, seen from a's parent.
Placement compose(const Placement& a, const Placement& b);

/// A body's inertial data at the run's parameters, in its own frame: m, centre of mass c, inertia Θ about c.
struct BodyInertiaValues {
  std::string name;
  double mass = 0;
  std::array<double, 3> com{0, 0, 0};
  std::array<double, 9> inertia{0, 0, 0, 0, 0, 0, 0, 0, 0};
};

/// The box of equal mass and inertia about the centre of mass: edges a_k along the principal axes e_k of Θ with
/// Θ_k = m (a_{k+1}² + a_{k+2}²) / 12, so a_k² = 6 (Θ_{k+1} + Θ_{k+2} − Θ_k) / m (clamped at 0: a slender rod's box
/// is a segment). Its placement in the body frame: R = (e_1 e_2 e_3), det R = 1; p = c.
struct InertiaBox {
  std::array<double, 3> edges{0, 0, 0};
  Placement in_body;
};
InertiaBox inertia_box(const BodyInertiaValues& body);

class BodyPoses {
 public:
  /// `parameters` in model.parameters order. A model without bodies to place (general coordinates without
  /// `bodies`, bundle models without `tree`) has none: then bodies() is empty.
  BodyPoses(const Model& model, const std::vector<double>& parameters);

  const std::vector<BodyInertiaValues>& bodies() const { return bodies_; }
  /// Whether the poses hang from a moving group frame (a floating tree) rather than from the world.
  bool floating() const { return floating_; }

  /// Every body's frame in the world at time t and coordinates q (model.coordinates order: joints or general
  /// coordinates; a floating tree's Γ and velocities are not needed), with the group frame at `base` (floating trees;
  /// ignored otherwise).
  std::vector<Placement> at(double t, const std::vector<double>& q, const Placement& base) const;

 private:
  const Model& model_;
  GiNaC::exmap parameters_;
  std::vector<BodyInertiaValues> bodies_;
  bool floating_ = false;
  // Trees: body k ≥ 1 is tree body k − 1, body 0 the base (the world's: not drawn, massless).
  const KinematicTree* tree_ = nullptr;
  std::vector<Placement> joint_frame_;       // (rotation, offset) of each tree body in its parent
  std::vector<std::array<double, 3>> axis_;  // joint axis in the joint frame
};

}  // namespace hamel
