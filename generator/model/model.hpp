// The model description (schema 1): symbols and expressions as the user wrote them, before any
// derivation. See docs/model-format.md; the paper's notation is in comments.
#pragma once

#include "algebra/intermediates.hpp"
#include "model/input_error.hpp"

#include <ginac/ginac.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hamel {

/// A named symbol with a default value (parameters) or without (coordinates, velocities, inputs).
struct Parameter {
  GiNaC::realsymbol symbol;
  double default_value = 0.0;
  /// Fixed at generation time (model/fold_parameters.hpp): the model's expressions hold its value, not the symbol.
  bool folded = false;
};

/// A rigid body of a kinematic tree: inertial data in its own frame.
struct RigidBody {
  std::string name;
  GiNaC::ex mass;
  GiNaC::ex com[3];         ///< centre of mass in the body frame
  GiNaC::ex inertia[3][3];  ///< about the centre of mass, body-frame axes
};

/// A rigid body of a model in general coordinates (key `bodies` beside `coordinates`): inertial data in its frame and
/// the frame's pose in the world, R(q, t) and p(q, t), as expressions that may use definitions. The kinetic energy is
/// assembled from them when loading (model/body_energy.hpp); `hamel animate` draws them where they are.
struct PosedBody {
  RigidBody body;
  GiNaC::ex rotation[3][3];
  GiNaC::ex position[3];
};

/// A body of a kinematic tree joined to its parent by a one-degree-of-freedom joint. Its pose relative to
/// the parent is g = (rotation, offset) · exp(q S), S = (axis, 0) for a revolute and (0, axis) for a
/// prismatic joint, axis resolved in the joint frame, which is the body frame at q = 0.
struct TreeBody {
  RigidBody body;
  int parent = -1;  ///< index into KinematicTree::bodies, −1 for the base
  bool prismatic = false;
  GiNaC::ex axis[3];
  GiNaC::ex offset[3];
  GiNaC::ex rotation[3][3];      ///< identity unless given
  GiNaC::realsymbol coordinate;  ///< the joint coordinate, a shape coordinate r^I (index = body index)
  // Joint properties as robot files give them (zero when absent): armature a adds ½ a ṙ² to T (a rotor's
  // reflected inertia), damping d the force −d ṙ, stiffness k the potential ½ k (r − reference)².
  GiNaC::ex armature = 0, damping = 0, stiffness = 0, reference = 0;
};

/// A floating base (the group frame, left-trivialized) carrying a tree of bodies (model key `tree`), or, in
/// a model without `group`, the world carrying them (a fixed base: `base: world`).
struct KinematicTree {
  RigidBody base;                ///< a fixed base's is the massless "world"
  std::vector<TreeBody> bodies;  ///< parents before children; body k moves with shape coordinate k
  bool fixed_base = false;
  /// The gravitational acceleration g in the world frame (key `tree.gravity`). On a floating base, resolved in the base
  /// frame it is the advected quantity Γ = Rᵀ g (Holm, Marsden & Ratiu 1998; the heavy top's direction of gravity),
  /// with Γ̇ = Γ × ω: a base that turns carries Γ in the state as `gravity_state`, Γ(0) = g (the base frame starts
  /// aligned with the world); a base that only translates (R1–R3) has Γ = g.
  GiNaC::ex gravity[3] = {0, 0, 0};
  std::vector<GiNaC::realsymbol> gravity_state;  ///< Γ_x, Γ_y, Γ_z (named gravity_x, ...), or empty
  bool has_gravity() const { return !gravity[0].is_zero() || !gravity[1].is_zero() || !gravity[2].is_zero(); }
};

/// A force and a torque applied to a body (model key `wrenches`): resolved in the body's frame or in the world's, the
/// force acting at `point` (body frame; the torque is free). Expressions of t, the state, inputs and parameters.
struct AppliedWrench {
  std::string body;
  bool world = false;
  GiNaC::ex point[3] = {0, 0, 0};
  GiNaC::ex force[3] = {0, 0, 0};
  GiNaC::ex torque[3] = {0, 0, 0};
};

/// The base's name, then every body's, in file order.
std::vector<std::string> tree_body_names(const KinematicTree& tree);

/// The principal-bundle part of a model (paper Sec. 3–6): configuration (g, r) ∈ G × shape space, with the
/// group velocity ξ (ξ̂ = g⁻¹ġ left, ġg⁻¹ right) and the shape coordinates r (Model::coordinates).
struct Bundle {
  std::string group;                              ///< "SO3", "SE3", "SO3xR3", "SE2", "R1".."R6", products
  bool right = false;                             ///< right trivialization (spatial velocities)
  std::vector<GiNaC::realsymbol> group_velocity;  ///< ξ^α, in the basis order of the group
  bool mechanical = true;                         ///< mechanical connection (mechConn) or kinematic (KinConnect)
  GiNaC::matrix kinematic_connection;             ///< A^α_I(r), rows α, columns I, when kinematic
  GiNaC::ex kinetic;                              ///< T(ξ, r, ṙ), from `kinetic:` or assembled from `bodies:`
  GiNaC::ex potential;                            ///< V(r)
  std::vector<std::string> bodies;                ///< body names when T came from `bodies:`
  std::optional<KinematicTree> tree;              ///< set when the bodies form a tree (key `tree`); then
                                                  ///< `kinetic` is empty: see derive/kinematic_tree.hpp
  /// Constraints that leave some group directions free (key `constraints` on a bundle; Bloch, Krishnaprasad,
  /// Marsden & Murray 1996): C_ξ(r) ξ + C_r(r) ṙ = 0, k < dim G rows, G-invariant because written in ξ. Then the
  /// connection is the nonholonomic one (derive/nonholonomic_connection.hpp) and `mechanical` is false.
  bool nonholonomic = false;
  std::vector<GiNaC::realsymbol> constraint_velocities;  ///< the constraints' names: C_ξ ξ + C_r ṙ, held at zero
  GiNaC::matrix constraint_group;                        ///< C_ξ(r), k × dim G
  GiNaC::matrix constraint_shape;                        ///< C_r(r), k × (number of shape coordinates)
  /// Names of the velocities along S = D ∩ V (dim G − k of them, `Omega_S`, or `Omega_S1`, ... for several): ξ = Z Ω_S
  /// − 𝒜ṙ.
  std::vector<GiNaC::realsymbol> momentum_velocities;
};

