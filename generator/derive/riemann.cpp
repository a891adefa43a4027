// The Riemannian view, paper section "Remark on Classical Riemannian Geometry Formulations" (conventions
// in riemann.hpp). Every step is kept through the program (Intermediates::keep): the metric is the Hessian
// of L in the rates, its derivatives and the Christoffel symbols of the first kind are small programs over
// it, those of the second kind come from a symbolic LDLᵀ of g (never an expanded g⁻¹), and the curvature is
// formed from first-kind symbols so that no derivative of g⁻¹ is taken:
//
//   R_abcd = ∂_c Γ_a,db − ∂_d Γ_a,cb − Γ_e,ca Γᵉ_db + Γ_e,da Γᵉ_cb
//
// (g_ae Rᵉ_bcd with g_ae ∂_c Γᵉ_db = ∂_c Γ_a,db − (Γ_a,ce + Γ_e,ca) Γᵉ_db, i.e. metric compatibility
// ∂_c g_ae = Γ_a,ce + Γ_e,ca; the Γ_a,ce Γᵉ_db terms cancel against g_ae Γᵉ_cf Γᶠ_db).
#include "derive/riemann.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/quadratic_form.hpp"
#include "algebra/simplify.hpp"
#include "model/input_error.hpp"
#include "report/progress.hpp"

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>

