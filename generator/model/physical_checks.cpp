#include "model/physical_checks.hpp"

#include "model/expression_parser.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hamel {

double real_value_at(const GiNaC::ex& e, const GiNaC::exmap& values) {
  try {
    const GiNaC::ex v = e.subs(values).evalf();
    if (GiNaC::is_a<GiNaC::numeric>(v) && GiNaC::ex_to<GiNaC::numeric>(v).is_real())
      return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
  } catch (const std::exception&) {
  }
  return std::nan("");
}

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::vector<double> symmetric_eigenvalues(std::vector<double> a, std::size_t n) {
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0;
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
    if (off < 1e-300) break;
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (apq == 0) continue;
        // Golub & Van Loan, Algorithm 8.4.1: the rotation that zeroes a_pq.
        const double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
        const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (std::size_t k = 0; k < n; ++k) {
          const double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (std::size_t k = 0; k < n; ++k) {
          const double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
      }
  }
  std::vector<double> eig(n);
  for (std::size_t k = 0; k < n; ++k) eig[k] = a[k * n + k];
  std::sort(eig.begin(), eig.end());
  return eig;
}

GiNaC::exmap parameter_defaults(const Model& model) {
  GiNaC::exmap values;
  for (const Parameter& p : model.parameters) values[p.symbol] = exact_number(p.default_value);
  return values;
}

std::string rigid_body_problem(const RigidBody& body, const GiNaC::exmap& values, std::string& subkey) {
  subkey = "mass";
  const double m = real_value_at(body.mass, values);
  if (m < 0) return "the mass is " + number(m) + " at the parameter defaults; expected a mass >= 0";
  subkey = "inertia";
  std::vector<double> theta(9);
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) theta[i * 3 + j] = real_value_at(body.inertia[i][j], values);
  for (double v : theta)
    if (std::isnan(v)) return "";  // not a number at the defaults: nothing to decide here
  const std::vector<double> e = symmetric_eigenvalues(theta, 3);
  const double scale = std::max({std::fabs(e[0]), std::fabs(e[2]), 1e-300});
  const std::string moments = "principal moments " + number(e[0]) + ", " + number(e[1]) + ", " + number(e[2]);
  if (e[0] < -1e-12 * scale)
    return "the inertia is not positive semi-definite at the parameter defaults (" + moments +
           "); expected moments >= 0";
  // Only for bodies with three positive moments: a zero moment marks an idealisation (a slender rod, a lamina
  // of a planar model, 0 0 I) that the equations handle and that the inequality would wrongly refuse.
  if (e[0] > 1e-12 * scale && e[0] + e[1] < e[2] * (1 - 1e-9))
    return "the principal moments violate the triangle inequality at the parameter defaults (" + moments +
           ": the two smaller ones sum to less than the largest); no rigid body has such an inertia";
  return "";
}

std::string joint_axis_problem(const TreeBody& body, const GiNaC::exmap& values) {
  double norm2 = 0;
  for (const GiNaC::ex& a : body.axis) {
    const double v = real_value_at(a, values);
    if (std::isnan(v)) return "";
    norm2 += v * v;
  }
  if (norm2 < 1e-12) return "the joint axis is zero at the parameter defaults; expected a unit vector";
  return "";
}

std::string joint_property_problem(const GiNaC::ex& value, const GiNaC::exmap& values, const std::string& what) {
  const double v = real_value_at(value, values);
  if (v < 0) return "the joint " + what + " is " + number(v) + " at the parameter defaults; expected a value >= 0";
  return "";
}