/// A holonomic constraint g(q) = 0 (model key `holonomic`, general coordinates). It enters the derivation as the
/// quasi-velocity u^α = ġ^α = G^α_a(q) q̇^a held at zero, named after the constraint (derive/holonomic_constraints.hpp).
struct HolonomicConstraint {
  GiNaC::realsymbol velocity;       ///< u^α = ġ^α; its name is the constraint's
  GiNaC::ex g;                      ///< g(q), in coordinates, parameters and definitions of these
  std::vector<GiNaC::ex> gradient;  ///< G^α_a = ∂g/∂q^a, a = 1..n, through the definitions
};

struct Model {
  std::string name;
  std::string description;
  std::string source_path;  ///< as given on the command line
  std::string source_hash;  ///< FNV-1a 64 of the file's bytes, hex

  GiNaC::realsymbol time{"t"};
  std::vector<Parameter> parameters;
  std::vector<GiNaC::realsymbol> coordinates;       ///< q^a
  std::vector<GiNaC::realsymbol> rates;             ///< q̇^a, spelled <name>_dot
  std::vector<GiNaC::realsymbol> quasi_velocities;  ///< u^a, eq. (u2)
  std::vector<GiNaC::realsymbol> inputs;            ///< run-time inputs in forces

  GiNaC::matrix A;  ///< u = A(q) q̇, eq. (u2); rows: u^a, columns: q^b (not stored for a fixed-base tree: u = q̇)
  GiNaC::matrix B;  ///< q̇ = B(q) u, only when given in the file (a fixed-base tree: not stored, the identity)
  bool B_given = false;
  std::vector<int> constrained;  ///< indices α of quasi-velocities held at zero, eq. (PfaffianConstr)
  /// Holonomic constraints (key `holonomic`), in file order: their velocities ġ are the first quasi-velocities and
  /// are constrained; A's first rows are their gradients (derive/holonomic_constraints.hpp).
  std::vector<HolonomicConstraint> holonomic;
  /// The dependent coordinates s of the partition q = (s, r) hamel chose (sys1), indices in file order; empty when
  /// the model has no holonomic constraints or gives `quasi_velocities` itself.
  std::vector<int> dependent_coordinates;

  std::optional<Bundle> bundle;  ///< set for bundle models; then coordinates are the shape r^I and A, B are empty
  /// A fixed-base tree (model key `tree` without `group`): coordinates are the joints, u = q̇ (A = B = 1),
  /// the Lagrangian follows from the bodies (derive/kinematic_tree.hpp).
  std::optional<KinematicTree> tree;
  /// A fixed-base tree with closed loops (key `loops`) is derived in general coordinates, the joints, without `tree`:
  /// this keeps its bodies and joints, which say where the bodies are (`hamel animate`).
  std::optional<KinematicTree> closed_tree;

  /// Named sub-expressions (model key `definitions`), in order; every expression below may use them, and
  /// they stay intermediate symbols through the derivation into the emitted code.
  Intermediates definitions;

  std::vector<PosedBody> posed_bodies;  ///< key `bodies` in general coordinates, in file order

  GiNaC::ex lagrangian;                 ///< L(q, q̇, u, t); for bundle models l = T − V
  std::vector<GiNaC::ex> forces;        ///< Q_a dual to q^a (zeros when absent); for bundles Q_I on the shape
  std::vector<AppliedWrench> wrenches;  ///< key `wrenches` (kinematic trees)

  /// State variables whose natural start is not 0, as expressions in the parameters: Γ(0) = g of a floating base
  /// under gravity. Verbs start there unless the model's `initial`, a scene or --init say otherwise.
  std::map<std::string, GiNaC::ex> state_defaults;

  /// A representative initial state (key `initial`): state variable name → value, the others 0; the default of
  /// `simulate` and `report`, which a scene's `initial` and --init override (cli/options.hpp: initial_state). Names
  /// are checked when a verb uses them, against the state the derivation gives.
  std::map<std::string, double> initial;

  /// Where each key stood in the file ("quasi_velocities.A", "lagrangian", ...), for later errors.
  std::map<std::string, SourceLocation> locations;

  std::size_t n() const { return coordinates.size(); }
  /// Indices I of the independent quasi-velocities, in file order, eq. (PfaffForm).
  std::vector<int> independent() const;
  /// All symbols a numeric evaluation of the model may need, by name.
  GiNaC::symtab symbols() const;
  /// The position of the input called `name`; an InputError naming `option` and listing the inputs otherwise.
  std::size_t input_index(const std::string& name, const std::string& option) const;
};

/// 0, …, n − 1 without the indices in `constrained`, in order: the independent quasi-velocities, eq. (PfaffForm).
std::vector<int> unconstrained_indices(std::size_t n, const std::vector<int>& constrained);

}  // namespace hamel
