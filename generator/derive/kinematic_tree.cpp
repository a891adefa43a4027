#include "derive/kinematic_tree.hpp"

#include "algebra/simplify.hpp"

#include "derive/articulated_body.hpp"
#include "derive/spatial_algebra.hpp"
#include "derive/tree_derivatives.hpp"
#include "lie/lie_algebra.hpp"

#include <array>
#include <string>

namespace hamel {

using GiNaC::ex;
using namespace spatial;

namespace {

// 𝕀 = [[Θ − m[c]×², m[c]×], [−m[c]×, m 1]]: the spatial inertia about the body frame's origin, with
// momentum 𝕀 V = (Θ ω + c × p, p), p = m (v + ω × c).
Mat6 spatial_inertia(const RigidBody& b) {
  const Vec3 c{b.com[0], b.com[1], b.com[2]};
  const Mat3 C = skew(c);
  Mat6 I;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) {
      ex cc = 0;
      for (std::size_t j = 0; j < 3; ++j) cc += C[r][j] * C[j][k];
      I[r][k] = expand_keeping_powers_of_sums(b.inertia[r][k] - b.mass * cc);
      I[r][k + 3] = expand_keeping_powers_of_sums(b.mass * C[r][k]);
      I[r + 3][k] = expand_keeping_powers_of_sums(-b.mass * C[r][k]);
      I[r + 3][k + 3] = r == k ? b.mass : ex(0);
    }
  return I;
}

// The columns of the map ξ ↦ base twist (ω, v): which se(3) directions the group moves.
std::vector<Vec6> base_directions(const std::string& group) {
  std::vector<Vec6> s;
  for (int k : tree_base_directions(group)) s.push_back(unit6(k));
  return s;
}

class TreeProgram {
 public:
  explicit TreeProgram(Intermediates& tape) : name_(tape) {}
  ex name(const ex& e) { return name_(e); }
  Vec3 name(const Vec3& v) { return name_(v); }
  Vec6 name(const Vec6& v) { return name_(v); }
  Namer& namer() { return name_; }

  // The joint's pose: (rotation, offset) · exp(q S).
  Link link(const TreeBody& body) {
    Link l;
    const ex q = body.coordinate;
    Mat3 J;  // the joint's own rotation
    if (body.prismatic) {
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) J[r][c] = r == c ? 1 : 0;
    } else {
      // Rodrigues: 1 + sin q [a]× + (1 − cos q) [a]×², a unit.
      const ex s = name(GiNaC::sin(q)), co = name(GiNaC::cos(q));
      const Mat3 K = skew({body.axis[0], body.axis[1], body.axis[2]});
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c) {
          ex k2 = 0;
          for (std::size_t j = 0; j < 3; ++j) k2 += K[r][j] * K[j][c];
          J[r][c] = expand_keeping_powers_of_sums((r == c ? 1 : 0) + s * K[r][c] +
                                                  (1 - co) * expand_keeping_powers_of_sums(k2));
        }
    }
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t c = 0; c < 3; ++c) {
        ex e = 0;
        for (std::size_t j = 0; j < 3; ++j) e += body.rotation[r][j] * J[j][c];
        l.R[r][c] = name(expand_keeping_powers_of_sums(e));
      }
      ex shift = 0;
      if (body.prismatic)
        for (std::size_t j = 0; j < 3; ++j) shift += body.rotation[r][j] * body.axis[j] * q;
      l.p[r] = name(expand_keeping_powers_of_sums(body.offset[r] + shift));
    }
    return l;
  }

 private:
  Namer name_;
};

// Σ ½ k_i (r_i − reference_i)²: the joint springs, a potential on the shape.
ex joint_springs(const Model& model, const KinematicTree& tree) {
  ex v = 0;
  for (std::size_t i = 0; i < tree.bodies.size(); ++i) {
    const TreeBody& b = tree.bodies[i];
    v += b.stiffness * GiNaC::pow(model.coordinates[i] - b.reference, 2) / 2;
  }
  return v;
}

