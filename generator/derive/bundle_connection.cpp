#include "derive/bundle_connection.hpp"

#include "algebra/simplify.hpp"
#include "derive/kinematic_tree.hpp"
#include "model/input_error.hpp"

#include <algorithm>
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
                                            const std::vector<StructureConstant>& c, int sign) {
  const unsigned m = A.rows();
  const unsigned d = static_cast<unsigned>(shape.size());
  std::vector<BundleCoefficient> out;
  for (unsigned alpha = 0; alpha < m; ++alpha)
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = I + 1; J < d; ++J) {
        ex b = A(alpha, I).diff(shape[J]) - A(alpha, J).diff(shape[I]);
        for (const StructureConstant& s : c)
          if (s.upper == static_cast<int>(alpha))
            b += sign * s.value * A(static_cast<unsigned>(s.lower_a), I) * A(static_cast<unsigned>(s.lower_b), J);
        b = simplify_bounded(b);
        if (b.is_zero()) continue;
        out.push_back({static_cast<int>(alpha), static_cast<int>(I), static_cast<int>(J), b});
        out.push_back({static_cast<int>(alpha), static_cast<int>(J), static_cast<int>(I), -b});
      }
  std::sort(out.begin(), out.end(), [](const BundleCoefficient& x, const BundleCoefficient& y) {
    return std::tie(x.alpha, x.lower_a, x.lower_b) < std::tie(y.alpha, y.lower_a, y.lower_b);
  });
  return out;
}

BundleGeometry derive_bundle_geometry(const Model& model) {
  if (model.bundle->tree) return derive_bundle_geometry(with_inlined_tree(model));  // symbolic: small trees only
  const Bundle& b = *model.bundle;
  BundleGeometry g;
  g.algebra = lie_algebra(b.group);
  g.structure_constants = structure_constants(g.algebra);
  g.trivialization_sign = b.right ? -1 : 1;
  const unsigned m = g.algebra.dim();
  const unsigned d = static_cast<unsigned>(model.coordinates.size());
  const SourceLocation where =
      model.locations.count("kinetic") ? model.locations.at("kinetic") : SourceLocation{model.source_path, 0, 0};

  // Eq. (M): the Hessian of T in v = (ξ, ṙ); T is a quadratic form iff T = ½ vᵀ H v with H free of v.
  std::vector<GiNaC::realsymbol> v(b.group_velocity);
  v.insert(v.end(), model.rates.begin(), model.rates.end());
  matrix H(m + d, m + d);
  ex quadratic_part = 0;
  bool velocity_free = true;
  for (unsigned i = 0; i < m + d; ++i)
    for (unsigned j = 0; j < m + d; ++j) {
      H(i, j) = b.kinetic.diff(v[i]).diff(v[j]).expand();
      for (const auto& s : v) velocity_free = velocity_free && !H(i, j).has(s);
      quadratic_part += H(i, j) * v[i] * v[j] / 2;
    }
  g.quadratic = velocity_free && (b.kinetic - quadratic_part).expand().is_zero();
  if (g.quadratic) {
    g.L = matrix(m, m);
    g.K = matrix(m, d == 0 ? 1 : d);
    g.S = matrix(d == 0 ? 1 : d, d == 0 ? 1 : d);
    for (unsigned i = 0; i < m; ++i)
      for (unsigned j = 0; j < m; ++j) g.L(i, j) = simplify(H(i, j));
    for (unsigned i = 0; i < m; ++i)
      for (unsigned J = 0; J < d; ++J) g.K(i, J) = simplify(H(i, m + J));
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = 0; J < d; ++J) g.S(I, J) = simplify(H(m + I, m + J));
  }

  if (b.mechanical) {
    if (!g.quadratic)
      throw InputError(where, "kinetic",
                       "a mechanical connection needs a kinetic energy that is a quadratic form in the group velocity "
                       "and the shape rates (eq. T); this one is not");
    if (identically_singular(g.L))
      throw InputError(where, "kinetic",
                       "the locked inertia L = d2T/dxi dxi is singular (identically, in r), so the mechanical "
                       "connection A = L^-1 K does not exist; every group direction must carry kinetic energy");
    // Eq. (mechConn): A = L⁻¹K, by solving L A = K (never inverting the full mass matrix).
    g.connection = matrix(m, d);
    if (d > 0) {
      matrix X(m, d);
      std::vector<GiNaC::symbol> unknowns;
      matrix vars(m, d);
      for (unsigned i = 0; i < m; ++i)
        for (unsigned J = 0; J < d; ++J) {
          unknowns.emplace_back("X" + std::to_string(i) + "_" + std::to_string(J));
          vars(i, J) = unknowns.back();
        }
      X = g.L.solve(vars, g.K, GiNaC::solve_algo::gauss);
      g.connection = simplify(X);
    }
  } else {
    g.connection = b.kinematic_connection;
  }

  g.curvature = curvature_of(g.connection, model.coordinates, g.structure_constants, g.trivialization_sign);
  // Eq. (gamma42): E^α_βI = γ^α_Iβ = ±c^α_βλ A^λ_I.
  for (unsigned alpha = 0; alpha < m; ++alpha)
    for (unsigned beta = 0; beta < m; ++beta)
      for (unsigned I = 0; I < d; ++I) {
        ex e = 0;
        for (const StructureConstant& s : g.structure_constants)
          if (s.upper == static_cast<int>(alpha) && s.lower_a == static_cast<int>(beta))
            e += g.trivialization_sign * s.value * g.connection(static_cast<unsigned>(s.lower_b), I);
        e = simplify_bounded(e);
        if (!e.is_zero()) g.E.push_back({static_cast<int>(alpha), static_cast<int>(beta), static_cast<int>(I), e});
      }
  if (b.mechanical && d > 0) {
    // Eq. (MOmega): the shape block S − AᵀLA.
    const matrix At = g.connection.transpose();
    const GiNaC::matrix block = g.S.sub(At.mul(g.L).mul(g.connection));
    g.shape_inertia = GiNaC::matrix(d, d);
    for (unsigned I = 0; I < d; ++I)
      for (unsigned J = 0; J < d; ++J) g.shape_inertia(I, J) = simplify_bounded(block(I, J));
  }
  return g;
}

}  // namespace hamel
