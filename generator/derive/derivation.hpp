// The whole derivation of a model. General coordinates (paper Sec. 2): quasi-velocities (u2), Hamel
// coefficients (gamma, gammaNH), equations of motion (BHEqu2/BHconstr) with kinematics (qadot). Bundle
// models (Sec. 3–6): structure constants, connection, curvature and E (bundle_connection), then the
// equations in the chosen form (bundle_forms) through the same equation builder.
#pragma once

#include "derive/bundle_connection.hpp"
#include "derive/bundle_forms.hpp"
#include "derive/hamel_coefficients.hpp"
#include "derive/hamel_equations.hpp"
#include "derive/hamel_system.hpp"
#include "derive/nonholonomic_momentum.hpp"
#include "derive/quasi_velocities.hpp"
#include "model/model.hpp"

#include <optional>
#include <string>

namespace hamel {

/// What the derivation is asked for. How u̇ is then computed (the --dynamics option) is the kernels' choice
/// (emit/equations_of_motion.hpp): the derivation gives M u̇ = f and, for trees, the tree for recursive algorithms.
struct DeriveSettings {
  std::string form;  ///< bundle models: "ep", "lp", "ldap" or "momentum"; empty: the connection's default
};

struct Derivation {
  QuasiVelocities quasi_velocities;       ///< general coordinates only
  std::optional<BundleGeometry> bundle;   ///< bundle models only
  std::optional<BundleForm> form;         ///< bundle models only
  std::vector<GiNaC::ex> group_velocity;  ///< bundle models: ξ^α(r, u_I) for the reconstruction (KinRec)
  HamelSystem system;                     ///< what the equations were derived from; its gamma are the
                                          ///< Hamel coefficients of the velocities in the state
  HamelEquations equations;
  std::optional<NonholonomicMomentum> momentum_equation;  ///< bundle models with `constraints` (BKMM 1996)
};

/// Runs every derivation step on `model`. Throws InputError for models that are inconsistent.
Derivation derive(const Model& model, const DeriveSettings& settings = {});

/// The system of a model in general coordinates: ℒ(q, u) = L(q, B u), Q in u, γ from eq. (gamma).
/// `program` holds the intermediates γ and the model's expressions use (the model's definitions first).
HamelSystem general_coordinate_system(const Model& model, const QuasiVelocities& qv,
                                      std::vector<HamelCoefficient> gamma, Intermediates program);

}  // namespace hamel