// The mass matrix by composite rigid bodies in the common frame: M_αβ = ⟨e_α, 𝕀ᶜ_0 e_β⟩, and with
// U_I = 𝕀ᶜ_I s_I, M_JI = ⟨s_J, U_I⟩ for J = I (plus the armature) and every ancestor J, M_αI = ⟨e_α, U_I⟩.
// One dot product per pair; nothing is carried between frames.
GiNaC::matrix composite_mass_matrix(const CommonFrame& frame, const std::vector<int>& parent,
                                    const std::vector<Vec6>& base, const KinematicTree& tree, TreeProgram& prog) {
  const std::size_t m = base.size(), N = parent.size(), d = m + N - 1;
  GiNaC::matrix M(static_cast<unsigned>(d), static_cast<unsigned>(d));
  auto set = [&](std::size_t r, std::size_t c, const ex& v) {
    M(static_cast<unsigned>(r), static_cast<unsigned>(c)) = v;
    M(static_cast<unsigned>(c), static_cast<unsigned>(r)) = v;
  };
  for (std::size_t alpha = 0; alpha < m; ++alpha)
    for (std::size_t beta = alpha; beta < m; ++beta) set(alpha, beta, dot(base[alpha], frame.composite[0](base[beta])));
  for (std::size_t i = 1; i < N; ++i) {
    const Vec6 U = prog.name(frame.composite[i](frame.axis[i]));
    set(m + i - 1, m + i - 1, dot(frame.axis[i], U) + tree.bodies[i - 1].armature);
    for (std::size_t j = static_cast<std::size_t>(parent[i]); j != 0; j = static_cast<std::size_t>(parent[j]))
      set(m + j - 1, m + i - 1, dot(frame.axis[j], U));
    for (std::size_t alpha = 0; alpha < m; ++alpha) set(alpha, m + i - 1, dot(base[alpha], U));
  }
  return M;
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
  sys.velocities = group_velocity;
  sys.velocities.insert(sys.velocities.end(), model.rates.begin(), model.rates.end());
  sys.B = GiNaC::matrix(un, um + un);
  for (unsigned I = 0; I < un; ++I) sys.B(I, um + I) = 1;
  sys.lagrangian = eq.reduced_lagrangian;
  sys.forces = model.forces;
  for (const StructureConstant& s : geo.structure_constants)
    sys.gamma.push_back({s.upper, s.lower_a, s.lower_b, s.value});
  const char* where = fixed ? "lagrangian" : "kinetic";
  sys.where = model.locations.count(where) ? model.locations.at(where) : SourceLocation{model.source_path, 0, 0};
  return sys;
}

// The weight's potential −Σ m_i g·c_i, c_i the centres of mass in the world (common frame); named when not 0.
ex weight_potential(const KinematicTree& tree, const CommonFrame& frame, TreeProgram& prog) {
  if (tree.gravity[0].is_zero() && tree.gravity[1].is_zero() && tree.gravity[2].is_zero()) return 0;
  ex weight = 0;
  for (const Inertia& I : frame.inertia)
    for (std::size_t r = 0; r < 3; ++r) weight -= tree.gravity[r] * I.h[r];  // h = m c in the world
  return prog.name(weight);
}

// Whether forces or joint dampers act (the energy is then not an invariant).
bool forced(const Model& model, const KinematicTree& tree) {
  bool any = false;
  for (const ex& q : model.forces) any = any || !q.is_zero();
  for (const TreeBody& body : tree.bodies) any = any || !body.damping.is_zero();
  return any;
}

// Gravity as an upward acceleration of the base, (0, −g) (Featherstone): every body's wrench then carries its weight
// without a separate potential gradient.
Vec6 gravity_as_base_acceleration(const KinematicTree& tree) {
  return join({0, 0, 0}, {-tree.gravity[0], -tree.gravity[1], -tree.gravity[2]});
}

// The bodies in the order of the recursion: body 0 is the base, body k + 1 moves with r^k. Each body's parent, its
// joint's pose in the parent's frame, its axis and its spatial inertia in its own frame.
struct TreeBodies {
  std::vector<int> parent;
  std::vector<Link> link;
  std::vector<Vec6> axis;
  std::vector<Mat6> inertia;
};

