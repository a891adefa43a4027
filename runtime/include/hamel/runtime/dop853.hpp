// SPDX-License-Identifier: MIT
// Adaptive Dormand-Prince 8(5,3) integrator with 7th-order dense output, after Hairer's DOP853.
//
// Reference: E. Hairer, S. P. Norsett, G. Wanner, "Solving Ordinary Differential
// Equations I", 2nd ed., Springer 1993, Section II.10, and the Fortran code
// dop853.f by Hairer and Wanner, whose coefficients (given there to 30 digits),
// error estimator and step-size controller are reproduced here. The tableau is
// checked against the Runge-Kutta order conditions by
// tests/runtime/dop853_tableau_satisfies_order_conditions_test.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "hamel/runtime/integration.hpp"
#include "hamel/runtime/status.hpp"

namespace hamel::runtime {

/// Settings of integrate_dop853, in the run's scalar type Real (Dop853Options for double).
template <class Real>
struct BasicDop853Options {
  Real rtol = Real(1e-10);    // relative tolerance, per component
  Real atol = Real(1e-12);    // absolute tolerance, per component; keep it > 0 for states near 0
  Real h0 = 0;                // initial step (sign ignored, finite); 0: automatic (Hairer's algorithm)
  Real h_max = 0;             // largest step; 0 (or +infinity): no limit; negative or NaN: invalid_argument
  long max_steps = 10000000;  // limit on step attempts, accepted plus rejected
  // Times the steps end on exactly, ascending (knots of a piecewise-linear input table, where the right-hand side has a
  // kink); those outside (t0, t_end) are ignored. nullptr: none. Not owned: they must outlive the run.
  const Real* stops = nullptr;
  std::size_t n_stops = 0;
};
using Dop853Options = BasicDop853Options<double>;

namespace detail::dop853 {

// Stages are numbered from 0 here (stage i of the book is index i - 1).
// Stages 0..11 make one step; stage 12 is f(t + h, x_new), whose row of a is
// the weight vector b, so that it doubles as the next step's stage 0 (FSAL);
// stages 13..15 exist only for the continuous extension.
constexpr int kStepStages = 12;
constexpr int kStages = 16;

// Nodes; c[i] equals the sum of row i of a (checked by the tableau test).
constexpr double c[kStages] = {0.0,
                               0.526001519587677318785587544488e-01,
                               0.789002279381515978178381316732e-01,
                               0.118350341907227396726757197510e+00,
                               0.281649658092772603273242802490e+00,
                               0.333333333333333333333333333333e+00,
                               0.25,
                               0.307692307692307692307692307692e+00,
                               0.651282051282051282051282051282e+00,
                               0.6,
                               0.857142857142857142857142857142e+00,
                               1.0,
                               1.0,
                               0.1,
                               0.2,
                               0.777777777777777777777777777778e+00};

// Runge-Kutta matrix, strictly lower triangular; row 12 is b.
constexpr double a[kStages][kStages] = {
    {},
    {5.26001519587677318785587544488e-2},
    {1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2},
    {2.95875854768068491816892993775e-2, 0.0, 8.87627564304205475450678981324e-2},
    {2.41365134159266685502369798665e-1, 0.0, -8.84549479328286085344864962717e-1, 9.24834003261792003115737966543e-1},
    {3.7037037037037037037037037037e-2, 0.0, 0.0, 1.70828608729473871279604482173e-1,
     1.25467687566822425016691814123e-1},
    {3.7109375e-2, 0.0, 0.0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2, -1.7578125e-2},
    {3.70920001185047927108779319836e-2, 0.0, 0.0, 1.70383925712239993810214054705e-1,
     1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2, 8.27378916381402288758473766002e-3},
    {6.24110958716075717114429577812e-1, 0.0, 0.0, -3.36089262944694129406857109825e0,
     -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1, 2.01540675504778934086186788979e1,
     -4.34898841810699588477366255144e1},
    {4.77662536438264365890433908527e-1, 0.0, 0.0, -2.48811461997166764192642586468e0,
     -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1, 1.52792336328824235832596922938e1,
     -3.32882109689848629194453265587e1, -2.03312017085086261358222928593e-2},
    {-9.3714243008598732571704021658e-1, 0.0, 0.0, 5.18637242884406370830023853209e0, 1.09143734899672957818500254654e0,
     -8.14978701074692612513997267357e0, -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1,
     2.49360555267965238987089396762e0, -3.0467644718982195003823669022e0},
    {2.27331014751653820792359768449e0, 0.0, 0.0, -1.05344954667372501984066689879e1,
     -2.00087205822486249909675718444e0, -1.79589318631187989172765950534e1, 2.79488845294199600508499808837e1,
     -2.85899827713502369474065508674e0, -8.87285693353062954433549289258e0, 1.23605671757943030647266201528e1,
     6.43392746015763530355970484046e-1},
    {5.42937341165687622380535766363e-2, 0.0, 0.0, 0.0, 0.0, 4.45031289275240888144113950566e0,
     1.89151789931450038304281599044e0, -5.8012039600105847814672114227e0, 3.1116436695781989440891606237e-1,
     -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2},
    {5.61675022830479523392909219681e-2, 0.0, 0.0, 0.0, 0.0, 0.0, 2.53500210216624811088794765333e-1,
     -2.46239037470802489917441475441e-1, -1.24191423263816360469010140626e-1, 1.5329179827876569731206322685e-1,
     8.20105229563468988491666602057e-3, 7.56789766054569976138603589584e-3, -8.298e-3},
    {3.18346481635021405060768473261e-2, 0.0, 0.0, 0.0, 0.0, 2.83009096723667755288322961402e-2,
     5.35419883074385676223797384372e-2, -5.49237485713909884646569340306e-2, 0.0, 0.0,
     -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4, -3.40465008687404560802977114492e-4,
     1.41312443674632500278074618366e-1},
    {-4.28896301583791923408573538692e-1, 0.0, 0.0, 0.0, 0.0, -4.69762141536116384314449447206e0,
     7.68342119606259904184240953878e0, 4.06898981839711007970213554331e0, 3.56727187455281109270669543021e-1, 0.0, 0.0,
     0.0, -1.39902416515901462129418009734e-3, 2.9475147891527723389556272149e0, -9.15095847217987001081870187138e0},
};

// Weights of the order-8 solution (row 12 of a).
// inline: a reference, unlike a const object, would otherwise have external linkage in every includer.
inline constexpr const double (&b)[kStages] = a[kStepStages];

// b minus the weights of the embedded fifth-order method (ER1..ER12 of dop853.f).
constexpr double er[kStepStages] = {0.1312004499419488073250102996e-1,
                                    0.0,
                                    0.0,
                                    0.0,
                                    0.0,
                                    -0.1225156446376204440720569753e+1,
                                    -0.4957589496572501915214079952e+0,
                                    0.1664377182454986536961530415e+1,
                                    -0.3503288487499736816886487290e+0,
                                    0.3341791187130174790297318841e+0,
                                    0.8192320648511571246570742613e-1,
                                    -0.2235530786388629525884427845e-1};

// Weights of the embedded third-order method, which uses stages 0, 8 and 11 only
// (BHH1..BHH3 of dop853.f).
constexpr double bhh0 = 0.244094488188976377952755905512e+00;
constexpr double bhh8 = 0.733846688281611857341361741547e+00;
constexpr double bhh11 = 0.220588235294117647058823529412e-01;

// Coefficients d[m][j] of the dense output terms r4..r7 (D4j..D7j of
// dop853.f); the terms r0..r3 follow from x, x_new and the end derivatives.
constexpr double d[4][kStages] = {
    {-0.84289382761090128651353491142e+1, 0.0, 0.0, 0.0, 0.0, 0.56671495351937776962531783590e+0,
     -0.30689499459498916912797304727e+1, 0.23846676565120698287728149680e+1, 0.21170345824450282767155149946e+1,
     -0.87139158377797299206789907490e+0, 0.22404374302607882758541771650e+1, 0.63157877876946881815570249290e+0,
     -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e+2, -0.91946323924783554000451984436e+1,
     -0.44360363875948939664310572000e+1},
    {0.10427508642579134603413151009e+2, 0.0, 0.0, 0.0, 0.0, 0.24228349177525818288430175319e+3,
     0.16520045171727028198505394887e+3, -0.37454675472269020279518312152e+3, -0.22113666853125306036270938578e+2,
     0.77334326684722638389603898808e+1, -0.30674084731089398182061213626e+2, -0.93321305264302278729567221706e+1,
     0.15697238121770843886131091075e+2, -0.31139403219565177677282850411e+2, -0.93529243588444783865713862664e+1,
     0.35816841486394083752465898540e+2},
    {0.19985053242002433820987653617e+2, 0.0, 0.0, 0.0, 0.0, -0.38703730874935176555105901742e+3,
     -0.18917813819516756882830838328e+3, 0.52780815920542364900561016686e+3, -0.11573902539959630126141871134e+2,
     0.68812326946963000169666922661e+1, -0.10006050966910838403183860980e+1, 0.77771377980534432092869265740e+0,
     -0.27782057523535084065932004339e+1, -0.60196695231264120758267380846e+2, 0.84320405506677161018159903784e+2,
     0.11992291136182789328035130030e+2},
    {-0.25693933462703749003312586129e+2, 0.0, 0.0, 0.0, 0.0, -0.15418974869023643374053993627e+3,
     -0.23152937917604549567536039109e+3, 0.35763911791061412378285349910e+3, 0.93405324183624310003907691704e+2,
     -0.37458323136451633156875139351e+2, 0.10409964950896230045147246184e+3, 0.29840293426660503123344363579e+2,
     -0.43533456590011143754432175058e+2, 0.96324553959188282948394950600e+2, -0.39177261675615439165231486172e+2,
     -0.14972683625798562581422125276e+3},
};

// Step-size controller of dop853.f. Its default beta is 0, i.e. plain
// (not PI) control: the high order already makes the step sequence smooth.
constexpr double safety = 0.9;
constexpr double fac_min = 0.333;  // h_new / h >= 0.333
constexpr double fac_max = 6.0;    // h_new / h <= 6
constexpr double expo = 1.0 / 8.0;

/// The tables above in the scalar type Real, converted at compile time: a float run reads no double.
template <class Real>
struct Tables {
  Real c[kStages] = {};
  Real a[kStages][kStages] = {};
  Real er[kStepStages] = {};
  Real d[4][kStages] = {};
};
template <class Real>
constexpr Tables<Real> convert_tables() {
  Tables<Real> t{};
  for (int i = 0; i < kStages; ++i) {
    t.c[i] = static_cast<Real>(c[i]);
    for (int j = 0; j < kStages; ++j) t.a[i][j] = static_cast<Real>(a[i][j]);
    for (int m = 0; m < 4; ++m) t.d[m][i] = static_cast<Real>(d[m][i]);
  }
  for (int i = 0; i < kStepStages; ++i) t.er[i] = static_cast<Real>(er[i]);
  return t;
}
template <class Real>
inline constexpr Tables<Real> tables = convert_tables<Real>();

}  // namespace detail::dop853

/// Caller-provided work space of the heap-free integrate_dop853: a non-owning view of reals(n) reals of type Real (the
/// run's scalar type); Dop853Workspace for double.
template <class Real>
struct BasicDop853Workspace {
  /// Reals needed for n states: 16 stage derivatives, a stage argument, the new state, seven dense
  /// output terms and a sample.
  static constexpr std::size_t reals(std::size_t n) { return (detail::dop853::kStages + 10) * n; }
  static constexpr std::size_t doubles(std::size_t n) { return reals(n); }

