// The composite-rigid-body algorithm (Featherstone, Rigid Body Dynamics Algorithms, 2008, §6.2) in the common frame:
// the composite inertias 𝕀ᶜ_i of the subtrees, summed from the leaves in, and the joint-space mass matrix of
// u = (ξ, ṙ) (HEorig1, HEorig2): M_αβ = ⟨e_α, 𝕀ᶜ_0 e_β⟩ and, with U_I = 𝕀ᶜ_I s_I, M_JI = ⟨s_J, U_I⟩ for J = I (plus
// the armature) and every ancestor J, M_αI = ⟨e_α, U_I⟩. One dot product per entry; nothing is carried between
// frames, and bodies on different branches give structural zeros.
#pragma once

#include "rbd/tree.hpp"

namespace hamel::rbd {

/// Fills frame.composite (named; a fixed base's own composite is not formed: it is never read).
void composite_inertias(const TreeModel& model, CommonFrame& frame, const Namer<Ex>& name);

/// M (m + n rows and columns: base directions, then joints), from frame.composite.
GiNaC::matrix mass_matrix(const TreeModel& model, const CommonFrame& frame, const Namer<Ex>& name);

}  // namespace hamel::rbd
