// The torque-free asymmetric rigid body near its intermediate axis (Dzhanibekov effect), models/free_rigid_body.yaml
// integrated from its emitted rhs kernel, against the analytic solution in Jacobi elliptic functions (Landau and
// Lifshitz, Mechanics, §37), with energy and |Π| drift; then the same motion spun up to 1e3 rad/s over a long
// horizon (fast spin). sn, cn, dn are computed here by the AGM / descending Landen transformation
// (Abramowitz and Stegun 16.4) and checked on their own first.
#include "scene_support.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>

namespace {

using hamel::runtime::Status;
using Vec3 = std::array<double, 3>;

struct Jacobi {
  double sn, cn, dn;
};

// sn, cn, dn of u for the parameter m = k², with m1 = 1 − m passed separately so that m near 1 keeps its
// digits (A&S 16.4.3: a_0 = 1, b_0 = √m1, c_0 = √m; φ_N = 2^N a_N u; φ_{n−1} = (φ_n + asin(c_n sin φ_n / a_n))/2).
Jacobi jacobi(double u, double m, double m1) {
  if (m == 0) return {std::sin(u), std::cos(u), 1.0};
  std::array<double, 32> a{}, c{};
  a[0] = 1;
  c[0] = std::sqrt(m);
  double b = std::sqrt(m1);
  int n = 0;
  while (std::fabs(c[n]) > 1e-17 * a[n] && n < 30) {
    a[n + 1] = (a[n] + b) / 2;
    c[n + 1] = (a[n] - b) / 2;
    b = std::sqrt(a[n] * b);
    ++n;
  }
  double phi = std::ldexp(a[n] * u, n);
  for (int j = n; j > 0; --j) phi = (phi + std::asin(c[j] * std::sin(phi) / a[j])) / 2;
  // dn = cos φ0 / cos(φ1 − φ0) (A&S 16.4.3) is 0/0 at u = K; dn² = 1 − m sn² = m1 + m cn² has no cancellation.
  const double cn = std::cos(phi);
  return {std::sin(phi), cn, std::sqrt(m1 + m * cn * cn)};
}

// K(m) = π / (2 AGM(1, √m1)).
double complete_elliptic_k(double m1) {
  double a = 1, b = std::sqrt(m1);
  for (int i = 0; i < 40 && std::fabs(a - b) > 1e-16 * a; ++i) {
    const double next = (a + b) / 2;
    b = std::sqrt(a * b);
    a = next;
  }
  return M_PI / (2 * a);
}

TEST(JacobiElliptic, LimitsIdentitiesAndDerivatives) {
  for (double u : {-2.3, 0.0, 0.4, 12.5}) EXPECT_DOUBLE_EQ(jacobi(u, 0.0, 1.0).sn, std::sin(u));
  for (double u : {-2.3, 0.0, 0.4, 1.7, 4.0}) {
    // m near 1, u well inside the quarter period K = 9.4: A&S 16.15.1, 16.15.3,
    // sn = tanh u + m1/4 (sinh u cosh u − u) sech² u + O(m1²), dn = sech u + m1/4 (sinh u cosh u + u) tanh u sech u.
    const double m1 = 1e-7, sech = 1 / std::cosh(u);
    const Jacobi t = jacobi(u, 1 - m1, m1);
    EXPECT_NEAR(t.sn, std::tanh(u) + m1 / 4 * (std::sinh(u) * std::cosh(u) - u) * sech * sech, 1e-12);
    EXPECT_NEAR(t.dn, sech + m1 / 4 * (std::sinh(u) * std::cosh(u) + u) * std::tanh(u) * sech, 1e-12);
  }
  for (double m : {0.1, 0.5, 0.9, 1 - 1e-6}) {
    const double m1 = 1 - m, K = complete_elliptic_k(m1);
    EXPECT_NEAR(jacobi(K, m, m1).sn, 1.0, 1e-14);
    EXPECT_NEAR(jacobi(K, m, m1).cn, 0.0, 1e-7);  // cn has a simple zero at K: |cn| ≈ dn |u − K|
    EXPECT_NEAR(jacobi(2 * K, m, m1).sn, 0.0, 1e-12);
    for (double u : {0.3, 1.1, 2.9, 7.0}) {
      const Jacobi s = jacobi(u, m, m1);
      EXPECT_NEAR(s.sn * s.sn + s.cn * s.cn, 1.0, 1e-14);
      EXPECT_NEAR(s.dn * s.dn + m * s.sn * s.sn, 1.0, 1e-14);
      // d sn/du = cn dn, d cn/du = −sn dn, d dn/du = −m sn cn (central differences, h = 1e-5).
      const double h = 1e-5;
      const Jacobi p = jacobi(u + h, m, m1), q = jacobi(u - h, m, m1);
      EXPECT_NEAR((p.sn - q.sn) / (2 * h), s.cn * s.dn, 1e-9);
      EXPECT_NEAR((p.cn - q.cn) / (2 * h), -s.sn * s.dn, 1e-9);
      EXPECT_NEAR((p.dn - q.dn) / (2 * h), -m * s.sn * s.cn, 1e-9);
    }
  }
}

// Euler's equations with I1 < I2 < I3 and M² > 2 E I2 (the body circulates around axis 3), from
// ω(0) = (a, 0, c) (L&L §37): ω = (A1 cn τ, A2 sn τ, A3 dn τ), τ = τ' t with
//   A1² = (2E I3 − M²) / (I1 (I3 − I1)), A2² = (2E I3 − M²) / (I2 (I3 − I2)), A3² = (M² − 2E I1) / (I3 (I3 − I1)),
//   τ' = √((I3 − I2)(M² − 2E I1) / (I1 I2 I3)), k² = (I2 − I1)(2E I3 − M²) / ((I3 − I2)(M² − 2E I1)).
// Started at τ0 = K the body spins almost exactly about the intermediate axis: ω(0) = (0, A2, A3 k').
struct Dzhanibekov {
  double I1 = 1, I2 = 2, I3 = 3;  // the model's defaults
  double A1, A2, A3, rate, m, m1, tau0;
  double scale = 1;  // ω_λ(t) = λ ω(λ t): the same motion spun up λ times

