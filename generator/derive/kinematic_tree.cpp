#include "derive/kinematic_tree.hpp"

#include "algebra/simplify.hpp"
#include "lie/lie_algebra.hpp"
#include "rbd/aba.hpp"
#include "rbd/crba.hpp"
#include "rbd/forward_kinematics.hpp"
#include "rbd/joint.hpp"
#include "rbd/rnea.hpp"

#include <algorithm>
#include <string>

namespace hamel {

using GiNaC::ex;
using namespace rbd;

namespace {

// The columns of the map ξ ↦ base twist (ω, v): which se(3) directions the group moves.
std::vector<Vec6<Ex>> base_directions(const std::string& group) {
  std::vector<Vec6<Ex>> s;
  for (int k : tree_base_directions(group)) s.push_back(unit6<Ex>(k));
  return s;
}

BodyInertia inertial_data(const RigidBody& b) {
  BodyInertia out;
  out.mass = b.mass;
  for (std::size_t r = 0; r < 3; ++r) {
    out.com[r] = b.com[r];
    for (std::size_t c = 0; c < 3; ++c) out.rotational[r][c] = b.inertia[r][c];
  }
  return out;
}

// Gravity as an upward acceleration of the base, (0, −g) (Featherstone): every body's wrench then carries its weight
// without a separate potential gradient. On a floating base g resolved in the base's frame: Γ, the state's when the
// base turns relative to gravity, else the constant g.
Vec6<Ex> gravity_as_base_acceleration(const KinematicTree& tree) {
  if (!tree.gravity_state.empty())
    return join<Ex>({0, 0, 0}, {-tree.gravity_state[0], -tree.gravity_state[1], -tree.gravity_state[2]});
  return join<Ex>({0, 0, 0}, {-tree.gravity[0], -tree.gravity[1], -tree.gravity[2]});
}

// The applied wrenches (model key `wrenches`) of each body, in its frame about its origin: (τ + ρ × f, f) for a force f
// at the point ρ and a torque τ; a world-frame wrench (fixed base) turned into the body's frame by its pose in the
// world.
std::vector<Vec6<Ex>> applied_wrenches(const Model& model, const KinematicTree& tree, const CommonFrame& world,
                                       const Namer<Ex>& name) {
  const std::vector<std::string> names = tree_body_names(tree);
  std::vector<Vec6<Ex>> out(names.size(), zero6<Ex>());
  for (const AppliedWrench& w : model.wrenches) {
    const std::size_t i = static_cast<std::size_t>(std::find(names.begin(), names.end(), w.body) - names.begin());
    Vec3<Ex> f{w.force[0], w.force[1], w.force[2]}, tau{w.torque[0], w.torque[1], w.torque[2]};
    if (w.world) {  // Rᵀ: the world's components in the body's frame
      const Mat3<Ex>& R = world.R[i];
      Vec3<Ex> fb, tb;
      for (std::size_t r = 0; r < 3; ++r) {
        fb[r] = R[0][r] * f[0] + R[1][r] * f[1] + R[2][r] * f[2];
        tb[r] = R[0][r] * tau[0] + R[1][r] * tau[1] + R[2][r] * tau[2];
      }
      f = name(fb);
      tau = tb;
    }
    const Vec3<Ex> moment = tau + cross(Vec3<Ex>{w.point[0], w.point[1], w.point[2]}, f);
    out[i] = name(out[i] + join(moment, f));
  }
  return out;
}

// Γ̇ = Γ × ω (ω the base's angular velocity in its frame): gravity resolved in a turning base.
std::vector<ex> gravity_kinematics(const KinematicTree& tree, const std::vector<Vec6<Ex>>& base,
                                   const std::vector<GiNaC::realsymbol>& group_velocity) {
  if (tree.gravity_state.empty()) return {};
  Vec6<Ex> twist = zero6<Ex>();
  for (std::size_t alpha = 0; alpha < base.size(); ++alpha) twist = twist + base[alpha] * Ex(group_velocity[alpha]);
  const Vec3<Ex> G{tree.gravity_state[0], tree.gravity_state[1], tree.gravity_state[2]};
  const Vec3<Ex> rate = cross(G, angular(twist));
  return {rate[0], rate[1], rate[2]};
}

// The rigid-body model of the tree: body 0 is the base, body k + 1 moves with r^k; its joint's pose at the
// configuration is named in the program.
TreeModel tree_model(const Model& model, const KinematicTree& tree, const std::vector<Vec6<Ex>>& base,
                     const Namer<Ex>& name) {
  TreeModel t;
  t.parent.push_back(-1);
  t.link.emplace_back();
  t.axis.push_back(zero6<Ex>());
  t.body.push_back(inertial_data(tree.base));
  t.armature.push_back(0);
  for (std::size_t i = 0; i < tree.bodies.size(); ++i) {
    const TreeBody& b = tree.bodies[i];
    Joint joint;
    joint.prismatic = b.prismatic;
    for (std::size_t r = 0; r < 3; ++r) {
      joint.axis[r] = b.axis[r];
      joint.offset[r] = b.offset[r];
      for (std::size_t c = 0; c < 3; ++c) joint.rotation[r][c] = b.rotation[r][c];
    }
    t.parent.push_back(b.parent + 1);
    t.link.push_back(joint_pose(joint, model.coordinates[i], name));
    t.axis.push_back(joint_axis(joint));
    t.body.push_back(inertial_data(b.body));
    t.armature.push_back(b.armature);
  }
  for (const BodyInertia& b : t.body) t.inertia.push_back(spatial_inertia(b));
  t.base = base;
  t.root_acceleration = gravity_as_base_acceleration(tree);
  t.external.assign(t.size(), zero6<Ex>());
  return t;
}

// Σ ½ k_i (r_i − reference_i)²: the joint springs, a potential on the shape.
ex joint_springs(const Model& model, const KinematicTree& tree) {
  ex v = 0;
  for (std::size_t i = 0; i < tree.bodies.size(); ++i) {
    const TreeBody& b = tree.bodies[i];
    v += b.stiffness * GiNaC::pow(model.coordinates[i] - b.reference, 2) / 2;
  }
  return v;
}

// The blocks of M = [[L, K], [Kᵀ, S]] (group, shape) that the bundle kernels read; S alone on a fixed base.
void split_mass_matrix(const GiNaC::matrix& M, unsigned m, bool fixed, BundleGeometry& geo) {
  const unsigned n = M.rows() - m;
  if (!fixed) geo.L = GiNaC::matrix(m, m);
  if (!fixed) geo.K = GiNaC::matrix(m, n);
  geo.S = GiNaC::matrix(n, n);
  for (unsigned r = 0; r < m + n && !fixed; ++r)
    for (unsigned c = 0; c < m + n; ++c) {
      const ex& v = M(r, c);
      if (r < m && c < m)
        geo.L(r, c) = v;
      else if (r < m)
        geo.K(r, c - m) = v;
      else if (c >= m)
        geo.S(r - m, c - m) = v;
    }
}

// The system the recursion stands for: velocities (ξ, ṙ), q̇ = ṙ, the Lagrangian and forces, and as Hamel
// coefficients the group's structure constants.
HamelSystem tree_system(const Model& model, bool fixed, const std::vector<GiNaC::realsymbol>& group_velocity,
                        const BundleGeometry& geo, const HamelEquations& eq) {
  HamelSystem sys;
  const unsigned um = static_cast<unsigned>(group_velocity.size()), un = static_cast<unsigned>(model.rates.size());
  sys.form = fixed ? "Euler-Lagrange, recursive over the kinematic tree on a fixed base"
                   : "Euler-Poincare + Euler-Lagrange (HEorig1, HEorig2), recursive over the kinematic tree";
  sys.coordinates = model.coordinates;
  const std::vector<GiNaC::realsymbol>& gravity =
      fixed ? std::vector<GiNaC::realsymbol>{} : model.bundle->tree->gravity_state;
  sys.coordinates.insert(sys.coordinates.end(), gravity.begin(), gravity.end());
  sys.velocities = group_velocity;
  sys.velocities.insert(sys.velocities.end(), model.rates.begin(), model.rates.end());
  // q̇ = B u: ṙ = ṙ, and Γ̇ = Γ × ω, linear in ξ.
  const unsigned nq = static_cast<unsigned>(sys.coordinates.size());
  sys.B = GiNaC::matrix(nq, um + un);
  for (unsigned I = 0; I < un; ++I) sys.B(I, um + I) = 1;
  for (unsigned k = un; k < nq; ++k)
    for (unsigned alpha = 0; alpha < um; ++alpha) sys.B(k, alpha) = eq.kinematics[k].diff(group_velocity[alpha]);
  sys.lagrangian = eq.reduced_lagrangian;
  sys.forces = model.forces;
  for (const StructureConstant& s : geo.structure_constants)
    sys.gamma.push_back({s.upper, s.lower_a, s.lower_b, s.value});
  sys.where_key = "tree";
  sys.where = model.locations.count("tree") ? model.locations.at("tree") : SourceLocation{model.source_path, 0, 0};
  return sys;
}

// The weight's potential −Σ m_i g·c_i, c_i the centres of mass in the world (common frame); named when not 0.
ex weight_potential(const KinematicTree& tree, const CommonFrame& frame, const Namer<Ex>& name) {
  if (tree.gravity[0].is_zero() && tree.gravity[1].is_zero() && tree.gravity[2].is_zero()) return 0;
  ex weight = 0;
  for (const Inertia<Ex>& I : frame.inertia)
    for (std::size_t r = 0; r < 3; ++r) weight -= tree.gravity[r] * I.h[r];  // h = m c in the world
  return name(weight);
}

// Whether forces or joint dampers act (the energy is then not an invariant).
bool forced(const Model& model, const KinematicTree& tree) {
  bool any = !model.wrenches.empty();
  for (const ex& q : model.forces) any = any || !q.is_zero();
  for (const TreeBody& body : tree.bodies) any = any || !body.damping.is_zero();
  return any;
}

}  // namespace

TreeDerivation derive_tree(const Model& model) {
  // A fixed base (model.tree, no group) is the same recursion with no base directions (m = 0).
  const bool fixed = !model.bundle;
  const KinematicTree& tree = fixed ? *model.tree : *model.bundle->tree;
  const std::vector<GiNaC::realsymbol> group_velocity =
      fixed ? std::vector<GiNaC::realsymbol>{} : model.bundle->group_velocity;
  TreeDerivation out;
  HamelEquations& eq = out.equations;
  // The model's definitions come first (forces and the potential may use them), then the recursion's names.
  eq.intermediates = model.definitions;
  const Namer<Ex> name([&eq](const Ex& e) { return eq.intermediates.define(e); });

  BundleGeometry& geo = out.geometry;
  if (!fixed) {
    geo.algebra = lie_algebra(model.bundle->group);
    geo.structure_constants = structure_constants(geo.algebra);
  }
  geo.trivialization_sign = 1;
  geo.quadratic = true;
  geo.connection_derived = false;

  const std::size_t m = group_velocity.size();
  const std::size_t n = tree.bodies.size();
  const std::size_t N = n + 1;  // body 0 is the base, body k + 1 moves with r^k
  const ex base_potential = fixed ? ex(0) : model.bundle->potential;

  auto dynamics = std::make_shared<TreeDynamics>();
  TreeDynamics& dyn = *dynamics;
  dyn.model = tree_model(model, tree, fixed ? std::vector<Vec6<Ex>>{} : base_directions(model.bundle->group), name);
  dyn.base_velocity.assign(group_velocity.begin(), group_velocity.end());
  dyn.coordinates.assign(model.coordinates.begin(), model.coordinates.end());
  dyn.rates.assign(model.rates.begin(), model.rates.end());
  dyn.gravity_state.assign(tree.gravity_state.begin(), tree.gravity_state.end());
  dyn.frame = forward_kinematics(dyn.model, name);
  composite_inertias(dyn.model, dyn.frame, name);
  if (!model.wrenches.empty()) dyn.model.external = applied_wrenches(model, tree, dyn.frame, name);

  // The bodies' frames at u̇ = 0: twists, momenta, wrenches summed inward, the kinetic energy.
  const FrameView local(dyn.model);
  const Motion motion = rnea_motion(local, dyn.base_velocity, dyn.rates, {}, {}, name);
  dyn.local_twist = motion.v;
  dyn.local_momentum = motion.h;
  dyn.local_axis_rate = motion.psi;
  const std::vector<Vec6<Ex>> F = rnea_forces(local, with_applied(local, motion.f), name);
  ex kinetic = 0;
  for (std::size_t i = 0; i < N; ++i) {
    kinetic += dot(motion.v[i], motion.h[i]) / 2;
    if (i > 0) kinetic += tree.bodies[i - 1].armature * GiNaC::pow(model.rates[i - 1], 2) / 2;
  }

  const std::size_t d = m + n;
  eq.mass_matrix = mass_matrix(dyn.model, dyn.frame, name);

  // Symbols for u̇ at which the Jacobian differentiates the inverse dynamics (rbd/rnea_derivatives.hpp).
  for (std::size_t k = 0; k < d; ++k) eq.acceleration_symbols.emplace_back(GiNaC::realsymbol("a_" + std::to_string(k)));
  dyn.accelerations.assign(eq.acceleration_symbols.begin(), eq.acceleration_symbols.end());

  // f = Q − (velocity-product part of the projected wrenches); the joint forces τ_I = Q_I − ∂(V + springs)/∂r^I −
  // d_I ṙ_I, shared by f and the articulated-body algorithm; none on the base.
  const ex springs = joint_springs(model, tree);
  std::vector<ex> joint_force(n);
  for (std::size_t i = 0; i < n; ++i)
    joint_force[i] = model.forces[i] - (base_potential + springs).diff(model.coordinates[i]) -
                     tree.bodies[i].damping * model.rates[i];
  eq.forcing = forcing(local, F, joint_force);
  dyn.joint_force = joint_force;
  dyn.generalized_force.assign(m, ex(0));
  dyn.generalized_force.insert(dyn.generalized_force.end(), joint_force.begin(), joint_force.end());
  if (dyn.model.has_external()) {  // Jᵀ f_ext, differentiated symbolically by the Jacobian
    const std::vector<Ex> Q = applied_generalized_forces(FrameView(dyn.model, dyn.frame, name), name);
    for (std::size_t k = 0; k < d; ++k) dyn.generalized_force[k] += Q[k];
  }

  for (std::size_t k = 0; k < d; ++k) eq.independent.push_back(static_cast<int>(k));
  eq.factor_last_first = true;  // u = (ξ, ṙ) in body order: parents before children
  for (std::size_t I = 0; I < n; ++I) eq.kinematics.push_back(model.rates[I]);
  for (const ex& rate : gravity_kinematics(tree, dyn.model.base, group_velocity)) eq.kinematics.push_back(rate);
  const ex T = name(kinetic);
  // The weight's potential needs the bodies' heights: on a fixed base they are known; a floating base's is not in
  // the state, so its energy is no invariant under gravity (it falls).
  const ex weight = fixed ? weight_potential(tree, dyn.frame, name) : ex(0);
  eq.reduced_lagrangian = T - base_potential - springs - weight;
  eq.energy_terms = {T + base_potential + springs + weight};
  eq.conservative = !forced(model, tree) && (fixed || !tree.has_gravity());
  eq.tree = dynamics;

  split_mass_matrix(eq.mass_matrix, static_cast<unsigned>(m), fixed, geo);
  out.system = tree_system(model, fixed, group_velocity, geo, eq);
  return out;
}

GiNaC::ex tree_kinetic_energy(const Model& model) {
  const TreeDerivation d = derive_tree(model);
  // energy_terms = {T + V} with T one intermediate: inlining it gives the expression.
  const ex potential = model.bundle->potential + joint_springs(model, *model.bundle->tree);
  return expand_keeping_powers_of_sums(
      d.equations.intermediates.inline_all(d.equations.energy_terms.at(0) - potential));
}

Model with_inlined_tree(const Model& model) {
  Model expanded = model;
  expanded.bundle->kinetic = tree_kinetic_energy(model);
  // The joints' springs and dampers become the potential and shape forces of the general bundle path.
  const KinematicTree& tree = *model.bundle->tree;
  expanded.bundle->potential = model.bundle->potential + joint_springs(model, tree);
  for (std::size_t i = 0; i < tree.bodies.size(); ++i)
    expanded.forces[i] = model.forces[i] - tree.bodies[i].damping * model.rates[i];
  expanded.lagrangian = expanded.bundle->kinetic - expanded.bundle->potential;
  expanded.bundle->tree.reset();
  return expanded;
}

}  // namespace hamel
