// Holonomic constraints as quasi-velocities held at zero: (PfaffianConstr2), (sys1), (salpha), (sys2), (HE-holo),
// (solConstr); see the header.
#include "derive/holonomic_constraints.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/identity_test.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace hamel {

namespace {

SourceLocation location_of(const Model& model, const std::string& key) {
  auto it = model.locations.find(key);
  return it == model.locations.end() ? SourceLocation{model.source_path, 0, 0} : it->second;
}

std::string key_of(const HolonomicConstraint& c) { return "holonomic." + c.velocity.get_name(); }

// A configuration at which G is evaluated: coordinates at `coordinates`, parameters at their defaults.
struct Configuration {
  GiNaC::exmap values;
  std::string text;  // "theta1 = 0.5, theta2 = -1.2"
};

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

Configuration configuration(const Model& model, const std::vector<double>& coordinates) {
  Configuration c;
  c.values[model.time] = 0;
  for (std::size_t a = 0; a < model.n(); ++a) {
    c.values[model.coordinates[a]] = exact_number(coordinates[a]);
    c.text += (a ? ", " : "") + model.coordinates[a].get_name() + " = " + number(coordinates[a]);
  }
  for (const Parameter& p : model.parameters) c.values[p.symbol] = exact_number(p.default_value);
  return c;
}

// The configuration of the model's `initial`, and three generic ones (fixed rationals that no trigonometric
// identity singles out, as the checks of A in derive/quasi_velocities.cpp use).
std::vector<Configuration> configurations(const Model& model) {
  std::vector<Configuration> out;
  std::vector<double> q(model.n(), 0.0);
  for (std::size_t a = 0; a < model.n(); ++a) {
    auto it = model.initial.find(model.coordinates[a].get_name());
    if (it != model.initial.end()) q[a] = it->second;
  }
  out.push_back(configuration(model, q));
  for (std::size_t k = 0; k < 3; ++k) {
    for (std::size_t a = 0; a < model.n(); ++a)
      q[a] = static_cast<double>((31 + 17 * a + 53 * k) % 89 + 5) / 71.0 * ((a + k) % 2 ? -1.0 : 1.0);
    out.push_back(configuration(model, q));
  }
  return out;
}

// G at `c` in doubles, or nothing where an entry is not a finite real number there (a pole).
std::optional<std::vector<std::vector<double>>> gradients_at(const Model& model, const Configuration& c) {
  const GiNaC::exmap all = model.definitions.evaluate(c.values);
  std::vector<std::vector<double>> G;
  for (const HolonomicConstraint& h : model.holonomic) {
    G.emplace_back();
    for (const GiNaC::ex& e : h.gradient) {
      GiNaC::ex v;
      try {
        v = e.subs(all).evalf();
      } catch (const std::exception&) {
        return std::nullopt;
      }
      if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real()) return std::nullopt;
      const double d = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
      if (!std::isfinite(d)) return std::nullopt;
      G.back().push_back(d);
    }
  }
  return G;
}

}  // namespace

std::vector<int> dependent_coordinates_by_pivoting(const std::vector<std::vector<double>>& G) {
  const std::size_t k = G.size();
  if (k == 0) return {};
  const std::size_t n = G.front().size();
  // Columns of G, orthogonalized against the columns already picked (modified Gram–Schmidt).
  std::vector<std::vector<double>> column(n, std::vector<double>(k));
  double largest = 0;
  for (std::size_t a = 0; a < n; ++a) {
    double norm = 0;
    for (std::size_t i = 0; i < k; ++i) column[a][i] = G[i][a], norm += G[i][a] * G[i][a];
    largest = std::max(largest, std::sqrt(norm));
  }
  if (!(largest > 0)) return {};
  std::vector<int> picked;
  std::vector<bool> used(n, false);
  for (std::size_t step = 0; step < k; ++step) {
    std::size_t best = n;
    double best_norm = -1;
    for (std::size_t a = 0; a < n; ++a) {
      if (used[a]) continue;
      double norm = 0;
      for (double v : column[a]) norm += v * v;
      if (norm >= best_norm) best_norm = norm, best = a;  // >=: ties go to the later coordinate
    }
    if (best == n || !(std::sqrt(best_norm) > 1e-9 * largest)) return {};
    used[best] = true;
    picked.push_back(static_cast<int>(best));
    std::vector<double> unit = column[best];
    const double norm = std::sqrt(best_norm);
    for (double& v : unit) v /= norm;
    for (std::size_t a = 0; a < n; ++a) {
      if (used[a]) continue;
      double dot = 0;
      for (std::size_t i = 0; i < k; ++i) dot += unit[i] * column[a][i];
      for (std::size_t i = 0; i < k; ++i) column[a][i] -= dot * unit[i];
    }
  }
  std::sort(picked.begin(), picked.end());
  return picked;
}

