// Eq. (u2): q̇ = B(q) u with B = A⁻¹; A must be regular (valid local coordinates).
#include "derive/quasi_velocities.hpp"

#include "algebra/expression_text.hpp"
#include "algebra/simplify.hpp"
#include "model/input_error.hpp"

namespace hamel {

namespace {

SourceLocation location_of(const Model& model, const std::string& key) {
  auto it = model.locations.find(key);
  return it == model.locations.end() ? SourceLocation{model.source_path, 0, 0} : it->second;
}

}  // namespace

QuasiVelocities derive_quasi_velocities(const Model& model) {
  QuasiVelocities qv;
  qv.A = simplify(model.A);
  const unsigned n = qv.A.rows();
  const GiNaC::ex det = simplify(qv.A.determinant());
  if (det.is_zero())
    throw InputError(location_of(model, "quasi_velocities.A"), "quasi_velocities.A",
                     "A(q) is singular (its determinant is identically zero); the quasi-velocities must be "
                     "independent combinations of the coordinate rates");
  if (model.B_given) {
    qv.B = simplify(model.B);
    const GiNaC::matrix product = qv.A.mul(qv.B);
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < n; ++j)
        if (!is_zero_exactly(product(i, j) - (i == j ? 1 : 0)))
          throw InputError(location_of(model, "quasi_velocities.B"), "quasi_velocities.B",
                           "B is not the inverse of A: (A*B)[" + std::to_string(i) + "][" + std::to_string(j) +
                               "] simplifies to " + to_text(simplify(product(i, j))) +
                               (i == j ? ", expected 1" : ", expected 0"));
  } else {
    // GiNaC inverts by elimination; simplify() then applies sin² + cos² = 1 that it does not know.
    qv.B = simplify(qv.A.inverse());
  }
  return qv;
}

}  // namespace hamel
