#include "model/physical_checks.hpp"

#include "model/expression_parser.hpp"

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
