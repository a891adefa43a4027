#include "derive/nonholonomic_momentum.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/quadratic_form.hpp"
#include "derive/nonholonomic_connection.hpp"

#include <stdexcept>

namespace hamel {

using GiNaC::ex;
using GiNaC::matrix;

BundleSystem nonholonomic_system(const Model& model, const BundleGeometry& geometry) {
  if (!geometry.nonholonomic)
    throw std::logic_error("nonholonomic_system: the geometry has no nonholonomic connection");
  const Bundle& b = *model.bundle;
  const NonholonomicConnection& nh = *geometry.nonholonomic;
  const unsigned m = geometry.algebra.dim();
  const unsigned k = static_cast<unsigned>(b.constraint_velocities.size());
  const unsigned d = static_cast<unsigned>(model.n());
  const int sign = geometry.trivialization_sign;
  const matrix& P = nh.frame;
  const matrix& Q = nh.coframe;
  const matrix& A = geometry.connection;

  BundleSystem out;
  HamelSystem& sys = out.system;
  sys.form = "nonholonomic momentum and reduced shape equations (Bloch, Krishnaprasad, Marsden & Murray 1996)";
  sys.coordinates = model.coordinates;
  sys.velocities.assign(b.constraint_velocities.begin(), b.constraint_velocities.end());
  sys.velocities.insert(sys.velocities.end(), b.momentum_velocities.begin(), b.momentum_velocities.end());
  for (const auto& r : model.rates) sys.velocities.push_back(r);
  for (unsigned c = 0; c < k; ++c) sys.constrained.push_back(static_cast<int>(c));
  sys.B = matrix(d == 0 ? 1 : d, m + d);
  for (unsigned I = 0; I < d; ++I) sys.B(I, m + I) = 1;
  sys.program = geometry.program;
  Intermediates& program = sys.program;

  // ξ = P ν − 𝒜ṙ into l and the forces as intermediates (derivatives by the chain rule through ξ(ν, ṙ)).
  GiNaC::exmap to_frame;
  for (unsigned a = 0; a < m; ++a) {
    ex xi = 0, xi_on_D = 0;
    for (unsigned c = 0; c < m; ++c) {
      xi += P(a, c) * sys.velocities[c];
      if (c >= k) xi_on_D += P(a, c) * sys.velocities[c];
    }
    for (unsigned I = 0; I < d; ++I) {
      xi -= A(a, I) * model.rates[I];
      xi_on_D -= A(a, I) * model.rates[I];
    }
    to_frame[b.group_velocity[a]] = program.define(xi);
    out.group_velocity.push_back(xi_on_D);
  }
  Intermediates::SubstitutionMemo memo;
  sys.lagrangian = program.substitute(model.lagrangian, to_frame, memo);
  for (const ex& q : model.forces) sys.forces.push_back(program.substitute(q, to_frame, memo));
  sys.where_key = model.locations.count("bodies") ? "bodies" : "kinetic";
  sys.where = model.locations.count(sys.where_key) ? model.locations.at(sys.where_key)
                                                   : SourceLocation{model.source_path, 0, 0};

  // Brackets of the frame in the basis E_α, then γ^c = Q^c_α (bracket)^α.
  const auto add = [&](unsigned x, unsigned y, const std::vector<ex>& bracket) {
    for (unsigned c = 0; c < m; ++c) {
      ex g = 0;
      for (unsigned a = 0; a < m; ++a) g += Q(c, a) * bracket[a];
      if (shown_zero(g, program)) continue;
      g = program.keep(g);
      sys.gamma.push_back({static_cast<int>(c), static_cast<int>(x), static_cast<int>(y), g});
      sys.gamma.push_back({static_cast<int>(c), static_cast<int>(y), static_cast<int>(x), -g});
    }
  };
  for (unsigned x = 0; x < m; ++x)
    for (unsigned y = x + 1; y < m; ++y) {  // [e_x, e_y] = ±c^α_βλ P^β_x P^λ_y E_α
      std::vector<ex> bracket(m, 0);
      for (const StructureConstant& s : geometry.structure_constants)
        bracket[static_cast<unsigned>(s.upper)] +=
            sign * s.value * P(static_cast<unsigned>(s.lower_a), x) * P(static_cast<unsigned>(s.lower_b), y);
      add(x, y, bracket);
    }
  for (unsigned x = 0; x < m; ++x)
    for (unsigned I = 0; I < d; ++I) {  // [e_x, e_I] = −(∂_I P^α_x ± c^α_βλ P^β_x 𝒜^λ_I) E_α
      std::vector<ex> bracket(m, 0);
      for (unsigned a = 0; a < m; ++a) bracket[a] = -program.diff(P(a, x), model.coordinates[I]);
      for (const StructureConstant& s : geometry.structure_constants)
        bracket[static_cast<unsigned>(s.upper)] -=
            sign * s.value * P(static_cast<unsigned>(s.lower_a), x) * A(static_cast<unsigned>(s.lower_b), I);
      add(x, m + I, bracket);
    }
  for (unsigned I = 0; I < d; ++I)
    for (unsigned J = I + 1; J < d; ++J) {  // [e_I, e_J] = ℬ^α_IJ E_α (paper sign: ℬ = γ)
      std::vector<ex> bracket(m, 0);
      for (const BundleCoefficient& c : geometry.curvature)
        if (c.lower_a == static_cast<int>(I) && c.lower_b == static_cast<int>(J))
          bracket[static_cast<unsigned>(c.upper)] = c.value;
      add(m + I, m + J, bracket);
    }
  sort_by_indices(sys.gamma);
  return out;
}

NonholonomicMomentum nonholonomic_momentum(const Model& model, const BundleGeometry& geometry, const HamelSystem& sys,
                                           Intermediates& program) {
  const Bundle& b = *model.bundle;
  const unsigned k = static_cast<unsigned>(b.constraint_velocities.size());
  const unsigned s = static_cast<unsigned>(b.momentum_velocities.size());
  const unsigned nu = static_cast<unsigned>(sys.velocities.size());
  NonholonomicMomentum out;
  GiNaC::exmap held;
  for (int c : sys.constrained) held[sys.velocities[static_cast<std::size_t>(c)]] = 0;
  Intermediates::SubstitutionMemo held_memo;
  std::vector<ex> conjugate(nu);  // ∂ℒ/∂ν^a on D
  for (unsigned a = 0; a < nu; ++a)
    conjugate[a] = program.substitute(program.diff(sys.lagrangian, sys.velocities[a]), held, held_memo);

  // Ω_S = (I^S)⁻¹ p.
  matrix p(s, 1);
  for (unsigned j = 0; j < s; ++j) {
    out.momenta.emplace_back(s == 1 ? "p_S" : "p_S" + std::to_string(j + 1));
    p(j, 0) = out.momenta.back();
  }
  const matrix omega = solve_positive_definite(geometry.nonholonomic->locked_inertia, p, program);
  GiNaC::exmap to_momentum;
  for (unsigned j = 0; j < s; ++j) to_momentum[b.momentum_velocities[j]] = omega(j, 0);
  Intermediates::SubstitutionMemo memo;
  for (unsigned j = 0; j < s; ++j) {
    const unsigned row = k + j;
    out.momentum.push_back(conjugate[row]);
    ex rate = 0;
    for (const HamelCoefficient& g : sys.gamma) {
      if (g.lower_a != static_cast<int>(row) || g.lower_b < static_cast<int>(k)) continue;
      rate -= conjugate[static_cast<unsigned>(g.upper)] * g.value * sys.velocities[static_cast<unsigned>(g.lower_b)];
    }
    out.rate.push_back(program.substitute(rate, to_momentum, memo));
  }
  return out;
}

}  // namespace hamel
