// The phase of the satellite along the paper's Sec. 6c shape path (6 cycles of
// r(t) = (π(cos 2πt − 1), π sin 2πt, π/2 sin 4πt)), computed by compute_phase from the generator's
// mechanical connection and locked inertia, agrees with an independent computation from angular-momentum
// conservation about the total centre of mass (satellite_reference.hpp: Θ_c, J and c from the physical
// parameters, the rotation as a unit quaternion):
//  - zero momentum: R Θ_c ω + R J φ̇ = 0, so ω = −Θ_c⁻¹ J φ̇;
//  - rest (base at rest at t = 0): h0 = J φ̇(0), ω = Θ_c⁻¹ (Rᵀ h0 − J φ̇); the dynamic phase (the shape
//    frozen at r(0)) is the free rotation ω = Θ_c⁻¹ Rᵀ h0;
//  - the total centre of mass moves with the constant velocity (linear momentum)/M, which is zero here
//    (each rotor's centre of mass is on its spin axis), so p_c = c and the base frame F_b is at
//    p_b = p_c − R c.
// Both models are checked, and against each other: SO(3)×R³ at the centre of mass and SE(3) at F_b give
// the same rotation, and the SE(3) translation is p_c − R c with p_c from the SO(3)×R³ translation.
#include "satellite_reference.hpp"

#include "derive/derivation.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/phase.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

namespace {

using satellite::Physical;

constexpr int kCycles = 6;

std::string model_path(const std::string& name) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : ".") + "/models/" + name + ".yaml";
}

struct Loaded {
  hamel::Model model;
  hamel::Derivation derivation;
  std::vector<double> parameters;
  Physical physical;
};

// Loads the model, folds every parameter at its default and derives the momentum form.
Loaded load(const std::string& name) {
  const hamel::Model raw = hamel::load_model(model_path(name));
  std::map<std::string, double> values;
  std::vector<double> parameters;
  for (const auto& p : raw.parameters) {
    values[p.symbol.get_name()] = p.default_value;
    parameters.push_back(p.default_value);
  }
  hamel::Model folded = hamel::fold_parameters(raw, values);
  hamel::Derivation d = hamel::derive(folded, hamel::DeriveSettings{"momentum"});
  return {std::move(folded), std::move(d), std::move(parameters), satellite::physical(raw)};
}

hamel::PhaseResult phase(const Loaded& s, hamel::PhaseMomentum momentum, int steps_per_cycle) {
  const GiNaC::ex t = s.model.time, pi = GiNaC::Pi;
  hamel::PhaseRequest req;
  req.path = {pi * (cos(2 * pi * t) - 1), pi * sin(2 * pi * t), pi / 2 * sin(4 * pi * t)};
  req.period = 1;
  req.cycles = kCycles;
  req.momentum = momentum;
  req.steps_per_cycle = steps_per_cycle;
  req.samples_per_cycle = 4;
  return hamel::compute_phase(s.model, s.derivation, s.parameters, req);
}

Eigen::Matrix3d R_of(const hamel::GroupPose& p) {
  EXPECT_TRUE(p.R.has_value());
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = (*p.R)[static_cast<std::size_t>(3 * i + j)];
  return R;
}
Eigen::Vector3d p_of(const hamel::GroupPose& p) {
  EXPECT_EQ(p.p.size(), 3u);
  return Eigen::Vector3d(p.p.at(0), p.p.at(1), p.p.at(2));
}

// The independent reference: R after each cycle from angular-momentum conservation.
struct Reference {
  std::vector<Eigen::Matrix3d> zero, rest, dynamic;
  Eigen::Vector3d p_c_rate;  // velocity of the total centre of mass with the rest momentum
};

Reference reference(const Physical& s, int steps_per_unit) {
  const Eigen::Matrix3d inv = s.Theta_c.inverse();
  const Eigen::Vector3d h0 = s.J * satellite::path_rate(0.0);
  Reference r;
  r.zero = satellite::rotations_per_cycle(
      [&](double t, const Eigen::Matrix3d&) -> Eigen::Vector3d { return -inv * (s.J * satellite::path_rate(t)); },
      kCycles, steps_per_unit);
  r.rest = satellite::rotations_per_cycle(
      [&](double t, const Eigen::Matrix3d& R) -> Eigen::Vector3d {
        return inv * (R.transpose() * h0 - s.J * satellite::path_rate(t));
      },
      kCycles, steps_per_unit);
  r.dynamic = satellite::rotations_per_cycle(
      [&](double, const Eigen::Matrix3d& R) -> Eigen::Vector3d { return inv * (R.transpose() * h0); }, kCycles,
      steps_per_unit);
  const Eigen::Vector3d phi0 = satellite::path_rate(0.0);
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) linear += s.rotor_linear_momentum[static_cast<std::size_t>(i)] * phi0[i];
  r.p_c_rate = linear / s.M;
  return r;
}

