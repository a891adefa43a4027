#include "import/tree_import.hpp"

#include "model/expression_parser.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <sstream>

namespace hamel {

const std::vector<std::string>& ignorable_categories() {
  static const std::vector<std::string> c{"contacts", "tendons",   "equality", "limits",
                                          "gravity",  "actuators", "friction", "fluid"};
  return c;
}

void MassProperties::add(double m, const double c[3], const double I[3][3]) {
  mass += m;
  const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (int i = 0; i < 3; ++i) {
    moment[i] += m * c[i];
    for (int j = 0; j < 3; ++j) origin_inertia[i][j] += I[i][j] + m * ((i == j ? cc : 0) - c[i] * c[j]);
  }
}

void MassProperties::about_com(double com[3], double inertia[3][3]) const {
  for (int i = 0; i < 3; ++i) com[i] = mass > 0 ? moment[i] / mass : 0;
  const double cc = com[0] * com[0] + com[1] * com[1] + com[2] * com[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inertia[i][j] = origin_inertia[i][j] - mass * ((i == j ? cc : 0) - com[i] * com[j]);
}

namespace {

// Shortest decimal that reads back as the same double; values within 1e-14 of the largest entry's scale
// of zero are rounding noise of frame compositions and written as 0.
std::string number(double v, double scale = 1) {
  if (std::abs(v) <= 1e-14 * std::max(scale, 1e-300) || v == 0) return "0";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string vec(const double* v) {
  const double s = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  return "[" + number(v[0], s) + ", " + number(v[1], s) + ", " + number(v[2], s) + "]";
}

std::string mat(const double m[3][3]) {
  double s = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s = std::max(s, std::abs(m[i][j]));
  std::string out = "[";
  for (int i = 0; i < 3; ++i) {
    out += i ? ", [" : "[";
    for (int j = 0; j < 3; ++j) out += (j ? ", " : "") + number(m[i][j], s);
    out += "]";
  }
  return out + "]";
}

bool identity(const double R[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(R[i][j] - (i == j ? 1 : 0)) > 1e-15) return false;
  return true;
}

// YAML double-quoted scalar.
std::string yaml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

void inertial_lines(std::ostringstream& y, const std::string& indent, const MassProperties& m) {
  double com[3], I[3][3];
  m.about_com(com, I);
  // Symmetrize exactly: the loader checks Θ = Θᵀ symbolically.
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) I[i][j] = I[j][i] = (I[i][j] + I[j][i]) / 2;
  y << indent << "mass: " << number(m.mass) << "\n";
  y << indent << "com: " << vec(com) << "\n";
  y << indent << "inertia: " << mat(I) << "\n";
}

}  // namespace

std::string tree_model_yaml(const ImportedTree& t) {
  std::ostringstream y;
  y << "# Imported by `hamel import` from " << t.source << " (" << t.format << ").\n";
  y << "schema: 1\n";
  y << "name: " << t.name << "\n";
  std::string description = "Imported from " + t.source + " (" + t.format + ")" +
                            (t.floating ? "; floating base '" + t.base_name + "' (SE3)" : "; fixed base");
  if (!t.left_out.empty()) {
    description += "; left out:";
    for (std::size_t i = 0; i < t.left_out.size(); ++i)
      description += (i ? "," : "") + std::string(" ") + t.left_out[i];
  }
  y << "description: " << yaml_string(description) << "\n";
  if (t.floating) {
    y << "group: SE3\ntrivialization: left\n";
    y << "group_velocity: [wx, wy, wz, vx, vy, vz]   # the base frame's body twist\n";
    y << "connection: mechanical\n";
  }
  const bool gravity = t.gravity[0] != 0 || t.gravity[1] != 0 || t.gravity[2] != 0;
  if (t.floating && gravity && !identity(t.base_pose.R)) {
    // The base starts turned: gravity in its frame, Γ(0) = Rᵀ g, is where the state starts.
    double start[3];
    for (int i = 0; i < 3; ++i)
      start[i] =
          t.base_pose.R[0][i] * t.gravity[0] + t.base_pose.R[1][i] * t.gravity[1] + t.base_pose.R[2][i] * t.gravity[2];
    y << "initial: {gravity_x: " << number(start[0]) << ", gravity_y: " << number(start[1])
      << ", gravity_z: " << number(start[2]) << "}   # gravity in the base frame as the file orients it\n";
  }
  y << "tree:\n";
  if (t.floating) {
    y << "  base:\n    name: " << t.base_name << "\n";
    inertial_lines(y, "    ", t.base);
    if (gravity)
      y << "  gravity: " << vec(t.gravity) << "   # in the world frame; the state holds it in the base frame\n";
  } else {
    y << "  base: world   # fixed base: the bodies hang from the world frame\n";
    if (gravity) y << "  gravity: " << vec(t.gravity) << "   # in the world frame\n";
  }
  y << "  bodies:\n";
  const std::string base_label = t.floating ? t.base_name : "world";
  for (const ImportedBody& b : t.bodies) {
    y << "    - name: " << b.name << "\n";
    y << "      parent: " << (b.parent < 0 ? base_label : t.bodies[static_cast<std::size_t>(b.parent)].name) << "\n";
    y << "      joint:\n";
    y << "        name: " << b.joint << "\n";
    y << "        type: " << (b.prismatic ? "prismatic" : "revolute") << "\n";
    y << "        axis: " << vec(b.axis) << "\n";
    y << "        offset: " << vec(b.joint_frame.p) << "\n";
    if (!identity(b.joint_frame.R)) y << "        rotation: " << mat(b.joint_frame.R) << "\n";
    if (b.armature != 0) y << "        armature: " << number(b.armature) << "\n";
    if (b.damping != 0) y << "        damping: " << number(b.damping) << "\n";
    if (b.stiffness != 0) y << "        stiffness: " << number(b.stiffness) << "\n";
    if (b.stiffness != 0 && b.reference != 0) y << "        reference: " << number(b.reference) << "\n";
    inertial_lines(y, "      ", b.inertial);
  }
  bool driven = false;
  for (const ImportedBody& b : t.bodies) driven = driven || !b.drives.empty();
  if (driven) {
    y << "forces:   # one generalized force per joint, in body order\n";
    for (const ImportedBody& b : t.bodies) {
      std::string f;
      for (const auto& [input, gain] : b.drives)
        f += (f.empty() ? "" : " + ") + (gain == 1 ? input : number(gain) + "*" + input);
      y << "  - " << (f.empty() ? "0" : f) << "   # " << b.joint << "\n";
    }
    y << "inputs: [";
    for (std::size_t i = 0; i < t.inputs.size(); ++i) y << (i ? ", " : "") << t.inputs[i];
    y << "]\n";
  }
  return y.str();
}

}  // namespace hamel
