#include "numeric/body_poses.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace hamel {

namespace {

double value(const GiNaC::ex& e, const GiNaC::exmap& at, const std::string& what) {
  const GiNaC::ex v = e.subs(at).evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real()) {
    std::ostringstream text;
    text << v;
    throw std::runtime_error(what + " has no real value at the run's parameters: " + text.str());
  }
  return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
}

BodyInertiaValues inertia_values(const RigidBody& body, const GiNaC::exmap& at) {
  BodyInertiaValues out;
  out.name = body.name;
  out.mass = value(body.mass, at, body.name + ".mass");
  for (int i = 0; i < 3; ++i) {
    out.com[i] = value(body.com[i], at, body.name + ".com");
    for (int j = 0; j < 3; ++j) out.inertia[3 * i + j] = value(body.inertia[i][j], at, body.name + ".inertia");
  }
  return out;
}

// exp(q S) of a joint: a rotation by q about the unit axis (Rodrigues) or a translation by q along it.
Placement joint_motion(const std::array<double, 3>& a, double q, bool prismatic) {
  Placement m;
  if (prismatic) {
    m.p = {q * a[0], q * a[1], q * a[2]};
    return m;
  }
  const double c = std::cos(q), s = std::sin(q), v = 1 - c;
  m.R = {c + a[0] * a[0] * v,        a[0] * a[1] * v - a[2] * s, a[0] * a[2] * v + a[1] * s,
         a[1] * a[0] * v + a[2] * s, c + a[1] * a[1] * v,        a[1] * a[2] * v - a[0] * s,
         a[2] * a[0] * v - a[1] * s, a[2] * a[1] * v + a[0] * s, c + a[2] * a[2] * v};
  return m;
}

}  // namespace

Placement compose(const Placement& a, const Placement& b) {
  Placement out;
  for (int i = 0; i < 3; ++i) {
    out.p[i] = a.p[i];
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a.R[3 * i + k] * b.R[3 * k + j];
      out.R[3 * i + j] = s;
      out.p[i] += a.R[3 * i + j] * b.p[j];
    }
  }
  return out;
}

InertiaBox inertia_box(const BodyInertiaValues& body) {
  Eigen::Matrix3d theta;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) theta(i, j) = 0.5 * (body.inertia[3 * i + j] + body.inertia[3 * j + i]);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(theta);
  Eigen::Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1;
  const Eigen::Vector3d I = eig.eigenvalues();
  InertiaBox box;
  for (int k = 0; k < 3; ++k) {
    const double a2 = body.mass > 0 ? 6 * (I((k + 1) % 3) + I((k + 2) % 3) - I(k)) / body.mass : 0;
    box.edges[k] = a2 > 0 ? std::sqrt(a2) : 0;
  }
  for (int i = 0; i < 3; ++i) {
    box.in_body.p[i] = body.com[i];
    for (int j = 0; j < 3; ++j) box.in_body.R[3 * i + j] = axes(i, j);
  }
  return box;
}

BodyPoses::BodyPoses(const Model& model, const std::vector<double>& parameters) : model_(model) {
  for (std::size_t k = 0; k < model.parameters.size() && k < parameters.size(); ++k)
    parameters_[model.parameters[k].symbol] = parameters[k];
  tree_ = model.tree                           ? &*model.tree
          : model.bundle && model.bundle->tree ? &*model.bundle->tree
          : model.closed_tree                  ? &*model.closed_tree
                                               : nullptr;
  if (tree_) {
    floating_ = !tree_->fixed_base;
    bodies_.push_back(inertia_values(tree_->base, parameters_));
    for (const TreeBody& b : tree_->bodies) {
      bodies_.push_back(inertia_values(b.body, parameters_));
      Placement frame;
      std::array<double, 3> axis{};
      for (int i = 0; i < 3; ++i) {
        frame.p[i] = value(b.offset[i], parameters_, b.body.name + ".joint.offset");
        axis[i] = value(b.axis[i], parameters_, b.body.name + ".joint.axis");
        for (int j = 0; j < 3; ++j)
          frame.R[3 * i + j] = value(b.rotation[i][j], parameters_, b.body.name + ".joint.rotation");
      }
      const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
      for (double& a : axis) a /= norm;
      joint_frame_.push_back(frame);
      axis_.push_back(axis);
    }
    return;
  }
  if (model.bundle) return;
  for (const PosedBody& b : model.posed_bodies) bodies_.push_back(inertia_values(b.body, parameters_));
}

std::vector<Placement> BodyPoses::at(double t, const std::vector<double>& q, const Placement& base) const {
  std::vector<Placement> out;
  if (tree_) {
    out.push_back(floating_ ? base : Placement{});
    for (std::size_t k = 0; k < tree_->bodies.size(); ++k) {
      const TreeBody& b = tree_->bodies[k];
      const Placement& parent = out[static_cast<std::size_t>(b.parent + 1)];
      out.push_back(compose(compose(parent, joint_frame_[k]), joint_motion(axis_[k], q.at(k), b.prismatic)));
    }
    return out;
  }
  GiNaC::exmap at = parameters_;
  at[model_.time] = t;
  for (std::size_t a = 0; a < model_.coordinates.size(); ++a) at[model_.coordinates[a]] = q.at(a);
  Intermediates::ValueMemo memo;
  const auto eval = [&](const GiNaC::ex& e, const std::string& what) {
    const GiNaC::ex v = model_.definitions.value_at(e, at, memo);
    if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real())
      throw std::runtime_error(what + " has no real value at t = " + std::to_string(t));
    return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
  };
  for (const PosedBody& b : model_.posed_bodies) {
    Placement pose;
    for (int i = 0; i < 3; ++i) {
      pose.p[i] = eval(b.position[i], b.body.name + ".position");
      for (int j = 0; j < 3; ++j) pose.R[3 * i + j] = eval(b.rotation[i][j], b.body.name + ".rotation");
    }
    out.push_back(pose);
  }
  return out;
}

}  // namespace hamel
