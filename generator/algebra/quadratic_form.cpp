#include "algebra/quadratic_form.hpp"

#include "algebra/identity_test.hpp"

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
  matrix F(m, m);  // unit lower triangle
  std::vector<ex> D(m);
  for (unsigned k = 0; k < m; ++k) {
    ex pivot = L(k, k);
    for (unsigned j = 0; j < k; ++j)
      if (!F(k, j).is_zero()) pivot -= F(k, j) * F(k, j) * D[j];
    D[k] = program.keep(pivot);
    for (unsigned i = k + 1; i < m; ++i) {
      ex e = L(i, k);
      for (unsigned j = 0; j < k; ++j)
        if (!F(i, j).is_zero() && !F(k, j).is_zero()) e -= F(i, j) * F(k, j) * D[j];
      F(i, k) = e.is_zero() ? ex(0) : program.keep(e / D[k]);
    }
  }
  matrix X(m, d);
  for (unsigned c = 0; c < d; ++c) {
    std::vector<ex> y(m);
    for (unsigned i = 0; i < m; ++i) {
      ex e = K(i, c);
      for (unsigned j = 0; j < i; ++j)
        if (!F(i, j).is_zero()) e -= F(i, j) * y[j];
      y[i] = program.keep(e);
    }
    for (unsigned i = m; i-- > 0;) {
      ex e = y[i] / D[i];
      for (unsigned j = i + 1; j < m; ++j)
        if (!F(j, i).is_zero()) e -= F(j, i) * X(j, c);
      X(i, c) = program.keep(e, inline_size);
    }
  }
  return X;
}

}  // namespace hamel
