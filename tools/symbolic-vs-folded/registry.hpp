// The rhs kernels under comparison: every emitted package registers itself here from its adapter
// (adapter.cpp.in), under its model and its variant ("symbolic": p[] read at run time; "folded": --fold all).
#pragma once

#include <string>
#include <vector>

namespace svf {

using rhs_function = void (*)(double t, const double* x, const double* p, const double* in, double* out);

struct Package {
  std::string model, variant;
  rhs_function rhs;
  int n_state, n_parameters, n_inputs, n_out, n_temporaries;
  const double* default_parameters;
  std::string operations;  // emit's count for rhs, e.g. "52 (11 add, 34 mul, 3 div, 4 call)"
};

inline std::vector<Package>& packages() {
  static std::vector<Package> all;
  return all;
}

inline bool add(Package p) {
  packages().push_back(std::move(p));
  return true;
}

}  // namespace svf