void add_holonomic_quasi_velocities(Model& model, bool others_given) {
  const std::size_t n = model.n();
  const std::size_t k = model.holonomic.size();
  if (k == 0) return;
  const SourceLocation where = location_of(model, "holonomic");
  Intermediates& program = model.definitions;

  // G = ∂g/∂q through the definitions; a constraint whose gradient vanishes identically constrains nothing.
  const std::vector<GiNaC::symbol> coordinates(model.coordinates.begin(), model.coordinates.end());
  for (HolonomicConstraint& h : model.holonomic) {
    h.gradient = program.diff(h.g, coordinates);
    bool zero = true;
    for (const GiNaC::ex& e : h.gradient)
      zero = zero && (e.is_zero() || identically_zero(e, program) == Identity::zero);
    if (zero)
      throw InputError(location_of(model, key_of(h)), key_of(h),
                       "the constraint " + quote(to_text(program.inline_all(h.g)), 120) +
                           " does not depend on the coordinates (its gradient dg/dq is identically zero): it is a "
                           "condition on the parameters, not a constraint on the motion; expected g(q) = 0 that "
                           "depends on the coordinates");
  }

  // Independence: rank G = k somewhere. G Gᵀ is singular everywhere exactly when every k × k minor of G vanishes.
  const std::vector<Configuration> points = configurations(model);
  if (k > 1) {
    GiNaC::matrix gram(static_cast<unsigned>(k), static_cast<unsigned>(k));
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < k; ++j) {
        GiNaC::ex s = 0;
        for (std::size_t a = 0; a < n; ++a) s += model.holonomic[i].gradient[a] * model.holonomic[j].gradient[a];
        gram(static_cast<unsigned>(i), static_cast<unsigned>(j)) = s;
      }
    Identity singular = identically_singular(gram, program);
    std::string how = "shown exactly, by evaluation at random points modulo a prime";
    if (singular == Identity::undecided) {
      // Numerically: rank below k at every generic configuration where G is defined.
      bool full_somewhere = false, checked = false;
      for (std::size_t p = 1; p < points.size(); ++p)
        if (const auto G = gradients_at(model, points[p])) {
          checked = true;
          full_somewhere = full_somewhere || !dependent_coordinates_by_pivoting(*G).empty();
        }
      if (checked && !full_somewhere) {
        singular = Identity::zero;
        how = "shown numerically at three generic configurations, e.g. " + points[1].text;
      }
    }
    if (singular == Identity::zero)
      throw InputError(where, "holonomic",
                       "the " + std::to_string(k) +
                           " constraints are not independent: their gradients dg/dq have rank below " +
                           std::to_string(k) + " at every configuration (" + how +
                           "); expected independent constraints (leave out the redundant ones)");
  }

  // The other quasi-velocities: the file's, or the rates of the independent coordinates of a partition.
  GiNaC::matrix others = model.A;
  std::vector<GiNaC::realsymbol> other_names = model.quasi_velocities;
  if (!others_given) {
    std::vector<int> dependent;
    for (const Configuration& c : points) {
      if (const auto G = gradients_at(model, c)) dependent = dependent_coordinates_by_pivoting(*G);
      if (!dependent.empty()) break;
    }
    if (dependent.empty())
      throw InputError(where, "holonomic",
                       "cannot choose dependent coordinates: the gradients dg/dq have rank below " + std::to_string(k) +
                           " at the initial configuration (" + points.front().text +
                           ") and at three generic ones; expected independent constraints, or give "
                           "'quasi_velocities' with the other " +
                           std::to_string(n - k) + " quasi-velocities");
    model.dependent_coordinates = dependent;
    others = GiNaC::matrix(static_cast<unsigned>(n - k), static_cast<unsigned>(n));
    other_names.clear();
    unsigned row = 0;
    for (std::size_t a = 0; a < n; ++a) {
      if (std::find(dependent.begin(), dependent.end(), static_cast<int>(a)) != dependent.end()) continue;
      others(row++, static_cast<unsigned>(a)) = 1;  // u^I = ṙ^I (sys1)
      other_names.push_back(model.rates[a]);
    }
    model.locations["quasi_velocities.A"] = where;
  }

  // A = [G; the others] and the constrained velocities: the k constraint velocities first (α = 1..k, the paper's
  // numbering), then the file's constraints among the others.
  GiNaC::matrix A(static_cast<unsigned>(n), static_cast<unsigned>(n));
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t a = 0; a < n; ++a)
      A(static_cast<unsigned>(i), static_cast<unsigned>(a)) = model.holonomic[i].gradient[a];
  for (unsigned i = 0; i < others.rows(); ++i)
    for (unsigned a = 0; a < n; ++a) A(static_cast<unsigned>(k) + i, a) = others(i, a);
  std::vector<GiNaC::realsymbol> names;
  for (const HolonomicConstraint& h : model.holonomic) names.push_back(h.velocity);
  names.insert(names.end(), other_names.begin(), other_names.end());
  std::vector<int> constrained;
  for (std::size_t i = 0; i < k; ++i) constrained.push_back(static_cast<int>(i));
  for (int c : model.constrained) constrained.push_back(c + static_cast<int>(k));

  if (others_given && identically_singular(A, program) == Identity::zero)
    throw InputError(location_of(model, "quasi_velocities.A"), "quasi_velocities.A",
                     "A(q), with the gradients dg/dq of the " + std::to_string(k) +
                         " constraints of 'holonomic' as its first rows, is singular (its determinant is "
                         "identically zero, shown exactly by evaluation at random points modulo a prime); expected "
                         "quasi-velocities that complete the constraint gradients to a regular A");
  model.A = A;
  model.quasi_velocities = names;
  model.constrained = constrained;
}

}  // namespace hamel
