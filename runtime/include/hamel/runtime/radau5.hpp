// SPDX-License-Identifier: MIT
// Implicit Radau IIA integrator of order 5 (3 stages) for stiff systems, after Hairer and Wanner's RADAU5.
//
// Reference: E. Hairer, G. Wanner, "Solving Ordinary Differential Equations II",
// 2nd ed., Springer 1996, Sections IV.5 and IV.8, and the Fortran code
// radau5.f by Hairer and Wanner, whose Newton control, error estimator and
// step-size strategy are followed here. The tableau is checked against the
// collocation conditions by tests/runtime/radau5_tableau_test.cpp.
//
// One deliberate departure from radau5.f: the 3n x 3n stage system is solved
// as it stands, with a dense LU of I - h (A (x) J), instead of being
// transformed with the eigenvectors of A into one real and one complex n x n
// system. The transformation saves about a factor 5 in LU flops, which only
// matters for large n; the models this runtime serves have n <= ~50, where a
// 150 x 150 LU costs about a millisecond and the rhs and Jacobian dominate,
// and the untransformed form needs no complex arithmetic and is far easier to
// check. Convergence of the Newton iteration is measured on the untransformed
// increments accordingly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/lu.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Settings of integrate_radau5.
///
/// rtol and atol bound the estimated local error per step, as in dopri5.hpp
/// and dop853.hpp. This departs from radau5.f, which replaces the user's rtol
/// by rtol' = 0.1 rtol^(2/3) (and atol by atol rtol' / rtol) to aim at a global
/// error near rtol. Measured on the tests' problems the transformation misses
/// that aim in both directions: on a Kepler orbit (non-stiff) the untransformed
/// tolerance already gives a global error of 0.1..5 rtol for rtol = 1e-11..1e-3
/// (the O(h^4) estimate overstates the O(h^6) local error), while on the stiff
/// Prothero-Robinson problem, where local errors are damped instead of
/// accumulated, the global error approaches rtol' itself, i.e. 100..1000 rtol
/// at rtol = 1e-9..1e-11 with the transformation against at most 4 rtol
/// without it. Callers who want radau5.f's behaviour pass the transformed
/// values.
///
/// Real is the run's scalar type (Radau5Options for double).
template <class Real>
struct BasicRadau5Options {
  Real rtol = Real(1e-6);         // relative tolerance; values below 1e-13 are raised to 1e-13
  Real atol = Real(1e-8);         // absolute tolerance; keep it > 0 for states near 0
  Real h0 = 0;                    // initial step (sign ignored, finite); 0: 1e-6 as in radau5.f (capped by interval)
  Real h_max = 0;                 // largest step; 0 (or +infinity): no limit; negative or NaN: invalid_argument
  long max_steps = 1000000;       // limit on step attempts, accepted plus rejected
  int max_newton_iterations = 7;  // per step attempt (NIT of radau5.f)
  int max_newton_failures = 10;   // Newton failures without an accepted step in between before newton_failure
  Real fixed_step = 0;            // > 0: fixed steps without error control (see integrate_radau5); < 0, NaN: invalid
  // Times the steps end on exactly, ascending (knots of a piecewise-linear input table, where the right-hand side has a
  // kink); those outside (t0, t_end) are ignored. nullptr: none. Not owned: they must outlive the run.
  const Real* stops = nullptr;
  std::size_t n_stops = 0;
};
using Radau5Options = BasicRadau5Options<double>;

namespace detail::radau5 {

constexpr double sqrt6 = 2.449489742783178098197284074705891391966;

// Radau IIA nodes and Runge-Kutta matrix (Hairer & Wanner II, Table IV.5.6).
// The method is stiffly accurate: the last row of a is b, and c3 = 1.
constexpr double c1 = (4.0 - sqrt6) / 10.0;
constexpr double c2 = (4.0 + sqrt6) / 10.0;
constexpr double c[3] = {c1, c2, 1.0};
constexpr double a[3][3] = {
    {(88.0 - 7.0 * sqrt6) / 360.0, (296.0 - 169.0 * sqrt6) / 1800.0, (-2.0 + 3.0 * sqrt6) / 225.0},
    {(296.0 + 169.0 * sqrt6) / 1800.0, (88.0 + 7.0 * sqrt6) / 360.0, (-2.0 - 3.0 * sqrt6) / 225.0},
    {(16.0 - sqrt6) / 36.0, (16.0 + sqrt6) / 36.0, 1.0 / 9.0},
};

// Embedded error estimator of radau5.f: gamma0 is the real eigenvalue of a,
// (6 + 81^(1/3) - 9^(1/3)) / 30, and
//   err = (I - h gamma0 J)^-1 gamma0 (h f(t, x) + dd1 Z1 + dd2 Z2 + dd3 Z3)
// is the difference to an order-3 solution that also uses f(t, x); the solve
// with I - h gamma0 J damps the stiff components, whose raw estimate would be
// huge although the L-stable method handles them well.
constexpr double gamma0 = 0.2748888295956773677478286035994147792947;
constexpr double dd[3] = {-(13.0 + 7.0 * sqrt6) / 3.0, (-13.0 + 7.0 * sqrt6) / 3.0, -1.0 / 3.0};

// Controller constants of radau5.f.
constexpr double safety = 0.9;
constexpr double fac_min = 0.2;   // h_new / h >= 1/5 ...
constexpr double fac_max = 8.0;   // ... and <= 8 after an error test
constexpr double thet = 0.001;    // Newton contraction below which the Jacobian is kept
constexpr double keep_low = 1.0;  // a proposed h_new / h in [1, 1.2] keeps h and the LU factors
constexpr double keep_high = 1.2;
constexpr int max_singular = 5;  // consecutive singular iteration matrices before newton_failure

}  // namespace detail::radau5

