#include "model/fold_parameters.hpp"

#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

namespace hamel {

Model fold_parameters(const Model& model, const std::map<std::string, double>& values) {
  GiNaC::exmap fold;
  for (const auto& [name, v] : values) {
    bool found = false;
    for (const auto& p : model.parameters)
      if (p.symbol.get_name() == name) {
        fold[p.symbol] = exact_number(v);
        found = true;
      }
    if (!found) throw InputError("--fold: '" + name + "' is not a parameter of model '" + model.name + "'");
  }
  Model out = model;
  for (Parameter& p : out.parameters)
    if (fold.count(p.symbol)) p.folded = true;
  const auto sub = [&](const GiNaC::ex& e) { return e.subs(fold); };
  const auto sub_matrix = [&](GiNaC::matrix& m) {
    for (unsigned i = 0; i < m.rows(); ++i)
      for (unsigned j = 0; j < m.cols(); ++j) m(i, j) = sub(m(i, j));
  };
  out.definitions.substitute_in_definitions(fold);
  out.lagrangian = sub(out.lagrangian);
  for (auto& q : out.forces) q = sub(q);
  sub_matrix(out.A);
  sub_matrix(out.B);
  for (AppliedWrench& w : out.wrenches)
    for (int i = 0; i < 3; ++i)
      for (GiNaC::ex* e : {&w.point[i], &w.force[i], &w.torque[i]}) *e = sub(*e);
  for (auto& d : out.state_defaults) d.second = sub(d.second);
  for (HolonomicConstraint& h : out.holonomic) {
    h.g = sub(h.g);
    for (GiNaC::ex& e : h.gradient) e = sub(e);
  }
  for (PosedBody& b : out.posed_bodies) {
    b.body.mass = sub(b.body.mass);
    for (int i = 0; i < 3; ++i) {
      b.position[i] = sub(b.position[i]);
      b.body.com[i] = sub(b.body.com[i]);
      for (int j = 0; j < 3; ++j) {
        b.rotation[i][j] = sub(b.rotation[i][j]);
        b.body.inertia[i][j] = sub(b.body.inertia[i][j]);
      }
    }
  }
  if (out.bundle) {
    out.bundle->kinetic = sub(out.bundle->kinetic);
    out.bundle->potential = sub(out.bundle->potential);
    sub_matrix(out.bundle->kinematic_connection);
    sub_matrix(out.bundle->constraint_group);
    sub_matrix(out.bundle->constraint_shape);
  }
  for (KinematicTree* tree : {out.bundle && out.bundle->tree ? &*out.bundle->tree : nullptr,
                              out.tree ? &*out.tree : nullptr, out.closed_tree ? &*out.closed_tree : nullptr}) {
    if (tree) {
      for (GiNaC::ex& g : tree->gravity) g = sub(g);
      const auto sub_body = [&](RigidBody& b) {
        b.mass = sub(b.mass);
        for (int i = 0; i < 3; ++i) {
          b.com[i] = sub(b.com[i]);
          for (int j = 0; j < 3; ++j) b.inertia[i][j] = sub(b.inertia[i][j]);
        }
      };
      sub_body(tree->base);
      for (TreeBody& tb : tree->bodies) {
        sub_body(tb.body);
        for (int i = 0; i < 3; ++i) {
          tb.axis[i] = sub(tb.axis[i]);
          tb.offset[i] = sub(tb.offset[i]);
          for (int j = 0; j < 3; ++j) tb.rotation[i][j] = sub(tb.rotation[i][j]);
        }
        for (GiNaC::ex* e : {&tb.armature, &tb.damping, &tb.stiffness, &tb.reference}) *e = sub(*e);
      }
    }
  }
  return out;
}

std::vector<std::size_t> symbolic_parameters(const Model& model) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < model.parameters.size(); ++i)
    if (!model.parameters[i].folded) out.push_back(i);
  return out;
}

}  // namespace hamel
