// Spatial algebra on se(3), generic in the scalar: the rigid-body algorithms of rbd/ run on GiNaC expressions
// (derivation, every quantity a named intermediate) and on nodes of the expression graph (emit/graph_scalar.hpp:
// the Jacobian's solves) with the same code. A scalar type S needs +, −, ·, / and unary −, construction from an
// int (0 and 1), and `is_zero(S)` found by argument-dependent lookup (GiNaC has it for ex).
//
// Twists and motion vectors are (ω, v), v the velocity of the point at the frame's origin; wrenches and momenta
// are (moment about the origin, force). Motion cross product ad_V W = V × W; force cross product
// V ×* F = −ad*_V F; ⟨V × W, F⟩ + ⟨W, V ×* F⟩ = 0 (Featherstone, Rigid Body Dynamics Algorithms, ch. 2).
#pragma once

#include <ginac/ginac.h>

#include <array>
#include <cstddef>
#include <functional>

namespace hamel::rbd {

template <class S>
using Vec3 = std::array<S, 3>;
template <class S>
using Vec6 = std::array<S, 6>;
template <class S>
using Mat3 = std::array<Vec3<S>, 3>;
template <class S>
using Mat6 = std::array<Vec6<S>, 6>;

template <class S>
Vec3<S> cross(const Vec3<S>& a, const Vec3<S>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class S>
Vec3<S> angular(const Vec6<S>& v) {
  return {v[0], v[1], v[2]};
}
template <class S>
Vec3<S> linear(const Vec6<S>& v) {
  return {v[3], v[4], v[5]};
}
template <class S>
Vec6<S> join(const Vec3<S>& a, const Vec3<S>& b) {
  return {a[0], a[1], a[2], b[0], b[1], b[2]};
}
template <class S>
Vec6<S> zero6() {
  return {S(0), S(0), S(0), S(0), S(0), S(0)};
}
template <class S>
Vec6<S> unit6(int k) {
  Vec6<S> e = zero6<S>();
  e[static_cast<std::size_t>(k)] = S(1);
  return e;
}
template <class S>
Mat3<S> identity3() {
  return {{{S(1), S(0), S(0)}, {S(0), S(1), S(0)}, {S(0), S(0), S(1)}}};
}
template <class S>
Vec6<S> operator+(const Vec6<S>& a, const Vec6<S>& b) {
  Vec6<S> c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] + b[k];
  return c;
}
template <class S>
Vec6<S> operator-(const Vec6<S>& a, const Vec6<S>& b) {
  Vec6<S> c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] - b[k];
  return c;
}
template <class S>
Vec6<S> operator*(const Vec6<S>& a, const S& s) {
  Vec6<S> c;
  for (std::size_t k = 0; k < 6; ++k) c[k] = a[k] * s;
  return c;
}
template <class S>
S dot(const Vec6<S>& a, const Vec6<S>& b) {
  S s = S(0);
  for (std::size_t k = 0; k < 6; ++k) s = s + a[k] * b[k];
  return s;
}
/// ⟨a, b⟩ summed in pairs, ((a₀b₀ + a₁b₁) + (a₂b₂ + a₃b₃)) + (a₄b₄ + a₅b₅): shorter chains of dependent additions
/// in a program of graph nodes (for expressions the same sum as dot).
template <class S>
S paired_dot(const Vec6<S>& a, const Vec6<S>& b) {
  S pair[3] = {S(0), S(0), S(0)};
  for (std::size_t k = 0; k < 3; ++k) pair[k] = a[2 * k] * b[2 * k] + a[2 * k + 1] * b[2 * k + 1];
  return (pair[0] + pair[1]) + pair[2];
}
template <class S>
Vec6<S> times(const Mat6<S>& m, const Vec6<S>& v) {
  Vec6<S> out;
  for (std::size_t r = 0; r < 6; ++r) {
    S s = S(0);
    for (std::size_t c = 0; c < 6; ++c) s = s + m[r][c] * v[c];
    out[r] = s;
  }
  return out;
}
template <class S>
Mat6<S> operator+(const Mat6<S>& a, const Mat6<S>& b) {
  Mat6<S> c;
  for (std::size_t r = 0; r < 6; ++r) c[r] = a[r] + b[r];
  return c;
}
template <class S>
Mat3<S> skew(const Vec3<S>& c) {
  return {{{S(0), -c[2], c[1]}, {c[2], S(0), -c[0]}, {-c[1], c[0], S(0)}}};
}
template <class S>
Vec3<S> operator+(const Vec3<S>& a, const Vec3<S>& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
template <class S>
Vec3<S> operator-(const Vec3<S>& a, const Vec3<S>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
template <class S>
Vec3<S> operator*(const Mat3<S>& m, const Vec3<S>& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2], m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}
/// A B.
template <class S>
Mat3<S> operator*(const Mat3<S>& A, const Mat3<S>& B) {
  Mat3<S> C;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) C[r][k] = A[r][0] * B[0][k] + A[r][1] * B[1][k] + A[r][2] * B[2][k];
  return C;
}

