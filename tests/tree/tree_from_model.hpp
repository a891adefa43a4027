// The reference tree (tree_reference.hpp) of a model file's `tree:` block: the loader's data (masses,
// centres of mass, inertias, axes, offsets, rotations as the file wrote them) evaluated at the parameters'
// default values. Only the parsed numbers are shared with the generator, none of its derivation.
#pragma once

#include "tree_reference.hpp"

#include "model/model.hpp"

#include <ginac/ginac.h>

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace tree_ref {

inline Real evaluate(const GiNaC::ex& e, const GiNaC::exmap& values) {
  const GiNaC::ex v = e.subs(values).evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(v)) {
    std::ostringstream s;
    s << e;
    throw std::runtime_error("tree_ref: not a number: " + s.str());
  }
  return static_cast<Real>(GiNaC::ex_to<GiNaC::numeric>(v).to_double());
}

inline GiNaC::exmap default_values(const hamel::Model& model) {
  GiNaC::exmap m;
  for (const auto& p : model.parameters) m[p.symbol] = p.default_value;
  return m;
}

inline Inertial inertial_of(const hamel::RigidBody& b, const GiNaC::exmap& v) {
  Inertial out;
  out.mass = evaluate(b.mass, v);
  for (int i = 0; i < 3; ++i) {
    out.com[i] = evaluate(b.com[i], v);
    for (int j = 0; j < 3; ++j) out.inertia(i, j) = evaluate(b.inertia[i][j], v);
  }
  return out;
}

inline Tree tree_of(const hamel::Model& model) {
  if (!model.bundle || !model.bundle->tree) throw std::runtime_error("tree_ref: " + model.name + " has no tree");
  const GiNaC::exmap v = default_values(model);
  const hamel::KinematicTree& k = *model.bundle->tree;
  Tree t;
  t.group = model.bundle->group;
  t.base = inertial_of(k.base, v);
  for (const hamel::TreeBody& tb : k.bodies) {
    Body b;
    b.parent = tb.parent;
    b.prismatic = tb.prismatic;
    for (int i = 0; i < 3; ++i) {
      b.axis[i] = evaluate(tb.axis[i], v);
      b.offset[i] = evaluate(tb.offset[i], v);
      for (int j = 0; j < 3; ++j) b.rotation(i, j) = evaluate(tb.rotation[i][j], v);
    }
    b.inertial = inertial_of(tb.body, v);
    t.bodies.push_back(b);
  }
  return t;
}

/// The parameters' default values in file order (the kernels' p).
inline std::vector<double> default_parameters(const hamel::Model& model) {
  std::vector<double> p;
  for (const auto& q : model.parameters) p.push_back(q.default_value);
  return p;
}

}  // namespace tree_ref
