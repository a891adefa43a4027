#include "numeric/linearization.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hamel {

Spectrum spectrum(const LinearSystem& s) {
  const int n = s.nx;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(s.a(i, k)))
        throw EigenvalueFailure("the linearization has a non-finite entry A[" + std::to_string(i + 1) + "][" +
                                std::to_string(k + 1) +
                                "] = d x'/d x at this point (the equations are singular or overflow there), so A "
                                "has no eigenvalues; expected a point where the equations and their derivatives are "
                                "finite");
  // Balanced first (Parlett & Reinsch: D^-1 A D with D a diagonal of powers of 2, exact and with the same eigenvalues),
  // so that rows and columns have comparable norms: the tests for zero below are relative to the largest entry, and
  // unbalanced, A = [[0, 1], [-1e20, 0]] (a spring of stiffness 1e20) had its 1 taken for 0 and the eigenvalues
  // +-1e10 i reported as 0, 0.
  Eigen::MatrixXd balanced(n, n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) balanced(i, k) = s.a(i, k);
  for (int sweep = 0, done = 0; sweep < 200 && !done; ++sweep) {
    done = 1;
    for (int i = 0; i < n; ++i) {
      double c = 0, r = 0;
      for (int j = 0; j < n; ++j)
        if (j != i) c += std::fabs(balanced(j, i)), r += std::fabs(balanced(i, j));
      if (c == 0 || r == 0 || !std::isfinite(c + r)) continue;
      const double total = c + r;
      double f = 1;
      for (double g = r / 2; c < g && f < 0x1p500; f *= 2, c *= 4) {
      }
      for (double g = r * 2; c > g && f > 0x1p-500; f /= 2, c /= 4) {
      }
      if ((c + r) / f < 0.95 * total) {
        done = 0;
        balanced.row(i) /= f;
        balanced.col(i) *= f;
      }
    }
  }
  const auto a_at = [&](int i, int k) { return balanced(i, k); };
  double scale = 1;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) scale = std::max(scale, std::fabs(a_at(i, k)));
  const double zero = 1e-12 * scale;
  // Deflation: a component whose column vanishes on the remaining rows splits A block-triangularly.
  std::vector<bool> kept(static_cast<std::size_t>(n), true);
  Spectrum out;
  for (bool changed = true; changed;) {
    changed = false;
    for (int k = 0; k < n; ++k) {
      if (!kept[static_cast<std::size_t>(k)]) continue;
      bool column_zero = true;
      for (int i = 0; i < n && column_zero; ++i)
        if (kept[static_cast<std::size_t>(i)] && i != k) column_zero = std::fabs(a_at(i, k)) <= zero;
      if (column_zero && std::fabs(a_at(k, k)) <= zero) {
        kept[static_cast<std::size_t>(k)] = false;
        out.decoupled.push_back(k);
        out.values.push_back({0, 0});
        changed = true;
      }
    }
  }
  std::vector<int> rest;
  for (int k = 0; k < n; ++k)
    if (kept[static_cast<std::size_t>(k)]) rest.push_back(k);
  if (!rest.empty()) {
    const Eigen::Index m = static_cast<Eigen::Index>(rest.size());
    Eigen::MatrixXd a(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j)
        a(i, j) = a_at(rest[static_cast<std::size_t>(i)], rest[static_cast<std::size_t>(j)]);
    Eigen::EigenSolver<Eigen::MatrixXd> solver(a, false);
    if (solver.info() != Eigen::Success)
      throw EigenvalueFailure(
          "the eigenvalue iteration (Eigen's real Schur form of A) did not converge at this point; "
          "the matrix A is printed by linearize without --sweep, expected a point where A is "
          "not badly scaled");
    for (Eigen::Index i = 0; i < m; ++i)
      out.values.push_back({solver.eigenvalues()(i).real(), solver.eigenvalues()(i).imag()});
  }
  std::sort(out.values.begin(), out.values.end(),
            [](const Eigenvalue& x, const Eigenvalue& y) { return x.re != y.re ? x.re < y.re : x.im < y.im; });
  return out;
}

