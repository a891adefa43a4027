// A system in quasi-velocities, the common input of the equations of motion (BHEqu2/BHconstr): the
// coordinates the Lagrangian depends on, the quasi-velocities u^a, the kinematics q̇ = B u, the Hamel
// coefficients γ^c_ab and the quasi-velocities held at zero. Every form the generator derives is one
// of these: a model in general coordinates (core path: γ from eq. (gamma)) and, for bundle models, the
// Euler–Poincaré/Euler–Lagrange, Lagrange–Poincaré, Lagrange–d'Alembert–Poincaré and momentum forms
// (bundle path: γ from structure constants, connection and curvature, eqs. gamma41–gamma43).
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/hamel_coefficients.hpp"
#include "model/input_error.hpp"

#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace hamel {

/// A position constraint g(q) = 0 the motion keeps: a holonomic constraint of a model in general coordinates
/// (derive/holonomic_constraints.hpp), whose velocity form ġ = G q̇ is among the constrained velocities. The emitted
/// constraint_position and constraint_position_jacobian kernels evaluate g and G for the runtime's projector
/// (runtime/include/hamel/runtime/projection.hpp), which needs nothing else: any derivation that can state its
/// position constraints this way gets the kernels, the projection after every step and simulate's projection of
/// the initial state.
struct PositionConstraint {
  std::string name;
  GiNaC::ex g;                      ///< g(q), may use the program's intermediates
  std::vector<GiNaC::ex> gradient;  ///< ∂g/∂q^a over the system's coordinates, in their order
};

struct HamelSystem {
  std::string form;                                      ///< e.g. "Boltzmann-Hamel (BHEqu2)", for reports
  std::vector<GiNaC::realsymbol> coordinates;            ///< q^a the Lagrangian and forces may depend on
  std::vector<GiNaC::realsymbol> velocities;             ///< u^a
  std::vector<int> constrained;                          ///< indices of u held at zero
  GiNaC::matrix B;                                       ///< q̇ = B u: rows coordinates, columns velocities
  GiNaC::ex lagrangian;                                  ///< ℒ(q, u, t), already in quasi-velocities
  std::vector<GiNaC::ex> forces;                         ///< Q_a dual to q^a, in quasi-velocities
  std::vector<HamelCoefficient> gamma;                   ///< all non-zero γ^c_ab, indices into velocities
  std::vector<std::vector<GiNaC::ex>> constraint_form;   ///< per constrained u^α: A^α_a(q) with u^α = A^α_a q̇^a,
                                                         ///< for the residual monitor; empty if not in q̇ alone
  std::vector<PositionConstraint> position_constraints;  ///< g(q) = 0, for the constraint_position kernels
  SourceLocation where;                                  ///< for errors about the Lagrangian: the key it came from,
  std::string where_key = "lagrangian";                  ///< `lagrangian`, `bodies`, `kinetic` or `tree`
  Intermediates program;  ///< definitions of the intermediate symbols the expressions above may use

  std::vector<int> independent() const;
};

}  // namespace hamel