  Real* data = nullptr;
  std::size_t size = 0;  // reals at data
};
using Dop853Workspace = BasicDop853Workspace<double>;

/// Integrates x' = rhs(t, x) from t0 to t_end (t_end may lie before t0) with
/// the adaptive Dormand-Prince 8(5,3) method, advancing with the eighth-order
/// solution and reusing f(t + h, x_new) as the next first stage (FSAL): 12 rhs
/// evaluations per accepted step, 11 per rejected one.
///
/// Error estimate (as dop853.f): with err5 and err3 the RMS over components of
/// the scaled differences to the embedded fifth- and third-order solutions,
/// scaled by atol + rtol * max(|x_i|, |x_new_i|), the step is accepted when
/// err = err5^2 / sqrt(err5^2 + 0.01 err3^2) <= 1. This behaves like err5 where
/// the fifth-order estimate is trustworthy, yet is O(h^8) like the error of
/// the solution itself, which is what makes the controller exponent 1/8 right.
///
/// observe(t, x) is called at t0, at every t0 + k*sample_dt strictly inside the
/// interval, and at t_end, once each and in order; samples come from the
/// seventh-order continuous extension of dop853.f, which costs three extra rhs
/// evaluations in each step that contains a sample (and none otherwise; the
/// step sequence does not depend on sampling). sample_dt <= 0 observes every
/// accepted step instead.
///
/// Failures leave the last accepted state and its time in the result:
/// step_size_underflow when the controller needs h < 1e-14 * max(1, |t|);
/// non_finite_state for a non-finite t0, t_end, initial state or initial
/// derivative, or when non-finite stages persist (any non-finite stage,
/// including f(t + h, x_new) and the three of the continuous extension, makes
/// the attempt a rejected step retried with a step 3 times smaller) down to
/// that underflow limit; too_many_steps when opt.max_steps attempts do not
/// suffice.
///
/// invalid_argument, before any work: a tolerance that is negative or not
/// finite, opt.h0 not finite, opt.h_max negative or NaN, a sample_dt below the
/// resolution of t or asking for more than 1e15 samples (detail::sampling_valid); in the heap-free form
/// also a work space smaller than Dop853Workspace::doubles(n) (or null).
///
/// Heap-free form: x holds the n initial values on entry and the state at the
/// returned t on return; nothing in the run allocates, and the observer sees
/// pointers into x and work.
///
/// With a projector (projection.hpp; the last argument, optional): the samples of
/// a step are interpolated from the step as computed and projected one by one
/// before they are observed, then the new state is projected, accepted and
/// observed, and the first stage of the next step is evaluated at it (one more
/// rhs evaluation per step). A projector status other than ok ends the run with
/// it and the last accepted state.
template <class Rhs, class Real, class Observer, class Projector>
BasicIntegrationOutcome<Real> integrate_dop853(Rhs&& rhs, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicDop853Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicDop853Workspace<Real> work,
                                               Projector&& project) {
  namespace k = detail::dop853;
  const detail::dop853::Tables<Real>& T = k::tables<Real>;
  detail::AdaptiveSteps<BasicDop853Options<Real>> steps(t0, t_end, opt);
  if (!steps.start(x, n, work.data, work.size, BasicDop853Workspace<Real>::reals(n), sample_dt, observe)) {
    return steps.result;
  }

  // The work space: 16 stage derivatives, the stage argument, the new state,
  // the dense output terms r1..r7 and a sample.
  Real* f[k::kStages];
  for (int s = 0; s < k::kStages; ++s) f[s] = work.data + static_cast<std::size_t>(s) * n;
  Real* stage = work.data + static_cast<std::size_t>(k::kStages) * n;
  Real* x_new = stage + n;
  Real* r[8] = {nullptr};  // r[0] would be x itself
  for (int m = 1; m < 8; ++m) r[m] = x_new + static_cast<std::size_t>(m) * n;
  Real* sample = r[7] + n;

  if (!steps.first_derivative(rhs, x, f[0], n)) {
    return steps.result;
  }
  steps.first_step(rhs, x, f[0], 8, stage, f[1], n);

  detail::SampleClock<Real> clock(t0, t_end, sample_dt);
  const Real inv_n = n > 0 ? Real(1.0) / static_cast<Real>(n) : Real(0.0);

  // Stage s from the stages before it: stage = x + hs * sum_j a[s][j] f[j],
  // skipping the many zero coefficients; f[s] = rhs(t + c[s] hs, stage).
  auto eval_stage = [&](int s, Real t_stage, Real hs) {
    std::copy(x, x + n, stage);
    for (int j = 0; j < s; ++j) {
      const Real w = hs * T.a[s][j];
      if (w != Real(0.0)) {
        const Real* fj = f[j];
        for (std::size_t i = 0; i < n; ++i) stage[i] += w * fj[i];
      }
    }
    rhs(t_stage, stage, f[s]);
    ++steps.result.stats.rhs_evals;
    return all_finite(f[s], n);
  };

  while (steps.begin_attempt()) {
    const Real t = steps.t, hs = steps.hs, t_next = steps.t_next;

    bool finite = true;
    for (int s = 1; s < k::kStepStages && finite; ++s) {
      finite = eval_stage(s, s == k::kStepStages - 1 ? t_next : t + T.c[s] * hs, hs);
    }
    Real err = Real(0.0);
    if (finite) {
      Real err5 = Real(0.0);
      Real err3 = Real(0.0);
      for (std::size_t i = 0; i < n; ++i) {
        Real incr = Real(0.0);  // sum_j b_j f_j
        Real e5 = Real(0.0);    // sum_j er_j f_j
        for (int j = 0; j < k::kStepStages; ++j) {
          incr += T.a[k::kStepStages][j] * f[j][i];
          e5 += T.er[j] * f[j][i];
        }
        x_new[i] = x[i] + hs * incr;
        const Real e3 = incr - Real(k::bhh0) * f[0][i] - Real(k::bhh8) * f[8][i] - Real(k::bhh11) * f[11][i];
        const Real sk = opt.atol + opt.rtol * std::max(std::fabs(x[i]), std::fabs(x_new[i]));
        err5 += (e5 / sk) * (e5 / sk);
        err3 += (e3 / sk) * (e3 / sk);
      }
      // err5 and err3 are sums of squares here; the combination is dop853.f's.
      Real deno = err5 + Real(0.01) * err3;
      if (deno <= Real(0.0)) deno = Real(1.0);
      err = steps.h * err5 * std::sqrt(inv_n / deno);
      finite = std::isfinite(err) && all_finite(x_new, n);
    }

    Real fac11 = Real(0.0);
    if (finite) {
      fac11 = std::pow(err, Real(k::expo));
      if (err > Real(1.0)) {
        steps.reject(std::min(Real(1.0) / Real(k::fac_min), fac11 / Real(k::safety)));
        continue;
      }
      // The step is good; the derivative at its end (the next first stage) and,
      // if samples fall inside it, the extra stages must be finite as well.
      rhs(t_next, x_new, f[k::kStepStages]);
      ++steps.result.stats.rhs_evals;
      finite = all_finite(f[k::kStepStages], n);
    }
    const bool sample_due = clock.due(t_next);
    if (finite && sample_due) {
      for (int s = k::kStepStages + 1; s < k::kStages && finite; ++s) {
        finite = eval_stage(s, t + T.c[s] * hs, hs);
      }
    }
    if (!finite) {
      steps.reject_non_finite(Real(k::fac_min));
      continue;
    }

    const Real h_new = steps.next_step(
        std::clamp(fac11 / Real(k::safety), Real(1.0) / Real(k::fac_max), Real(1.0) / Real(k::fac_min)));

    if (sample_due) {
      // Continuous extension of dop853.f:
      //   x(t + theta hs) = x + theta (r1 + (1-theta) (r2 + theta (r3 + (1-theta) (r4 + theta (r5
      //                       + (1-theta) (r6 + theta r7))))))
      // with r1 = x_new - x, r2 = hs f0 - r1, r3 = r1 - hs f12 - r2 and
      // r4..r7 = hs * sum_j d[m][j] f_j over all 16 stages.
      for (std::size_t i = 0; i < n; ++i) {
        const Real dx = x_new[i] - x[i];
        const Real bspl = hs * f[0][i] - dx;
        r[1][i] = dx;
        r[2][i] = bspl;
        r[3][i] = dx - hs * f[k::kStepStages][i] - bspl;
        for (int m = 0; m < 4; ++m) {
          Real s = Real(0.0);
          for (int j = 0; j < k::kStages; ++j) s += T.d[m][j] * f[j][i];
          r[4 + m][i] = hs * s;
        }
      }
      while (clock.due(t_next)) {
        const Real ts = clock.next();
        const Real theta = (ts - t) / hs;
        const Real theta1 = Real(1.0) - theta;
        for (std::size_t i = 0; i < n; ++i) {
          const Real tail = r[4][i] + theta * (r[5][i] + theta1 * (r[6][i] + theta * r[7][i]));
          sample[i] = x[i] + theta * (r[1][i] + theta1 * (r[2][i] + theta * (r[3][i] + theta1 * tail)));
        }
        if constexpr (detail::projects<Projector>) {
          const Status projected = project(ts, sample);
          if (projected != Status::ok) {
            steps.end(projected);
            return steps.result;
          }
        }
        observe(ts, sample);
        clock.advance();
      }
    }

    if constexpr (detail::projects<Projector>) {
      const Status projected = project(t_next, x_new);
      if (projected != Status::ok) {
        steps.end(projected);
        return steps.result;
      }
    }
    std::swap(f[0], f[k::kStepStages]);  // first same as last
    if (!steps.accept(x, x_new, n, h_new, clock.enabled(), observe)) {
      break;
    }
    if constexpr (detail::projects<Projector>) {
      if (!steps.first_derivative(rhs, x, f[0], n)) {  // at the projected state
        break;
      }
    }
  }
  return steps.result;
}

/// Heap-free form without a projector.
template <class Rhs, class Real, class Observer>
BasicIntegrationOutcome<Real> integrate_dop853(Rhs&& rhs, detail::same_t<Real>* x, std::size_t n,
                                               detail::same_t<Real> t0, detail::same_t<Real> t_end,
                                               const BasicDop853Options<Real>& opt, detail::same_t<Real> sample_dt,
                                               Observer&& observe, BasicDop853Workspace<Real> work) {
  return integrate_dop853(rhs, x, n, t0, t_end, opt, sample_dt, observe, work, NoProjector{});
}

/// Convenience form of integrate_dop853: the work space is allocated once, before the first step, and
/// the final state is returned in the result's vector. Results are bit-identical to the heap-free form.
template <class Rhs, class Observer, class Projector>
IntegrationResult integrate_dop853(Rhs&& rhs, std::vector<double> x, double t0, double t_end, const Dop853Options& opt,
                                   double sample_dt, Observer&& observe, Projector&& project) {
  return detail::run_with_allocated_work<Dop853Workspace>(
      std::move(x), [&](double* xs, std::size_t n, Dop853Workspace w) {
        return integrate_dop853(rhs, xs, n, t0, t_end, opt, sample_dt, observe, w, project);
      });
}

/// Convenience form without a projector.
template <class Rhs, class Observer>
IntegrationResult integrate_dop853(Rhs&& rhs, std::vector<double> x, double t0, double t_end, const Dop853Options& opt,
                                   double sample_dt, Observer&& observe) {
  return integrate_dop853(rhs, std::move(x), t0, t_end, opt, sample_dt, observe, NoProjector{});
}

}  // namespace hamel::runtime
