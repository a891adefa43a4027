// Eq. (u2): q̇ = B(q) u with B = A⁻¹; A must be regular (valid local coordinates).
#include "derive/quasi_velocities.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/simplify.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

namespace hamel {

namespace {

SourceLocation location_of(const Model& model, const std::string& key) {
  auto it = model.locations.find(key);
  return it == model.locations.end() ? SourceLocation{model.source_path, 0, 0} : it->second;
}

// A configuration at which A(q) and A·B are also checked numerically: the coordinates at rational
// values that no trigonometric identity singles out, the parameters at their defaults.
struct SamplePoint {
  GiNaC::exmap values;
  std::string text;  // "x = 0.43662, theta = -0.67606, m (default) = 1"
};

std::vector<SamplePoint> sample_points(const Model& model) {
  std::vector<SamplePoint> points(3);
  for (std::size_t k = 0; k < points.size(); ++k) {
    SamplePoint& p = points[k];
    auto show = [&p](const std::string& name, double v) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.6g", v);
      p.text += (p.text.empty() ? "" : ", ") + name + " = " + buf;
    };
    for (std::size_t a = 0; a < model.n(); ++a) {
      const long numerator = static_cast<long>((31 + 17 * a + 53 * k) % 89 + 5);
      const GiNaC::numeric v = GiNaC::numeric(numerator, 71) * ((a + k) % 2 ? -1 : 1);
      p.values[model.coordinates[a]] = v;
      show(model.coordinates[a].get_name(), v.to_double());
    }
    for (const Parameter& param : model.parameters) {
      p.values[param.symbol] = exact_number(param.default_value);
      show(param.symbol.get_name() + " (default)", param.default_value);
    }
  }
  return points;
}

// The real number `e` evaluates to at `p`, if it does (not outside the domain of a function there).
std::optional<double> value_at(const GiNaC::ex& e, const SamplePoint& p) {
  try {
    const GiNaC::ex v = e.subs(p.values).evalf();
    if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real()) return std::nullopt;
    const double d = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
    if (!std::isfinite(d)) return std::nullopt;
    return d;
  } catch (const std::exception&) {
    return std::nullopt;  // a pole at this point
  }
}

// |det A| relative to the product of A's row lengths (Hadamard's bound), by Gaussian elimination with
// partial pivoting in double precision: 0 for a singular matrix, 1 for an orthogonal one.
std::optional<double> relative_determinant(const GiNaC::matrix& A, const SamplePoint& p) {
  const unsigned n = A.rows();
  std::vector<std::vector<double>> m(n, std::vector<double>(n));
  double bound = 1;
  for (unsigned i = 0; i < n; ++i) {
    double row = 0;
    for (unsigned j = 0; j < n; ++j) {
      const std::optional<double> v = value_at(A(i, j), p);
      if (!v) return std::nullopt;
      m[i][j] = *v;
      row += *v * *v;
    }
    bound *= std::sqrt(row);
  }
  if (bound == 0) return 0.0;
  double det = 1;
  for (unsigned c = 0; c < n; ++c) {
    unsigned pivot = c;
    for (unsigned r = c + 1; r < n; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c])) pivot = r;
    if (m[pivot][c] == 0) return 0.0;
    std::swap(m[pivot], m[c]);
    det *= m[c][c];
    for (unsigned r = c + 1; r < n; ++r) {
      const double f = m[r][c] / m[c][c];
      for (unsigned j = c; j < n; ++j) m[r][j] -= f * m[c][j];
    }
  }
  return std::fabs(det) / bound;
}

constexpr double singular_tolerance = 1e-10;  // relative determinant below which A counts as singular
constexpr double inverse_tolerance = 1e-9;    // |A·B − I| entries above which B is not A⁻¹

}  // namespace

QuasiVelocities derive_quasi_velocities(const Model& model) {
  QuasiVelocities qv;
  qv.A = simplify(model.A);
  const unsigned n = qv.A.rows();
  const SourceLocation where_A = location_of(model, "quasi_velocities.A");
  const GiNaC::ex det = simplify(qv.A.determinant());
  if (det.is_zero())
    throw InputError(where_A, "quasi_velocities.A",
                     "A(q) is singular: its determinant is identically zero (shown symbolically); the "
                     "quasi-velocities must be independent combinations of the coordinate rates");

  // Symbolically non-zero is not enough: the simplifier may miss an identity, or the determinant may
  // vanish for the parameters' default values. Singular at every sampled configuration means singular.
  const std::vector<SamplePoint> points = sample_points(model);
  std::optional<double> smallest;
  const SamplePoint* first = nullptr;
  bool regular_somewhere = false;
  for (const SamplePoint& p : points) {
    const std::optional<double> r = relative_determinant(qv.A, p);
    if (!r) continue;
    if (!first) first = &p, smallest = *r;
    regular_somewhere = regular_somewhere || *r > singular_tolerance;
  }
  if (first && !regular_somewhere)
    throw InputError(where_A, "quasi_velocities.A",
                     "A(q) is singular at every sampled configuration (shown numerically; det A = " +
                         quote(to_text(det), 120) + " did not simplify to 0): at " + first->text +
                         ", |det A| divided by the product of its row lengths is " + shortest_decimal(*smallest) +
                         "; the quasi-velocities must be independent combinations of the coordinate rates");

  if (model.B_given) {
    qv.B = simplify(model.B);
    const GiNaC::matrix product = qv.A.mul(qv.B);
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < n; ++j) {
        const GiNaC::ex deviation = product(i, j) - (i == j ? 1 : 0);
        if (is_zero_exactly(deviation)) continue;
        // Not shown to be zero: a sampled configuration where it is not zero proves B wrong; where it is
        // zero at every one, the simplifier merely missed an identity and B is accepted.
        std::string evidence;
        bool checked = false;
        for (const SamplePoint& p : points) {
          const std::optional<double> v = value_at(deviation, p);
          if (!v) continue;
          checked = true;
          if (std::fabs(*v) > inverse_tolerance) {
            evidence = "; at " + p.text + " it is " + shortest_decimal(*v + (i == j ? 1 : 0));
            break;
          }
        }
        if (checked && evidence.empty()) continue;
        throw InputError(location_of(model, "quasi_velocities.B"), "quasi_velocities.B",
                         "B is not the inverse of A: (A*B)[" + std::to_string(i) + "][" + std::to_string(j) +
                             "] simplifies to " + quote(to_text(simplify(product(i, j))), 120) +
                             (i == j ? ", expected 1" : ", expected 0") + evidence);
      }
  } else {
    // GiNaC inverts by elimination; simplify() then applies sin² + cos² = 1 that it does not know.
    qv.B = simplify(qv.A.inverse());
  }
  return qv;
}

}  // namespace hamel
