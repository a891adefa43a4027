// Eq. (u2): q̇ = B(q) u with B = A⁻¹; A must be regular (valid local coordinates).
#include "derive/quasi_velocities.hpp"

#include "algebra/digits_guard.hpp"
#include "algebra/expression_text.hpp"
#include "algebra/identity_test.hpp"
#include "algebra/simplify.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

#include <array>
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

// Regularity of A at a sampled configuration, decided without doubles (a double overflows for
// A = [[1e200]] and underflows for diag(1e200, 1e-200)): the entries are evaluated exactly where they
// are rational there, in 50 digits otherwise. `relative` is |det A| divided by the product of A's row
// lengths (Hadamard's bound): 0 for a singular matrix, 1 for an orthogonal one; in [0, 1], so a double
// holds it. With exact entries A is regular iff det A != 0 (decided in rationals); with 50-digit entries
// iff `relative` exceeds singular_tolerance_50_digits, far above the rounding of an identically singular A.
struct Regularity {
  bool regular;
  double relative;
};

constexpr double singular_tolerance_50_digits = 1e-30;

std::optional<Regularity> regularity_at(const GiNaC::matrix& A, const SamplePoint& p) {
  const unsigned n = A.rows();
  const DigitsGuard digits(50);
  std::vector<std::vector<GiNaC::numeric>> m(n, std::vector<GiNaC::numeric>(n));
  bool exact = true;
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = 0; j < n; ++j) {
      GiNaC::ex v;
      try {
        v = A(i, j).subs(p.values);
        if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_rational()) {
          exact = false;
          v = v.evalf();
        }
      } catch (const std::exception&) {
        return std::nullopt;  // a pole at this point
      }
      if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real()) return std::nullopt;
      m[i][j] = GiNaC::ex_to<GiNaC::numeric>(v);
    }
  GiNaC::numeric bound = 1;
  for (unsigned i = 0; i < n; ++i) {
    GiNaC::numeric row = 0;
    for (unsigned j = 0; j < n; ++j) row += m[i][j] * m[i][j];
    bound *= GiNaC::ex_to<GiNaC::numeric>(GiNaC::sqrt(row).evalf());
  }
  // Gaussian elimination with partial pivoting, in rationals when every entry is one.
  GiNaC::numeric det = 1;
  for (unsigned c = 0; c < n && !det.is_zero(); ++c) {
    unsigned pivot = c;
    for (unsigned r = c + 1; r < n; ++r)
      if (GiNaC::abs(m[r][c]) > GiNaC::abs(m[pivot][c])) pivot = r;
    if (m[pivot][c].is_zero()) {
      det = 0;
      break;
    }
    std::swap(m[pivot], m[c]);
    det *= m[c][c];
    for (unsigned r = c + 1; r < n; ++r) {
      const GiNaC::numeric f = m[r][c] / m[c][c];
      for (unsigned j = c; j < n; ++j) m[r][j] -= f * m[c][j];
    }
  }
  if (det.is_zero() || bound.is_zero()) return Regularity{false, 0.0};
  const double relative = GiNaC::ex_to<GiNaC::numeric>(GiNaC::ex(GiNaC::abs(det) / bound).evalf()).to_double();
  return Regularity{exact || relative > singular_tolerance_50_digits, relative};
}

constexpr double inverse_tolerance = 1e-9;  // |A·B − I| entries above which B is not A⁻¹

}  // namespace

