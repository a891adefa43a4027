// Spatial algebra on se(3) with GiNaC entries, for the recursive derivations over kinematic trees
// (derive/kinematic_tree.cpp, derive/articulated_body.cpp, derive/tree_derivatives.cpp). Twists and motion
// vectors are (ω, v), v the velocity of the point at the frame's origin; wrenches and momenta are (moment about
// the origin, force).
// Motion cross product ad_V W = V × W; force cross product V ×* F = −ad*_V F; ⟨V × W, F⟩ + ⟨W, V ×* F⟩ = 0.
#pragma once

#include "algebra/intermediates.hpp"

#include <ginac/ginac.h>

#include <array>

namespace hamel::spatial {

using GiNaC::ex;

using Vec3 = std::array<ex, 3>;
using Vec6 = std::array<ex, 6>;
using Mat3 = std::array<Vec3, 3>;
using Mat6 = std::array<Vec6, 6>;

inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3 angular(const Vec6& v) { return {v[0], v[1], v[2]}; }
inline Vec3 linear(const Vec6& v) { return {v[3], v[4], v[5]}; }
inline Vec6 join(const Vec3& a, const Vec3& b) { return {a[0], a[1], a[2], b[0], b[1], b[2]}; }
inline Vec6 zero6() { return {0, 0, 0, 0, 0, 0}; }
inline Vec6 unit6(int k) {
  Vec6 e = zero6();
  e[static_cast<std::size_t>(k)] = 1;
  return e;
}
inline Vec6 operator+(const Vec6& a, const Vec6& b) {
  Vec6 c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] + b[k];
  return c;
}
inline Vec6 operator*(const Vec6& a, const ex& s) {
  Vec6 c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] * s;
  return c;
}
inline ex dot(const Vec6& a, const Vec6& b) {
  ex s = 0;
  for (std::size_t k = 0; k < 6; ++k) s += a[k] * b[k];
  return s;
}
inline Vec6 times(const Mat6& m, const Vec6& v) {
  Vec6 out;
  for (std::size_t r = 0; r < 6; ++r) {
    ex s = 0;
    for (std::size_t c = 0; c < 6; ++c) s += m[r][c] * v[c];
    out[r] = s;
  }
  return out;
}
inline Vec6 times_transposed(const Mat6& m, const Vec6& v) {  // mᵀ v
  Mat6 t;
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t c = 0; c < 6; ++c) t[r][c] = m[c][r];
  return times(t, v);
}
inline Mat3 skew(const Vec3& c) { return {{{0, -c[2], c[1]}, {c[2], 0, -c[0]}, {-c[1], c[0], 0}}}; }

// ad_V W for twists V = (ω, v), W = (a, b): the velocity-product term of a body's acceleration.
inline Vec6 ad(const Vec6& V, const Vec6& W) {
  const Vec3 w = angular(V), v = linear(V), a = angular(W), b = linear(W);
  const Vec3 top = cross(w, a), l = cross(w, b), r = cross(v, a);
  return join(top, {l[0] + r[0], l[1] + r[1], l[2] + r[2]});
}

// −ad*_V h for a twist V = (ω, v) and a momentum h = (l, p): (ω×l + v×p, ω×p), the gyroscopic wrench
// of the Euler–Poincaré equation on SE(3), left-trivialized.
inline Vec6 coadjoint_term(const Vec6& V, const Vec6& h) {
  const Vec3 w = angular(V), v = linear(V), l = angular(h), p = linear(h);
  const Vec3 a = cross(w, l), b = cross(v, p);
  return join({a[0] + b[0], a[1] + b[1], a[2] + b[2]}, cross(w, p));
}

