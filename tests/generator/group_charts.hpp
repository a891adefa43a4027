// Canonical coordinates s on the groups of the bundle models, written in the tests independently of the
// generator's Lie-algebra basis: each group element g(s) is an explicit matrix (ZYX Euler angles for the
// rotation, Rz(psi) Ry(theta) Rx(phi); position p), the velocity ξ is read off g⁻¹ ∂g/∂s^k (left) or
// ∂g/∂s^k g⁻¹ (right) with the tests' own "vee" (ω̂ v = ω × v, angular before linear), so that
// ξ = A_s(s) ṡ and ṡ = B_s(s) ξ. The only convention shared with generator/lie is that documented order
// and hat map (docs/model-format.md), not any code.
#pragma once

#include "algebra/simplify.hpp"

#include <ginac/ginac.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamel::test {

struct GroupChart {
  std::vector<GiNaC::realsymbol> s;  ///< canonical coordinates on G
  GiNaC::matrix A;                   ///< ξ = A(s) ṡ, m × m
  GiNaC::matrix B;                   ///< ṡ = B(s) ξ, B = A⁻¹
};

namespace chart_detail {

using GiNaC::cos;
using GiNaC::ex;
using GiNaC::matrix;
using GiNaC::sin;

inline matrix rotation_zyx(const ex& psi, const ex& theta, const ex& phi) {
  const matrix Rz = {{cos(psi), -sin(psi), 0}, {sin(psi), cos(psi), 0}, {0, 0, 1}};
  const matrix Ry = {{cos(theta), 0, sin(theta)}, {0, 1, 0}, {-sin(theta), 0, cos(theta)}};
  const matrix Rx = {{1, 0, 0}, {0, cos(phi), -sin(phi)}, {0, sin(phi), cos(phi)}};
  return Rz.mul(Ry).mul(Rx);
}

// The group element and its inverse as explicit matrices; vee reads the velocity components off a
// Lie-algebra element in that representation.
struct Representation {
  matrix g, g_inverse;
  std::function<std::vector<ex>(const matrix&)> vee;
  std::function<matrix(const std::vector<ex>&)> hat;
};

inline std::vector<ex> vee_so3(const matrix& X, unsigned at) {
  return {X(at + 2, at + 1), X(at + 0, at + 2), X(at + 1, at + 0)};
}

// ω̂ with ω̂ v = ω × v, written into X at (at, at).
inline void hat_so3(matrix& X, const std::vector<ex>& w, unsigned at) {
  X(at + 0, at + 1) = -w[2];
  X(at + 0, at + 2) = w[1];
  X(at + 1, at + 0) = w[2];
  X(at + 1, at + 2) = -w[0];
  X(at + 2, at + 0) = -w[1];
  X(at + 2, at + 1) = w[0];
}

inline Representation representation(const std::string& group, const std::vector<GiNaC::realsymbol>& s) {
  Representation r;
  if (group == "SO3") {
    r.g = rotation_zyx(s[0], s[1], s[2]);
    r.g_inverse = r.g.transpose();
    r.vee = [](const matrix& X) { return vee_so3(X, 0); };
    r.hat = [](const std::vector<ex>& w) {
      matrix X(3, 3);
      hat_so3(X, w, 0);
      return X;
    };
  } else if (group == "SE3" || group == "SO3xR3") {
    const matrix R = rotation_zyx(s[0], s[1], s[2]);
    const matrix Rt = R.transpose();
    const matrix p = {{s[3]}, {s[4]}, {s[5]}};
    if (group == "SE3") {
      // g = [[R, p], [0, 1]], g⁻¹ = [[Rᵀ, −Rᵀp], [0, 1]].
      const matrix minus_Rt_p = Rt.mul(p).mul_scalar(-1);
      r.g = matrix(4, 4);
      r.g_inverse = matrix(4, 4);
      for (unsigned i = 0; i < 3; ++i) {
        for (unsigned j = 0; j < 3; ++j) {
          r.g(i, j) = R(i, j);
          r.g_inverse(i, j) = Rt(i, j);
        }
        r.g(i, 3) = p(i, 0);
        r.g_inverse(i, 3) = minus_Rt_p(i, 0);
      }
      r.g(3, 3) = r.g_inverse(3, 3) = 1;
      r.vee = [](const matrix& X) {
        std::vector<ex> xi = vee_so3(X, 0);
        for (unsigned i = 0; i < 3; ++i) xi.push_back(X(i, 3));
        return xi;
      };
      r.hat = [](const std::vector<ex>& xi) {
        matrix X(4, 4);
        hat_so3(X, xi, 0);
        for (unsigned i = 0; i < 3; ++i) X(i, 3) = xi[3 + i];
        return X;
      };
    } else {
      // Direct product: diag(R, [[1, p], [0, 1]]), a 7×7 block-diagonal matrix.
      r.g = matrix(7, 7);
      r.g_inverse = matrix(7, 7);
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned j = 0; j < 3; ++j) {
          r.g(i, j) = R(i, j);
          r.g_inverse(i, j) = Rt(i, j);
        }
      for (unsigned i = 3; i < 7; ++i) r.g(i, i) = r.g_inverse(i, i) = 1;
      for (unsigned i = 0; i < 3; ++i) {
        r.g(3 + i, 6) = p(i, 0);
        r.g_inverse(3 + i, 6) = -p(i, 0);
      }
      r.vee = [](const matrix& X) {
        std::vector<ex> xi = vee_so3(X, 0);
        for (unsigned i = 0; i < 3; ++i) xi.push_back(X(3 + i, 6));
        return xi;
      };
      r.hat = [](const std::vector<ex>& xi) {
        matrix X(7, 7);
        hat_so3(X, xi, 0);
        for (unsigned i = 0; i < 3; ++i) X(3 + i, 6) = xi[3 + i];
        return X;
      };
    }
  } else if (group == "SE2") {
    const ex c = cos(s[0]), sn = sin(s[0]), x = s[1], y = s[2];
    r.g = matrix{{c, -sn, x}, {sn, c, y}, {0, 0, 1}};
    r.g_inverse = matrix{{c, sn, -c * x - sn * y}, {-sn, c, sn * x - c * y}, {0, 0, 1}};
    r.vee = [](const matrix& X) { return std::vector<ex>{X(1, 0), X(0, 2), X(1, 2)}; };
    r.hat = [](const std::vector<ex>& xi) { return matrix{{0, -xi[0], xi[1]}, {xi[0], 0, xi[2]}, {0, 0, 0}}; };
  } else {
    throw std::invalid_argument("group_charts: no chart for " + group);
  }
  return r;
}