namespace {

bool uses_intermediates(const GiNaC::matrix& m, const Intermediates& program) {
  for (unsigned i = 0; i < m.rows(); ++i)
    for (unsigned j = 0; j < m.cols(); ++j)
      if (!program.used_by(m(i, j)).empty()) return true;
  return false;
}

// B = A⁻¹ by Gauss–Jordan elimination through intermediate symbols: every multiplier and every updated
// entry passes through Intermediates::keep, so small entries stay closed forms and large ones become named
// definitions, and nothing is expanded into one formula. A pivot must not vanish identically (decided
// exactly, algebra/identity_test), and the elimination divides by it also at the configurations where the
// model is used: so the pivot is chosen by partial pivoting on a numeric shadow of the elimination at the
// reference configuration q = 0 (parameters at their defaults) — the one users linearize about — and, where
// A is singular there, at a generic configuration. Otherwise a pivot that is zero at q = 0 (sin φ of an
// upright bicycle) would leave removable 0/0 in B at exactly that point.
GiNaC::matrix eliminate_inverse(const Model& model, const GiNaC::matrix& A, Intermediates& program) {
  const unsigned n = A.rows();
  std::vector<std::vector<GiNaC::ex>> a(n, std::vector<GiNaC::ex>(2 * n, 0));
  for (unsigned i = 0; i < n; ++i) {
    for (unsigned j = 0; j < n; ++j) a[i][j] = A(i, j);
    a[i][n + i] = 1;
  }
  // Numeric shadows: [0] at q = 0, [1] at a generic point.
  std::array<std::vector<std::vector<double>>, 2> shadow;
  for (int s = 0; s < 2; ++s) {
    GiNaC::exmap values;
    values[model.time] = 0;
    for (std::size_t k = 0; k < model.coordinates.size(); ++k)
      values[model.coordinates[k]] =
          s == 0 ? GiNaC::numeric(0) : GiNaC::numeric(static_cast<long>(17 + 23 * k % 41), 73);
    for (const Parameter& p : model.parameters) values[p.symbol] = exact_number(p.default_value);
    const GiNaC::exmap all = program.evaluate(values);
    shadow[static_cast<std::size_t>(s)].assign(n, std::vector<double>(2 * n, 0.0));
    for (unsigned i = 0; i < n; ++i) {
      for (unsigned j = 0; j < n; ++j) {
        const GiNaC::ex v = A(i, j).subs(all).evalf();
        shadow[static_cast<std::size_t>(s)][i][j] =
            GiNaC::is_a<GiNaC::numeric>(v) && GiNaC::ex_to<GiNaC::numeric>(v).is_real()
                ? GiNaC::ex_to<GiNaC::numeric>(v).to_double()
                : std::nan("");
      }
      shadow[static_cast<std::size_t>(s)][i][n + i] = 1;
    }
  }
  for (unsigned c = 0; c < n; ++c) {
    std::vector<unsigned> candidates;
    for (unsigned r = c; r < n; ++r) {
      const GiNaC::ex& e = a[r][c];
      if (e.is_zero()) continue;
      if (!GiNaC::is_a<GiNaC::numeric>(e) && identically_zero(e, program) == Identity::zero) continue;
      candidates.push_back(r);
    }
    if (candidates.empty()) return GiNaC::matrix(0, 0);  // singular
    unsigned pivot = candidates.front();
    for (std::size_t s = 0; s < 2; ++s) {
      double best = 0;
      for (unsigned r : candidates)
        if (std::fabs(shadow[s][r][c]) > best) best = std::fabs(shadow[s][r][c]), pivot = r;
      if (best > 1e-9) break;
    }
    std::swap(a[c], a[pivot]);
    for (auto& m : shadow) std::swap(m[c], m[pivot]);
    const GiNaC::ex inverse_pivot = program.keep(1 / a[c][c]);
    for (unsigned j = c; j < 2 * n; ++j)
      if (!a[c][j].is_zero()) a[c][j] = j == c ? GiNaC::ex(1) : program.keep(a[c][j] * inverse_pivot);
    for (auto& m : shadow) {
      const double p = m[c][c];
      for (unsigned j = c; j < 2 * n; ++j) m[c][j] /= p;
    }
    for (unsigned r = 0; r < n; ++r) {
      if (r == c || a[r][c].is_zero()) continue;
      const GiNaC::ex factor = a[r][c];
      for (unsigned j = c; j < 2 * n; ++j)
        if (!a[c][j].is_zero()) a[r][j] = j == c ? GiNaC::ex(0) : program.keep(a[r][j] - factor * a[c][j]);
      for (auto& m : shadow) {
        const double f = m[r][c];
        for (unsigned j = c; j < 2 * n; ++j) m[r][j] -= f * m[c][j];
      }
    }
  }
  GiNaC::matrix B(n, n);
  for (unsigned i = 0; i < n; ++i)
    for (unsigned j = 0; j < n; ++j) B(i, j) = a[i][n + j];
  return B;
}

}  // namespace