Linearizer::Linearizer(const KernelSet& kernels, int nx, int ni)
    : nx_(nx),
      ni_(ni),
      rhs_(kernels.graph, kernels.get("rhs").outputs),
      linearization_(kernels.graph, kernels.get("linearization").outputs) {}

LinearSystem Linearizer::at(double t, const std::vector<double>& x, const std::vector<double>& p,
                            const std::vector<double>& in) const {
  LinearSystem s;
  s.nx = nx_;
  s.ni = ni_;
  s.residual.resize(static_cast<std::size_t>(nx_));
  std::vector<double> ab(static_cast<std::size_t>(nx_ * nx_ + nx_ * ni_));
  const double* pp = p.empty() ? nullptr : p.data();
  const double* ip = in.empty() ? nullptr : in.data();
  rhs_.evaluate(t, x.data(), pp, ip, s.residual.data());
  linearization_.evaluate(t, x.data(), pp, ip, ab.data());
  s.A.assign(ab.begin(), ab.begin() + nx_ * nx_);
  s.B.assign(ab.begin() + nx_ * nx_, ab.end());
  return s;
}

SteadyResult find_steady_motion(const std::function<LinearSystem(const std::vector<double>&)>& linearize,
                                std::vector<double> x, const std::vector<int>& free, const std::vector<int>& moving) {
  const int n = static_cast<int>(x.size());
  std::vector<int> equations;
  for (int k = 0; k < n; ++k)
    if (std::find(moving.begin(), moving.end(), k) == moving.end()) equations.push_back(k);
  const auto norm = [&](const LinearSystem& s) {
    double r = 0;
    for (int k : equations) r = std::max(r, std::fabs(s.residual[static_cast<std::size_t>(k)]));
    return r;
  };
  // Convergence is judged on x' alone, never on |x| (a point far out is not steadier): max |x'_k| over the equations
  // against 1 or, if larger, the rates at which the moving coordinates advance (the motion's own scale of x').
  const auto rate_scale = [&](const LinearSystem& s) {
    double m = 1;
    for (int k : moving) m = std::max(m, std::fabs(s.residual[static_cast<std::size_t>(k)]));
    return std::isfinite(m) ? m : 1.0;
  };
  LinearSystem s = linearize(x);
  double r = norm(s);
  SteadyResult out;
  // Without a free component (or an equation) there is no Newton system: the point is steady or it is not.
  for (int it = 0; it < 60 && !free.empty() && !equations.empty() && r > 1e-13 * rate_scale(s); ++it) {
    Eigen::MatrixXd J(static_cast<Eigen::Index>(equations.size()), static_cast<Eigen::Index>(free.size()));
    Eigen::VectorXd f(static_cast<Eigen::Index>(equations.size()));
    for (std::size_t i = 0; i < equations.size(); ++i) {
      f(static_cast<Eigen::Index>(i)) = s.residual[static_cast<std::size_t>(equations[i])];
      for (std::size_t j = 0; j < free.size(); ++j)
        J(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = s.a(equations[i], free[j]);
    }
    const Eigen::VectorXd step = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(J).solve(-f);
    // Backtracking: halve the step until the residual decreases.
    double lambda = 1;
    for (int tries = 0; tries < 30; ++tries, lambda /= 2) {
      std::vector<double> trial = x;
      for (std::size_t j = 0; j < free.size(); ++j)
        trial[static_cast<std::size_t>(free[j])] += lambda * step(static_cast<Eigen::Index>(j));
      LinearSystem ts = linearize(trial);
      const double tr = norm(ts);
      if (std::isfinite(tr) && tr < r) {
        x = trial, s = ts, r = tr;
        break;
      }
    }
    out.iterations = it + 1;
    if (lambda < 1e-8) break;
  }
  out.x = x;
  out.residual = r;
  if (!(r <= 1e-9 * rate_scale(s)))
    throw std::runtime_error("Newton's method found no steady motion near the given point (max |x'| = " +
                             std::to_string(r) + " after " + std::to_string(out.iterations) + " steps)");
  return out;
}

namespace {

// The eigenvalues without the `structural` smallest in modulus (the zero eigenvalues every point of a sweep has).
std::vector<Eigenvalue> beyond_structural(const Spectrum& s, int structural) {
  std::vector<Eigenvalue> v = s.values;
  std::sort(v.begin(), v.end(),
            [](const Eigenvalue& a, const Eigenvalue& b) { return std::hypot(a.re, a.im) < std::hypot(b.re, b.im); });
  v.erase(v.begin(), v.begin() + std::min<std::ptrdiff_t>(structural, static_cast<std::ptrdiff_t>(v.size())));
  return v;
}

// The number of those eigenvalues in the open right half-plane, without those within `tolerance` of the axis.
int unstable(const Spectrum& s, int structural, double tolerance) {
  int count = 0;
  for (const Eigenvalue& e : beyond_structural(s, structural)) count += e.re > tolerance;
  return count;
}

// The eigenvalue closest to the imaginary axis, without the structural ones.
Eigenvalue nearest_axis(const Spectrum& s, int structural) {
  Eigenvalue best{1e300, 0};
  for (const Eigenvalue& e : beyond_structural(s, structural))
    if (std::fabs(e.re) < std::fabs(best.re)) best = e;
  return best;
}

double magnitude(const Spectrum& s) {
  double m = 1;
  for (const Eigenvalue& e : s.values) m = std::max(m, std::hypot(e.re, e.im));
  return m;
}

int near_zero(const Spectrum& s) {
  const double tol = 1e-9 * magnitude(s);
  int k = 0;
  for (const Eigenvalue& e : s.values) k += std::hypot(e.re, e.im) <= tol;
  return k;
}

}  // namespace

Sweep sweep(const std::function<Spectrum(double)>& spectrum_at, double from, double to, double step) {
  Sweep out;
  const long count = static_cast<long>(std::floor((to - from) / step + 1e-9)) + 1;
  for (long k = 0; k < count; ++k) {
    const double v = from + static_cast<double>(k) * step;
    out.values.push_back(v);
    out.spectra.push_back(spectrum_at(v));
  }
  // The zero eigenvalues present at every point (symmetries, conserved quantities) are not crossings.
  int structural = static_cast<int>(out.spectra.empty() ? 0 : out.spectra[0].values.size());
  for (const Spectrum& s : out.spectra) structural = std::min(structural, near_zero(s));
  const auto tolerance = [](const Spectrum& s) { return 1e-9 * magnitude(s); };
  for (std::size_t k = 0; k + 1 < out.spectra.size(); ++k) {
    const int before = unstable(out.spectra[k], structural, tolerance(out.spectra[k]));
    const int after = unstable(out.spectra[k + 1], structural, tolerance(out.spectra[k + 1]));
    if (before == after) continue;
    // Bisection on the sign of the real part of the eigenvalue nearest the axis (continuous through the
    // crossing), down to the last representable digits of the swept value.
    double a = out.values[k], b = out.values[k + 1];
    Eigenvalue ea = nearest_axis(out.spectra[k], structural), eb = nearest_axis(out.spectra[k + 1], structural);
    // The sign of that real part is meaningful only where it is clearly off the axis on both sides: a
    // conservative system's stable side has real parts of rounding size (the sleeping top), and there the
    // count of eigenvalues right of the axis decides instead (its real part grows like a square root).
    const bool signs_differ = (ea.re < 0) != (eb.re < 0) && std::fabs(ea.re) > tolerance(out.spectra[k]) &&
                              std::fabs(eb.re) > tolerance(out.spectra[k + 1]);
    for (int it = 0; it < 200 && b - a > 4e-16 * std::max(1.0, std::fabs(a)); ++it) {
      const double m = 0.5 * (a + b);
      const Spectrum sm = spectrum_at(m);
      bool left;
      if (signs_differ) {
        const Eigenvalue em = nearest_axis(sm, structural);
        left = (em.re < 0) == (ea.re < 0);
      } else {
        left = unstable(sm, structural, tolerance(sm)) == before;
      }
      if (left)
        a = m;
      else
        b = m;
    }
    Crossing c;
    c.value = 0.5 * (a + b);
    const Eigenvalue at = nearest_axis(spectrum_at(c.value), structural);
    c.frequency = std::fabs(at.im);
    c.complex = c.frequency > 1e-7 * magnitude(out.spectra[k]);
    c.to_unstable = after > before;
    out.crossings.push_back(c);
  }
  return out;
}

}  // namespace hamel
