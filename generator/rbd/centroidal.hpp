// The centroidal momentum of a kinematic tree (Orin, Lee & Goswami, Centroidal dynamics of a humanoid robot, Auton.
// Robots 35, 2013): the momentum of all bodies about their common centre of mass G, h_G = (L_G, p) with
// L_G = Σ_i (L_i about the common origin) − c × p, in the common frame (rbd/tree.hpp: the base's frame at the instant
// on a floating base, the world on a fixed one). It is linear in u = (ξ, ṙ), h_G = A_G(q) u: A_G is the centroidal
// momentum matrix. Bodies' own momenta 𝕀_i v_i come from the outward pass of rnea in the common frame; the joints'
// armature (rotor inertia in joint space) carries no momentum here.
#pragma once

#include "rbd/tree.hpp"

namespace hamel::rbd {

struct CentroidalMomentum {
  Vec6<Ex> momentum;  ///< h_G = (L_G, p): angular about the centre of mass, then linear
  Vec3<Ex> com;       ///< c, the centre of mass in the common frame
  Ex mass;            ///< the total mass (a fixed base's own body not counted)
};

CentroidalMomentum centroidal_momentum(const TreeDynamics& tree, const Namer<Ex>& name);

}  // namespace hamel::rbd