/// Caller-provided work space of the heap-free integrate_radau5: non-owning views of reals(n) reals of type Real
/// (the run's scalar type) and ints(n) ints; Radau5Workspace for double.
template <class Real>
struct BasicRadau5Workspace {
  /// Reals needed for n states: the n x n Jacobian, the 3n x 3n iteration matrix, the n x n matrix
  /// of the error estimate, four vectors of 3n (stage increments and derivatives, Newton increment,
  /// collocation polynomial) and six of n.
  static constexpr std::size_t reals(std::size_t n) { return 11 * n * n + 18 * n; }
  static constexpr std::size_t doubles(std::size_t n) { return reals(n); }
  /// Ints needed for n states: the pivots of the two LU factorisations.
  static constexpr std::size_t ints(std::size_t n) { return 4 * n; }

  Real* data = nullptr;
  std::size_t size = 0;  // reals at data
  int* pivots = nullptr;
  std::size_t pivot_count = 0;  // ints at pivots
};
using Radau5Workspace = BasicRadau5Workspace<double>;

/// Forward-difference Jacobian for callers without an analytic one.
///
/// Column j is (rhs(t, x + delta_j e_j) - rhs(t, x)) / delta_j with
/// delta_j = sqrt(eps * max(1e-5, |x_j|)) as in radau5.f, which balances
/// truncation against rounding for O(1)-scaled problems (about 8 correct
/// digits). That is plenty for the simplified Newton iteration, which only
/// needs an approximate Jacobian to converge; the solution's accuracy is set
/// by the residual, not by the Jacobian. Each call costs n + 1 rhs evaluations,
/// which the integrator does not see: rhs_evals() counts them here.
///
/// Heap-free unless asked: with the caller's work space (the three-argument constructor) nothing allocates, and no
/// allocation or release is compiled in (the object holds no container; firmware links no malloc or free through it).
/// Only the two-argument constructor allocates its work space, with new[], and only its objects (and copies of them)
/// release it. Real is the scalar type (double, or float for a float package), deduced from the work space.
template <class Rhs, class Real = double>
class FiniteDifferenceJacobian {
 public:
  /// Reals of work space for n states (the heap-free constructor's `work`).
  static constexpr std::size_t doubles(std::size_t n) { return 3 * n; }
  static constexpr std::size_t reals(std::size_t n) { return 3 * n; }

  /// Keeps a copy of rhs (pass std::ref for a stateful one) and allocates work space for n states (new[]).
  FiniteDifferenceJacobian(Rhs rhs, std::size_t n)
      : rhs_(std::move(rhs)), n_(n), work_(allocate(reals(n))), allocate_(&allocate), release_(&release) {}

  /// Heap-free: work is reals(n) reals of the caller's, used for as long as this object is.
  FiniteDifferenceJacobian(Rhs rhs, std::size_t n, Real* work) : rhs_(std::move(rhs)), n_(n), work_(work) {}

  /// A copy of an allocating object allocates its own work space; a copy of a heap-free one shares the caller's.
  FiniteDifferenceJacobian(const FiniteDifferenceJacobian& other)
      : rhs_(other.rhs_),
        n_(other.n_),
        work_(other.allocate_ != nullptr ? other.allocate_(reals(other.n_)) : other.work_),
        allocate_(other.allocate_),
        release_(other.release_),
        evals_(other.evals_) {}
  FiniteDifferenceJacobian(FiniteDifferenceJacobian&& other) noexcept
      : rhs_(std::move(other.rhs_)),
        n_(other.n_),
        work_(other.work_),
        allocate_(other.allocate_),
        release_(other.release_),
        evals_(other.evals_) {
    other.work_ = nullptr;
    other.allocate_ = nullptr;
    other.release_ = nullptr;
  }
  FiniteDifferenceJacobian& operator=(const FiniteDifferenceJacobian&) = delete;
  FiniteDifferenceJacobian& operator=(FiniteDifferenceJacobian&&) = delete;
  ~FiniteDifferenceJacobian() {
    if (release_ != nullptr) release_(work_);
  }

  /// Writes df/dx at (t, x) to J, row-major n x n.
  void operator()(Real t, const Real* x, Real* J) {
    Real* f0 = work_;
    Real* f1 = f0 + n_;
    Real* xp = f1 + n_;
    rhs_(t, x, f0);
    std::copy(x, x + n_, xp);
    for (std::size_t j = 0; j < n_; ++j) {
      xp[j] = x[j] + std::sqrt(std::numeric_limits<Real>::epsilon() * std::max(Real(1e-5), std::fabs(x[j])));
      const Real delta = xp[j] - x[j];  // the increment actually represented
      rhs_(t, xp, f1);
      for (std::size_t i = 0; i < n_; ++i) J[i * n_ + j] = (f1[i] - f0[i]) / delta;
      xp[j] = x[j];
    }
    evals_ += static_cast<long>(n_) + 1;
  }

  /// rhs evaluations spent on Jacobians so far.
  long rhs_evals() const { return evals_; }

 private:
  // Reached only through the pointers the allocating constructor sets: a heap-free object compiles no new[]/delete[].
  static Real* allocate(std::size_t count) { return new Real[count]; }
  static void release(Real* work) { delete[] work; }

  Rhs rhs_;
  std::size_t n_;
  Real* work_ = nullptr;                      // the caller's work space, or the one allocate_ gave
  Real* (*allocate_)(std::size_t) = nullptr;  // null for the caller's work space
  void (*release_)(Real*) = nullptr;          // null for the caller's work space
  long evals_ = 0;
};