TreeBodies tree_bodies(const KinematicTree& tree, TreeProgram& prog) {
  const std::size_t N = tree.bodies.size() + 1;
  TreeBodies b{std::vector<int>(N, -1), std::vector<Link>(N), std::vector<Vec6>(N), std::vector<Mat6>(N)};
  b.inertia[0] = spatial_inertia(tree.base);
  for (std::size_t i = 1; i < N; ++i) {
    const TreeBody& body = tree.bodies[i - 1];
    b.parent[i] = body.parent + 1;
    b.link[i] = prog.link(body);
    b.axis[i] = body.prismatic ? join({0, 0, 0}, {body.axis[0], body.axis[1], body.axis[2]})
                               : join({body.axis[0], body.axis[1], body.axis[2]}, {0, 0, 0});
    b.inertia[i] = spatial_inertia(body.body);
  }
  return b;
}

// The recursion for the Jacobian (derive/tree_derivatives.hpp), with every body's pose, axis and inertia in the
// common frame (base frame, or the world on a fixed base), from which M is formed; its accelerations and joint
// forces are set once the forcing is known.
std::shared_ptr<TreeRecursion> tree_recursion(const Model& model, const KinematicTree& tree, const TreeBodies& b,
                                              const std::vector<Vec6>& base,
                                              const std::vector<GiNaC::realsymbol>& group_velocity,
                                              Intermediates& tape) {
  auto recursion = std::make_shared<TreeRecursion>();
  recursion->parent = b.parent;
  recursion->link = b.link;
  recursion->axis = b.axis;
  recursion->bodies.push_back(tree.base);
  for (const TreeBody& body : tree.bodies) recursion->bodies.push_back(body.body);
  recursion->base = base;
  recursion->base_acceleration = gravity_as_base_acceleration(tree);
  recursion->base_velocity.assign(group_velocity.begin(), group_velocity.end());
  recursion->coordinates.assign(model.coordinates.begin(), model.coordinates.end());
  recursion->rates.assign(model.rates.begin(), model.rates.end());
  for (const TreeBody& body : tree.bodies) recursion->armature.push_back(body.armature);
  recursion->frame = common_frame(*recursion, tape);
  return recursion;
}

// The body-frame pass at u̇ = 0: twists V_i = Ad_{g_pi⁻¹} V_p + S_i ṙ_i, accelerations a_i (the velocity-product
// terms ad_{V_i} S_i ṙ_i carried outward from gravity_as_base_acceleration), momenta h_i = 𝕀_i V_i, the
// Euler–Poincaré wrenches F summed from the leaves to the base (children come after their parents, each body's
// total named once), and the kinetic energy.
struct BodyFramePass {
  std::vector<Vec6> V, a, h, F;
  ex kinetic = 0;
};

BodyFramePass body_frame_pass(const Model& model, const KinematicTree& tree, const TreeBodies& b,
                              const std::vector<Vec6>& base, const std::vector<GiNaC::realsymbol>& group_velocity,
                              TreeProgram& prog) {
  const std::size_t N = b.parent.size();
  BodyFramePass pass{std::vector<Vec6>(N), std::vector<Vec6>(N), std::vector<Vec6>(N), std::vector<Vec6>(N), 0};
  Vec6 base_twist = zero6();
  for (std::size_t alpha = 0; alpha < group_velocity.size(); ++alpha)
    base_twist = base_twist + base[alpha] * group_velocity[alpha];
  pass.V[0] = base_twist;
  pass.a[0] = gravity_as_base_acceleration(tree);
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) {
      const std::size_t p = static_cast<std::size_t>(b.parent[i]);
      const Vec6 joint = b.axis[i] * model.rates[i - 1];
      pass.V[i] = prog.name(b.link[i].to_child(pass.V[p]) + joint);
      pass.a[i] = prog.name(b.link[i].to_child(pass.a[p]) + ad(pass.V[i], joint));
    }
    pass.h[i] = prog.name(times(b.inertia[i], pass.V[i]));
    pass.kinetic += dot(pass.V[i], pass.h[i]) / 2;
    if (i > 0) pass.kinetic += tree.bodies[i - 1].armature * GiNaC::pow(model.rates[i - 1], 2) / 2;
    pass.F[i] = times(b.inertia[i], pass.a[i]) + coadjoint_term(pass.V[i], pass.h[i]);
  }
  for (std::size_t i = N; i-- > 1;) {
    pass.F[i] = prog.name(pass.F[i]);
    const std::size_t p = static_cast<std::size_t>(b.parent[i]);
    pass.F[p] = pass.F[p] + b.link[i].to_parent(pass.F[i]);
  }
  pass.F[0] = prog.name(pass.F[0]);
  return pass;
}

}  // namespace

