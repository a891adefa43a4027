// The kinetic energy of tree models (hamel::tree_kinetic_energy, the inlined T(ξ, r, ṙ) of the recursion)
// equals kinetic energies written by hand, exactly (GiNaC):
//  - models/satellite_se3_tree.yaml (each rotor a revolute child of the base) against the bundle kinetic
//    energy that models/satellite_se3.yaml assembles from its hand-written twists. The two models declare
//    their own symbols, so those of the tree model are mapped to the satellite's by name;
//  - an SE(2) base with one revolute link, T from the planar formula written in this file;
//  - an SE(2) base with a prismatic link in a rotated joint frame;
//  - an SE(3) base with a prismatic link along a general axis in a rotated joint frame.
// Differences are first expanded; where the two sides use different frames the trigonometric identity
// sin² + cos² = 1 is settled by the rational substitution sin a = 2s/(1+s²), cos a = (1−s²)/(1+s²) and
// GiNaC's normal().
#include "derive/kinematic_tree.hpp"
#include "model/load_model.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>

namespace {

using GiNaC::ex;

std::string model_path(const std::string& name) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/models/" + name + ".yaml";
}

/// Replaces every symbol of `from` by the symbol of `to` with the same name.
ex map_symbols(const ex& e, const hamel::Model& from, const hamel::Model& to) {
  const GiNaC::symtab a = from.symbols(), b = to.symbols();
  GiNaC::exmap m;
  for (const auto& [name, sym] : a) {
    const auto it = b.find(name);
    if (it != b.end()) m[sym] = it->second;
  }
  return e.subs(m);
}

/// How a difference of two kinetic energies was shown to vanish.
enum class Zero { expanded, rational_substitution, not_zero };

Zero vanishes(const ex& difference, const std::vector<GiNaC::realsymbol>& angles) {
  const ex d = difference.expand();
  if (d.is_zero()) return Zero::expanded;
  GiNaC::exmap m;
  for (const auto& a : angles) {
    const GiNaC::realsymbol s(a.get_name() + "_s");
    m[sin(a)] = 2 * s / (1 + s * s);
    m[cos(a)] = (1 - s * s) / (1 + s * s);
  }
  return d.subs(m).normal().is_zero() ? Zero::rational_substitution : Zero::not_zero;
}

std::string text(const ex& e) {
  std::ostringstream s;
  s << e;
  return s.str();
}

TEST(TreeKineticEnergy, SatelliteAsTreeEqualsHandWrittenBundle) {
  const hamel::Model hand = hamel::load_model(model_path("satellite_se3"));
  const hamel::Model tree = hamel::load_model(model_path("satellite_se3_tree"));
  ASSERT_TRUE(hand.bundle.has_value());
  ASSERT_TRUE(tree.bundle.has_value() && tree.bundle->tree.has_value());
  // Same parameters, shape coordinates and group velocity, by name and in the same order.
  ASSERT_EQ(hand.parameters.size(), tree.parameters.size());
  for (std::size_t i = 0; i < hand.parameters.size(); ++i) {
    EXPECT_EQ(hand.parameters[i].symbol.get_name(), tree.parameters[i].symbol.get_name());
    EXPECT_EQ(hand.parameters[i].default_value, tree.parameters[i].default_value);
  }
  ASSERT_EQ(hand.coordinates.size(), tree.coordinates.size());
  for (std::size_t i = 0; i < hand.coordinates.size(); ++i)
    EXPECT_EQ(hand.coordinates[i].get_name(), tree.coordinates[i].get_name());
  ASSERT_EQ(hand.bundle->group_velocity.size(), tree.bundle->group_velocity.size());

  const ex T_tree = map_symbols(hamel::tree_kinetic_energy(tree), tree, hand);
  const ex T_hand = hand.definitions.inline_all(hand.bundle->kinetic);
  const Zero z = vanishes(T_tree - T_hand, hand.coordinates);
  EXPECT_NE(z, Zero::not_zero) << "tree:  " << text(T_tree) << "\nhand:  " << text(T_hand);
  std::printf("satellite_se3_tree: T_tree - T_hand = 0 %s\n",
              z == Zero::expanded ? "after expand()" : "after the rational substitution of sin, cos");
}