template <class Rhs>
FiniteDifferenceJacobian(Rhs, std::size_t) -> FiniteDifferenceJacobian<Rhs, double>;
template <class Rhs, class Real>
FiniteDifferenceJacobian(Rhs, std::size_t, Real*) -> FiniteDifferenceJacobian<Rhs, Real>;

namespace detail::radau5 {

/// One run of integrate_radau5 (documented there): its settings, work space and step-control state, with one method
/// per part of a step attempt. operator() runs it.
template <class Real, class Rhs, class Jac, class Observer, class Projector>
class Run {
 public:
  Run(Rhs& rhs, Jac& jac, Real* x, std::size_t n, Real t0, Real t_end, const BasicRadau5Options<Real>& opt,
      Real sample_dt, Observer& observe, BasicRadau5Workspace<Real> work, Projector& project)
      : rhs_(rhs),
        jac_(jac),
        observe_(observe),
        project_(project),
        opt_(opt),
        work_(work),
        x_(x),
        n_(n),
        n3_(3 * n),
        t0_(t0),
        t_end_(t_end),
        span_(t_end - t0),
        dir_(span_ > 0 ? Real(1.0) : -Real(1.0)),
        fixed_(opt.fixed_step > 0),
        h_limit_(opt.h_max > 0 ? opt.h_max : std::numeric_limits<Real>::infinity()),
        nit_(std::max(1, opt.max_newton_iterations)),
        rtol_(std::max(opt.rtol, Real(1e-13))),
        atol_(opt.atol),
        // Newton stopping threshold of radau5.f, relative to the error weights: a few percent of the tolerance, but
        // no less than rounding can deliver.
        fnewt_(std::max(Real(10.0) * Real(0.5) * eps / rtol_, std::min(Real(0.03), std::sqrt(rtol_)))),
        inv_n_(n > 0 ? Real(1.0) / static_cast<Real>(n) : Real(0.0)),
        inv_n3_(n > 0 ? Real(1.0) / static_cast<Real>(3 * n) : Real(0.0)),
        clock_(t0, t_end, sample_dt),
        stops_(opt.stops, opt.n_stops, dir_) {
    result_.t = t0;
  }

  BasicIntegrationOutcome<Real> operator()() {
    if (start() == Next::stop) return result_;
    for (;;) {
      Next next = plan_attempt();
      if (next == Next::proceed) next = prepare_matrices();
      if (next == Next::proceed) next = attempt();
      if (next == Next::stop) return result_;
    }
  }

 private:
  static constexpr Real eps = std::numeric_limits<Real>::epsilon();
  // The method's constants in the run's scalar type; they hide the namespace's doubles of the same names.
  static constexpr Real c1 = Real(radau5::c1), c2 = Real(radau5::c2), gamma0 = Real(radau5::gamma0);
  static constexpr Real c[3] = {Real(radau5::c[0]), Real(radau5::c[1]), Real(radau5::c[2])};
  static constexpr Real a[3][3] = {{Real(radau5::a[0][0]), Real(radau5::a[0][1]), Real(radau5::a[0][2])},
                                   {Real(radau5::a[1][0]), Real(radau5::a[1][1]), Real(radau5::a[1][2])},
                                   {Real(radau5::a[2][0]), Real(radau5::a[2][1]), Real(radau5::a[2][2])}};
  static constexpr Real dd[3] = {Real(radau5::dd[0]), Real(radau5::dd[1]), Real(radau5::dd[2])};
  static constexpr Real safety = Real(radau5::safety), fac_min = Real(radau5::fac_min), fac_max = Real(radau5::fac_max),
                        thet = Real(radau5::thet), keep_low = Real(radau5::keep_low),
                        keep_high = Real(radau5::keep_high);
  enum class Failure { none, non_finite, newton };
  /// What a part of the run leaves to the loop: go on with this attempt, make the next one, or return the result.
  enum class Next { proceed, again, stop };

  Next stop(Status status) {
    result_.status = status;
    return Next::stop;
  }

  // The checks before any work, the first observation, the work space, the first derivative and the first step.
  Next start() {
    if (!detail::buffers_fit(x_, n_, work_.data, work_.size, BasicRadau5Workspace<Real>::doubles(n_)) ||
        (work_.pivots == nullptr && BasicRadau5Workspace<Real>::ints(n_) > 0) ||
        work_.pivot_count < BasicRadau5Workspace<Real>::ints(n_) ||
        !detail::adaptive_settings_valid(opt_.rtol, opt_.atol, opt_.h0, opt_.h_max) || !(opt_.fixed_step >= 0) ||
        !clock_.valid()) {
      return stop(Status::invalid_argument);
    }
    if (!std::isfinite(t0_) || !std::isfinite(t_end_) || !all_finite(x_, n_)) {
      return stop(Status::non_finite_state);
    }
    if (fixed_) {
      if (const Status grid = detail::fixed_step_count(t0_, t_end_, opt_.fixed_step, count_); grid != Status::ok) {
        return stop(grid);
      }
    }
    observe_(t0_, x_);
    if (span_ == Real(0.0)) {
      return stop(Status::ok);
    }
    J_ = work_.data;
    M_ = J_ + n_ * n_;
    E_ = M_ + n3_ * n3_;
    Z_ = E_ + n_ * n_;
    F_ = Z_ + n3_;
    dZ_ = F_ + n3_;
    cont_ = dZ_ + n3_;
    f0_ = cont_ + n3_;
    f_new_ = f0_ + n_;
    scal_ = f_new_ + n_;
    stage_ = scal_ + n_;
    err_vec_ = stage_ + n_;
    sample_ = err_vec_ + n_;
    piv_M_ = work_.pivots;
    piv_E_ = piv_M_ + n3_;

    t_ = t0_;
    rhs_(t_, x_, f0_);
    ++result_.stats.rhs_evals;
    if (!all_finite(f0_, n_)) {
      return stop(Status::non_finite_state);
    }
    update_scal();
    h_fixed_ = fixed_ ? std::fabs(span_) / static_cast<Real>(count_) : Real(0.0);
    h_ = fixed_ ? h_fixed_ : std::fabs(opt_.h0);
    if (h_ == Real(0.0) || !std::isfinite(h_)) {
      h_ = detail::default_first_step(t_);
    }
    h_ = std::min({h_, h_limit_, std::fabs(span_)});
    return Next::proceed;
  }

