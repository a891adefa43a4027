// Eq. (gamma): γ^c_ab := (∂A^c_r/∂q^s − ∂A^c_s/∂q^r) B^r_a B^s_b. They vanish identically iff the
// quasi-velocities are holonomic; for canonical coordinates on a Lie group they are ±c^c_ab.
#include "derive/hamel_coefficients.hpp"

#include "algebra/identity_test.hpp"

#include <algorithm>
#include <tuple>

namespace hamel {

std::vector<HamelCoefficient> hamel_coefficients(const Model& model, const QuasiVelocities& qv) {
  Intermediates program = model.definitions;
  std::vector<HamelCoefficient> out = hamel_coefficients(model, qv, program);
  for (HamelCoefficient& h : out) h.value = program.inline_all(h.value);
  return out;
}

std::vector<HamelCoefficient> hamel_coefficients(const Model& model, const QuasiVelocities& qv,
                                                 Intermediates& program) {
  const unsigned n = static_cast<unsigned>(model.n());
  std::vector<HamelCoefficient> out;
  for (unsigned c = 0; c < n; ++c) {
    // The exterior derivative of the Pfaffian form du^c: curl[r][s] = ∂A^c_r/∂q^s − ∂A^c_s/∂q^r.
    GiNaC::matrix curl(n, n);
    bool closed = true;
    for (unsigned r = 0; r < n; ++r)
      for (unsigned s = r + 1; s < n; ++s) {
        const GiNaC::ex d =
            program.diff(qv.A(c, r), model.coordinates[s]) - program.diff(qv.A(c, s), model.coordinates[r]);
        curl(r, s) = d;
        curl(s, r) = -d;
        closed = closed && d.is_zero();
      }
    if (closed) continue;  // exactly closed form: no coefficient with this upper index
    std::vector<HamelCoefficient> row;
    for (unsigned a = 0; a < n; ++a)
      for (unsigned b = a + 1; b < n; ++b) {
        GiNaC::ex g = 0;
        for (unsigned r = 0; r < n; ++r)
          for (unsigned s = 0; s < n; ++s)
            if (!curl(r, s).is_zero()) g += curl(r, s) * qv.B(r, a) * qv.B(s, b);
        if (shown_zero(g, program)) continue;
        g = program.keep(g, 400);
        if (g.is_zero()) continue;
        out.push_back({static_cast<int>(c), static_cast<int>(a), static_cast<int>(b), g});
        out.push_back({static_cast<int>(c), static_cast<int>(b), static_cast<int>(a), -g});
      }
  }
  sort_by_indices(out);
  return out;
}

}  // namespace hamel