std::string kinetic_energy_problem(const Model& model) {
  const std::size_t n = model.n();
  if (model.bundle || n == 0 || model.A.rows() != n || model.A.cols() != n) return "";
  // Everything below works on the program (algebra/intermediates.hpp), never on its expansion: the substitution
  // u = A q_dot, the numbers of a configuration and the derivatives by the rates become definitions of a copy, and
  // values are taken through the definitions. Inlined, 60 definitions d_k = d_{k-1}^2 + d_{k-1} are 2^60 terms.
  Intermediates program = model.definitions;
  // u = A(q) q_dot, eq. (u2): the Lagrangian as a function of q and q_dot alone.
  GiNaC::exmap u_of_rates;
  for (std::size_t a = 0; a < model.quasi_velocities.size() && a < n; ++a) {
    GiNaC::ex row = 0;
    for (std::size_t b = 0; b < n; ++b)
      row += model.A(static_cast<unsigned>(a), static_cast<unsigned>(b)) * model.rates[b];
    u_of_rates[model.quasi_velocities[a]] = row;
  }
  GiNaC::exmap at_rest;  // q_dot = 0
  for (std::size_t a = 0; a < n; ++a) at_rest[model.rates[a]] = 0;
  try {
    Intermediates::SubstitutionMemo through_rates;
    const GiNaC::ex L = program.substitute(model.lagrangian, u_of_rates, through_rates);
    for (std::size_t k = 0; k < 3; ++k) {
      GiNaC::exmap values = parameter_defaults(model);
      std::string point;
      for (std::size_t a = 0; a < n; ++a) {
        // The sample configurations of the A checks (derive/quasi_velocities.cpp), chosen the same way.
        const long numerator = static_cast<long>((31 + 17 * a + 53 * k) % 89 + 5);
        const GiNaC::numeric v = GiNaC::numeric(numerator, 71) * ((a + k) % 2 ? -1 : 1);
        values[model.coordinates[a]] = v;
        point += (point.empty() ? "" : ", ") + model.coordinates[a].get_name() + " = " + number(v.to_double());
      }
      values[model.time] = 0;
      for (const auto& u : model.quasi_velocities) values[u] = 0;
      // L at this configuration in floating point (floats, not exact numbers: exact arithmetic through definitions
      // can double the digits per definition), a function of the rates alone, differentiated twice: far cheaper than
      // the Hessian of the symbolic L evaluated entry by entry (`hamel derive` of the Whipple bicycle: 2.5 -> 1.6 s).
      for (auto& [symbol, v] : values) v = v.evalf();
      Intermediates::SubstitutionMemo here;
      const GiNaC::ex L_here = program.substitute(L, values, here);
      const std::vector<GiNaC::symbol> rates(model.rates.begin(), model.rates.end());
      const std::vector<GiNaC::ex> dL = program.diff(L_here, rates);
      Intermediates::ValueMemo rest;
      std::vector<double> h(n * n);
      for (std::size_t a = 0; a < n; ++a) {
        const std::vector<GiNaC::ex> d2L = program.diff(dL[a], rates);
        for (std::size_t b = a; b < n; ++b) {
          const GiNaC::ex v = program.value_at(d2L[b], at_rest, rest);
          if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real())
            return "";  // not a number at the defaults: nothing to decide here
          h[a * n + b] = h[b * n + a] = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
          if (!std::isfinite(h[a * n + b])) return "";
        }
      }
      const std::vector<double> e = symmetric_eigenvalues(h, n);
      const double scale = std::max({std::fabs(e.front()), std::fabs(e.back()), 1e-300});
      if (e.front() < -1e-9 * scale)
        return "the kinetic energy is not positive semi-definite: d^2L/dq_dot^2 has the eigenvalue " +
               number(e.front()) + " at " + point +
               ", q_dot = 0, parameters at their defaults; expected a positive "
               "kinetic energy";
    }
  } catch (const std::exception&) {
    return "";  // not a number at the defaults (a division by zero, an overflow): nothing to decide here
  }
  return "";
}

}  // namespace hamel