  explicit Dzhanibekov(double eta, double lambda = 1) : scale(lambda) {
    // ω(τ = 0) = (1, 0, c) with c² = (1 + η) I1 (I2 − I1) / (I3 (I3 − I2)): η > 0 is the distance from the
    // separatrix M² = 2 E I2, and k'² = m1 = η / (1 + η).
    const double a = 1, c = std::sqrt((1 + eta) * I1 * (I2 - I1) / (I3 * (I3 - I2)));
    const double twoE = I1 * a * a + I3 * c * c, M2 = I1 * I1 * a * a + I3 * I3 * c * c;
    A1 = std::sqrt((twoE * I3 - M2) / (I1 * (I3 - I1)));
    A2 = std::sqrt((twoE * I3 - M2) / (I2 * (I3 - I2)));
    A3 = std::sqrt((M2 - twoE * I1) / (I3 * (I3 - I1)));
    rate = std::sqrt((I3 - I2) * (M2 - twoE * I1) / (I1 * I2 * I3));
    m1 = eta / (1 + eta);
    m = 1 / (1 + eta);
    tau0 = complete_elliptic_k(m1);
  }
  Vec3 omega(double t) const {
    const Jacobi s = jacobi(tau0 + rate * scale * t, m, m1);
    return {scale * A1 * s.cn, scale * A2 * s.sn, scale * A3 * s.dn};
  }
  double energy(const Vec3& w) const { return 0.5 * (I1 * w[0] * w[0] + I2 * w[1] * w[1] + I3 * w[2] * w[2]); }
  double momentum(const Vec3& w) const {
    return std::sqrt(I1 * I1 * w[0] * w[0] + I2 * I2 * w[1] * w[1] + I3 * I3 * w[2] * w[2]);
  }
};

struct Comparison {
  double error = 0;  ///< max over samples of |ω − ω_exact|_∞ / scale
  double energy_drift = 0, momentum_drift = 0;
  int flips = 0;  ///< sign changes of ω_y: passages from one side of the intermediate axis to the other
  hamel::runtime::IntegrationResult result;
};

Comparison compare(hamel::test::SceneModel& body, const Dzhanibekov& exact, const std::string& integrator,
                   double setting, double t_end, double sample) {
  Comparison c;
  const Vec3 w0 = exact.omega(0);
  const double e0 = exact.energy(w0), p0 = exact.momentum(w0);
  double last_y = w0[1];
  c.result = body.run(integrator, setting, body.state({{"wx", w0[0]}, {"wy", w0[1]}, {"wz", w0[2]}}), t_end, sample,
                      [&](double t, const double* x) {
                        const Vec3 w{x[0], x[1], x[2]}, e = exact.omega(t);
                        for (int i = 0; i < 3; ++i) c.error = std::max(c.error, std::fabs(w[i] - e[i]) / exact.scale);
                        c.energy_drift = std::max(c.energy_drift, std::fabs(exact.energy(w) - e0) / e0);
                        c.momentum_drift = std::max(c.momentum_drift, std::fabs(exact.momentum(w) - p0) / p0);
                        if (w[1] * last_y < 0) ++c.flips;
                        last_y = w[1];
                      });
  return c;
}

TEST(Dzhanibekov, IntermediateAxisFlipsMatchTheEllipticSolution) {
  hamel::test::SceneModel body("free_rigid_body.yaml");
  ASSERT_EQ(body.size(), 3u);
  const Dzhanibekov exact(1e-6);  // k' = 1e-3: a half period 2K/τ' = 28.7 s between flips
  struct Run {
    const char* integrator;
    double setting, bound;
  };
  // Near the separatrix the motion amplifies errors (a factor ~1/k' per passage). Measured: dop853 1.3e-9,
  // dopri5 9.5e-8, radau5 1.2e-8, rk4 (h = 2e-3) 1.5e-9; the bounds leave a factor 10 to 100.
  for (const Run& r :
       {Run{"dop853", 1e-12, 1e-7}, Run{"dopri5", 1e-11, 1e-6}, Run{"radau5", 1e-11, 1e-6}, Run{"rk4", 2e-3, 1e-7}}) {
    SCOPED_TRACE(r.integrator);
    const Comparison c = compare(body, exact, r.integrator, r.setting, 120.0, 0.25);
    ASSERT_EQ(c.result.status, Status::ok);
    EXPECT_LT(c.error, r.bound);
    EXPECT_EQ(c.flips, 4);
    EXPECT_LT(c.energy_drift, 1e-8);
    EXPECT_LT(c.momentum_drift, 1e-8);
    std::cout << "[ dzhanibekov ] " << r.integrator << " " << r.setting << ": " << c.result.stats.steps
              << " steps, max |w - w_exact| " << c.error << ", energy drift " << c.energy_drift << ", |Pi| drift "
              << c.momentum_drift << ", flips " << c.flips << "\n";
  }
}

TEST(Dzhanibekov, FastSpinAtAThousandRadiansPerSecondOverALongHorizon) {
  hamel::test::SceneModel body("free_rigid_body.yaml");
  // |ω| = 1e3 rad/s, 1.2 s: 1200 rad of rotation, 42 flips. The adaptive methods take as many steps as for the
  // same motion at 1 rad/s over 1200 s; the error is relative to the spin rate.
  const Dzhanibekov exact(1e-6, 1e3);
  for (const char* integrator : {"dop853", "dopri5", "radau5", "rk4"}) {
    SCOPED_TRACE(integrator);
    const bool fixed = std::string(integrator) == "rk4";
    const Comparison c = compare(body, exact, integrator, fixed ? 2e-6 : 1e-12, 1.2, 1e-3);
    ASSERT_EQ(c.result.status, Status::ok);
    EXPECT_TRUE(hamel::test::finite(c.result.x));
    EXPECT_EQ(c.flips, 42);
    EXPECT_LT(c.error, 1e-5);  // measured: dop853 8e-8, dopri5 3e-7, radau5 8e-7, rk4 (h = 2e-6) 1.2e-6
    EXPECT_LT(c.energy_drift, 1e-8);
    EXPECT_LT(c.momentum_drift, 1e-8);
    std::cout << "[ fast spin   ] " << integrator << ": " << c.result.stats.steps << " steps, max |w - w_exact| / 1e3 "
              << c.error << ", energy drift " << c.energy_drift << ", |Pi| drift " << c.momentum_drift << "\n";
  }
}

}  // namespace
