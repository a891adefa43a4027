// `hamel linearize` (numeric/linearization, the `linearization` kernel) against published stability results.
//
// The Whipple bicycle (models/whipple_bicycle.yaml, written with definitions, bodies and rows of A as
// expressions; every parameter symbolic) linearized by `hamel linearize` about upright straight running,
// against the benchmark of Meijaard, Papadopoulos, Ruina & Schwab, Proc. R. Soc. A 463 (2007) 1955: the
// eigenvalues of their Table 2 at v = 0, 4, 5 and 10 m/s, and the weave and capsize speeds, which their
// linearized equations (M q'' + v C1 q' + (g K0 + v^2 K2) q = 0) give independently of any nonlinear model.
//
// The heavy symmetric top (models/heavy_top.yaml): the sleeping top is stable iff C² ω² > 4 A m g l with A the
// transverse moment of inertia about the pivot (Maxwell; e.g. Goldstein, Classical Mechanics, sec. 5.7); its
// linearization has the characteristic polynomial s⁴ + (C²ω²/A² − 2k) s² + k², k = m g l / A.
//
// The free rigid body (models/free_rigid_body.yaml, a bundle model on SO(3) in the Euler–Poincaré form):
// steady rotation at rate w about a principal axis j has the eigenvalues 0 and ±w √((I_j − I_i)(I_k − I_j)/(I_i I_k))
// (Euler's equations linearized by hand): real about the intermediate axis (unstable), imaginary otherwise.
#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"
#include "numeric/linearization.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

std::string source(const std::string& relative) {
  const char* root = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + relative;
}

struct Bicycle {
  hamel::Model model = hamel::load_model(source("models/whipple_bicycle.yaml"));
  hamel::Derivation derivation = hamel::derive(model, {});
  hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  int nx = static_cast<int>(model.n() + model.independent().size());
  hamel::Linearizer linearizer{kernels, nx, 0};
  std::vector<double> p;
  int v_index = -1;
  Bicycle() {
    for (const hamel::Parameter& par : model.parameters) p.push_back(par.default_value);
    for (int k = 0; k < static_cast<int>(derivation.equations.independent.size()); ++k)
      if (derivation.system
              .velocities[static_cast<std::size_t>(derivation.equations.independent[static_cast<std::size_t>(k)])]
              .get_name() == "v")
        v_index = static_cast<int>(model.n()) + k;
  }
  hamel::Spectrum at(double v) const {
    std::vector<double> x(static_cast<std::size_t>(nx), 0.0);
    x[static_cast<std::size_t>(v_index)] = v;
    return hamel::spectrum(linearizer.at(0.0, x, p, {}));
  }
};

const Bicycle& bicycle() {
  static const Bicycle b;
  return b;
}

// The eigenvalues of a spectrum that are not (numerically) zero.
std::vector<std::complex<double>> nonzero(const hamel::Spectrum& s) {
  std::vector<std::complex<double>> out;
  for (const hamel::Eigenvalue& e : s.values)
    if (std::hypot(e.re, e.im) > 1e-8) out.emplace_back(e.re, e.im);
  return out;
}

TEST(WhippleBicycle, EigenvaluesMatchTable2OfMeijaardEtAl) {
  ASSERT_GE(bicycle().v_index, 0) << "the model has no quasi-velocity v";
  const struct {
    double v;
    std::vector<std::complex<double>> expected;
  } table[] = {
      {0, {{5.53094371765393, 0}, {-5.53094371765393, 0}, {3.13164324790656, 0}, {-3.13164324790656, 0}}},
      {4,
       {{-12.15861426576447, 0},
        {-1.42944427361326, 0},
        {0.41325331521125, 3.07910818603206},
        {0.41325331521125, -3.07910818603206}}},
      {5,
       {{-14.07838969279822, 0},
        {-0.32286642900409, 0},
        {-0.77534188219585, 4.46486771378823},
        {-0.77534188219585, -4.46486771378823}}},
      {10,
       {{-24.62459635017404, 0},
        {0.16105338653172, 0},
        {-3.72016840437287, 10.90681139476287},
        {-3.72016840437287, -10.90681139476287}}},
  };
  double worst = 0;
  for (const auto& row : table) {
    const std::vector<std::complex<double>> got = nonzero(bicycle().at(row.v));
    ASSERT_EQ(got.size(), row.expected.size()) << "v = " << row.v;
    for (const std::complex<double>& e : row.expected) {
      double best = 1e300;
      for (const std::complex<double>& g : got) best = std::min(best, std::abs(g - e));
      // Ten significant digits of the eigenvalue (Table 2 prints 14).
      EXPECT_LT(best, 1e-10 * std::abs(e))
          << "v = " << row.v << ": eigenvalue " << e.real() << " + " << e.imag() << "i";
      worst = std::max(worst, best / std::abs(e));
    }
  }
  std::printf("[measured] Whipple bicycle: max relative deviation from Table 2: %.3g\n", worst);
}

TEST(WhippleBicycle, SweepFindsWeaveAndCapsizeSpeeds) {
  const hamel::Sweep s = hamel::sweep([](double v) { return bicycle().at(v); }, 0.0, 10.0, 0.1);
  ASSERT_EQ(s.crossings.size(), 2u);
  const hamel::Crossing& weave = s.crossings[0];
  const hamel::Crossing& capsize = s.crossings[1];
  EXPECT_TRUE(weave.complex);
  EXPECT_FALSE(weave.to_unstable);
  EXPECT_NEAR(weave.value, 4.29238253634111, 1e-10 * 4.29);
  EXPECT_FALSE(capsize.complex);
  EXPECT_TRUE(capsize.to_unstable);
  EXPECT_NEAR(capsize.value, 6.02426201538837, 1e-10 * 6.02);
  std::printf("[measured] weave speed %.15g (Table 2: 4.29238253634111), capsize speed %.15g (6.02426201538837)\n",
              weave.value, capsize.value);
}