// Reference step: 1e-4 (10^4 RK4 steps per cycle).
constexpr int kReferenceSteps = 10000;
// compute_phase: 2000 RKMK4 steps per cycle (the CLI default) and 8000. Both are converged to rounding
// (measured differences to the reference: at most 6e-13 in R, 3e-14 in p); the tolerance allows for the
// ~1e-12 rounding of the reference itself.
constexpr int kCoarse = 2000, kFine = 8000;
constexpr double kTolerance = 1e-11;

class SatellitePhase : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    se3_ = new Loaded(load("satellite_se3"));
    so3xr3_ = new Loaded(load("satellite_so3xr3"));
    ref_ = new Reference(reference(so3xr3_->physical, kReferenceSteps));
  }
  static void TearDownTestSuite() {
    delete se3_;
    delete so3xr3_;
    delete ref_;
  }
  static Loaded* se3_;
  static Loaded* so3xr3_;
  static Reference* ref_;
};
Loaded* SatellitePhase::se3_ = nullptr;
Loaded* SatellitePhase::so3xr3_ = nullptr;
Reference* SatellitePhase::ref_ = nullptr;

TEST_F(SatellitePhase, BothModelsDescribeTheSameSatellite) {
  const Physical& a = se3_->physical;
  const Physical& b = so3xr3_->physical;
  EXPECT_EQ(a.M, b.M);
  EXPECT_EQ((a.c - b.c).norm(), 0.0);
  EXPECT_EQ((a.Theta_c - b.Theta_c).norm(), 0.0);
  // No linear momentum from the rotors: the rest momentum leaves the centre of mass in place.
  for (const auto& l : a.rotor_linear_momentum) EXPECT_LT(l.norm(), 1e-15);
}

// The reference is converged: its truncation error at 10^4 steps per cycle is below 1e-15 (it is
// 8e-11 at 500 steps and falls as h^4); what remains is rounding accumulated over 6·10^4 renormalised
// steps, about 1e-12 (measured against 2·10^4 steps per cycle).
TEST_F(SatellitePhase, ReferenceIsConverged) {
  const Reference fine = reference(so3xr3_->physical, 2 * kReferenceSteps);
  double worst = 0;
  for (int k = 0; k < kCycles; ++k) {
    const auto K = static_cast<std::size_t>(k);
    worst = std::max({worst, (fine.zero[K] - ref_->zero[K]).norm(), (fine.rest[K] - ref_->rest[K]).norm(),
                      (fine.dynamic[K] - ref_->dynamic[K]).norm()});
  }
  std::printf("quaternion reference, h = 1e-4 vs 5e-5: max |dR|_F = %.2e\n", worst);
  EXPECT_LT(worst, kTolerance);
}

