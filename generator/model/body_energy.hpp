// The kinetic energy of a rigid body of a model file's `bodies` (docs/model-format.md): from its pose in general
// coordinates, or from its twist on a bundle. The loader reads and checks the keys; the physics is here.
//
// Both build T = ½ m |v_c|² + ½ ωᵀΘω (v_c the centre of mass's velocity, ω the body-frame angular velocity, Θ the
// inertia about the centre of mass) through named intermediates of the model's program, so T stays a short
// expression and nothing is expanded. Kinematic trees form their energy from the spatial recursion instead
// (derive/kinematic_tree.cpp, ½ ⟨V, 𝕀 V⟩); tests/tree/tree_kinetic_energy_matches_hand_written_test.cpp checks that
// against the twist form on models/satellite_se3.yaml.
#pragma once

#include "model/model.hpp"

#include <ginac/ginac.h>

#include <vector>

namespace hamel {

/// The rotation by `angle` about coordinate axis `axis` (0 = x, 1 = y, 2 = z).
GiNaC::matrix rotation_about(unsigned axis, const GiNaC::ex& angle);

/// T of `body` at the pose (R(q, t), p(q, t)): with p_c = p + R c and ω̂ = RᵀṘ. R's non-numeric entries, ω and ṗ_c
/// become definitions of model.definitions named _<body>_R<ij>, _<body>_w<i> and _<body>_v<i>; Ṙ and ṗ_c follow
/// by the chain rule through them (Intermediates::diff) along model.rates and model.time.
GiNaC::ex posed_body_kinetic_energy(Model& model, const RigidBody& body, const GiNaC::matrix& R,
                                    const std::vector<GiNaC::ex>& position);

/// T of `body` moving with the twist (ω, v) of its frame's origin, resolved in its frame: v_c = v + ω × c. ω and
/// v_c become definitions of model.definitions named _<body>_w<i> and _<body>_v<i> (symbols and numbers stay).
GiNaC::ex twist_body_kinetic_energy(Model& model, const RigidBody& body, const std::vector<GiNaC::ex>& twist);

}  // namespace hamel
