#include "derive/bundle_connection.hpp"

#include "algebra/identity_test.hpp"
#include "algebra/quadratic_form.hpp"
#include "model/input_error.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace hamel {

using GiNaC::ex;
using GiNaC::matrix;

std::vector<BundleCoefficient> BundleGeometry::curvature_in(CurvatureSign sign) const {
  std::vector<BundleCoefficient> out = curvature;
  if (sign == CurvatureSign::gauge)
    for (auto& b : out) b.value = -b.value;
  return out;
}

std::vector<BundleCoefficient> curvature_of(const matrix& A, const std::vector<GiNaC::realsymbol>& shape,
                                            const std::vector<StructureConstant>& c, int sign, Intermediates& program) {
  const unsigned m = A.rows();
  const unsigned d = static_cast<unsigned>(shape.size());
  std::vector<BundleCoefficient> out;
  for (unsigned alpha = 0; alpha < m; ++alpha)
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = I + 1; J < d; ++J) {
        ex b = program.diff(A(alpha, I), shape[J]) - program.diff(A(alpha, J), shape[I]);
        for (const StructureConstant& s : c)
          if (s.upper == static_cast<int>(alpha))
            b += sign * s.value * A(static_cast<unsigned>(s.lower_a), I) * A(static_cast<unsigned>(s.lower_b), J);
        if (shown_zero(b, program)) continue;
        b = program.keep(b);
        out.push_back({static_cast<int>(alpha), static_cast<int>(I), static_cast<int>(J), b});
        out.push_back({static_cast<int>(alpha), static_cast<int>(J), static_cast<int>(I), -b});
      }
  sort_by_indices(out);
  return out;
}

BundleGeometry inlined(const BundleGeometry& geometry) {
  BundleGeometry out = geometry;
  const Intermediates& program = geometry.program;
  const auto expand = [&](matrix& m) {
    for (unsigned i = 0; i < m.rows(); ++i)
      for (unsigned j = 0; j < m.cols(); ++j) m(i, j) = program.inline_all(m(i, j));
  };
  for (matrix* m : {&out.L, &out.K, &out.S, &out.connection, &out.shape_inertia}) expand(*m);
  for (auto* list : {&out.curvature, &out.E})
    for (BundleCoefficient& c : *list) c.value = program.inline_all(c.value);
  out.program = Intermediates{};
  return out;
}

BundleGeometry derive_bundle_geometry(const Model& model) {
  if (model.bundle->tree)  // derive/kinematic_tree derives trees, or inlines them first (with_inlined_tree)
    throw std::logic_error("derive_bundle_geometry: a tree model must be inlined first");
  const Bundle& b = *model.bundle;
  BundleGeometry g;
  g.program = model.definitions;
  Intermediates& program = g.program;
  g.algebra = lie_algebra(b.group);
  g.structure_constants = structure_constants(g.algebra);
  g.trivialization_sign = b.right ? -1 : 1;
  const unsigned m = g.algebra.dim();
  const unsigned d = static_cast<unsigned>(model.coordinates.size());
  // Errors about T name the key it came from: `bodies` for a model that lists bodies (it has no `kinetic`).
  const std::string key = model.locations.count("bodies") ? "bodies"
                          : model.locations.count("tree") ? "tree"
                                                          : "kinetic";
  const SourceLocation where =
      model.locations.count(key) ? model.locations.at(key) : SourceLocation{model.source_path, 0, 0};

  // Eq. (M): the Hessian of T in v = (ξ, ṙ), by the chain rule through the program.
  std::vector<GiNaC::realsymbol> v(b.group_velocity);
  v.insert(v.end(), model.rates.begin(), model.rates.end());
  matrix H(m + d, m + d);
  for (unsigned i = 0; i < m + d; ++i) {
    const ex dT = program.diff(b.kinetic, v[i]);
    for (unsigned j = 0; j <= i; ++j) {
      const ex second = program.diff(dT, v[j]);
      const std::optional<ex> closed = program.closed_form(second);
      H(i, j) = H(j, i) = closed ? *closed : program.keep(second, 400);
    }
  }
  g.quadratic = is_quadratic_form(b.kinetic, v, H, program);  // eq. (T)
  if (g.quadratic) {
    g.L = matrix(m, m);
    g.K = matrix(m, d == 0 ? 1 : d);
    g.S = matrix(d == 0 ? 1 : d, d == 0 ? 1 : d);
    for (unsigned i = 0; i < m; ++i)
      for (unsigned j = 0; j < m; ++j) g.L(i, j) = H(i, j);
    for (unsigned i = 0; i < m; ++i)
      for (unsigned J = 0; J < d; ++J) g.K(i, J) = H(i, m + J);
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = 0; J < d; ++J) g.S(I, J) = H(m + I, m + J);
  }

  if (b.mechanical) {
    if (!g.quadratic)
      throw InputError(where, key,
                       "a mechanical connection needs a kinetic energy that is a quadratic form in the group velocity "
                       "and the shape rates (eq. T); this one is not");
    if (identically_singular(g.L, program) == Identity::zero)
      throw InputError(where, key,
                       "the locked inertia L = d2T/dxi dxi is singular (identically, in r), so the mechanical "
                       "connection A = L^-1 K does not exist; every group direction must carry kinetic energy");
    // Eq. (mechConn): A = L⁻¹K by a symbolic LDLᵀ of the locked inertia (positive definite, no pivoting).
    g.connection = d > 0 ? solve_positive_definite(g.L, g.K, program) : matrix(m, d);
  } else if (b.nonholonomic) {
    if (!g.quadratic)
      throw InputError(where, "kinetic",
                       "the nonholonomic connection needs a kinetic energy that is a quadratic form in the group "
                       "velocity and the shape rates (eq. T); this one is not");
    g.nonholonomic = derive_nonholonomic_connection(model, g.L, g.K, program);
    g.connection = g.nonholonomic->connection;
  } else {
    g.connection = b.kinematic_connection;
  }

  g.curvature = curvature_of(g.connection, model.coordinates, g.structure_constants, g.trivialization_sign, program);
  // Eq. (gamma42): E^α_βI = γ^α_Iβ = ±c^α_βλ A^λ_I.
  for (unsigned alpha = 0; alpha < m; ++alpha)
    for (unsigned beta = 0; beta < m; ++beta)
      for (unsigned I = 0; I < d; ++I) {
        ex e = 0;
        for (const StructureConstant& s : g.structure_constants)
          if (s.upper == static_cast<int>(alpha) && s.lower_a == static_cast<int>(beta))
            e += g.trivialization_sign * s.value * g.connection(static_cast<unsigned>(s.lower_b), I);
        if (shown_zero(e, program)) continue;
        g.E.push_back({static_cast<int>(alpha), static_cast<int>(beta), static_cast<int>(I), program.keep(e)});
      }
  if (b.mechanical && d > 0) {
    // Eq. (MOmega): the shape block S − AᵀLA = S − KᵀA (L A = K).
    g.shape_inertia = GiNaC::matrix(d, d);
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = 0; J < d; ++J) {
        ex e = g.S(I, J);
        for (unsigned a = 0; a < m; ++a) e -= g.K(a, I) * g.connection(a, J);
        g.shape_inertia(I, J) = program.keep(e, 400);
      }
  }
  return g;
}

}  // namespace hamel
