#include "derive/nonholonomic_connection.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/quadratic_form.hpp"
#include "derive/holonomic_constraints.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace hamel {

using GiNaC::ex;
using GiNaC::matrix;

namespace {

// C_ξ in doubles at the shape `r` (parameters at their defaults), or nothing where an entry is not a finite number.
std::optional<std::vector<std::vector<double>>> constraint_rows_at(const Model& model, const std::vector<double>& r) {
  GiNaC::exmap values;
  values[model.time] = 0;
  for (std::size_t I = 0; I < model.n(); ++I) values[model.coordinates[I]] = exact_number(r[I]);
  for (const Parameter& p : model.parameters) values[p.symbol] = exact_number(p.default_value);
  const GiNaC::exmap all = model.definitions.evaluate(values);
  const matrix& C = model.bundle->constraint_group;
  std::vector<std::vector<double>> out(C.rows(), std::vector<double>(C.cols()));
  for (unsigned i = 0; i < C.rows(); ++i)
    for (unsigned j = 0; j < C.cols(); ++j) {
      ex v;
      try {
        v = C(i, j).subs(all).evalf();
      } catch (const std::exception&) {
        return std::nullopt;
      }
      if (!GiNaC::is_a<GiNaC::numeric>(v) || !GiNaC::ex_to<GiNaC::numeric>(v).is_real()) return std::nullopt;
      out[i][j] = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
      if (!std::isfinite(out[i][j])) return std::nullopt;
    }
  return out;
}

// The group directions the constraints are solved for: column pivoting on C_ξ at the initial shape, or at fixed
// generic shapes where C_ξ has rank below k there.
std::vector<int> solved_directions(const Model& model) {
  std::vector<double> r(model.n(), 0.0);
  for (std::size_t I = 0; I < model.n(); ++I)
    if (auto it = model.initial.find(model.coordinates[I].get_name()); it != model.initial.end()) r[I] = it->second;
  for (std::size_t attempt = 0; attempt < 4; ++attempt) {
    if (attempt > 0)
      for (std::size_t I = 0; I < model.n(); ++I)
        r[I] = static_cast<double>((31 + 17 * I + 53 * attempt) % 89 + 5) / 71.0 * ((I + attempt) % 2 ? -1.0 : 1.0);
    if (const auto C = constraint_rows_at(model, r)) {
      std::vector<int> picked = dependent_coordinates_by_pivoting(*C);
      if (!picked.empty()) return picked;
    }
  }
  return {};
}

// Cofactor matrix transposed: adj(C) with C adj(C) = det(C) I.
matrix adjugate(const matrix& C) {
  const unsigned k = C.rows();
  matrix adj(k, k);
  if (k == 1) {
    adj(0, 0) = 1;
    return adj;
  }
  for (unsigned i = 0; i < k; ++i)
    for (unsigned j = 0; j < k; ++j) {
      matrix cofactor(k - 1, k - 1);
      for (unsigned a = 0, ra = 0; a < k; ++a) {
        if (a == j) continue;
        for (unsigned b = 0, rb = 0; b < k; ++b) {
          if (b == i) continue;
          cofactor(ra, rb++) = C(a, b);
        }
        ++ra;
      }
      adj(i, j) = ((i + j) % 2 ? -1 : 1) * cofactor.determinant();
    }
  return adj;
}

}  // namespace