/// ad_V W for twists V = (ω, v), W = (a, b): the velocity-product term of a body's acceleration.
template <class S>
Vec6<S> ad(const Vec6<S>& V, const Vec6<S>& W) {
  const Vec3<S> w = angular(V), v = linear(V), a = angular(W), b = linear(W);
  const Vec3<S> top = cross(w, a), l = cross(w, b), r = cross(v, a);
  return join(top, {l[0] + r[0], l[1] + r[1], l[2] + r[2]});
}

/// V ×* h = −ad*_V h for a twist V = (ω, v) and a momentum h = (l, p): (ω×l + v×p, ω×p), the gyroscopic wrench
/// of the Euler–Poincaré equation on SE(3), left-trivialized.
template <class S>
Vec6<S> coadjoint_term(const Vec6<S>& V, const Vec6<S>& h) {
  const Vec3<S> w = angular(V), v = linear(V), l = angular(h), p = linear(h);
  const Vec3<S> a = cross(w, l), b = cross(v, p);
  return join({a[0] + b[0], a[1] + b[1], a[2] + b[2]}, cross(w, p));
}

/// What an articulated inertia 𝕀ᴬ (symmetric) passes to its body's parent: 𝕀ᴬ − U Uᵀ / D = 𝕀ᴬ − U Wᵀ, with
/// U = 𝕀ᴬ s and W = U / D named by the caller (Featherstone's 𝕀ᵃ): one product per entry.
template <class S>
Mat6<S> articulated_remainder(const Mat6<S>& IA, const Vec6<S>& U, const Vec6<S>& W) {
  Mat6<S> out;
  for (std::size_t r = 0; r < 6; ++r)
    for (std::size_t k = r; k < 6; ++k) out[r][k] = out[k][r] = IA[r][k] - U[r] * W[k];
  return out;
}

/// The pose of a body relative to its parent, g = (R, p), and the maps it induces: twists from the parent's frame
/// to the body's (Ad_{g⁻¹}), wrenches back (its transpose) and twists back (Ad_g).
template <class S>
struct Link {
  Mat3<S> R;
  Vec3<S> p;
  /// k when R is a rotation about e_k: row and column k of R are e_k and the other two rows and columns form a
  /// rotation of the plane, [[a, −b], [b, a]] (rbd/joint.cpp decides it from the entries before naming them); −1 if
  /// not known. inertia_to_parent then rotates by the double angle.
  int about = -1;
  Vec6<S> to_child(const Vec6<S>& V) const {
    const Vec3<S> w = angular(V), v = linear(V), wp = cross(w, p);
    Vec3<S> a, b;
    for (std::size_t r = 0; r < 3; ++r) {
      a[r] = R[0][r] * w[0] + R[1][r] * w[1] + R[2][r] * w[2];
      b[r] = R[0][r] * (v[0] + wp[0]) + R[1][r] * (v[1] + wp[1]) + R[2][r] * (v[2] + wp[2]);
    }
    return join(a, b);
  }
  Vec6<S> to_parent(const Vec6<S>& F) const {
    const Vec3<S> t = angular(F), f = linear(F);
    Vec3<S> Rt, Rf;
    for (std::size_t r = 0; r < 3; ++r) {
      Rt[r] = R[r][0] * t[0] + R[r][1] * t[1] + R[r][2] * t[2];
      Rf[r] = R[r][0] * f[0] + R[r][1] * f[1] + R[r][2] * f[2];
    }
    const Vec3<S> m = cross(p, Rf);
    return join({Rt[0] + m[0], Rt[1] + m[1], Rt[2] + m[2]}, Rf);
  }
  /// Twists from the body's frame to the parent's (Ad_g): (R ω, R v + p × R ω).
  Vec6<S> motion_to_parent(const Vec6<S>& V) const {
    const Vec3<S> w = R * angular(V);
    return join(w, R * linear(V) + cross(p, w));
  }
};