namespace hamel {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// A number of the tree's data at `values` (NaN when it is none): a plain number directly, for the 10 000 links of an
// imported chain, anything else through GiNaC.
double tree_value(const GiNaC::ex& e, const GiNaC::exmap& values) {
  if (GiNaC::is_a<GiNaC::numeric>(e) && GiNaC::ex_to<GiNaC::numeric>(e).is_real())
    return GiNaC::ex_to<GiNaC::numeric>(e).to_double();
  return real_value_at(e, values);
}

Mat3 skew(const Vec3& v) {
  Mat3 s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// The spatial inertia (angular rows first) about the world's origin of a body of mass m, centre of mass c and
// rotational inertia Ic about it, all in world axes.
Mat6 spatial_inertia(double m, const Vec3& c, const Mat3& Ic) {
  const Mat3 C = skew(c);
  Mat6 I;
  I.topLeftCorner<3, 3>() = Ic + m * C * C.transpose();
  I.topRightCorner<3, 3>() = m * C;
  I.bottomLeftCorner<3, 3>() = m * C.transpose();
  I.bottomRightCorner<3, 3>() = m * Mat3::Identity();
  return I;
}

// An inertia about point p (a matrix of the motion (omega, v_p)) as one about the point q = p - r: the motion at q
// moves p with v_p = v_q + omega x r, so it is T' I T with T = [[1, 0], [-[r]x, 1]].
Mat6 transported(const Mat6& I, const Vec3& r) {
  Mat6 T = Mat6::Identity();
  T.bottomLeftCorner<3, 3>() = -skew(r);
  return T.transpose() * I * T;
}

}  // namespace

int singular_tree_joint(const std::vector<NumericTreeBody>& bodies, const NumericTreeBody* base,
                        const std::vector<int>& directions, int* base_direction) {
  const std::size_t n = bodies.size();
  std::vector<NumericTreeBody> checked = bodies;
  if (base) checked.push_back(*base);
  for (const NumericTreeBody& b : checked) {
    bool finite = std::isfinite(b.mass) && std::isfinite(b.armature);
    for (int i = 0; i < 3; ++i) {
      finite = finite && std::isfinite(b.com[i]) && std::isfinite(b.axis[i]) && std::isfinite(b.offset[i]);
      for (int j = 0; j < 3; ++j) finite = finite && std::isfinite(b.inertia[i][j]) && std::isfinite(b.rotation[i][j]);
    }
    if (!finite || (b.axis[0] == 0 && b.axis[1] == 0 && b.axis[2] == 0)) return -1;  // nothing to decide here
  }
  // At three configurations (the joint coordinates at the sample values of the A checks, the base at the identity:
  // its pose does not change whether M is singular), the pivots D_i of the articulated-body algorithm, from the leaves
  // in: M is singular exactly when one of them is 0. Every body's inertias are held in world axes about its own joint's
  // origin p_i (never about the world's origin: 1000 links out, those entries were 1e6 and rounded a pivot of 0 to
  // 2e-11 of what the joint moves) and moved to the parent's origin by the links' offsets. D_i is compared with what
  // joint i moves, s_i' I^c_i s_i + armature (I^c_i the composite inertia of its subtree): below 1e-12 of that at
  // every configuration, no motion of joint i has inertia that the joints beyond it would not take up. (The ratio is
  // small in long chains: 5e-10 at 10 000 links.)
  int failed_first = -1;
  for (std::size_t k = 0; k < 3; ++k) {
    std::vector<Mat3> R(n);
    std::vector<Vec3> p(n);
    std::vector<Vec6> s(n);
    std::vector<Mat6> articulated(n), composite(n);
    for (std::size_t i = 0; i < n; ++i) {
      const NumericTreeBody& b = bodies[i];
      const long numerator = static_cast<long>((31 + 17 * i + 53 * k) % 89 + 5);
      const double q = static_cast<double>(numerator) / 71 * ((i + k) % 2 ? -1 : 1);
      const Mat3 R_parent = b.parent < 0 ? Mat3::Identity() : R[static_cast<std::size_t>(b.parent)];
      const Vec3 p_parent = b.parent < 0 ? Vec3::Zero() : p[static_cast<std::size_t>(b.parent)];
      Mat3 rotation, inertia;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) rotation(r, c) = b.rotation[r][c], inertia(r, c) = b.inertia[r][c];
      const Vec3 axis = Vec3(b.axis[0], b.axis[1], b.axis[2]).normalized();
      const Vec3 offset(b.offset[0], b.offset[1], b.offset[2]), com(b.com[0], b.com[1], b.com[2]);
      const Mat3 frame = R_parent * rotation;
      const Vec3 a = frame * axis;  // the axis in world axes
      if (b.prismatic) {
        R[i] = frame;
        p[i] = p_parent + R_parent * offset + a * q;
        s[i] << Vec3::Zero(), a;
      } else {
        R[i] = frame * Eigen::AngleAxisd(q, axis).toRotationMatrix();
        p[i] = p_parent + R_parent * offset;
        s[i] << a, Vec3::Zero();  // about its own origin, on the axis
      }
      articulated[i] = composite[i] = spatial_inertia(b.mass, R[i] * com, R[i] * inertia * R[i].transpose());
    }
    Mat6 base_articulated = Mat6::Zero(), base_composite = Mat6::Zero();
    if (base) {
      Mat3 inertia;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) inertia(r, c) = base->inertia[r][c];
      base_articulated = base_composite =
          spatial_inertia(base->mass, Vec3(base->com[0], base->com[1], base->com[2]), inertia);
    }
    int failed = -1;
    for (std::size_t i = n; i-- > 0;) {
      const Vec6 U = articulated[i] * s[i];
      const double D = s[i].dot(U) + bodies[i].armature;
      const double moved = s[i].dot(composite[i] * s[i]) + bodies[i].armature;
      if (!std::isfinite(D) || !std::isfinite(moved)) return -1;
      if (!(D > 1e-12 * moved) || !(moved > 0)) {
        failed = static_cast<int>(i);
        break;
      }
      const int parent = bodies[i].parent;
      Mat6& to_articulated = parent < 0 ? base_articulated : articulated[static_cast<std::size_t>(parent)];
      Mat6& to_composite = parent < 0 ? base_composite : composite[static_cast<std::size_t>(parent)];
      const Vec3 r = p[i] - (parent < 0 ? Vec3::Zero() : p[static_cast<std::size_t>(parent)]);
      to_articulated += transported(articulated[i] - U * U.transpose() / D, r);
      to_composite += transported(composite[i], r);
    }
    // A floating base (at the world's origin, which is its own): its block <e_a, I^A_0 e_b> over the group's
    // directions, factored as L D L' in their order; a pivot 0 relative to what direction a moves (<e_a, I^c_0 e_a>) is
    // singular.
    if (failed < 0 && base) {
      const std::size_t m = directions.size();
      Eigen::MatrixXd block(m, m);
      for (std::size_t a = 0; a < m; ++a)
        for (std::size_t b = 0; b < m; ++b) block(a, b) = base_articulated(directions[a], directions[b]);
      for (std::size_t a = 0; a < m; ++a) {
        const double moved = base_composite(directions[a], directions[a]);
        const double D = block(a, a);
        if (!std::isfinite(D) || !std::isfinite(moved)) return -1;
        if (!(D > 1e-12 * moved) || !(moved > 0)) {
          failed = -2;
          if (base_direction && k == 0) *base_direction = static_cast<int>(a);
          break;
        }
        for (std::size_t r = a + 1; r < m; ++r)
          for (std::size_t c = a + 1; c < m; ++c) block(r, c) -= block(r, a) * block(a, c) / D;
      }
    }
    if (failed == -1) return -1;  // regular here: M is not singular everywhere
    if (k == 0) failed_first = failed;
  }
  return failed_first;
}