  void update_scal() {
    for (std::size_t i = 0; i < n_; ++i) scal_[i] = atol_ + rtol_ * std::fabs(x_[i]);
  }

  // The limits on the run, and where this attempt ends.
  Next plan_attempt() {
    if (result_.stats.steps + result_.stats.rejected >= opt_.max_steps) {
      return stop(Status::too_many_steps);
    }
    if (!(h_ >= detail::min_step(t_))) {
      return stop(last_failure_ == Failure::non_finite ? Status::non_finite_state
                  : last_failure_ == Failure::newton   ? Status::newton_failure
                                                       : Status::step_size_underflow);
    }
    last_ = false;
    if (fixed_) {
      // As in rk4.hpp: step ends from t0 + i*h, so the grid does not drift.
      const long i = result_.stats.steps + 1;
      last_ = i == count_;
      t_next_ = last_ ? t_end_ : t0_ + dir_ * static_cast<Real>(i) * h_fixed_;
    } else {
      // Stretch or shrink the step to hit t_end exactly rather than leave a sliver.
      Real stop = t_end_;
      bool at_stop = false;
      if ((t_ + Real(1.01) * dir_ * h_ - t_end_) * dir_ > 0) {
        h_ = std::fabs(t_end_ - t_);
        last_ = true;
      } else {
        at_stop = stops_.clamp(t_, t_end_, h_, stop);
      }
      t_next_ = last_ ? t_end_ : at_stop ? stop : t_ + dir_ * h_;
    }
    hs_ = fixed_ ? t_next_ - t_ : dir_ * h_;
    // In fixed-step mode the grid's rounding must not force a new LU per step: the matrices use the nominal step
    // (they need only approximate I - h A J).
    h_mat_ = fixed_ ? dir_ * h_fixed_ : hs_;
    return Next::proceed;
  }

  // J when it is due, and the LU factors of I - h (A (x) J) and I - h gamma0 J when J or the step changed.
  Next prepare_matrices() {
    if (need_jac_) {
      jac_(t_, x_, J_);
      ++result_.stats.jac_evals;
      if (!all_finite(J_, n_ * n_)) {
        return stop(Status::non_finite_state);
      }
      need_jac_ = false;
      jac_current_ = true;
      jac_unproven_ = true;
      h_lu_ = Real(0.0);
    }
    if (h_mat_ == h_lu_) return Next::proceed;
    for (std::size_t p = 0; p < 3; ++p) {
      for (std::size_t i = 0; i < n_; ++i) {
        Real* row = M_ + (p * n_ + i) * n3_;
        for (std::size_t q = 0; q < 3; ++q) {
          const Real w = -h_mat_ * a[p][q];
          for (std::size_t j = 0; j < n_; ++j) row[q * n_ + j] = w * J_[i * n_ + j];
        }
        row[p * n_ + i] += Real(1.0);
      }
    }
    for (std::size_t i = 0; i < n_ * n_; ++i) E_[i] = -h_mat_ * gamma0 * J_[i];
    for (std::size_t i = 0; i < n_; ++i) E_[i * n_ + i] += Real(1.0);
    ++result_.stats.lu_decompositions;
    const bool ok = lu_factor(M_, piv_M_, static_cast<int>(n3_)) && lu_factor(E_, piv_E_, static_cast<int>(n_));
    if (ok) {
      h_lu_ = h_mat_;
      return Next::proceed;
    }
    h_lu_ = Real(0.0);
    ++result_.stats.rejected;
    reject_ = true;
    last_failure_ = Failure::newton;
    if (fixed_ || ++singular_ >= max_singular) {
      return stop(Status::newton_failure);
    }
    h_ *= Real(0.5);
    if (!jac_current_) need_jac_ = true;
    return Next::again;
  }

  // Starting values: the last collocation polynomial extrapolated to the new nodes,
  // cont(s) = x + s (cont1 + (s - c2 + 1) (cont2 + (s - c1 + 1) cont3)) with s measured in units of the old step from
  // its end; zero before.
  void starting_values() {
    if (!have_cont_) {
      std::fill(Z_, Z_ + n3_, Real(0.0));
      return;
    }
    const Real ratio = hs_ / h_old_;
    for (std::size_t p = 0; p < 3; ++p) {
      const Real s = c[p] * ratio;
      for (std::size_t i = 0; i < n_; ++i) {
        Z_[p * n_ + i] =
            s * (cont_[i] + (s - c2 + Real(1.0)) * (cont_[n_ + i] + (s - c1 + Real(1.0)) * cont_[2 * n_ + i]));
      }
    }
  }