/// A spatial inertia about a frame's origin: mass m, first moment h = m c, rotational inertia J about the origin
/// (symmetric). 𝕀 (ω, v) = (J ω + h × v, m v − h × ω). Inertias of bodies in one frame add.
template <class S>
struct Inertia {
  S m = S(0);
  Vec3<S> h{S(0), S(0), S(0)};
  Mat3<S> J{{{S(0), S(0), S(0)}, {S(0), S(0), S(0)}, {S(0), S(0), S(0)}}};
  Vec6<S> operator()(const Vec6<S>& x) const {
    const Vec3<S> w = angular(x), v = linear(x);
    const Vec3<S> hv = cross(h, v), hw = cross(h, w);
    return join(J * w + hv, {m * v[0] - hw[0], m * v[1] - hw[1], m * v[2] - hw[2]});
  }
  /// Column k: 𝕀 e_k.
  Mat6<S> matrix() const {
    Mat6<S> out;
    for (std::size_t k = 0; k < 6; ++k) {
      const Vec6<S> column = (*this)(unit6<S>(static_cast<int>(k)));
      for (std::size_t r = 0; r < 6; ++r) out[r][k] = column[r];
    }
    return out;
  }
  void add(const Inertia& o) {
    m = m + o.m;
    for (std::size_t r = 0; r < 3; ++r) {
      h[r] = h[r] + o.h[r];
      for (std::size_t c = 0; c < 3; ++c) J[r][c] = J[r][c] + o.J[r][c];
    }
  }
};

/// Names quantities in a program: for GiNaC expressions a definition of the derivation's intermediates
/// (Intermediates::define), for graph nodes nothing (every node is a value already). Entry by entry for vectors,
/// matrices and inertias; a symmetric matrix names each distinct entry once.
template <class S>
class Namer {
 public:
  explicit Namer(std::function<S(const S&)> name) : name_(std::move(name)) {}
  /// The namer that names nothing.
  static Namer identity() {
    return Namer([](const S& s) { return s; });
  }
  S operator()(const S& e) const { return name_(e); }
  Vec3<S> operator()(const Vec3<S>& v) const { return {(*this)(v[0]), (*this)(v[1]), (*this)(v[2])}; }
  Vec6<S> operator()(const Vec6<S>& v) const {
    Vec6<S> out;
    for (std::size_t k = 0; k < 6; ++k) out[k] = (*this)(v[k]);
    return out;
  }
  Mat3<S> operator()(const Mat3<S>& m) const { return {(*this)(m[0]), (*this)(m[1]), (*this)(m[2])}; }
  Mat6<S> operator()(const Mat6<S>& m) const {
    Mat6<S> out;
    for (std::size_t r = 0; r < 6; ++r) out[r] = (*this)(m[r]);
    return out;
  }
  /// A symmetric K×K (3×3 or 6×6), each distinct entry named once.
  template <std::size_t K>
  std::array<std::array<S, K>, K> symmetric(const std::array<std::array<S, K>, K>& m) const {
    std::array<std::array<S, K>, K> out;
    for (std::size_t r = 0; r < K; ++r)
      for (std::size_t c = r; c < K; ++c) out[r][c] = out[c][r] = (*this)(m[r][c]);
    return out;
  }
  Inertia<S> operator()(const Inertia<S>& I) const {
    Inertia<S> out;
    out.m = (*this)(I.m);
    out.h = (*this)(I.h);
    out.J = symmetric(I.J);
    return out;
  }

 private:
  std::function<S(const S&)> name_;
};