std::string tree_mass_matrix_problem(const Model& model, const KinematicTree& tree, const std::vector<int>& directions,
                                     const std::vector<std::string>& direction_names, int& body) {
  const GiNaC::exmap defaults = parameter_defaults(model);
  const auto numbers = [&](const RigidBody& rb, NumericTreeBody& b) {
    b.mass = tree_value(rb.mass, defaults);
    for (int i = 0; i < 3; ++i) {
      b.com[i] = tree_value(rb.com[i], defaults);
      for (int j = 0; j < 3; ++j) b.inertia[i][j] = tree_value(rb.inertia[i][j], defaults);
    }
  };
  std::vector<NumericTreeBody> bodies;
  for (const TreeBody& tb : tree.bodies) {
    NumericTreeBody b;
    b.parent = tb.parent;
    b.prismatic = tb.prismatic;
    numbers(tb.body, b);
    b.armature = tree_value(tb.armature, defaults);
    for (int i = 0; i < 3; ++i) {
      b.axis[i] = tree_value(tb.axis[i], defaults);
      b.offset[i] = tree_value(tb.offset[i], defaults);
      for (int j = 0; j < 3; ++j) b.rotation[i][j] = tree_value(tb.rotation[i][j], defaults);
    }
    bodies.push_back(b);
  }
  NumericTreeBody base;
  numbers(tree.base, base);
  int direction = -1;
  body = singular_tree_joint(bodies, tree.fixed_base ? nullptr : &base, directions, &direction);
  if (body == -2) {
    const std::string name = direction >= 0 && static_cast<std::size_t>(direction) < direction_names.size()
                                 ? direction_names[direction]
                                 : "";
    return "the mass matrix is singular: the floating base's motion" + (name.empty() ? "" : " along '" + name + "'") +
           " moves no mass or inertia that the joints do not take up (base '" + tree.base.name +
           "' and every body, at three sampled configurations, parameters at their defaults); expected a base or " +
           "bodies with mass and inertia";
  }
  if (body < 0) return "";
  const TreeBody& tb = tree.bodies[static_cast<std::size_t>(body)];
  return "the mass matrix is singular: joint '" + tb.coordinate.get_name() + "' moves no mass or inertia along its " +
         "motion that the joints beyond it do not take up (body '" + tb.body.name + "' and the bodies it carries, at " +
         "three sampled configurations, parameters at their defaults); expected a mass or inertia the joint moves, " +
         "or an armature";
}

}  // namespace hamel