QuasiVelocities derive_quasi_velocities(const Model& model, Intermediates& program) {
  QuasiVelocities qv;
  qv.A = simplify(model.A);
  const unsigned n = qv.A.rows();
  const SourceLocation where_A = location_of(model, "quasi_velocities.A");
  const std::string not_independent = "; the quasi-velocities must be independent combinations of the coordinate rates";
  // A written through definitions (or rows given as expressions in the rates) is decided and inverted
  // through the program; a matrix written out is inverted in closed form as before.
  const bool through_program = uses_intermediates(qv.A, program);
  if (through_program) {
    if (identically_singular(qv.A, program) == Identity::zero)
      throw InputError(where_A, "quasi_velocities.A",
                       "A(q) is singular: its determinant is identically zero (shown exactly, by evaluation at "
                       "random points modulo a prime)" +
                           not_independent);
  } else {
    const GiNaC::ex det = simplify(qv.A.determinant());
    if (det.is_zero())
      throw InputError(where_A, "quasi_velocities.A",
                       "A(q) is singular: its determinant is identically zero (shown symbolically)" + not_independent);
    // Symbolically non-zero is not enough: the simplifier may miss an identity, or the determinant may
    // vanish for the parameters' default values. Singular at every sampled configuration means singular.
    const std::vector<SamplePoint> points = sample_points(model);
    std::optional<double> smallest;
    const SamplePoint* first = nullptr;
    bool regular_somewhere = false;
    for (const SamplePoint& p : points) {
      const std::optional<Regularity> r = regularity_at(qv.A, p);
      if (!r) continue;
      if (!first) first = &p, smallest = r->relative;
      regular_somewhere = regular_somewhere || r->regular;
    }
    if (first && !regular_somewhere)
      throw InputError(
          where_A, "quasi_velocities.A",
          "A(q) is singular at every sampled configuration (shown numerically; det A = " + quote(to_text(det), 120) +
              " did not simplify to 0): at " + first->text + ", |det A| divided by the product of its row lengths is " +
              shortest_decimal(*smallest) + not_independent);
  }

  if (model.B_given) {
    qv.B = simplify(model.B);
    const GiNaC::matrix product = qv.A.mul(qv.B);
    const std::vector<SamplePoint> points = sample_points(model);
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < n; ++j) {
        const GiNaC::ex deviation = product(i, j) - (i == j ? 1 : 0);
        if (is_zero_almost_surely(deviation)) continue;
        const Identity exact = identically_zero(deviation, program);
        if (exact == Identity::zero) continue;
        // Not shown to be zero: a sampled configuration where it is not zero proves B wrong; where it is
        // zero at every one, the simplifier merely missed an identity and B is accepted.
        std::string evidence;
        bool checked = false;
        for (const SamplePoint& p : points) {
          // Through the definitions, never inlining them (a chain of squares is exponentially long inlined).
          std::optional<double> v;
          try {
            Intermediates::ValueMemo memo;
            v = value_at(program.value_at(deviation, p.values, memo), p);
          } catch (const std::exception&) {
          }
          if (!v) continue;
          checked = true;
          if (std::fabs(*v) > inverse_tolerance) {
            evidence = "; at " + p.text + " it is " + shortest_decimal(*v + (i == j ? 1 : 0));
            break;
          }
        }
        if (exact == Identity::undecided && checked && evidence.empty()) continue;
        throw InputError(location_of(model, "quasi_velocities.B"), "quasi_velocities.B",
                         "B is not the inverse of A: (A*B)[" + std::to_string(i) + "][" + std::to_string(j) +
                             "] simplifies to " + quote(to_text(simplify(product(i, j))), 120) +
                             (i == j ? ", expected 1" : ", expected 0") + evidence);
      }
  } else if (through_program) {
    qv.B = eliminate_inverse(model, qv.A, program);
    if (qv.B.rows() == 0)
      throw InputError(where_A, "quasi_velocities.A", "A(q) is singular: elimination found no pivot" + not_independent);
  } else {
    // GiNaC inverts by elimination; simplify() then applies sin² + cos² = 1 that it does not know.
    qv.B = simplify(qv.A.inverse());
  }
  return qv;
}

QuasiVelocities derive_quasi_velocities(const Model& model) {
  Intermediates program = model.definitions;
  QuasiVelocities qv = derive_quasi_velocities(model, program);
  for (unsigned i = 0; i < qv.B.rows(); ++i)
    for (unsigned j = 0; j < qv.B.cols(); ++j) qv.B(i, j) = program.inline_all(qv.B(i, j));
  return qv;
}

}  // namespace hamel