// Base: mass m0, centre of mass (c0x, c0y, c0z), inertia with Θzz = J0 (its other entries cannot enter a
// planar motion). Link: revolute about z at (a, b, h) in F_b, mass m1, centre of mass (c1x, c1y, c1z) in
// its frame, Θzz = J1. Planar: ω = w ẑ, a point at r in F_b moves with v + w ẑ × r, ẑ × (x, y) = (−y, x).
TEST(TreeKineticEnergy, PlanarBaseWithOneRevoluteLinkEqualsPlanarFormula) {
  const hamel::Model model = hamel::load_model_from_text(R"(schema: 1
name: se2_one_link
parameters: {m0: 3, c0x: 0.1, c0y: -0.2, c0z: 0.3, J0: 0.5, K0: 0.7, K0xz: 0.05, a: 0.4, b: 0.1, h: 0.2,
             m1: 1, c1x: 0.3, c1y: 0.05, c1z: -0.1, J1: 0.04, K1: 0.02}
group: SE2
trivialization: left
group_velocity: [w, vx, vy]
tree:
  base:
    name: base
    mass: m0
    com: [c0x, c0y, c0z]
    inertia: [[K0, 0, K0xz], [0, K0, 0], [K0xz, 0, J0]]
  bodies:
    - name: link
      parent: base
      joint: {name: q, type: revolute, axis: [0, 0, 1], offset: [a, b, h]}
      mass: m1
      com: [c1x, c1y, c1z]
      inertia: [[K1, 0, 0], [0, K1, 0], [0, 0, J1]]
)",
                                                         "se2_one_link.yaml");
  const GiNaC::symtab s = model.symbols();
  auto S = [&](const char* n) { return s.at(n); };
  const ex w = S("w"), vx = S("vx"), vy = S("vy"), q = S("q"), qd = S("q_dot");
  // Base centre of mass.
  const ex u0x = vx - w * S("c0y"), u0y = vy + w * S("c0x");
  // Link centre of mass in F_b: r = o + R(q) c1 (planar part), relative velocity q̇ ẑ × R(q) c1.
  const ex Rcx = cos(q) * S("c1x") - sin(q) * S("c1y"), Rcy = sin(q) * S("c1x") + cos(q) * S("c1y");
  const ex rx = S("a") + Rcx, ry = S("b") + Rcy;
  const ex u1x = vx - w * ry - qd * Rcy, u1y = vy + w * rx + qd * Rcx;
  const ex T_hand = S("m0") * (u0x * u0x + u0y * u0y) / 2 + S("J0") * w * w / 2 +
                    S("m1") * (u1x * u1x + u1y * u1y) / 2 + S("J1") * (w + qd) * (w + qd) / 2;
  const ex T_tree = hamel::tree_kinetic_energy(model);
  const Zero z = vanishes(T_tree - T_hand, model.coordinates);
  EXPECT_NE(z, Zero::not_zero) << "tree:  " << text(T_tree) << "\nhand:  " << text(T_hand);
}

// Prismatic link: joint frame at (a, b, 0) turned by the angle α with cos α = 3/5, sin α = 4/5 about z,
// sliding along its own x axis; the link keeps the orientation α, so ω = w ẑ.
TEST(TreeKineticEnergy, PlanarBaseWithPrismaticLinkEqualsPlanarFormula) {
  const hamel::Model model = hamel::load_model_from_text(R"(schema: 1
name: se2_slider
parameters: {m0: 3, c0x: 0.1, c0y: -0.2, J0: 0.5, a: 0.4, b: 0.1, m1: 1, c1x: 0.3, c1y: 0.05, J1: 0.04}
group: SE2
trivialization: left
group_velocity: [w, vx, vy]
tree:
  base:
    name: base
    mass: m0
    com: [c0x, c0y, 0]
    inertia: [[0, 0, 0], [0, 0, 0], [0, 0, J0]]
  bodies:
    - name: slider
      parent: base
      joint:
        name: s
        type: prismatic
        axis: [1, 0, 0]
        offset: [a, b, 0]
        rotation: [[3/5, -4/5, 0], [4/5, 3/5, 0], [0, 0, 1]]
      mass: m1
      com: [c1x, c1y, 0]
      inertia: [[0, 0, 0], [0, 0, 0], [0, 0, J1]]
)",
                                                         "se2_slider.yaml");
  const GiNaC::symtab s = model.symbols();
  auto S = [&](const char* n) { return s.at(n); };
  const ex w = S("w"), vx = S("vx"), vy = S("vy"), q = S("s"), qd = S("s_dot");
  const ex ca = GiNaC::numeric(3, 5), sa = GiNaC::numeric(4, 5);
  auto rot = [&](const ex& x, const ex& y) { return std::pair<ex, ex>{ca * x - sa * y, sa * x + ca * y}; };
  const ex u0x = vx - w * S("c0y"), u0y = vy + w * S("c0x");
  const auto [Rx, Ry] = rot(q + S("c1x"), S("c1y"));  // R_α (q e_x + c1)
  const ex rx = S("a") + Rx, ry = S("b") + Ry;
  const auto [ex_x, ex_y] = rot(1, 0);  // sliding direction in F_b
  const ex u1x = vx - w * ry + qd * ex_x, u1y = vy + w * rx + qd * ex_y;
  const ex T_hand = S("m0") * (u0x * u0x + u0y * u0y) / 2 + S("J0") * w * w / 2 +
                    S("m1") * (u1x * u1x + u1y * u1y) / 2 + S("J1") * w * w / 2;
  const ex T_tree = hamel::tree_kinetic_energy(model);
  EXPECT_EQ(vanishes(T_tree - T_hand, {}), Zero::expanded) << "tree:  " << text(T_tree) << "\nhand:  " << text(T_hand);
}