  // Simplified Newton iteration (radau5.f's convergence control): Z, newt_ and theta_, and h_factor_ after a failure.
  Failure newton() {
    h_factor_ = Real(0.5);  // step reduction after a Newton failure
    faccon_ = std::pow(std::max(faccon_, eps), Real(0.8));
    theta_ = thet;
    Real dyno_old = Real(0.0);
    Real thq_old = Real(0.0);
    newt_ = 0;
    for (;;) {
      if (newt_ >= nit_) return Failure::newton;
      for (std::size_t p = 0; p < 3; ++p) {
        for (std::size_t i = 0; i < n_; ++i) stage_[i] = x_[i] + Z_[p * n_ + i];
        rhs_(p == 2 ? t_next_ : t_ + c[p] * hs_, stage_, F_ + p * n_);
        ++result_.stats.rhs_evals;
        if (!all_finite(F_ + p * n_, n_)) return Failure::non_finite;
      }
      // dZ solves (I - h A (x) J) dZ = -Z + h (A (x) I) F.
      for (std::size_t p = 0; p < 3; ++p) {
        for (std::size_t i = 0; i < n_; ++i) {
          dZ_[p * n_ + i] = -Z_[p * n_ + i] + hs_ * (a[p][0] * F_[i] + a[p][1] * F_[n_ + i] + a[p][2] * F_[2 * n_ + i]);
        }
      }
      lu_solve(M_, piv_M_, dZ_, static_cast<int>(n3_));
      ++newt_;
      Real dyno = Real(0.0);
      for (std::size_t p = 0; p < 3; ++p) {
        for (std::size_t i = 0; i < n_; ++i) {
          const Real q = dZ_[p * n_ + i] / scal_[i];
          dyno += q * q;
        }
      }
      dyno = std::sqrt(dyno * inv_n3_);
      if (!std::isfinite(dyno)) return Failure::non_finite;
      if (newt_ > 1) {
        const Real thq = dyno / dyno_old;
        theta_ = newt_ == 2 ? thq : std::sqrt(thq * thq_old);
        thq_old = thq;
        if (!(theta_ < Real(0.99))) return Failure::newton;  // diverging
        faccon_ = theta_ / (Real(1.0) - theta_);
        if (newt_ < nit_) {
          // Predicted size of the remaining error after the iterations still allowed.
          const Real dyth = faccon_ * dyno * std::pow(theta_, static_cast<Real>(nit_ - 1 - newt_)) / fnewt_;
          if (dyth >= Real(1.0)) {
            const Real qnewt = std::clamp(dyth, Real(1e-4), Real(20.0));
            h_factor_ = Real(0.8) * std::pow(qnewt, -Real(1.0) / (Real(4.0) + nit_ - 1 - newt_));
            return Failure::newton;
          }
        }
      }
      dyno_old = std::max(dyno, eps);
      for (std::size_t i = 0; i < n3_; ++i) Z_[i] += dZ_[i];
      // radau5.f's test, plus two safeguards for stopping after one iteration, when faccon is inherited from earlier
      // steps rather than measured:
      // - a new Jacobian must first show contraction over two iterations: a grossly wrong J makes I - h A J huge and
      //   every increment tiny, which the inherited estimate would take for convergence (silently wrong results,
      //   seen in the tests);
      // - the increment itself must be within the tolerance (dyno <= 1): an estimate inherited from steps where
      //   theta was at rounding level otherwise certifies a large first correction after the step has grown
      //   eightfold (seen on the Kepler orbit at rtol = 1e-3: a 300x tol global error instead of 5x). Measured
      //   cost: < 1% more evaluations.
      const bool may_stop = newt_ >= 2 || nit_ < 2 || (!jac_unproven_ && dyno <= Real(1.0));
      if (may_stop && faccon_ * dyno <= fnewt_) return Failure::none;
    }
  }

  // The error estimate with the derivative f_start at the step start, in the RMS norm of the error weights.
  Real estimate(const Real* f_start) {
    for (std::size_t i = 0; i < n_; ++i) {
      err_vec_[i] = gamma0 * (hs_ * f_start[i] + dd[0] * Z_[i] + dd[1] * Z_[n_ + i] + dd[2] * Z_[2 * n_ + i]);
    }
    lu_solve(E_, piv_E_, err_vec_, static_cast<int>(n_));
    Real sum = Real(0.0);
    for (std::size_t i = 0; i < n_; ++i) sum += (err_vec_[i] / scal_[i]) * (err_vec_[i] / scal_[i]);
    return std::max(std::sqrt(sum * inv_n_), Real(1e-10));
  }

  // One attempt from the prepared matrices: the Newton iteration, the new state x_new (in stage_), its error and its
  // derivative (in f_new_); then rejected, or accepted.
  Next attempt() {
    starting_values();
    Failure failure = newton();
    if (failure == Failure::none) {
      if (newt_ >= 2) jac_unproven_ = false;
      for (std::size_t i = 0; i < n_; ++i) stage_[i] = x_[i] + Z_[2 * n_ + i];  // x_new (stiffly accurate)
      if (!all_finite(stage_, n_)) failure = Failure::non_finite;
    }
    Real err = Real(0.0);
    if (failure == Failure::none && !fixed_) {
      err = estimate(f0_);
      if (err >= Real(1.0) && (first_ || reject_)) {
        // err_vec + x stands in for the unknown stiff part of the solution.
        for (std::size_t i = 0; i < n_; ++i) err_vec_[i] += x_[i];
        rhs_(t_, err_vec_, f_new_);
        ++result_.stats.rhs_evals;
        if (all_finite(f_new_, n_)) err = estimate(f_new_);
      }
      if (!std::isfinite(err)) failure = Failure::non_finite;
    }
    if (failure == Failure::none && err < Real(1.0)) {
      rhs_(t_next_, stage_, f_new_);
      ++result_.stats.rhs_evals;
      if (!all_finite(f_new_, n_)) failure = Failure::non_finite;
    }
    if (failure != Failure::none) return failed(failure);

    // Proposed next step from the error (unused in fixed-step mode).
    const Real fac = std::min(safety, safety * (1 + 2 * nit_) / (newt_ + 2 * nit_));
    const Real quot = std::clamp(std::pow(err, Real(0.25)) / fac, Real(1.0) / fac_max, Real(1.0) / fac_min);
    if (err >= Real(1.0)) {
      ++result_.stats.rejected;
      reject_ = true;
      last_failure_ = Failure::none;
      h_ = first_ ? Real(0.1) * h_ : h_ / quot;
      if (!jac_current_) need_jac_ = true;
      return Next::again;
    }
    return accept(err, quot);
  }

