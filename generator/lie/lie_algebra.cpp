#include "lie/lie_algebra.hpp"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace hamel {

namespace {

using GiNaC::matrix;

matrix zeros(unsigned n) { return matrix(n, n); }

// so(3): E_i = ê_i, the skew matrix with ê_i v = e_i × v.
void add_so3(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at) {
  const int eps[3][3][3] = {
      {{0, 0, 0}, {0, 0, 1}, {0, -1, 0}}, {{0, 0, -1}, {0, 0, 0}, {1, 0, 0}}, {{0, 1, 0}, {-1, 0, 0}, {0, 0, 0}}};
  const char* axis[3] = {"x", "y", "z"};
  for (unsigned i = 0; i < 3; ++i) {
    matrix e = zeros(size);
    // (ê_i)_jk = −ε_ijk
    for (unsigned j = 0; j < 3; ++j)
      for (unsigned k = 0; k < 3; ++k) e(at + j, at + k) = -eps[i][j][k];
    basis.push_back(e);
    names.push_back(std::string("omega_") + axis[i]);
  }
}

// Translations of R^k as (k+1)×(k+1) homogeneous matrices: E_i has e_i in the last column.
void add_translations(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at,
                      unsigned k, unsigned column, const char* prefix) {
  const char* axis[6] = {"x", "y", "z", "4", "5", "6"};
  for (unsigned i = 0; i < k; ++i) {
    matrix e = zeros(size);
    e(at + i, column) = 1;
    basis.push_back(e);
    names.push_back(std::string(prefix) + axis[i]);
  }
}

void add_se3(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at) {
  add_so3(basis, names, size, at);
  add_translations(basis, names, size, at, 3, at + 3, "v_");
}

void add_se2(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at) {
  matrix e = zeros(size);
  e(at, at + 1) = -1;
  e(at + 1, at) = 1;
  basis.push_back(e);
  names.push_back("omega");
  add_translations(basis, names, size, at, 2, at + 2, "v_");
}

template <unsigned k>
void add_rk(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at) {
  add_translations(basis, names, size, at, k, at + k, "v_");
}

// A group a model may name, alone or as a factor of a product: the size of its square block, how its algebra's
// basis is written into that block (at row and column `at` of a size×size matrix), and the directions of a body's
// twist (ω, v) in which it moves a kinematic tree's floating base (empty: no tree base). The only list of groups.
struct Factor {
  const char* name;
  unsigned block;
  void (*add)(std::vector<matrix>& basis, std::vector<std::string>& names, unsigned size, unsigned at);
  std::vector<int> tree_base;
};

const std::vector<Factor>& factors() {
  static const std::vector<Factor> table = {
      {"SE3", 4, add_se3, {0, 1, 2, 3, 4, 5}},
      {"SO3", 3, add_so3, {0, 1, 2}},
      {"SE2", 3, add_se2, {2, 3, 4}},
      {"R1", 2, add_rk<1>, {3}},
      {"R2", 3, add_rk<2>, {3, 4}},
      {"R3", 4, add_rk<3>, {3, 4, 5}},
      {"R4", 5, add_rk<4>, {}},
      {"R5", 6, add_rk<5>, {}},
      {"R6", 7, add_rk<6>, {}},
  };
  return table;
}

// The factor called `name`; null when there is none.
const Factor* factor(const std::string& name) {
  for (const Factor& f : factors())
    if (name == f.name) return &f;
  return nullptr;
}

// "a, b or c"
std::string listed(const std::vector<std::string>& names, const char* last) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) text += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return text;
}

std::vector<std::string> split_product(const std::string& group) {
  std::vector<std::string> parts;
  std::string::size_type start = 0;
  while (true) {
    const auto x = group.find('x', start);
    parts.push_back(group.substr(start, x == std::string::npos ? std::string::npos : x - start));
    if (x == std::string::npos) break;
    start = x + 1;
  }
  return parts;
}

GiNaC::ex frobenius(const matrix& a, const matrix& b) {
  GiNaC::ex s = 0;
  for (unsigned i = 0; i < a.rows(); ++i)
    for (unsigned j = 0; j < a.cols(); ++j) s += a(i, j) * b(i, j);
  return s;
}

}  // namespace

std::vector<int> tree_base_directions(const std::string& group) {
  const Factor* f = factor(group);
  return f ? f->tree_base : std::vector<int>{};
}

std::string tree_base_groups() {
  std::vector<std::string> names;
  for (const Factor& f : factors())
    if (!f.tree_base.empty()) names.push_back(f.name);
  return listed(names, " or ");
}

std::vector<std::string> known_groups() {
  std::vector<std::string> names;
  for (const Factor& f : factors()) names.push_back(f.name);
  names.push_back("products such as SO3xR3");
  return names;
}

LieAlgebra lie_algebra(const std::string& group) {
  const std::vector<std::string> parts = split_product(group);
  unsigned size = 0;
  for (const auto& p : parts) {
    const Factor* f = factor(p);
    if (!f)
      throw std::invalid_argument("unknown group '" + group + "'; expected one of: " + listed(known_groups(), ", "));
    size += f->block;
  }
  LieAlgebra algebra;
  algebra.group = group;
  unsigned at = 0;
  for (const auto& p : parts) {
    const Factor& f = *factor(p);
    f.add(algebra.basis, algebra.basis_names, size, at);
    at += f.block;
  }
  return algebra;
}

std::vector<StructureConstant> structure_constants(const LieAlgebra& algebra) {
  const unsigned m = algebra.dim();
  matrix gram(m, m);
  for (unsigned a = 0; a < m; ++a)
    for (unsigned b = 0; b < m; ++b) gram(a, b) = frobenius(algebra.basis[a], algebra.basis[b]);
  const matrix gram_inverse = gram.inverse();
  std::vector<StructureConstant> out;
  for (unsigned b = 0; b < m; ++b)
    for (unsigned l = 0; l < m; ++l) {
      const matrix& Eb = algebra.basis[b];
      const matrix& El = algebra.basis[l];
      const matrix bracket = Eb.mul(El).sub(El.mul(Eb));
      matrix rhs(m, 1);
      for (unsigned a = 0; a < m; ++a) rhs(a, 0) = frobenius(algebra.basis[a], bracket);
      const matrix c = gram_inverse.mul(rhs);
      matrix check = zeros(bracket.rows());
      for (unsigned a = 0; a < m; ++a) check = check.add(algebra.basis[a].mul_scalar(c(a, 0)));
      if (!check.sub(bracket).expand().is_zero_matrix())
        throw std::logic_error("the basis of " + algebra.group + " is not closed under the bracket");
      for (unsigned a = 0; a < m; ++a)
        if (!c(a, 0).is_zero()) out.push_back({static_cast<int>(a), static_cast<int>(b), static_cast<int>(l), c(a, 0)});
    }
  sort_by_indices(out);
  return out;
}

std::vector<std::vector<std::vector<GiNaC::ex>>> dense(const std::vector<StructureConstant>& c, unsigned dim) {
  std::vector<std::vector<std::vector<GiNaC::ex>>> d(
      dim, std::vector<std::vector<GiNaC::ex>>(dim, std::vector<GiNaC::ex>(dim, GiNaC::ex(0))));
  for (const auto& s : c)
    d[static_cast<std::size_t>(s.upper)][static_cast<std::size_t>(s.lower_a)][static_cast<std::size_t>(s.lower_b)] =
        s.value;
  return d;
}

}  // namespace hamel
