// Parameters fixed at generation time: each named parameter is replaced by its value (an exact rational,
// see exact_number) in every expression of the model before derivation. Folding keeps derivations of
// models with many parameters small (the inverse of a symbolic 6×6 locked inertia in 19 parameters has
// millions of terms; with numbers it is a 6×6 of rationals) and lets the emitted kernels fold constants.
// The parameter list itself is unchanged, so the kernel ABI (the p array) stays the same.
#pragma once

#include "model/model.hpp"

#include <map>
#include <string>
#include <vector>

namespace hamel {

/// A copy of `model` with the parameters in `values` (name → value) folded in. Names that are not
/// parameters are input errors.
Model fold_parameters(const Model& model, const std::map<std::string, double>& values);

/// The parameters left symbolic (not folded), as indices into model.parameters in file order: parameter_jacobian's
/// columns, in the kernel and in the package's header alike.
std::vector<std::size_t> symbolic_parameters(const Model& model);

}  // namespace hamel
