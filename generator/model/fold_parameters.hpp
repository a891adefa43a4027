// Parameters fixed at generation time: each named parameter is replaced by its value (an exact rational,
// see exact_number) in every expression of the model before derivation. Folding keeps derivations of
// models with many parameters small (the inverse of a symbolic 6×6 locked inertia in 19 parameters has
// millions of terms; with numbers it is a 6×6 of rationals) and lets the emitted kernels fold constants.
// The parameter list itself is unchanged, so the kernel ABI (the p array) stays the same.
#pragma once

#include "model/model.hpp"

#include <map>
#include <string>

namespace hamel {

/// A copy of `model` with the parameters in `values` (name → value) folded in. Names that are not
/// parameters are input errors.
Model fold_parameters(const Model& model, const std::map<std::string, double>& values);

}  // namespace hamel