NonholonomicConnection derive_nonholonomic_connection(const Model& model, const matrix& L, const matrix& K,
                                                      Intermediates& program) {
  const Bundle& b = *model.bundle;
  const matrix& C = b.constraint_group;
  const unsigned k = C.rows(), m = C.cols(), s = m - k;
  const unsigned d = static_cast<unsigned>(model.n());
  const SourceLocation where_constraints = model.locations.count("constraints")
                                               ? model.locations.at("constraints")
                                               : SourceLocation{model.source_path, 0, 0};
  NonholonomicConnection nh;
  nh.solved = solved_directions(model);
  if (nh.solved.size() != k)
    throw InputError(where_constraints, "constraints",
                     "the constraints' coefficients of the group velocity have rank below " + std::to_string(k) +
                         " at the initial shape and at three generic ones; expected independent conditions on the "
                         "group velocity");
  for (unsigned a = 0; a < m; ++a)
    if (std::find(nh.solved.begin(), nh.solved.end(), static_cast<int>(a)) == nh.solved.end())
      nh.free.push_back(static_cast<int>(a));

  matrix Cs(k, k);
  for (unsigned i = 0; i < k; ++i)
    for (unsigned j = 0; j < k; ++j) Cs(i, j) = C(i, static_cast<unsigned>(nh.solved[j]));
  const matrix adj = adjugate(Cs);
  const ex det = program.keep(Cs.determinant());
  if (identically_zero(det, program) == Identity::zero)
    throw InputError(where_constraints, "constraints",
                     "the constraints' coefficients of the group velocity are dependent everywhere (their minor on " +
                         b.group_velocity[static_cast<std::size_t>(nh.solved[0])].get_name() +
                         ", ... vanishes identically); expected independent conditions on the group velocity");

  nh.sections = matrix(m, s);
  nh.frame = matrix(m, m);
  nh.coframe = matrix(m, m);
  for (unsigned j = 0; j < s; ++j) {
    const unsigned f = static_cast<unsigned>(nh.free[j]);
    nh.sections(f, j) = det;
    for (unsigned i = 0; i < k; ++i) {
      ex e = 0;
      for (unsigned l = 0; l < k; ++l) e -= adj(i, l) * C(l, f);
      nh.sections(static_cast<unsigned>(nh.solved[i]), j) = program.keep(e);
    }
  }
  for (unsigned i = 0; i < k; ++i)
    for (unsigned c = 0; c < k; ++c)
      nh.frame(static_cast<unsigned>(nh.solved[i]), c) = program.keep(adj(i, c) / det);  // Y = C_π⁻¹
  for (unsigned a = 0; a < m; ++a)
    for (unsigned j = 0; j < s; ++j) nh.frame(a, k + j) = nh.sections(a, j);
  for (unsigned c = 0; c < k; ++c)
    for (unsigned a = 0; a < m; ++a) nh.coframe(c, a) = C(c, a);
  for (unsigned j = 0; j < s; ++j) nh.coframe(k + j, static_cast<unsigned>(nh.free[j])) = program.keep(1 / det);

  // 𝒜_kin = Y C_r.
  nh.kinematic = matrix(m, d == 0 ? 1 : d);
  for (unsigned a = 0; a < m; ++a)
    for (unsigned I = 0; I < d; ++I) {
      ex e = 0;
      for (unsigned c = 0; c < k; ++c) e += nh.frame(a, c) * b.constraint_shape(c, I);
      nh.kinematic(a, I) = program.keep(e);
    }
  // I^S = Zᵀ L Z and the right-hand side Zᵀ (K − L 𝒜_kin) of the mechanical part.
  nh.locked_inertia = matrix(s, s);
  matrix LZ(m, s);
  for (unsigned a = 0; a < m; ++a)
    for (unsigned j = 0; j < s; ++j) {
      ex e = 0;
      for (unsigned c = 0; c < m; ++c) e += L(a, c) * nh.sections(c, j);
      LZ(a, j) = program.keep(e);
    }
  for (unsigned i = 0; i < s; ++i)
    for (unsigned j = 0; j <= i; ++j) {
      ex e = 0;
      for (unsigned a = 0; a < m; ++a) e += nh.sections(a, i) * LZ(a, j);
      nh.locked_inertia(i, j) = nh.locked_inertia(j, i) = program.keep(e, 400);
    }
  if (identically_singular(nh.locked_inertia, program) == Identity::zero)
    throw InputError(model.locations.count("kinetic") ? model.locations.at("kinetic") : where_constraints, "kinetic",
                     "the locked inertia on the group directions the constraints leave free, Z^T L Z, is singular "
                     "(identically, in r): those directions must carry kinetic energy");
  nh.connection = nh.kinematic;
  if (d > 0) {
    matrix rhs(s, d);
    for (unsigned j = 0; j < s; ++j)
      for (unsigned I = 0; I < d; ++I) {
        ex e = 0;
        for (unsigned a = 0; a < m; ++a) e += nh.sections(a, j) * K(a, I) - LZ(a, j) * nh.kinematic(a, I);
        rhs(j, I) = program.keep(e, 400);
      }
    const matrix X = solve_positive_definite(nh.locked_inertia, rhs, program);
    for (unsigned a = 0; a < m; ++a)
      for (unsigned I = 0; I < d; ++I) {
        ex e = nh.kinematic(a, I);
        for (unsigned j = 0; j < s; ++j) e += nh.sections(a, j) * X(j, I);
        nh.connection(a, I) = program.keep(e, 400);
      }
  }
  return nh;
}

}  // namespace hamel