// SE(3) base, prismatic link along the unit axis n = (2, 3, 6)/7 of a joint frame turned by the rational
// rotation R_j of the quaternion (1, 1, 2, 1)/√7: the link's angular velocity is ω, its centre of mass is at
// r = o + R_j (q n + c1) in F_b and moves with v + ω × r + q̇ R_j n; its inertia in F_b is R_j Θ1 R_jᵀ.
TEST(TreeKineticEnergy, SpatialBaseWithPrismaticLinkEqualsRigidBodyFormula) {
  const hamel::Model model = hamel::load_model_from_text(R"(schema: 1
name: se3_slider
parameters: {m0: 5, c0x: 0.1, c0y: -0.2, c0z: 0.05, A0: 1.1, B0: 1.3, C0: 0.9, D0: 0.1, E0: -0.05, F0: 0.02,
             ox: 0.3, oy: -0.1, oz: 0.5, m1: 1.5, c1x: 0.1, c1y: 0.02, c1z: -0.3, A1: 0.2, B1: 0.25, C1: 0.1,
             D1: 0.01, E1: 0.02, F1: -0.03}
group: SE3
trivialization: left
group_velocity: [wx, wy, wz, vx, vy, vz]
tree:
  base:
    name: base
    mass: m0
    com: [c0x, c0y, c0z]
    inertia: [[A0, D0, E0], [D0, B0, F0], [E0, F0, C0]]
  bodies:
    - name: slider
      parent: base
      joint:
        name: s
        type: prismatic
        axis: [2/7, 3/7, 6/7]
        offset: [ox, oy, oz]
        rotation: [[-3/7, 2/7, 6/7], [6/7, 3/7, 2/7], [-2/7, 6/7, -3/7]]
      mass: m1
      com: [c1x, c1y, c1z]
      inertia: [[A1, D1, E1], [D1, B1, F1], [E1, F1, C1]]
)",
                                                         "se3_slider.yaml");
  const GiNaC::symtab s = model.symbols();
  auto S = [&](const std::string& n) { return ex(s.at(n)); };
  using Vec = std::array<ex, 3>;
  auto cross = [](const Vec& a, const Vec& b) {
    return Vec{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  auto dot = [](const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  auto add = [](const Vec& a, const Vec& b) { return Vec{a[0] + b[0], a[1] + b[1], a[2] + b[2]}; };
  auto scale = [](const ex& k, const Vec& a) { return Vec{k * a[0], k * a[1], k * a[2]}; };
  using GiNaC::numeric;
  // Quaternion (1, 1, 2, 1), |.|² = 7: the rotation in the file.
  const ex R[3][3] = {{numeric(-3, 7), numeric(2, 7), numeric(6, 7)},
                      {numeric(6, 7), numeric(3, 7), numeric(2, 7)},
                      {numeric(-2, 7), numeric(6, 7), numeric(-3, 7)}};
  auto apply = [&](const Vec& a) {
    Vec r;
    for (int i = 0; i < 3; ++i) r[i] = R[i][0] * a[0] + R[i][1] * a[1] + R[i][2] * a[2];
    return r;
  };
  const Vec w{S("wx"), S("wy"), S("wz")}, v{S("vx"), S("vy"), S("vz")};
  const Vec n{numeric(2, 7), numeric(3, 7), numeric(6, 7)};
  const ex q = S("s"), qd = S("s_dot");
  auto inertia = [&](const std::string& k) {
    return std::array<Vec, 3>{Vec{S("A" + k), S("D" + k), S("E" + k)}, Vec{S("D" + k), S("B" + k), S("F" + k)},
                              Vec{S("E" + k), S("F" + k), S("C" + k)}};
  };
  const Vec c0{S("c0x"), S("c0y"), S("c0z")};
  const Vec u0 = add(v, cross(w, c0));
  const auto I0 = inertia("0");
  ex T_hand = S("m0") * dot(u0, u0) / 2 + dot(w, Vec{dot(I0[0], w), dot(I0[1], w), dot(I0[2], w)}) / 2;
  const Vec r = add(Vec{S("ox"), S("oy"), S("oz")}, apply(add(scale(q, n), Vec{S("c1x"), S("c1y"), S("c1z")})));
  const Vec u1 = add(add(v, cross(w, r)), scale(qd, apply(n)));
  // ωᵀ R_j Θ1 R_jᵀ ω = (R_jᵀ ω)ᵀ Θ1 (R_jᵀ ω).
  Vec wl;
  for (int i = 0; i < 3; ++i) wl[i] = R[0][i] * w[0] + R[1][i] * w[1] + R[2][i] * w[2];
  const auto I1 = inertia("1");
  T_hand += S("m1") * dot(u1, u1) / 2 + dot(wl, Vec{dot(I1[0], wl), dot(I1[1], wl), dot(I1[2], wl)}) / 2;
  const ex T_tree = hamel::tree_kinetic_energy(model);
  EXPECT_EQ(vanishes(T_tree - T_hand, {}), Zero::expanded) << "tree:  " << text(T_tree) << "\nhand:  " << text(T_hand);
}

}  // namespace