/// A symmetric 6×6 inertia 𝕀 (maps twists to wrenches) about a body's frame, seen from its parent's frame at pose
/// (R, p): X 𝕀 Xᵀ with X = [[R, P R], [0, R]] the wrench map of Link::to_parent, P = [p]×. By 3×3 blocks
/// 𝕀 = [[A, B], [Bᵀ, C]]: rotated A' = R A Rᵀ, B' = R B Rᵀ, C' = R C Rᵀ, then moved by p:
/// [[A' + P B'ᵀ − B'' P, B''], [B''ᵀ, C']] with B'' = B' + P C'. Fewer operations than X 𝕀 Xᵀ column by column,
/// most of all when R is a rotation about a coordinate axis (its zeros drop out of R X).
template <class S>
Mat6<S> inertia_to_parent(const Link<S>& l, const Mat6<S>& I, const Namer<S>& name) {
  const Mat3<S>& R = l.R;
  // A rotation about e_k (Link::about) with a = cos θ, b = sin θ in the plane of the axes i, j after k: by the
  // double angle, cos 2θ = a² − b² and sin 2θ = 2ab, shared by the three blocks. In that plane a symmetric block
  // X turns as X'_ii = ½(X_ii + X_jj) + ½(X_ii − X_jj) cos 2θ − X_ij sin 2θ, X'_jj likewise with the signs of the
  // last two terms flipped, X'_ij = ½(X_ii − X_jj) sin 2θ + X_ij cos 2θ; a general block's antisymmetric part
  // ½(X_ji − X_ij) does not turn. Row and column k: X'_ik = a X_ik − b X_jk, X'_jk = b X_ik + a X_jk (and X'_ki,
  // X'_kj alike), X'_kk = X_kk. Fewer operations than R X Rᵀ entry by entry.
  const bool planar = l.about >= 0;
  const std::size_t k0 = planar ? static_cast<std::size_t>(l.about) : 0, i0 = (k0 + 1) % 3, j0 = (k0 + 2) % 3;
  const S a = R[i0][i0], b = R[j0][i0];
  S cos2 = S(0), sin2 = S(0), half_cos2 = S(0), half_sin2 = S(0);
  if (planar) {
    cos2 = name(a * a - b * b);
    half_cos2 = name(cos2 * S(1) / S(2));
    half_sin2 = name(a * b);
    sin2 = name(half_sin2 + half_sin2);
  }
  const auto turn = [&](std::size_t row, std::size_t col, bool symmetric) {
    const auto x = [&](std::size_t r, std::size_t c) { return I[row + r][col + c]; };
    Mat3<S> out;
    const S sum = x(i0, i0) + x(j0, j0), difference = x(i0, i0) - x(j0, j0);
    const S off = symmetric ? x(i0, j0) : x(i0, j0) + x(j0, i0);  // symmetric: X_ij; else 2 × the symmetric part
    const S t = name(difference * half_cos2 - off * (symmetric ? sin2 : half_sin2));
    const S middle = name(sum * S(1) / S(2));
    out[i0][i0] = middle + t;
    out[j0][j0] = middle - t;
    const S u = difference * half_sin2 + off * (symmetric ? cos2 : half_cos2);
    if (symmetric) {
      out[i0][j0] = out[j0][i0] = u;
    } else {
      const S turned = name(u);                               // the symmetric part's X'_ij
      const S fixed = (x(j0, i0) - x(i0, j0)) * S(1) / S(2);  // the antisymmetric part: does not turn
      out[i0][j0] = turned - fixed;
      out[j0][i0] = turned + fixed;
    }
    out[i0][k0] = a * x(i0, k0) - b * x(j0, k0);
    out[j0][k0] = b * x(i0, k0) + a * x(j0, k0);
    out[k0][k0] = x(k0, k0);
    if (symmetric) {
      out[k0][i0] = out[i0][k0];
      out[k0][j0] = out[j0][k0];
    } else {
      out[k0][i0] = a * x(k0, i0) - b * x(k0, j0);
      out[k0][j0] = b * x(k0, i0) + a * x(k0, j0);
    }
    return symmetric ? name.symmetric(out) : name(out);
  };
  const auto rotate = [&](std::size_t row, std::size_t col, bool symmetric) {
    if (planar) return turn(row, col, symmetric);
    Mat3<S> RX;  // R X
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = 0; k < 3; ++k)
        RX[r][k] = R[r][0] * I[row][col + k] + R[r][1] * I[row + 1][col + k] + R[r][2] * I[row + 2][col + k];
    RX = name(RX);
    Mat3<S> out;
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = symmetric ? r : 0; k < 3; ++k) {
        out[r][k] = RX[r][0] * R[k][0] + RX[r][1] * R[k][1] + RX[r][2] * R[k][2];
        if (symmetric) out[k][r] = out[r][k];
      }
    return symmetric ? name.symmetric(out) : name(out);
  };
  const Mat3<S> A = rotate(0, 0, true), B = rotate(0, 3, false), C = rotate(3, 3, true);
  const Mat3<S> P = skew(l.p);
  Mat3<S> B2;  // B' + P C'
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) B2[r][k] = B[r][k] + P[r][0] * C[0][k] + P[r][1] * C[1][k] + P[r][2] * C[2][k];
  B2 = name(B2);
  Mat6<S> out;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t k = 0; k < 3; ++k) {
      out[r][k + 3] = out[k + 3][r] = B2[r][k];
      out[r + 3][k + 3] = C[r][k];
      if (k < r) continue;
      S a = A[r][k];  // + (P B'ᵀ)_rk − (B'' P)_rk
      for (std::size_t j = 0; j < 3; ++j) a = a + P[r][j] * B[k][j] - B2[r][j] * P[j][k];
      out[r][k] = out[k][r] = a;
    }
  return out;
}

}  // namespace hamel::rbd
