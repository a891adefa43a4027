// The references `hamel accuracy` measures the kernels against (numeric/kernel_accuracy): for every kernel that
// build_kernels (emit/kernels.hpp) makes, the derivation's symbolic expressions its outputs come from, in the same
// output order. The rhs and jacobian kernels end in an LDLᵀ solve built in the graph: their references are
// M u̇ = f (and M ∂u̇/∂x_k = ∂f/∂x_k − ∂M/∂x_k u̇), solved in high precision from the symbolic M, f and their symbolic
// derivatives (formed here by the chain rule through the intermediates).
#pragma once

#include "algebra/intermediates.hpp"
#include "derive/derivation.hpp"
#include "model/model.hpp"

#include <ginac/ginac.h>

#include <map>
#include <string>
#include <vector>

namespace hamel {

struct KernelReferences {
  enum class Kind {
    direct,    ///< the outputs are `expressions`
    rhs,       ///< kinematics, then M⁻¹ f
    jacobian,  ///< ∂(kinematics)/∂x, then M⁻¹ (∂f/∂x − ∂M/∂x u̇), column by column
  };
  struct Entry {
    Kind kind = Kind::direct;
    std::vector<GiNaC::ex> expressions;  ///< direct kernels
  };
  std::map<std::string, Entry> kernels;  ///< by kernel name; a kernel not listed has no reference

  std::size_t n = 0, d = 0, nx = 0;  ///< coordinates, independent velocities, state
  std::vector<GiNaC::ex> kinematics, forcing;
  std::vector<std::vector<GiNaC::ex>> mass;                    ///< d x d
  std::vector<std::vector<GiNaC::ex>> kinematics_by_x;         ///< [k][a]
  std::vector<std::vector<GiNaC::ex>> forcing_by_x;            ///< [k][i]
  std::vector<std::vector<std::vector<GiNaC::ex>>> mass_by_x;  ///< [k][i][j]
  Intermediates intermediates;                                 ///< the derivation's, extended by the derivatives above
};

/// The references of the kernels of build_kernels(model, derivation).
KernelReferences kernel_references(const Model& model, const Derivation& derivation);

/// The solution of A x = b by Gaussian elimination with partial pivoting, in the current precision; throws
/// std::domain_error for a singular A.
std::vector<GiNaC::numeric> solve(std::vector<std::vector<GiNaC::numeric>> A, std::vector<GiNaC::numeric> b);

}  // namespace hamel