TreeDerivation derive_tree(const Model& model, bool articulated) {
  // A fixed base (model.tree, no group) is the same recursion with no base directions (m = 0).
  const bool fixed = !model.bundle;
  const KinematicTree& tree = fixed ? *model.tree : *model.bundle->tree;
  const std::vector<GiNaC::realsymbol> group_velocity =
      fixed ? std::vector<GiNaC::realsymbol>{} : model.bundle->group_velocity;
  TreeDerivation out;
  HamelEquations& eq = out.equations;
  // The model's definitions come first (forces and the potential may use them), then the recursion's names.
  eq.intermediates = model.definitions;
  TreeProgram prog(eq.intermediates);

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
  const std::vector<Vec6> base = fixed ? std::vector<Vec6>{} : base_directions(model.bundle->group);
  const ex base_potential = fixed ? ex(0) : model.bundle->potential;

  const TreeBodies bodies = tree_bodies(tree, prog);
  const std::shared_ptr<TreeRecursion> recursion =
      tree_recursion(model, tree, bodies, base, group_velocity, eq.intermediates);
  const BodyFramePass pass = body_frame_pass(model, tree, bodies, base, group_velocity, prog);

  const std::size_t d = m + n;
  eq.mass_matrix = composite_mass_matrix(recursion->frame, bodies.parent, base, tree, prog);

  // Symbols for u̇ at which the Jacobian differentiates the inverse dynamics (TreeRecursion::accelerations).
  for (std::size_t k = 0; k < m + n; ++k)
    eq.acceleration_symbols.emplace_back(GiNaC::realsymbol("a_" + std::to_string(k)));

  // f = Q − (velocity-product part of the projected wrenches); Q_I = forces_I − ∂V/∂r^I, none on the base.
  // The joint forces τ_I = Q_I − ∂(V + springs)/∂r^I − d_I ṙ_I, shared by f and the articulated-body algorithm.
  eq.forcing.assign(d, 0);
  for (std::size_t alpha = 0; alpha < m; ++alpha) eq.forcing[alpha] = -dot(base[alpha], pass.F[0]);
  const ex springs = joint_springs(model, tree);
  std::vector<ex> joint_force(N);
  for (std::size_t i = 1; i < N; ++i) {
    const TreeBody& body = tree.bodies[i - 1];
    joint_force[i] = model.forces[i - 1] - (base_potential + springs).diff(model.coordinates[i - 1]) -
                     body.damping * model.rates[i - 1];
    eq.forcing[m + i - 1] = joint_force[i] - dot(bodies.axis[i], pass.F[i]);
  }
  recursion->accelerations.assign(eq.acceleration_symbols.begin(), eq.acceleration_symbols.end());
  recursion->joint_force.assign(joint_force.begin() + 1, joint_force.end());
  eq.tree = recursion;

  if (articulated) {
    std::vector<ex> armature(N, ex(0));
    for (std::size_t i = 1; i < N; ++i) armature[i] = tree.bodies[i - 1].armature;
    articulated_body(prog.namer(), {bodies.parent, bodies.link, bodies.axis, bodies.inertia, pass.V, pass.h}, base,
                     pass.a[0], model.rates, joint_force, armature, eq);
  }

  for (std::size_t k = 0; k < d; ++k) eq.independent.push_back(static_cast<int>(k));
  eq.factor_last_first = true;  // u = (ξ, ṙ) in body order: parents before children
  for (std::size_t I = 0; I < n; ++I) eq.kinematics.push_back(model.rates[I]);
  const ex T = prog.name(pass.kinetic);
  const ex weight = weight_potential(tree, recursion->frame, prog);
  eq.reduced_lagrangian = T - base_potential - springs - weight;
  eq.energy_terms = {T + base_potential + springs + weight};
  eq.conservative = !forced(model, tree);

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