namespace hamel {

using GiNaC::ex;
using GiNaC::matrix;

namespace {

const char* const purpose = "the Riemannian view (derive --riemann, kernel riemann_linearization)";

SourceLocation location_of(const Model& model, const std::string& key) {
  const auto it = model.locations.find(key);
  return it != model.locations.end() ? it->second : SourceLocation{model.source_path, 0, 0};
}

// Γ[a][b][c], symmetric in b, c (0 where shown zero).
using Symbols = std::vector<std::vector<std::vector<ex>>>;

// Only holonomic models in general coordinates with a Lagrangian of their own have this view.
void check_applicable(const Model& model) {
  if (model.bundle)
    throw InputError(location_of(model, "group"), "group",
                     std::string(purpose) +
                         " applies to holonomic models in general coordinates; this is a bundle "
                         "model on the group " +
                         model.bundle->group);
  // A tree on a fixed base keeps L = T - V, the joint springs and dampers in the recursion (model.lagrangian
  // is 0 there): the metric would be read from nothing.
  if (model.tree)
    throw InputError(location_of(model, "lagrangian"), "tree",
                     std::string(purpose) +
                         " applies to models that give their Lagrangian (or bodies) in general coordinates; this "
                         "is a kinematic tree on a fixed base, derived recursively (its M is the metric: emit "
                         "--kernels mass_matrix)");
  if (!model.constrained.empty())
    throw InputError(location_of(model, "constraints"), "constraints",
                     std::string(purpose) +
                         " applies to unconstrained models: with constraints the motion is not "
                         "geodesic for the metric of the configuration space");
}

// L(q, q̇, t) and the forces in the rates: a quasi-velocity the Lagrangian or a force uses by name stands for
// uᵃ = Aᵃ_b q̇ᵇ (u2). `at_rest` sets every rate to 0, through `rest_memo`.
struct InRates {
  ex lagrangian, lagrangian_at_rest;
  std::vector<ex> applied;
  GiNaC::exmap at_rest;
  Intermediates::SubstitutionMemo rest_memo;
};

InRates in_rates(const Model& model, Intermediates& program, const std::vector<GiNaC::realsymbol>& rate) {
  const auto n = static_cast<unsigned>(rate.size());
  GiNaC::exmap to_rates;
  for (unsigned a = 0; a < n; ++a) {
    ex u = 0;
    for (unsigned b = 0; b < n; ++b) u += model.A(a, b) * rate[b];
    to_rates[model.quasi_velocities[a]] = program.define(u);
  }
  InRates l;
  Intermediates::SubstitutionMemo memo;
  l.lagrangian = program.substitute(model.lagrangian, to_rates, memo);
  for (const ex& f : model.forces) l.applied.push_back(program.substitute(f, to_rates, memo));
  for (const auto& v : rate) l.at_rest[v] = 0;
  l.lagrangian_at_rest = program.substitute(l.lagrangian, l.at_rest, l.rest_memo);
  return l;
}

// g_ab = ∂²L/∂q̇ᵃ∂q̇ᵇ, and L − L(q, 0, t) must be exactly ½ g_ab q̇ᵃq̇ᵇ (third derivatives zero, nothing linear
// left): the metric of a natural system; V = −L(q, 0, t).
void metric_and_potential(const Model& model, Intermediates& program, InRates& l, RiemannGeometry& r) {
  const std::vector<GiNaC::realsymbol>& rate = r.rates;
  const auto n = static_cast<unsigned>(rate.size());
  // A model with `bodies` has its kinetic energy there, and perhaps no `lagrangian` at all.
  const std::string key = model.locations.count("bodies") ? "bodies" : "lagrangian";
  const SourceLocation where = location_of(model, key);
  matrix hessian(n, n);
  for (unsigned a = 0; a < n; ++a) {
    const ex dL = program.diff(l.lagrangian, rate[a]);
    for (unsigned b = 0; b <= a; ++b) hessian(a, b) = hessian(b, a) = program.keep(program.diff(dL, rate[b]), 400);
  }
  if (!is_quadratic_form(l.lagrangian - l.lagrangian_at_rest, rate, hessian, program))
    throw InputError(where, key,
                     std::string(purpose) +
                         " needs L = 1/2 g_ab(q) q_dot^a q_dot^b - V(q, t); this Lagrangian is not quadratic in the "
                         "rates, or has terms linear in them (gyroscopic or moving-frame terms)");
  r.metric = matrix(n, n);
  for (unsigned a = 0; a < n; ++a)
    for (unsigned b = 0; b <= a; ++b) {
      r.metric(a, b) = r.metric(b, a) = program.keep(program.substitute(hessian(a, b), l.at_rest, l.rest_memo), 400);
      if (!shown_zero(program.diff(r.metric(a, b), model.time), program))
        throw InputError(where, key,
                         std::string(purpose) + " needs a metric g_ab(q) that does not depend on t; d2L/d" +
                             rate[a].get_name() + " d" + rate[b].get_name() + " does (a rheonomic system)");
    }
  if (shown_singular(r.metric, program))
    throw InputError(where, key,
                     std::string(purpose) +
                         ": the metric d2L/dq_dot dq_dot is identically singular; every "
                         "coordinate must carry kinetic energy");
  r.potential = program.keep(-l.lagrangian_at_rest);
}

// Q_a = (forces)_a − ∂V/∂qᵃ, which must not depend on the velocities.
void generalized_forces(const Model& model, Intermediates& program, InRates& l, RiemannGeometry& r) {
  const auto n = static_cast<unsigned>(r.rates.size());
  for (unsigned a = 0; a < n; ++a) {
    const std::string key = "forces[" + std::to_string(a) + "]";
    for (unsigned b = 0; b < n; ++b)
      if (!shown_zero(program.diff(l.applied[a], r.rates[b]), program))
        throw InputError(location_of(model, key), key,
                         std::string(purpose) + " takes forces Q_a(q, t, inputs); this one depends on " +
                             r.rates[b].get_name() +
                             " (velocity-dependent forces add a damping term to the linearization)");
    r.forces.push_back(program.keep(program.substitute(l.applied[a], l.at_rest, l.rest_memo) +
                                    program.diff(l.lagrangian_at_rest, r.coordinates[a])));
  }
}

// Γ_a,bc = ½ (∂_b g_ac + ∂_c g_ab − ∂_a g_bc) from ∂_c g_ab, then Γᵃ_bc = g^ad Γ_d,bc, all columns (b, c) through
// one symbolic LDLᵀ of g. Returns (first kind, second kind) and lists the non-zero ones in r.
std::pair<Symbols, Symbols> christoffel_symbols(Intermediates& program, RiemannGeometry& r) {
  const std::vector<GiNaC::realsymbol>& q = r.coordinates;
  const auto n = static_cast<unsigned>(q.size());
  std::vector<matrix> metric_derivative(n, matrix(n, n));
  for (unsigned c = 0; c < n; ++c)
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = 0; b <= a; ++b)
        metric_derivative[c](a, b) = metric_derivative[c](b, a) = program.keep(program.diff(r.metric(a, b), q[c]));
  Symbols first(n, std::vector<std::vector<ex>>(n, std::vector<ex>(n)));
  std::vector<std::pair<unsigned, unsigned>> pairs;  // (b, c), b ≤ c: the columns of the solve below
  for (unsigned b = 0; b < n; ++b)
    for (unsigned c = b; c < n; ++c) pairs.emplace_back(b, c);
  matrix first_columns(n, static_cast<unsigned>(pairs.size()));
  for (unsigned a = 0; a < n; ++a)
    for (unsigned k = 0; k < pairs.size(); ++k) {
      const auto [b, c] = pairs[k];
      const ex e = (metric_derivative[b](a, c) + metric_derivative[c](a, b) - metric_derivative[a](b, c)) / 2;
      const ex kept = shown_zero(e, program) ? ex(0) : program.keep(e);
      first[a][b][c] = first[a][c][b] = first_columns(a, k) = kept;
      if (!kept.is_zero())
        r.first_kind.push_back({static_cast<int>(a), static_cast<int>(b), static_cast<int>(c), kept});
    }