inline std::vector<std::string> coordinate_names(const std::string& group) {
  if (group == "SO3") return {"s_psi", "s_theta", "s_phi"};
  if (group == "SE3" || group == "SO3xR3") return {"s_psi", "s_theta", "s_phi", "s_x", "s_y", "s_z"};
  if (group == "SE2") return {"s_theta", "s_x", "s_y"};
  throw std::invalid_argument("group_charts: no chart for " + group);
}

}  // namespace chart_detail

/// Canonical coordinates on `group` ("SO3", "SE3", "SO3xR3", "SE2") with the left (ξ̂ = g⁻¹ġ) or right
/// (ξ̂ = ġg⁻¹) velocity. Throws if g⁻¹ is not the inverse of g or A is not a velocity map.
inline GroupChart group_chart(const std::string& group, bool right) {
  using GiNaC::ex;
  using GiNaC::matrix;
  GroupChart chart;
  for (const auto& name : chart_detail::coordinate_names(group)) chart.s.emplace_back(name);
  const chart_detail::Representation rep = chart_detail::representation(group, chart.s);
  const matrix identity_check = rep.g.mul(rep.g_inverse);
  for (unsigned i = 0; i < identity_check.rows(); ++i)
    for (unsigned j = 0; j < identity_check.cols(); ++j)
      if (!is_zero_almost_surely(identity_check(i, j) - (i == j ? 1 : 0)))
        throw std::logic_error("group_charts: g_inverse is not the inverse of g for " + group);
  const unsigned m = static_cast<unsigned>(chart.s.size());
  chart.A = matrix(m, m);
  for (unsigned k = 0; k < m; ++k) {
    matrix dg(rep.g.rows(), rep.g.cols());
    for (unsigned i = 0; i < dg.rows(); ++i)
      for (unsigned j = 0; j < dg.cols(); ++j) dg(i, j) = rep.g(i, j).diff(chart.s[k]);
    const matrix X = simplify(right ? dg.mul(rep.g_inverse) : rep.g_inverse.mul(dg));
    // X must lie in the algebra (skew block, zero last row, ...): hat(vee(X)) reproduces it.
    const std::vector<ex> xi = rep.vee(X);
    const matrix back = rep.hat(xi);
    for (unsigned i = 0; i < X.rows(); ++i)
      for (unsigned j = 0; j < X.cols(); ++j)
        if (!is_zero_almost_surely(back(i, j) - X(i, j)))
          throw std::logic_error("group_charts: the velocity of " + group + " is not in its algebra");
    for (unsigned a = 0; a < m; ++a) chart.A(a, k) = simplify(xi[a]);
  }
  chart.B = simplify(chart.A.inverse());
  return chart;
}

}  // namespace hamel::test