  // An attempt that failed (Newton, non-finite values): retried with a shorter step, or the end of the run.
  Next failed(Failure failure) {
    ++result_.stats.rejected;
    reject_ = true;
    last_failure_ = failure;
    if (failure == Failure::non_finite) {
      // Most likely the stages left the region where the model is defined (or overflowed); a shorter step may stay
      // inside it.
      if (fixed_) return stop(Status::non_finite_state);
      h_ *= fac_min;
    } else {
      if (fixed_ || ++newton_failures_ >= opt_.max_newton_failures) {
        return stop(Status::newton_failure);
      }
      h_ *= h_factor_;
    }
    if (!jac_current_) need_jac_ = true;
    return Next::again;
  }

  // An accepted step with error err (< 1) and proposed step ratio quot: the controllers, the collocation polynomial,
  // the samples in the step, the new state, and the next step and Jacobian.
  Next accept(Real err, Real quot) {
    Real h_new = h_ / quot;
    ++result_.stats.steps;
    first_ = false;
    newton_failures_ = 0;
    singular_ = 0;
    if (!fixed_) {
      // Gustafsson's predictive controller: the observed change of the error from the previous accepted step may
      // call for a smaller step.
      if (result_.stats.steps > 1) {
        const Real facgus = std::clamp((h_acc_ / h_) * std::pow(err * err / err_acc_, Real(0.25)) / safety,
                                       Real(1.0) / fac_max, Real(1.0) / fac_min);
        quot = std::max(quot, facgus);
        h_new = h_ / quot;
      }
      h_acc_ = h_;
      err_acc_ = std::max(Real(1e-2), err);
    }
    if (const Status projected = observe_step(); projected != Status::ok) {
      return stop(projected);
    }
    if constexpr (detail::projects<Projector>) {
      if (const Status projected = project_(t_next_, stage_); projected != Status::ok) {
        return stop(projected);
      }
    }

    std::copy(stage_, stage_ + n_, x_);
    std::swap(f0_, f_new_);
    t_ = t_next_;
    result_.t = t_;
    update_scal();
    jac_current_ = false;
    if (!clock_.enabled() || last_) {
      observe_(t_, x_);
    }
    if (last_) {
      return stop(Status::ok);
    }
    if constexpr (detail::projects<Projector>) {
      // f at the step start, for the error estimate: f_new belonged to the state before its projection.
      rhs_(t_, x_, f0_);
      ++result_.stats.rhs_evals;
      if (!all_finite(f0_, n_)) {
        return stop(Status::non_finite_state);
      }
    }
    if (fixed_) {
      need_jac_ = theta_ > thet;
      return Next::again;
    }
    h_new = std::min(std::fabs(h_new), h_limit_);
    if (reject_) h_new = std::min(h_new, h_);
    reject_ = false;
    last_failure_ = Failure::none;
    if (theta_ <= thet) {
      // Newton converged so fast that J can serve another step; if the step would change only a little, keep it and
      // the factors as well.
      const Real qt = h_new / h_;
      if (!(qt >= keep_low && qt <= keep_high)) h_ = h_new;
    } else {
      need_jac_ = true;
      h_ = h_new;
    }
    return Next::again;
  }

  // The accepted step's collocation polynomial, and the samples that fall in the step, observed from it (each
  // projected first when there is a projector; its status, ok without one).
  Status observe_step() {
    // The polynomial through x (s = -1), x + Z1 (s = c1 - 1), x + Z2 (s = c2 - 1) and x_new = x + Z3 (s = 0), in
    // Newton form about the end point: cont1..3 are divided differences of u(s) = poly(s) - x_new.
    for (std::size_t i = 0; i < n_; ++i) {
      const Real z1 = Z_[i], z2 = Z_[n_ + i], z3 = Z_[2 * n_ + i];
      const Real u01 = (z2 - z3) / (c2 - Real(1.0));     // u[0, c2-1]
      const Real u12 = (z1 - z2) / (c1 - c2);            // u[c2-1, c1-1]
      const Real u23 = z1 / c1;                          // u[c1-1, -1], as u(-1) = -z3
      const Real u012 = (u12 - u01) / (c1 - Real(1.0));  // u[0, c2-1, c1-1]
      const Real u123 = (u12 - u23) / c2;                // u[c2-1, c1-1, -1]
      cont_[i] = u01;
      cont_[n_ + i] = u012;
      cont_[2 * n_ + i] = u012 - u123;  // u[0, c2-1, c1-1, -1] = (u123 - u012) / (-1 - 0)
    }
    have_cont_ = true;
    h_old_ = hs_;
    while (clock_.due(t_next_)) {
      const Real ts = clock_.next();
      const Real s = (ts - t_next_) / hs_;
      for (std::size_t i = 0; i < n_; ++i) {
        sample_[i] = stage_[i] +
                     s * (cont_[i] + (s - c2 + Real(1.0)) * (cont_[n_ + i] + (s - c1 + Real(1.0)) * cont_[2 * n_ + i]));
      }
      if constexpr (detail::projects<Projector>) {
        if (const Status projected = project_(ts, sample_); projected != Status::ok) {
          return projected;
        }
      }
      observe_(ts, sample_);
      clock_.advance();
    }
    return Status::ok;
  }

