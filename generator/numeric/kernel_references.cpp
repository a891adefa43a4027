#include "numeric/kernel_references.hpp"

#include <stdexcept>
#include <utility>

namespace hamel {

using GiNaC::ex;
using GiNaC::numeric;

std::vector<numeric> solve(std::vector<std::vector<numeric>> A, std::vector<numeric> b) {
  const std::size_t n = b.size();
  for (std::size_t j = 0; j < n; ++j) {
    std::size_t pivot = j;
    for (std::size_t i = j + 1; i < n; ++i)
      if (GiNaC::abs(A[i][j]) > GiNaC::abs(A[pivot][j])) pivot = i;
    if (A[pivot][j].is_zero()) throw std::domain_error("high precision: singular mass matrix");
    std::swap(A[j], A[pivot]);
    std::swap(b[j], b[pivot]);
    for (std::size_t i = j + 1; i < n; ++i) {
      const numeric f = A[i][j] / A[j][j];
      if (f.is_zero()) continue;
      for (std::size_t k = j; k < n; ++k) A[i][k] -= f * A[j][k];
      b[i] -= f * b[j];
    }
  }
  std::vector<numeric> x(n);
  for (std::size_t i = n; i-- > 0;) {
    numeric s = b[i];
    for (std::size_t k = i + 1; k < n; ++k) s -= A[i][k] * x[k];
    x[i] = s / A[i][i];
  }
  return x;
}

KernelReferences kernel_references(const Model& model, const Derivation& derivation) {
  KernelReferences r;
  const HamelEquations& eq = derivation.equations;
  const HamelSystem& sys = derivation.system;
  r.n = sys.coordinates.size();
  r.d = eq.independent.size();
  r.kinematics = eq.kinematics;
  r.forcing = eq.forcing;
  r.mass.assign(r.d, std::vector<ex>(r.d));
  for (unsigned i = 0; i < r.d; ++i)
    for (unsigned j = 0; j < r.d; ++j) r.mass[i][j] = eq.mass_matrix(i, j);

  using Kind = KernelReferences::Kind;
  r.kernels["kinematics"] = {Kind::direct, eq.kinematics};
  {
    std::vector<ex> m;
    for (const auto& row : r.mass) m.insert(m.end(), row.begin(), row.end());
    r.kernels["mass_matrix"] = {Kind::direct, m};
  }
  r.kernels["forcing"] = {Kind::direct, eq.forcing};
  {
    std::vector<ex> g;
    for (const HamelCoefficient& h : sys.gamma) g.push_back(h.value);
    r.kernels["hamel_coefficients"] = {Kind::direct, g};
  }
  r.kernels["rhs"] = {Kind::rhs, {}};
  r.kernels["energy"] = {Kind::direct, {eq.energy_terms.at(0)}};
  if (!eq.constraint_residual.empty()) r.kernels["constraint_residual"] = {Kind::direct, eq.constraint_residual};
  if (derivation.bundle) {
    const BundleGeometry& geo = *derivation.bundle;
    const std::size_t m = model.bundle->group_velocity.size();
    r.kernels["group_velocity"] = {Kind::direct, derivation.group_velocity};
    std::vector<ex> conn, locked;
    for (unsigned a = 0; a < m && geo.connection_derived; ++a)
      for (unsigned I = 0; I < r.n; ++I) conn.push_back(geo.connection(a, I));
    // Trees: A = L⁻¹K is solved in the kernel, not formed symbolically; not measured (reported as such).
    if (r.n > 0 && geo.connection_derived) r.kernels["connection"] = {Kind::direct, conn};
    if (geo.quadratic) {
      for (unsigned a = 0; a < m; ++a)
        for (unsigned c = 0; c < m; ++c) locked.push_back(geo.L(a, c));
      r.kernels["locked_inertia"] = {Kind::direct, locked};
    }
    if (model.bundle->mechanical && r.n > 0 && geo.connection_derived) {
      std::vector<ex> shape;
      for (unsigned I = 0; I < r.n; ++I)
        for (unsigned J = 0; J < r.n; ++J) shape.push_back(geo.shape_inertia(I, J));
      r.kernels["shape_inertia"] = {Kind::direct, shape};
    }
  }

  // Jacobian: derivatives with respect to the state (q, u_I).
  std::vector<GiNaC::symbol> state(sys.coordinates.begin(), sys.coordinates.end());
  for (int I : eq.independent) state.push_back(sys.velocities[static_cast<std::size_t>(I)]);
  r.nx = state.size();
  r.kinematics_by_x.resize(r.nx);
  r.forcing_by_x.resize(r.nx);
  r.mass_by_x.resize(r.nx);
  r.intermediates = eq.intermediates;
  for (std::size_t k = 0; k < r.nx; ++k) r.mass_by_x[k].assign(r.d, std::vector<ex>(r.d));
  const auto differentiate = [&](const std::vector<ex>& expressions, std::vector<std::vector<ex>>& by_x) {
    for (const ex& e : expressions) {
      const std::vector<ex> d = r.intermediates.diff(e, state);
      for (std::size_t k = 0; k < r.nx; ++k) by_x[k].push_back(d[k]);
    }
  };
  differentiate(r.kinematics, r.kinematics_by_x);
  differentiate(r.forcing, r.forcing_by_x);
  for (std::size_t i = 0; i < r.d; ++i)
    for (std::size_t j = 0; j < r.d; ++j) {
      const std::vector<ex> by_x = r.intermediates.diff(r.mass[i][j], state);
      for (std::size_t k = 0; k < r.nx; ++k) r.mass_by_x[k][i][j] = by_x[k];
    }
  r.kernels["jacobian"] = {Kind::jacobian, {}};
  return r;
}

}  // namespace hamel