void compare(const char* what, const Loaded& s, const Reference& ref, hamel::PhaseMomentum momentum, int steps,
             double tolerance) {
  const hamel::PhaseResult r = phase(s, momentum, steps);
  ASSERT_EQ(r.cycles.size(), static_cast<std::size_t>(kCycles));
  const bool rest = momentum == hamel::PhaseMomentum::rest;
  const std::vector<Eigen::Matrix3d>& expected = rest ? ref.rest : ref.zero;
  const bool se3 = r.group == "SE3";
  const Eigen::Vector3d& c = s.physical.c;
  double worst_R = 0, worst_p = 0, worst_dyn_R = 0, worst_dyn_p = 0;
  for (int k = 0; k < kCycles; ++k) {
    const auto K = static_cast<std::size_t>(k);
    const hamel::GroupPose& pose = r.cycles[K];
    EXPECT_DOUBLE_EQ(pose.t, k + 1.0);
    const Eigen::Matrix3d R = R_of(pose);
    worst_R = std::max(worst_R, (R - expected[K]).norm());
    // p_c(t) = c + ṗ_c t (SE3: F_b starts at the origin, so p_c(0) = c) and p_b = p_c − R c; the
    // SO(3)×R³ translation is p_c − p_c(0).
    const Eigen::Vector3d p_c = c + ref.p_c_rate * (k + 1.0);
    const Eigen::Vector3d p_expected = se3 ? Eigen::Vector3d(p_c - expected[K] * c) : Eigen::Vector3d(p_c - c);
    worst_p = std::max(worst_p, (p_of(pose) - p_expected).norm());
    if (rest) {
      ASSERT_EQ(r.dynamic.size(), static_cast<std::size_t>(kCycles));
      const Eigen::Matrix3d Rd = R_of(r.dynamic[K]);
      worst_dyn_R = std::max(worst_dyn_R, (Rd - ref.dynamic[K]).norm());
      const Eigen::Vector3d pd = se3 ? Eigen::Vector3d(p_c - ref.dynamic[K] * c) : Eigen::Vector3d(p_c - c);
      worst_dyn_p = std::max(worst_dyn_p, (p_of(r.dynamic[K]) - pd).norm());
    } else {
      EXPECT_TRUE(r.dynamic.empty());
    }
  }
  std::printf("%-30s %5d steps/cycle: max |R - R_ref|_F = %.2e, |p - p_ref| = %.2e", what, steps, worst_R, worst_p);
  if (rest) std::printf("; dynamic phase: %.2e, %.2e", worst_dyn_R, worst_dyn_p);
  std::printf("\n");
  EXPECT_LT(worst_R, tolerance) << what;
  EXPECT_LT(worst_p, tolerance) << what;
  EXPECT_LT(worst_dyn_R, tolerance) << what;
  EXPECT_LT(worst_dyn_p, tolerance) << what;
}

TEST_F(SatellitePhase, ZeroMomentumMatchesAngularMomentumConservation) {
  compare("SO3xR3 zero momentum", *so3xr3_, *ref_, hamel::PhaseMomentum::zero, kCoarse, kTolerance);
  compare("SO3xR3 zero momentum", *so3xr3_, *ref_, hamel::PhaseMomentum::zero, kFine, kTolerance);
  compare("SE3 zero momentum", *se3_, *ref_, hamel::PhaseMomentum::zero, kCoarse, kTolerance);
  compare("SE3 zero momentum", *se3_, *ref_, hamel::PhaseMomentum::zero, kFine, kTolerance);
}

TEST_F(SatellitePhase, RestMomentumMatchesAngularMomentumConservation) {
  compare("SO3xR3 rest momentum", *so3xr3_, *ref_, hamel::PhaseMomentum::rest, kCoarse, kTolerance);
  compare("SO3xR3 rest momentum", *so3xr3_, *ref_, hamel::PhaseMomentum::rest, kFine, kTolerance);
  compare("SE3 rest momentum", *se3_, *ref_, hamel::PhaseMomentum::rest, kCoarse, kTolerance);
  compare("SE3 rest momentum", *se3_, *ref_, hamel::PhaseMomentum::rest, kFine, kTolerance);
}

// SO(3)×R³ at the centre of mass and SE(3) at F_b: the same base rotation after every cycle, and the
// SE(3) translation is p_c − R c with p_c = c + (the SO(3)×R³ translation).
TEST_F(SatellitePhase, So3xR3AndSe3GiveTheSameBaseMotion) {
  for (auto momentum : {hamel::PhaseMomentum::zero, hamel::PhaseMomentum::rest}) {
    const hamel::PhaseResult a = phase(*so3xr3_, momentum, kCoarse);
    const hamel::PhaseResult b = phase(*se3_, momentum, kCoarse);
    ASSERT_EQ(a.cycles.size(), b.cycles.size());
    const Eigen::Vector3d& c = so3xr3_->physical.c;
    double worst_R = 0, worst_p = 0;
    for (std::size_t k = 0; k < a.cycles.size(); ++k) {
      const Eigen::Matrix3d Ra = R_of(a.cycles[k]), Rb = R_of(b.cycles[k]);
      worst_R = std::max(worst_R, (Ra - Rb).norm());
      const Eigen::Vector3d p_c = c + p_of(a.cycles[k]);
      worst_p = std::max(worst_p, (p_of(b.cycles[k]) - (p_c - Rb * c)).norm());
    }
    std::printf("SO3xR3 vs SE3 (%s): max |R_a - R_b|_F = %.2e, |p_b - (p_c - R c)| = %.2e\n",
                momentum == hamel::PhaseMomentum::zero ? "zero" : "rest", worst_R, worst_p);
    EXPECT_LT(worst_R, 1e-10);
    EXPECT_LT(worst_p, 1e-10);
  }
}

}  // namespace