  const matrix second_columns = solve_positive_definite(r.metric, first_columns, program);
  Symbols second(n, std::vector<std::vector<ex>>(n, std::vector<ex>(n)));
  for (unsigned a = 0; a < n; ++a)
    for (unsigned k = 0; k < pairs.size(); ++k) {
      const auto [b, c] = pairs[k];
      const ex value = shown_zero(second_columns(a, k), program) ? ex(0) : second_columns(a, k);
      second[a][b][c] = second[a][c][b] = value;
      if (!value.is_zero())
        r.second_kind.push_back({static_cast<int>(a), static_cast<int>(b), static_cast<int>(c), value});
    }
  std::sort(r.second_kind.begin(), r.second_kind.end(), [](const ChristoffelSymbol& x, const ChristoffelSymbol& y) {
    return std::tie(x.index, x.b, x.c) < std::tie(y.index, y.b, y.c);
  });
  return {std::move(first), std::move(second)};
}

// R_abcd for a < b, c < d, (a, b) ≤ (c, d), from first-kind symbols (file comment).
void curvature(Intermediates& program, const Symbols& first, const Symbols& second, RiemannGeometry& r) {
  const std::vector<GiNaC::realsymbol>& q = r.coordinates;
  const auto n = static_cast<unsigned>(q.size());
  for (unsigned a = 0; a < n; ++a)
    for (unsigned b = a + 1; b < n; ++b)
      for (unsigned c = a; c < n; ++c)
        for (unsigned d = c + 1; d < n; ++d) {
          if (c == a && d < b) continue;
          ex e = program.diff(first[a][d][b], q[c]) - program.diff(first[a][c][b], q[d]);
          for (unsigned f = 0; f < n; ++f) {
            if (!first[f][c][a].is_zero() && !second[f][d][b].is_zero()) e -= first[f][c][a] * second[f][d][b];
            if (!first[f][d][a].is_zero() && !second[f][c][b].is_zero()) e += first[f][d][a] * second[f][c][b];
          }
          if (shown_zero(e, program)) continue;
          r.curvature.push_back(
              {static_cast<int>(a), static_cast<int>(b), static_cast<int>(c), static_cast<int>(d), program.keep(e)});
        }
}

// Gᵃ_c = Γᵃ_bc q̇ᵇ; ∇_b Q_a = ∂_b Q_a − Γᶜ_ba Q_c; K_ab = R_cbda q̇ᶜq̇ᵈ − ∇_b Q_a.
void linearization_blocks(Intermediates& program, const Symbols& second, RiemannGeometry& r) {
  const std::vector<GiNaC::realsymbol>& q = r.coordinates;
  const std::vector<GiNaC::realsymbol>& rate = r.rates;
  const auto n = static_cast<unsigned>(q.size());
  r.connection_rate = matrix(n, n);
  r.force_gradient = matrix(n, n);
  r.stiffness = matrix(n, n);
  for (unsigned a = 0; a < n; ++a)
    for (unsigned c = 0; c < n; ++c) {
      ex e = 0;
      for (unsigned b = 0; b < n; ++b) e += second[a][b][c] * rate[b];
      r.connection_rate(a, c) = program.keep(e);
    }
  for (unsigned a = 0; a < n; ++a)
    for (unsigned b = 0; b < n; ++b) {
      ex gradient = program.diff(r.forces[a], q[b]);
      for (unsigned c = 0; c < n; ++c)
        if (!second[c][b][a].is_zero() && !r.forces[c].is_zero()) gradient -= second[c][b][a] * r.forces[c];
      r.force_gradient(a, b) = shown_zero(gradient, program) ? ex(0) : program.keep(gradient);
      ex k = -r.force_gradient(a, b);
      for (unsigned c = 0; c < n; ++c)
        for (unsigned d = 0; d < n; ++d) {
          const ex R = curvature_component(r, static_cast<int>(c), static_cast<int>(b), static_cast<int>(d),
                                           static_cast<int>(a));
          if (!R.is_zero()) k += R * rate[c] * rate[d];
        }
      r.stiffness(a, b) = shown_zero(k, program) ? ex(0) : program.keep(k);
    }
}

}  // namespace

ex curvature_component(const RiemannGeometry& geometry, int a, int b, int c, int d) {
  if (a == b || c == d) return 0;
  int sign = 1;
  if (a > b) std::swap(a, b), sign = -sign;
  if (c > d) std::swap(c, d), sign = -sign;
  if (a > c || (a == c && b > d)) std::swap(a, c), std::swap(b, d);
  for (const CurvatureComponent& r : geometry.curvature)
    if (r.a == a && r.b == b && r.c == c && r.d == d) return sign * r.value;
  return 0;
}

RiemannGeometry derive_riemann(const Model& model, Intermediates& program) {
  check_applicable(model);
  progress::Step step("deriving the Riemannian view of " + model.name + " (metric, Christoffel symbols, curvature)");
  const std::size_t program_size = program.size();
  RiemannGeometry r;
  r.coordinates = model.coordinates;
  r.rates = model.rates;
  InRates l = in_rates(model, program, r.rates);
  metric_and_potential(model, program, l, r);
  generalized_forces(model, program, l, r);
  const auto [first, second] = christoffel_symbols(program, r);
  curvature(program, first, second, r);
  linearization_blocks(program, second, r);
  step.detail(std::to_string(r.curvature.size()) + " non-zero curvature components, " +
              std::to_string(program.size() - program_size) + " intermediates");
  return r;
}

}  // namespace hamel
