// Gait design on the group of a bundle model (issue 50, beyond the paper's Sec. 6b): a closed shape path r(t),
// a truncated Fourier series, whose geometric phase — the net motion g(T) of the reconstruction (KinRec)
// ġ = g ξ (left) or ġ = ξ g (right) with ξ = −𝒜(r) ṙ, from g(0) = e — is a given group element g*, found at
// a small cost C = ∫₀ᵀ |ṙ|² dt (the identity metric on the shape space).
//
// Sensitivities. The variation of g(T) with a path coefficient c, η_c = (g⁻¹ ∂g/∂c)^∨ (left) or
// (∂g/∂c g⁻¹)^∨ (right), solves the forward sensitivity equation
//     η̇_c = ∂ξ/∂c ∓ ad_ξ η_c,   η_c(0) = 0   (− left, + right),
//     ∂ξ^α/∂c = −(∂𝒜^α_J/∂r^I ṙ^J) φ(t) − 𝒜^α_I φ̇(t)   for c the coefficient of φ(t) in r^I,
// integrated alongside the group by the same RKMK4 steps (runtime/lie/rkmk_coupled.hpp) with ∂𝒜/∂r from the
// generator's expression graph (numeric/connection_field.hpp). The residual e = log(g*⁻¹ g(T)) (left) or
// log(g(T) g*⁻¹) (right) then has the Jacobian dexp⁻¹(∓e) η.
//
// Optimiser (docs/gait.md): Levenberg–Marquardt steps of least weighted norm to reach the target (the weights
// those of the cost, so each step is the cheapest change of the path to first order), then descent of the
// cost on the set of gaits that reach it: the cost gradient projected on the null space of the Jacobian,
// each trial step followed by Gauss–Newton restoration of the target, kept when the cost decreased.
#pragma once

#include "derive/derivation.hpp"
#include "model/model.hpp"
#include "numeric/group_pose.hpp"

#include <limits>
#include <string>
#include <vector>

namespace hamel {

/// r^I(t) = r̄^I + Σ_{k=1..H} a^I_k cos(kωt) + b^I_k sin(kωt), ω = 2π/T.
struct FourierGait {
  double period = 1;
  int harmonics = 2;
  std::vector<double> center;        ///< r̄^I
  std::vector<double> cosine, sine;  ///< a^I_k, b^I_k at [I * harmonics + k − 1]

  unsigned n() const { return static_cast<unsigned>(center.size()); }
  double omega() const;
  /// r(t) and ṙ(t), n values each.
  void evaluate(double t, double* r, double* r_dot) const;
  /// C = ∫₀ᵀ |ṙ|² dt = (T/2) Σ_I Σ_k (kω)² ((a^I_k)² + (b^I_k)²).
  double cost() const;
  /// All coefficients in the order of the sensitivities: every a, every b, then r̄.
  std::vector<double> coefficients() const;
  void set_coefficients(const std::vector<double>& c);
  /// r^I(t) as an expression `hamel phase --path` parses (17 significant digits).
  std::string expression(unsigned I) const;
  /// The whole --path argument: the expressions of every coordinate separated by ';'.
  std::string path_argument() const;
};

/// g(T) along a gait, with the residual to a target and, on request, the sensitivities.
struct GaitPhase {
  GroupPose end;                  ///< g(T)
  std::vector<double> log_end;    ///< exponential coordinates of g(T) (the principal logarithm)
  std::vector<double> residual;   ///< e = log(g*⁻¹ g(T)) (left) or log(g(T) g*⁻¹) (right), m values
  std::vector<double> variation;  ///< η_c, m × N row-major by group index (N = coefficients().size())
  std::vector<double> jacobian;   ///< ∂e/∂c = dexp⁻¹(∓e) η, m × N
  long steps = 0;
};

/// The phase of `gait` with residual to g* = exp(target) (m exponential coordinates in the order of the model's
/// group velocity); with `sensitivities` also η and ∂e/∂c. Throws InputError when the reconstruction fails.
GaitPhase gait_phase(const Model& model, const Derivation& derivation, const std::vector<double>& parameters,
                     const FourierGait& gait, const std::vector<double>& target, int steps, bool sensitivities);

struct GaitRequest {
  std::vector<double> target;     ///< g* = exp(target), m exponential coordinates
  bool pseudo_holonomic = false;  ///< g* = e and the cost held at that of the initial path (excludes r = const)
  FourierGait initial;            ///< period, harmonics, centre and the starting coefficients
  bool free_center = false;       ///< optimise r̄ too (weight ω²T/2 in the step metric; no cost)
  double max_amplitude = std::numeric_limits<double>::infinity();  ///< bound on |r^I(t) − r̄^I|
  double max_rate = std::numeric_limits<double>::infinity();       ///< bound on |ṙ^I(t)|
  int steps_per_cycle = 2000;
  int max_iterations = 60;             ///< per stage (reaching the target; lowering the cost)
  double tolerance = 1e-12;            ///< on |e| (and the cost constraint of pseudo_holonomic, relative)
  double optimality_tolerance = 1e-3;  ///< on the relative projected cost gradient
  bool minimise_cost = true;
};

struct GaitResult {
  FourierGait gait;
  GaitPhase phase;   ///< at the result, without sensitivities
  double error = 0;  ///< |e|
  double cost = 0;
  double initial_cost = 0;
  double optimality = 0;  ///< |projected cost gradient| / |cost gradient| in the step metric (0: stationary)
  int target_iterations = 0, cost_iterations = 0;
  long phase_evaluations = 0;
  bool reached = false;     ///< |e| <= tolerance
  bool stationary = false;  ///< optimality <= optimality_tolerance
  std::string stop_reason;
};

/// Throws InputError when `request` does not fit `model`.
void check_gait_request(const Model& model, const GaitRequest& request);

GaitResult design_gait(const Model& model, const Derivation& derivation, const std::vector<double>& parameters,
                       const GaitRequest& request);

/// The curvature height function of component α over the (i, j) plane of the shape space, the other shape
/// coordinates at `base`: F = −(∂_i 𝒜_j − ∂_j 𝒜_i) + [𝒜_i, 𝒜_j] (left) or −(…) − [𝒜_i, 𝒜_j] (right). A small
/// loop traversed counter-clockwise in (r^i, r^j) moves the group by ∬ F (docs/gait.md).
std::vector<double> curvature_height(const Model& model, const Derivation& derivation,
                                     const std::vector<double>& parameters, const std::vector<double>& base, unsigned i,
                                     unsigned j, unsigned alpha, const std::vector<double>& xs,
                                     const std::vector<double>& ys);

}  // namespace hamel