// V − W and V scaled.
inline Vec6 operator-(const Vec6& a, const Vec6& b) {
  Vec6 c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] - b[k];
  return c;
}
inline Mat6 operator+(const Mat6& a, const Mat6& b) {
  Mat6 c;
  for (std::size_t r = 0; r < 6; ++r) c[r] = a[r] + b[r];
  return c;
}
// What an articulated inertia 𝕀ᴬ (symmetric) passes to its body's parent: 𝕀ᴬ − U Uᵀ / D = 𝕀ᴬ − U Wᵀ, with
// U = 𝕀ᴬ s and W = U / D named by the caller (Featherstone's 𝕀ᵃ): one product per entry.
inline Mat6 articulated_remainder(const Mat6& IA, const Vec6& U, const Vec6& W) {
  Mat6 out;
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t k = r; k < 6; ++k) out[r][k] = out[k][r] = IA[r][k] - U[r] * W[k];
  return out;
}
inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator*(const Mat3& m, const Vec3& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

// The pose of a body relative to its parent, g = (R, p), and the two maps it induces: twists from the
// parent's frame to the body's (Ad_{g⁻¹}) and wrenches back (its transpose).
struct Link {
  Mat3 R;
  Vec3 p;
  Vec6 to_child(const Vec6& V) const {
    const Vec3 w = angular(V), v = linear(V), wp = cross(w, p);
    Vec3 a, b;
    for (std::size_t r = 0; r < 3; ++r) {
      a[r] = R[0][r] * w[0] + R[1][r] * w[1] + R[2][r] * w[2];
      b[r] = R[0][r] * (v[0] + wp[0]) + R[1][r] * (v[1] + wp[1]) + R[2][r] * (v[2] + wp[2]);
    }
    return join(a, b);
  }
  Vec6 to_parent(const Vec6& F) const {
    const Vec3 t = angular(F), f = linear(F);
    Vec3 Rt, Rf;
    for (std::size_t r = 0; r < 3; ++r) {
      Rt[r] = R[r][0] * t[0] + R[r][1] * t[1] + R[r][2] * t[2];
      Rf[r] = R[r][0] * f[0] + R[r][1] * f[1] + R[r][2] * f[2];
    }
    const Vec3 m = cross(p, Rf);
    return join({Rt[0] + m[0], Rt[1] + m[1], Rt[2] + m[2]}, Rf);
  }
  // Twists from the body's frame to the parent's (Ad_g): (R ω, R v + p × R ω).
  Vec6 motion_to_parent(const Vec6& V) const {
    const Vec3 w = R * angular(V);
    return join(w, R * linear(V) + cross(p, w));
  }
};

// A spatial inertia about a frame's origin: mass m, first moment h = m c, rotational inertia J about the
// origin (symmetric). 𝕀 (ω, v) = (J ω + h × v, m v − h × ω). Inertias of bodies in one frame add.
struct Inertia {
  ex m = 0;
  Vec3 h{0, 0, 0};
  Mat3 J{{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  Vec6 operator()(const Vec6& x) const {
    const Vec3 w = angular(x), v = linear(x);
    const Vec3 hv = cross(h, v), hw = cross(h, w);
    return join(J * w + hv, {m * v[0] - hw[0], m * v[1] - hw[1], m * v[2] - hw[2]});
  }
  Mat6 matrix() const {  // column k: 𝕀 e_k
    Mat6 out;
    for (std::size_t k = 0; k < 6; ++k) {
      const Vec6 column = (*this)(unit6(static_cast<int>(k)));
      for (std::size_t r = 0; r < 6; ++r) out[r][k] = column[r];
    }
    return out;
  }
  void add(const Inertia& o) {
    m += o.m;
    for (std::size_t r = 0; r < 3; ++r) {
      h[r] += o.h[r];
      for (std::size_t c = 0; c < 3; ++c) J[r][c] += o.J[r][c];
    }
  }
};

// Names spatial quantities in a program (Intermediates::define, entry by entry): what the recursions over a
// tree keep as intermediate symbols.
class Namer {
 public:
  explicit Namer(Intermediates& tape) : tape_(tape) {}
  ex operator()(const ex& e) { return tape_.define(e); }
  Vec3 operator()(const Vec3& v) { return {(*this)(v[0]), (*this)(v[1]), (*this)(v[2])}; }
  Vec6 operator()(const Vec6& v) {
    Vec6 out;
    for (std::size_t k = 0; k < 6; ++k) out[k] = (*this)(v[k]);
    return out;
  }
  Mat3 operator()(const Mat3& m) { return {(*this)(m[0]), (*this)(m[1]), (*this)(m[2])}; }
  Mat6 operator()(const Mat6& m) {
    Mat6 out;
    for (std::size_t r = 0; r < 6; ++r) out[r] = (*this)(m[r]);
    return out;
  }
  // A symmetric K×K (3×3 or 6×6), each distinct entry named once.
  template <std::size_t K>
  std::array<std::array<ex, K>, K> symmetric(const std::array<std::array<ex, K>, K>& m) {
    std::array<std::array<ex, K>, K> out;
    for (std::size_t r = 0; r < K; ++r)
      for (std::size_t c = r; c < K; ++c) out[r][c] = out[c][r] = (*this)(m[r][c]);
    return out;
  }
  Inertia operator()(const Inertia& I) {
    Inertia out;
    out.m = (*this)(I.m);
    out.h = (*this)(I.h);
    out.J = symmetric(I.J);
    return out;
  }

 private:
  Intermediates& tape_;
};

// A symmetric 6×6 inertia 𝕀 (maps twists to wrenches) about a body's frame, seen from its parent's frame at
// pose (R, p): X 𝕀 Xᵀ with X = [[R, P R], [0, R]] the wrench map of Link::to_parent, P = [p]×. By 3×3 blocks
// 𝕀 = [[A, B], [Bᵀ, C]]: rotated A' = R A Rᵀ, B' = R B Rᵀ, C' = R C Rᵀ, then moved by p:
// [[A' + P B'ᵀ − B'' P, B''], [B''ᵀ, C']] with B'' = B' + P C'. Fewer operations than X 𝕀 Xᵀ column by column,
// most of all when R is a rotation about a coordinate axis (its zeros drop out of R X).
inline Mat6 inertia_to_parent(const Link& l, const Mat6& I, Namer& name) {
  const Mat3& R = l.R;
  const auto rotate = [&](std::size_t row, std::size_t col, bool symmetric) {
    Mat3 RX;  // R X
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = 0; k < 3; ++k)
        RX[r][k] = R[r][0] * I[row][col + k] + R[r][1] * I[row + 1][col + k] + R[r][2] * I[row + 2][col + k];
    RX = name(RX);
    Mat3 out;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = symmetric ? r : 0; k < 3; ++k) {
        out[r][k] = RX[r][0] * R[k][0] + RX[r][1] * R[k][1] + RX[r][2] * R[k][2];
        if (symmetric) out[k][r] = out[r][k];
      }
    return symmetric ? name.symmetric(out) : name(out);
  };
  const Mat3 A = rotate(0, 0, true), B = rotate(0, 3, false), C = rotate(3, 3, true);
  const Mat3 P = skew(l.p);
  Mat3 B2;  // B' + P C'
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) B2[r][k] = B[r][k] + P[r][0] * C[0][k] + P[r][1] * C[1][k] + P[r][2] * C[2][k];
  B2 = name(B2);
  Mat6 out;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) {
      out[r][k + 3] = out[k + 3][r] = B2[r][k];
      out[r + 3][k + 3] = C[r][k];
      if (k < r) continue;
      ex a = A[r][k];  // + (P B'ᵀ)_rk − (B'' P)_rk
      for (std::size_t j = 0; j < 3; ++j) a += P[r][j] * B[k][j] - B2[r][j] * P[j][k];
      out[r][k] = out[k][r] = a;
    }
  return out;
}

}  // namespace hamel::spatial
