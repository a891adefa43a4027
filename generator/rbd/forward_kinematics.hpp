// Forward kinematics into the common frame (the base's frame at the current instant, or the world on a fixed base):
// every body's pose R_i = R_λ R_link, p_i = p_λ + R_λ p_link, its joint axis s_i = Ad_{(R_i, p_i)} S_i and its
// spatial inertia about the common origin (centre of mass c = p_i + R_i c_b, rotational inertia R_i Θ R_iᵀ
// about it, J = R_i Θ R_iᵀ − m [c]×²), each named in the program. The data of the Frame::world convention.
#pragma once

#include "rbd/tree.hpp"

namespace hamel::rbd {

/// The poses, axes and inertias of `model` in the common frame (CommonFrame::composite is left empty: crba).
CommonFrame forward_kinematics(const TreeModel& model, const Namer<Ex>& name);

}  // namespace hamel::rbd