struct Top {
  hamel::Model model = hamel::load_model(source("models/heavy_top.yaml"));
  hamel::Derivation derivation = hamel::derive(model, {});
  hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  hamel::Linearizer linearizer{kernels, 6, 0};
  std::vector<double> p;
  double parameter(const std::string& name) const {
    for (std::size_t k = 0; k < model.parameters.size(); ++k)
      if (model.parameters[k].symbol.get_name() == name) return p[k];
    throw std::runtime_error("no parameter " + name);
  }
  Top() {
    for (const hamel::Parameter& par : model.parameters) p.push_back(par.default_value);
  }
  hamel::LinearSystem at(double spin, double tilt = 0) const {
    return linearizer.at(0.0, {tilt, 0, 0, 0, 0, spin}, p, {});
  }
};

TEST(HeavyTop, SleepingTopBoundIsMaxwells) {
  const Top top;
  const double m = top.parameter("m"), l = top.parameter("l"), g = top.parameter("g");
  const double A = top.parameter("A0") + m * l * l, C = top.parameter("C");
  const double bound = 2 * std::sqrt(A * m * g * l) / C;
  // Eigenvalues against the characteristic polynomial at a stable and an unstable spin.
  for (double spin : {0.5 * bound, 1.5 * bound}) {
    const hamel::Spectrum s = hamel::spectrum(top.at(spin));
    const double k = m * g * l / A, b = C * C * spin * spin / (A * A) - 2 * k;
    const std::complex<double> root = std::sqrt(std::complex<double>(b * b - 4 * k * k));
    for (const std::complex<double> s2 : {(-b + root) / 2.0, (-b - root) / 2.0}) {
      const std::complex<double> lambda = std::sqrt(s2);
      for (const std::complex<double> expected : {lambda, -lambda}) {
        double best = 1e300;
        for (const hamel::Eigenvalue& e : s.values)
          best = std::min(best, std::abs(std::complex<double>(e.re, e.im) - expected));
        EXPECT_LT(best, 1e-9 * std::abs(expected)) << "spin " << spin << ": eigenvalue " << expected;
      }
    }
  }
  const hamel::Sweep s = hamel::sweep([&](double w) { return hamel::spectrum(top.at(w)); }, 0.0, 100.0, 1.0);
  ASSERT_EQ(s.crossings.size(), 1u);
  EXPECT_FALSE(s.crossings[0].to_unstable);
  EXPECT_NEAR(s.crossings[0].value, bound, 1e-6 * bound);
  std::printf("[measured] sleeping top: stability bound %.15g, Maxwell %.15g\n", s.crossings[0].value, bound);
}

TEST(HeavyTop, SteadyMotionNewtonReturnsToTheSleepingTop) {
  const Top top;
  // From a tilted, slowly moving start, with the spin held: the only steady motion with c cyclic nearby is
  // the sleeping top.
  const auto linearize = [&](const std::vector<double>& x) { return top.linearizer.at(0.0, x, top.p, {}); };
  const hamel::SteadyResult r =
      hamel::find_steady_motion(linearize, {0.02, -0.01, 0.3, 0.01, 0.02, 80.0}, {0, 1, 3, 4}, {2});
  for (int k : {0, 1, 3, 4}) EXPECT_NEAR(r.x[static_cast<std::size_t>(k)], 0.0, 1e-10) << k;
  EXPECT_EQ(r.x[5], 80.0);
  EXPECT_LT(r.residual, 1e-10);
}

TEST(FreeRigidBody, IntermediateAxisIsUnstable) {
  const hamel::Model model = hamel::load_model(source("models/free_rigid_body.yaml"));
  const hamel::Derivation derivation = hamel::derive(model, {});
  const hamel::KernelSet kernels = hamel::build_kernels(model, derivation, {"rhs", "linearization"});
  const hamel::Linearizer linearizer(kernels, 3, 0);
  const std::vector<double> I = {1.0, 2.0, 3.0};
  std::vector<double> p;
  for (const hamel::Parameter& par : model.parameters) p.push_back(par.default_value);
  ASSERT_EQ(p, I);
  const double w = 1.7;
  for (int j = 0; j < 3; ++j) {
    std::vector<double> x(3, 0.0);
    x[static_cast<std::size_t>(j)] = w;
    const hamel::Spectrum s = hamel::spectrum(linearizer.at(0.0, x, p, {}));
    const int i = (j + 1) % 3, k = (j + 2) % 3;
    const double d = (I[static_cast<std::size_t>(j)] - I[static_cast<std::size_t>(i)]) *
                     (I[static_cast<std::size_t>(k)] - I[static_cast<std::size_t>(j)]) /
                     (I[static_cast<std::size_t>(i)] * I[static_cast<std::size_t>(k)]);
    const std::complex<double> expected = w * std::sqrt(std::complex<double>(d));
    for (const std::complex<double> e : {expected, -expected, std::complex<double>(0)}) {
      double best = 1e300;
      for (const hamel::Eigenvalue& v : s.values) best = std::min(best, std::abs(std::complex<double>(v.re, v.im) - e));
      EXPECT_LT(best, 1e-12 * std::max(1.0, std::abs(e))) << "axis " << j << ": eigenvalue " << e;
    }
  }
}

}  // namespace