  Rhs& rhs_;
  Jac& jac_;
  Observer& observe_;
  Projector& project_;
  const BasicRadau5Options<Real>& opt_;
  const BasicRadau5Workspace<Real> work_;
  Real* const x_;
  const std::size_t n_, n3_;
  const Real t0_, t_end_, span_, dir_;
  const bool fixed_;
  const Real h_limit_;
  const int nit_;
  const Real rtol_, atol_, fnewt_, inv_n_, inv_n3_;
  detail::SampleClock<Real> clock_;
  detail::Stops<Real> stops_;  // where steps end exactly (opt.stops)
  BasicIntegrationOutcome<Real> result_;

  // Work space (BasicRadau5Workspace<Real>::doubles(n) and ints(n)), laid out by start().
  Real* J_ = nullptr;        // n x n Jacobian
  Real* M_ = nullptr;        // 3n x 3n iteration matrix, then its LU factors
  Real* E_ = nullptr;        // n x n matrix I - h gamma0 J, then its LU factors
  Real* Z_ = nullptr;        // stage increments Z1, Z2, Z3 (3n)
  Real* F_ = nullptr;        // stage derivatives (3n)
  Real* dZ_ = nullptr;       // Newton increment (3n)
  Real* cont_ = nullptr;     // collocation polynomial of the last accepted step (3n)
  Real* f0_ = nullptr;       // f(t, x)
  Real* f_new_ = nullptr;    // f(t + h, x_new)
  Real* scal_ = nullptr;     // error weights atol + rtol |x|
  Real* stage_ = nullptr;    // a stage argument, then x_new
  Real* err_vec_ = nullptr;  // error estimate
  Real* sample_ = nullptr;
  int* piv_M_ = nullptr;
  int* piv_E_ = nullptr;

  long count_ = 0;  // number of steps in fixed-step mode
  Real h_fixed_ = Real(0.0);
  Real t_ = Real(0.0);
  Real h_ = Real(0.0);  // unsigned step of the next attempt
  // The attempt: whether it ends the run, where it ends, its signed step and the step its matrices use.
  bool last_ = false;
  Real t_next_ = Real(0.0), hs_ = Real(0.0), h_mat_ = Real(0.0);
  Failure last_failure_ = Failure::none;  // why the last attempt was rejected
  bool need_jac_ = true;                  // evaluate J before the next attempt
  bool jac_current_ = false;              // J was evaluated at the current (t, x)
  bool jac_unproven_ = true;              // no Newton iteration with this J has converged over >= 2 iterations yet
  Real h_lu_ = Real(0.0);                 // signed step of the current factors; 0: none
  bool first_ = true;                     // no step accepted yet
  bool reject_ = false;                   // the last attempt was rejected
  bool have_cont_ = false;                // cont and h_old describe an accepted step
  Real h_old_ = Real(0.0);                // signed step of that accepted step
  Real faccon_ = Real(1.0);               // contraction-based convergence factor eta, carried between steps
  Real theta_ = thet;                     // contraction of the last Newton iteration
  Real h_factor_ = Real(0.5);             // step reduction after a Newton failure
  int newt_ = 0;                          // Newton iterations of the last attempt
  Real h_acc_ = Real(0.0);                // Gustafsson controller: last accepted step ...
  Real err_acc_ = Real(0.0);              // ... and its error
  int newton_failures_ = 0;               // consecutive
  int singular_ = 0;                      // consecutive
};

}  // namespace detail::radau5

