#include "import/tree_import.hpp"

#include "model/expression_parser.hpp"
#include "model/physical_checks.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace hamel {

const std::vector<std::string>& ignorable_categories() {
  static const std::vector<std::string> c{"contacts", "tendons",   "equality", "limits",
                                          "gravity",  "actuators", "friction", "fluid"};
  return c;
}

void MassProperties::add(double m, const double c[3], const double I[3][3]) {
  const double total = mass + m;
  // Shares of the new total (each at most 1, so nothing below overflows that the data does not): the new centre is
  // com + (m / total) d, and the parallel-axis term m1 m2 / total |d|^2 = mass (m / total) |d|^2.
  const double share = total > 0 ? m / total : 0;
  const double d[3] = {c[0] - com[0], c[1] - com[1], c[2] - com[2]};
  const double reduced = mass * share;  // m1 m2 / (m1 + m2)
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inertia[i][j] += I[i][j] + reduced * ((i == j ? dd : 0) - d[i] * d[j]);
  for (int i = 0; i < 3; ++i) com[i] = mass > 0 || m > 0 ? com[i] + share * d[i] : 0;
  mass = total;
}

void MassProperties::about_com(double c[3], double I[3][3]) const {
  for (int i = 0; i < 3; ++i) {
    c[i] = com[i];
    for (int j = 0; j < 3; ++j) I[i][j] = inertia[i][j];
  }
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

// YAML double-quoted scalar: quotes, backslashes and every control character escaped (a path with a newline or an
// escape sequence in it stays one value).
std::string yaml_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

bool finite(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

bool finite(const Frame& f) { return finite(f.p, 3) && finite(&f.R[0][0], 9); }

// The eigenvalues of a symmetric 3×3 matrix, ascending (Smith's closed form).
void symmetric_eigenvalues(const double A[3][3], double out[3]) {
  const double p1 = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
  const double q = (A[0][0] + A[1][1] + A[2][2]) / 3;
  if (p1 == 0) {
    out[0] = A[0][0], out[1] = A[1][1], out[2] = A[2][2];
  } else {
    const double p2 =
        (A[0][0] - q) * (A[0][0] - q) + (A[1][1] - q) * (A[1][1] - q) + (A[2][2] - q) * (A[2][2] - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    double B[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) B[i][j] = (A[i][j] - (i == j ? q : 0)) / p;
    const double det = B[0][0] * (B[1][1] * B[2][2] - B[1][2] * B[2][1]) -
                       B[0][1] * (B[1][0] * B[2][2] - B[1][2] * B[2][0]) +
                       B[0][2] * (B[1][0] * B[2][1] - B[1][1] * B[2][0]);
    const double r = std::clamp(det / 2, -1.0, 1.0);
    const double phi = std::acos(r) / 3;
    out[2] = q + 2 * p * std::cos(phi);
    out[0] = q + 2 * p * std::cos(phi + 2 * M_PI / 3);
    out[1] = 3 * q - out[0] - out[2];
  }
  std::sort(out, out + 3);
}

// Mass properties as a body of the tree can have them; `who` names the body in the message.
void check_mass_properties(const MassProperties& m, const SourceLocation& where, const std::string& who) {
  if (!std::isfinite(m.mass) || !finite(m.com, 3) || !finite(&m.inertia[0][0], 9))
    throw InputError(where, who,
                     "its mass, centre of mass or inertia (with every body merged into it) is not a finite number, or "
                     "beyond the range of a double; expected finite values");
  if (m.mass < 0) throw InputError(where, who, "its mass is " + number(m.mass) + "; expected a mass of at least 0");
  double com[3], I[3][3];
  m.about_com(com, I);
  double scale = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) scale = std::max(scale, std::abs(I[i][j]));
  const double eps = 1e-9 * scale;
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (std::abs(I[i][j] - I[j][i]) > eps)
        throw InputError(where, who, "its inertia is not symmetric; expected a symmetric inertia tensor");
  double l[3];
  symmetric_eigenvalues(I, l);
  if (l[0] < -eps)
    throw InputError(where, who,
                     "its inertia has a negative principal moment (" + number(l[0]) +
                         "); expected a positive semi-definite inertia tensor");
  if (l[2] > l[0] + l[1] + eps)
    throw InputError(where, who,
                     "its principal moments of inertia " + number(l[0]) + ", " + number(l[1]) + ", " + number(l[2]) +
                         " violate the triangle inequality (the largest exceeds the sum of the others); expected "
                         "the moments of a physical body");
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

void check_imported_tree(const ImportedTree& t) {
  if (!finite(t.gravity, 3))
    throw InputError(t.gravity_where, "gravity", "is not a finite vector; expected three finite numbers");
  if (!finite(t.base_pose))
    throw InputError(t.base_where, "base", "its position or orientation is not finite; expected finite numbers");
  if (t.floating) check_mass_properties(t.base, t.base_where, "base '" + t.base_name + "'");
  // What each joint carries: its body and every body beyond it.
  std::vector<double> carried(t.bodies.size(), 0.0);
  for (std::size_t k = t.bodies.size(); k-- > 0;) {
    const ImportedBody& b = t.bodies[k];
    const std::string who = b.what.empty() ? "joint '" + b.joint + "'" : b.what;
    if (!finite(b.joint_frame))
      throw InputError(b.where, who,
                       "its origin (position or orientation) is not finite, or its orientation is a zero "
                       "quaternion; expected finite numbers and a non-zero quaternion");
    const double n = std::sqrt(b.axis[0] * b.axis[0] + b.axis[1] * b.axis[1] + b.axis[2] * b.axis[2]);
    if (!finite(b.axis, 3) || !(n > 0)) throw InputError(b.where, who + " axis", "expected a finite, non-zero axis");
    for (const auto& [value, name] :
         {std::pair{b.damping, "damping"}, std::pair{b.armature, "armature"}, std::pair{b.stiffness, "stiffness"},
          std::pair{b.reference, "spring reference"}}) {
      if (!std::isfinite(value))
        throw InputError(b.where, who + " " + name, "is not a finite number; expected a finite value");
      if (value < 0 && std::string(name) != "spring reference")
        throw InputError(b.where, who + " " + name, "is " + number(value) + "; expected a value of at least 0");
    }
    for (const auto& [input, gain] : b.drives)
      if (!std::isfinite(gain))
        throw InputError(b.where, who, "the gain of its input " + input + " is not finite; expected a finite gain");
    check_mass_properties(b.inertial, b.where, "body '" + b.name + "' (moved by " + who + ")");
    double weight = b.inertial.mass;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) weight += std::abs(b.inertial.inertia[i][j]);
    carried[k] += weight;
    if (b.parent >= 0) carried[static_cast<std::size_t>(b.parent)] += carried[k];
    if (carried[k] == 0 && b.armature == 0)
      throw InputError(b.where, who,
                       "moves nothing: body '" + b.name +
                           "' and every body beyond it have no mass and no inertia, so the mass matrix would be "
                           "singular; expected an <inertial> with a positive mass on a body it moves (or armature)");
  }
  // What carries mass can still move nothing along a joint's motion: a point mass on a hinge's axis, a link whose
  // only mass sits on the axis of a second, coaxial hinge. The mass matrix is then singular at every configuration
  // (with closed loops only the constrained one counts: a massless body welded to another is fine).
  if (!t.loops.empty()) return;
  std::vector<NumericTreeBody> numeric;
  for (const ImportedBody& b : t.bodies) {
    NumericTreeBody n;
    n.parent = b.parent;
    n.prismatic = b.prismatic;
    n.mass = b.inertial.mass;
    n.armature = b.armature;
    b.inertial.about_com(n.com, n.inertia);
    for (int i = 0; i < 3; ++i) {
      n.axis[i] = b.axis[i];
      n.offset[i] = b.joint_frame.p[i];
      for (int j = 0; j < 3; ++j) n.rotation[i][j] = b.joint_frame.R[i][j];
    }
    numeric.push_back(n);
  }
  NumericTreeBody base;
  base.mass = t.base.mass;
  t.base.about_com(base.com, base.inertia);
  const int k = singular_tree_joint(numeric, t.floating ? &base : nullptr, {0, 1, 2, 3, 4, 5});  // SE3
  if (k == -2)
    throw InputError(t.base_where, "base '" + t.base_name + "'",
                     "the floating base and the bodies it carries have no mass or inertia along one of its motions, "
                     "so the mass matrix would be singular; expected an <inertial> with a positive mass and inertia");
  if (k >= 0) {
    const ImportedBody& b = t.bodies[static_cast<std::size_t>(k)];
    throw InputError(b.where, b.what.empty() ? "joint '" + b.joint + "'" : b.what,
                     "moves no mass or inertia along its motion that the joints beyond it do not take up (body '" +
                         b.name +
                         "' and the bodies it carries, at three sampled configurations), so the mass "
                         "matrix would be singular; expected an <inertial> the joint moves off its axis (or armature)");
  }
}

std::string tree_model_yaml(const ImportedTree& t) {
  std::ostringstream y;
  y << "# Imported by `hamel import` from " << printable(t.source) << " (" << t.format << ").\n";
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
  if (!t.loops.empty()) {
    y << "loops:   # closed loops (MJCF <equality>): a point, or a frame, of body held on one of to\n";
    for (const ImportedLoop& l : t.loops) {
      y << "  - name: " << l.name << "\n";
      y << "    type: " << (l.weld ? "weld" : "connect") << "\n";
      y << "    body: " << l.body << "\n";
      y << "    point: " << vec(l.point) << "\n";
      if (l.weld && !identity(l.rotation)) y << "    rotation: " << mat(l.rotation) << "\n";
      y << "    to: " << l.to << "\n";
      y << "    to_point: " << vec(l.to_point) << "\n";
      if (l.weld) y << "    to_rotation: " << mat(l.to_rotation) << "\n";
    }
  }
  return y.str();
}

}  // namespace hamel
