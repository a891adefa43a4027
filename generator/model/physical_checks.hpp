// Physical plausibility of a model, checked numerically when it is loaded: a kinetic energy that is not
// positive semi-definite, a body with negative mass, an inertia that is not positive semi-definite or whose
// principal moments violate the triangle inequality, a joint axis that is zero at the parameter defaults, a
// negative joint armature, damping or stiffness.
// Such models derive without complaint and fail later as "non-finite state"; here they are input errors that
// name the key and the point. Each function returns "" when the check passes, else the problem.
#pragma once

#include "model/model.hpp"

#include <string>
#include <vector>

namespace hamel {

/// The value of `e` at `values` as a double, or NaN when it does not evaluate to a real number there.
double real_value_at(const GiNaC::ex& e, const GiNaC::exmap& values);

/// Eigenvalues (ascending) of the symmetric n x n matrix `a` (row-major), by cyclic Jacobi rotations.
std::vector<double> symmetric_eigenvalues(std::vector<double> a, std::size_t n);

/// Values of the parameters at their defaults, for evaluating inertial data.
GiNaC::exmap parameter_defaults(const Model& model);

/// Mass and inertia of `body` at `values`: "" or the problem; `subkey` is set to "mass" or "inertia".
std::string rigid_body_problem(const RigidBody& body, const GiNaC::exmap& values, std::string& subkey);

/// A joint axis of squared length 0 at `values` (a parameter that is zero at its default).
std::string joint_axis_problem(const TreeBody& body, const GiNaC::exmap& values);

/// A joint's armature, damping or stiffness (`what`) below zero at `values`: a negative armature can make M
/// indefinite, negative damping or stiffness feed energy in (robot files never carry them).
std::string joint_property_problem(const GiNaC::ex& value, const GiNaC::exmap& values, const std::string& what);

/// d^2 L / dq_dot^2 (with u = A(q) q_dot) at q_dot = 0, t = 0 and three sampled configurations, parameters at
/// their defaults: "" or the problem and the point where it has a negative eigenvalue.
std::string kinetic_energy_problem(const Model& model);

/// A body of a tree in numbers (model.hpp's TreeBody at the parameter defaults, or an imported body).
struct NumericTreeBody {
  int parent = -1;
  bool prismatic = false;
  double axis[3] = {0, 0, 1}, offset[3] = {0, 0, 0};
  double rotation[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double mass = 0, com[3] = {0, 0, 0}, inertia[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};  ///< about the com
  double armature = 0;
};

/// The index of a joint whose pivot in the articulated-body algorithm is 0 at three sampled configurations (the
/// deepest, at the first): the tree's mass matrix is singular everywhere. -1 when it is regular at one of them, or the
/// data are not finite.
/// With a floating `base` (its mass properties; its joint fields unused) moving in the se(3) `directions` (indices
/// into (omega, v), lie/lie_algebra.hpp's tree_base_directions): -2 when the base's block is singular, with
/// `base_direction` the position in `directions` of the first direction whose pivot vanishes.
int singular_tree_joint(const std::vector<NumericTreeBody>& bodies, const NumericTreeBody* base = nullptr,
                        const std::vector<int>& directions = {}, int* base_direction = nullptr);

/// A tree whose joint-space mass matrix is singular at three sampled configurations (parameters at their defaults):
/// a joint that moves nothing with mass or inertia along its motion (a massless body, a point mass on the joint's
/// axis, two coaxial joints on a massless link). "" or the problem; `body` is then the index of the body whose joint
/// it names (the deepest such joint), or -2 for a floating base moving in `directions` (named `direction_names`)
/// that carries nothing along one of them. Numbers only: a tree whose data are no numbers at the defaults passes.
std::string tree_mass_matrix_problem(const Model& model, const KinematicTree& tree, const std::vector<int>& directions,
                                     const std::vector<std::string>& direction_names, int& body);

}  // namespace hamel