/// Integrates x' = rhs(t, x) from t0 to t_end (t_end may lie before t0) with
/// the 3-stage Radau IIA method of order 5, which is L-stable and stiffly
/// accurate: the right tool when the system has fast decaying modes (stiff
/// springs, penalty constraints) that force explicit methods to tiny steps.
///
/// jac(t, x, J) writes df/dx at (t, x) to J (row-major n x n); without an
/// analytic Jacobian pass FiniteDifferenceJacobian(rhs, n).
///
/// Each attempt solves the collocation equations Z_i = h sum_j a_ij
/// f(t + c_j h, x + Z_j) by simplified Newton iterations with the matrix
/// I - h (A (x) J), J evaluated at the step start. As in radau5.f: the
/// iteration starts from the previous step's collocation polynomial; it stops
/// when the contraction-corrected increment theta / (1 - theta) |dZ| is below
/// max(5 eps / rtol, min(0.03, sqrt(rtol))) in the scaled RMS norm of the
/// error test (beyond radau5.f, a single iteration suffices only if J has
/// already shown contraction and |dZ| <= 1; see the loop); the Jacobian is re-evaluated after every accepted step
/// unless the iteration contracted by theta <= 0.001, and the LU factors are kept as long as J and h are (a proposed
/// step change within [1, 1.2] is declined to keep them).
///
/// Step control (radau5.f): the error estimate above, in the RMS norm with
/// weights atol + rtol |x_i| at the step start, is accepted when <= 1; on the
/// first step and after a rejection an estimate >= 1 is recomputed once with
/// f(t, x + err) (Shampine's improvement for stiff problems). The new step is
/// h / clamp(err^(1/4) / fac, 1/8, 5) with fac = 0.9 (1 + 2 nit) / (newt + 2
/// nit) capped at 0.9 (fewer Newton iterations allow larger steps), combined
/// with Gustafsson's predictive controller; after a rejection the step does not
/// grow, and a rejected first step shrinks tenfold.
///
/// observe(t, x) is called at t0, at every t0 + k*sample_dt strictly inside the
/// interval, and at t_end, once each and in order; samples come from the cubic
/// collocation polynomial of the step at no extra cost. sample_dt <= 0
/// observes every accepted step instead. The error test controls the step
/// ends only: where stiffness lets the steps grow long compared with the
/// variation of a forcing term (on the Prothero-Robinson test problem, steps
/// of ~7 across sin t), the cubic between them can be far off (0.6 there)
/// although every step end is within the tolerance. Bound opt.h_max when
/// samples between steps must be accurate in such a regime.
///
/// opt.fixed_step > 0 makes ceil(|t_end - t0| / fixed_step - 1e-9) equal steps
/// without error estimation, for convergence studies; the Newton iteration
/// still converges to the tolerance above, so use a tight rtol there. Any
/// failure (Newton, singular matrix, non-finite values) then ends the run at
/// once with its status, since there is no step to adapt.
///
/// Failures leave the last accepted state and its time in the result:
/// - newton_failure: opt.max_newton_failures attempts, with no step accepted
///   in between, whose Newton iteration diverged (contraction theta >= 0.99), was predicted to miss the
///   tolerance within max_newton_iterations, or ran out of iterations; each
///   such attempt is retried with a smaller step (halved, or by radau5.f's
///   predicted factor) after re-evaluating J if it was not current. Also when
///   the iteration matrix is singular (lu_factor refuses it) 5 times with no
///   step accepted in between, each time retried with half the step, and when
///   the step underflows after a Newton failure.
/// - non_finite_state: a non-finite t0, t_end, initial state or initial
///   derivative; a non-finite Jacobian (at once: a shorter step cannot change
///   J at the current state); or non-finite stage derivatives, new-state
///   derivative or error estimate (each treated as a rejected attempt and
///   retried with a step 5 times smaller) that persist down to the underflow
///   limit.
/// - step_size_underflow when the error controller needs h < 1e-14 * max(1, |t|).
/// - too_many_steps when opt.max_steps attempts do not suffice.
///
/// Costs: per Newton iteration 3 rhs evaluations and one solve with the
/// 3n x 3n factors; per accepted step one more rhs evaluation at the new
/// state. stats.jac_evals counts calls of jac, stats.lu_decompositions the
/// factorisations of the iteration matrix (each paired with the n x n one of
/// I - h gamma0 J for the error estimate). Work space: 11 n^2 + 18 n doubles
/// and 4 n ints (Radau5Workspace).
///
/// invalid_argument, before any work: a tolerance that is negative or not
/// finite, opt.h0 not finite, opt.h_max or opt.fixed_step negative or NaN, a
/// sample_dt below the resolution of t or asking for more than 1e15 samples (detail::sampling_valid); in
/// the heap-free form also a work space smaller than Radau5Workspace::doubles(n)
/// doubles and Radau5Workspace::ints(n) ints (or null).
///
/// Heap-free form: x holds the n initial values on entry and the state at the
/// returned t on return; nothing in the run allocates (provided jac does not:
/// FiniteDifferenceJacobian can take its work space from the caller too), and
/// the observer sees pointers into x and work.
///
/// With a projector (projection.hpp; the last argument, optional): the samples
/// of a step are taken from its collocation polynomial and projected one by one
/// before they are observed, then the new state is projected, accepted and
/// observed, and f at it (the next error estimate's f at the step start) is
/// evaluated again: one more rhs evaluation per step. The next Newton iteration
/// still starts from the step's polynomial. A projector status other than ok
/// ends the run with it and the last accepted state.
template <class Rhs, class Jac, class Real, class Observer, class Projector>
BasicIntegrationOutcome<Real> integrate_radau5(Rhs&& rhs, Jac&& jac, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicRadau5Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicRadau5Workspace<Real> work,
                                               Projector&& project) {
  return detail::radau5::Run<Real, std::remove_reference_t<Rhs>, std::remove_reference_t<Jac>,
                             std::remove_reference_t<Observer>, std::remove_reference_t<Projector>>(
      rhs, jac, x, n, t0, t_end, opt, sample_dt, observe, work, project)();
}

/// Heap-free form without a projector.
template <class Rhs, class Jac, class Real, class Observer>
BasicIntegrationOutcome<Real> integrate_radau5(Rhs&& rhs, Jac&& jac, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicRadau5Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicRadau5Workspace<Real> work) {
  NoProjector none;
  return integrate_radau5(rhs, jac, x, n, t0, t_end, opt, sample_dt, observe, work, none);
}

/// Convenience form of integrate_radau5: the work space is allocated once, before the first step, and
/// the final state is returned in the result's vector. Results are bit-identical to the heap-free form.
template <class Rhs, class Jac, class Observer, class Projector>
IntegrationResult integrate_radau5(Rhs&& rhs, Jac&& jac, std::vector<double> x, double t0, double t_end,
                                   const Radau5Options& opt, double sample_dt, Observer&& observe,
                                   Projector&& project) {
  const std::size_t n = x.size();
  std::vector<double> work(Radau5Workspace::doubles(n));
  std::vector<int> pivots(Radau5Workspace::ints(n));
  const IntegrationOutcome outcome =
      integrate_radau5(rhs, jac, x.data(), n, t0, t_end, opt, sample_dt, observe,
                       Radau5Workspace{work.data(), work.size(), pivots.data(), pivots.size()}, project);
  return detail::to_result(outcome, std::move(x));
}

/// Convenience form without a projector.
template <class Rhs, class Jac, class Observer>
IntegrationResult integrate_radau5(Rhs&& rhs, Jac&& jac, std::vector<double> x, double t0, double t_end,
                                   const Radau5Options& opt, double sample_dt, Observer&& observe) {
  return integrate_radau5(rhs, jac, std::move(x), t0, t_end, opt, sample_dt, observe, NoProjector{});
}

}  // namespace hamel::runtime
