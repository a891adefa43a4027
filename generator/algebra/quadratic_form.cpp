#include "algebra/quadratic_form.hpp"

#include "algebra/identity_test.hpp"
#include "rbd/ldlt.hpp"

#include <string>

namespace hamel {

using GiNaC::ex;
using GiNaC::matrix;

// The third derivatives are tested as one trilinear form T‴(v)[a, b, c] in fresh symbols a, b, c (zero as a
// polynomial iff every third derivative is zero).
bool is_quadratic_form(const ex& T, const std::vector<GiNaC::realsymbol>& v, const matrix& H, Intermediates& program) {
  const std::size_t n = v.size();
  ex derivative = T;
  for (const char* direction : {"a", "b", "c"}) {
    ex along = 0;
    for (std::size_t i = 0; i < n; ++i)
      along += GiNaC::realsymbol(std::string("_dir_") + direction + std::to_string(i)) * program.diff(derivative, v[i]);
    derivative = along;
  }
  if (!shown_zero(derivative, program)) return false;
  ex rest = T;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) rest -= H(static_cast<unsigned>(i), static_cast<unsigned>(j)) * v[i] * v[j] / 2;
  return shown_zero(rest, program);
}

matrix solve_positive_definite(const matrix& L, const matrix& K, Intermediates& program, std::size_t inline_size) {
  const unsigned m = L.rows(), d = K.cols();
  rbd::LdltOptions<ex> o;
  const rbd::Namer<ex> keep([&program](const ex& e) { return program.keep(e); });
  o.pivot = o.factor = o.forward = keep;
  o.solution = rbd::Namer<ex>([&program, inline_size](const ex& e) { return program.keep(e, inline_size); });
  std::vector<std::vector<ex>> S(m, std::vector<ex>(m)), columns(d, std::vector<ex>(m));
  for (unsigned i = 0; i < m; ++i)
    for (unsigned j = 0; j < m; ++j) S[i][j] = L(i, j);
  for (unsigned c = 0; c < d; ++c)
    for (unsigned i = 0; i < m; ++i) columns[c][i] = K(i, c);
  const std::vector<std::vector<ex>> solved = rbd::ldlt_solve(S, columns, o);
  matrix X(m, d);
  for (unsigned c = 0; c < d; ++c)
    for (unsigned i = 0; i < m; ++i) X(i, c) = solved[c][i];
  return X;
}

}  // namespace hamel
