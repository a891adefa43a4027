#include "numeric/gait.hpp"

#include "model/input_error.hpp"
#include "numeric/connection_field.hpp"
#include "numeric/phase.hpp"

#include <hamel/runtime/lie/rkmk_coupled.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>

namespace hamel {

namespace lie = runtime::lie;

namespace {

constexpr double two_pi = 6.283185307179586476925286766559;

}  // namespace

double FourierGait::omega() const { return two_pi / period; }

void FourierGait::evaluate(double t, double* r, double* r_dot) const {
  const double w = omega();
  for (unsigned I = 0; I < n(); ++I) {
    r[I] = center[I];
    r_dot[I] = 0;
  }
  for (int k = 1; k <= harmonics; ++k) {
    const double c = std::cos(k * w * t), s = std::sin(k * w * t), kw = k * w;
    for (unsigned I = 0; I < n(); ++I) {
      const std::size_t at = I * static_cast<std::size_t>(harmonics) + static_cast<std::size_t>(k - 1);
      r[I] += cosine[at] * c + sine[at] * s;
      r_dot[I] += kw * (sine[at] * c - cosine[at] * s);
    }
  }
}

double FourierGait::cost() const {
  double sum = 0;
  for (unsigned I = 0; I < n(); ++I)
    for (int k = 1; k <= harmonics; ++k) {
      const std::size_t at = I * static_cast<std::size_t>(harmonics) + static_cast<std::size_t>(k - 1);
      sum += k * k * (cosine[at] * cosine[at] + sine[at] * sine[at]);
    }
  return 0.5 * period * omega() * omega() * sum;
}

std::vector<double> FourierGait::coefficients() const {
  std::vector<double> c = cosine;
  c.insert(c.end(), sine.begin(), sine.end());
  c.insert(c.end(), center.begin(), center.end());
  return c;
}

void FourierGait::set_coefficients(const std::vector<double>& c) {
  const std::size_t h = cosine.size();
  std::copy(c.begin(), c.begin() + static_cast<long>(h), cosine.begin());
  std::copy(c.begin() + static_cast<long>(h), c.begin() + static_cast<long>(2 * h), sine.begin());
  std::copy(c.begin() + static_cast<long>(2 * h), c.end(), center.begin());
}

std::string FourierGait::expression(unsigned I) const {
  std::ostringstream s;
  s << std::setprecision(17) << center[I];
  for (int k = 1; k <= harmonics; ++k) {
    const std::size_t at = I * static_cast<std::size_t>(harmonics) + static_cast<std::size_t>(k - 1);
    // ω t written as 2*Pi*k*t/T: the parser knows Pi, so phase evaluates the same frequency as the designer.
    std::ostringstream arg;
    arg << std::setprecision(17) << "2*Pi*" << k << "*t/" << period;
    if (cosine[at] != 0) s << (cosine[at] < 0 ? " - " : " + ") << std::abs(cosine[at]) << "*cos(" << arg.str() << ")";
    if (sine[at] != 0) s << (sine[at] < 0 ? " - " : " + ") << std::abs(sine[at]) << "*sin(" << arg.str() << ")";
  }
  return s.str();
}

std::string FourierGait::path_argument() const {
  std::string out;
  for (unsigned I = 0; I < n(); ++I) out += (I ? ";" : "") + expression(I);
  return out;
}

namespace {

// The basis function of coefficient c (every a, every b, then r̄) and its rate at t: which coordinate it moves.
struct Basis {
  unsigned coordinate;
  double value, rate;
};
Basis basis(const FourierGait& gait, std::size_t c, double t) {
  const std::size_t h = static_cast<std::size_t>(gait.harmonics), block = gait.n() * h;
  if (c >= 2 * block) return {static_cast<unsigned>(c - 2 * block), 1.0, 0.0};
  const bool is_sine = c >= block;
  const std::size_t within = is_sine ? c - block : c;
  const double kw = static_cast<double>(within % h + 1) * gait.omega();
  const double cs = std::cos(kw * t), sn = std::sin(kw * t);
  return is_sine ? Basis{static_cast<unsigned>(within / h), sn, kw * cs}
                 : Basis{static_cast<unsigned>(within / h), cs, -kw * sn};
}

template <class G>
GaitPhase reconstruct(ConnectionField& field, bool right, const FourierGait& gait, const std::vector<double>& target,
                      int steps, bool sensitivities) {
  constexpr std::size_t m = G::dim;
  const unsigned n = gait.n();
  const std::size_t N = sensitivities ? gait.coefficients().size() : 0;
  std::vector<double> r(n), r_dot(n), D(m * n);
  std::array<double, m> xi{};
  double cached = std::numeric_limits<double>::quiet_NaN();
  // r, ṙ, 𝒜 and ξ = −𝒜 ṙ at t, once per time (stages 2 and 3 of a step share theirs; ξ does not depend on g).
  const auto at = [&](double t) {
    if (t == cached) return;
    cached = t;
    gait.evaluate(t, r.data(), r_dot.data());
    field.evaluate(r.data());
    for (unsigned a = 0; a < m; ++a) {
      xi[a] = 0;
      for (unsigned I = 0; I < n; ++I) xi[a] -= field.A(a, I) * r_dot[I];
    }
    if (!sensitivities) return;
    for (unsigned a = 0; a < m; ++a)
      for (unsigned I = 0; I < n; ++I) {
        double s = 0;
        for (unsigned J = 0; J < n; ++J) s += field.dA(a, J, I) * r_dot[J];
        D[a * n + I] = s;
      }
  };
  const auto velocity = [&](double t, const double*, double* out) {
    at(t);
    std::copy(xi.begin(), xi.end(), out);
  };
  // η̇_c = ∂ξ/∂c ∓ ad_ξ η_c, η stored c-major (m values per coefficient).
  const auto variation = [&](double t, const double* eta, double* out) {
    at(t);
    const typename G::Matrix ad = G::ad(xi);
    const double sign = right ? 1.0 : -1.0;
    for (std::size_t c = 0; c < N; ++c) {
      const Basis b = basis(gait, c, t);
      const double* e = eta + c * m;
      for (std::size_t a = 0; a < m; ++a) {
        double v = -D[a * n + b.coordinate] * b.value - field.A(static_cast<unsigned>(a), b.coordinate) * b.rate;
        for (std::size_t k = 0; k < m; ++k) v += sign * ad[a * m + k] * e[k];
        out[c * m + a] = v;
      }
    }
  };
  const lie::Trivialization side = right ? lie::Trivialization::right : lie::Trivialization::left;
  const auto run =
      lie::integrate_rkmk4_coupled<G>(side, variation, velocity, G::identity(), std::vector<double>(N * m, 0.0), 0.0,
                                      gait.period, gait.period / steps, 0.0, lie::NoCoupledObserver{});
  if (run.status != runtime::Status::ok)
    throw InputError("gait: the reconstruction failed at t = " + std::to_string(run.t) + ": " +
                     std::string(runtime::describe(run.status)) + " (is the path outside the model's shape space?)");
  GaitPhase out;
  out.steps = run.stats.steps;
  out.end = pose_of(gait.period, run.g);
  const typename G::Vector log_end = G::log(run.g);
  out.log_end.assign(log_end.begin(), log_end.end());
  typename G::Vector v;
  std::copy(target.begin(), target.end(), v.begin());
  const typename G::Element goal = G::exp(v);
  const typename G::Element error = right ? G::compose(run.g, G::inverse(goal)) : G::compose(G::inverse(goal), run.g);
  typename G::Vector e = G::log(error);
  out.residual.assign(e.begin(), e.end());
  if (!sensitivities) return out;
  out.variation.assign(m * N, 0.0);
  out.jacobian.assign(m * N, 0.0);
  if (!right)
    for (double& x : e) x = -x;
  const typename G::Matrix dexpinv = G::dexpinv(e);
  for (std::size_t c = 0; c < N; ++c)
    for (std::size_t a = 0; a < m; ++a) {
      out.variation[a * N + c] = run.x[c * m + a];
      double s = 0;
      for (std::size_t k = 0; k < m; ++k) s += dexpinv[a * m + k] * run.x[c * m + k];
      out.jacobian[a * N + c] = s;
    }
  return out;
}

// The reconstruction of one model, set up once (the connection's expression graph) and run for many gaits.
class GaitReconstruction {
 public:
  GaitReconstruction(const Model& model, const Derivation& d, const std::vector<double>& parameters)
      : field_(model, d, parameters, true), right_(model.bundle->right), group_(model.bundle->group) {}
  GaitPhase operator()(const FourierGait& gait, const std::vector<double>& target, int steps, bool sensitivities) {
    return with_group(group_, [&](auto tag) {
      return reconstruct<typename decltype(tag)::type>(field_, right_, gait, target, steps, sensitivities);
    });
  }
  ConnectionField& field() { return field_; }

 private:
  ConnectionField field_;
  bool right_;
  std::string group_;
};

double norm(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s);
}

// The largest |r^I(t) − r̄^I| and |ṙ^I(t)| over 64 samples per harmonic.
std::pair<double, double> extent(const FourierGait& gait) {
  const int samples = 64 * std::max(1, gait.harmonics);
  std::vector<double> r(gait.n()), r_dot(gait.n());
  double amplitude = 0, rate = 0;
  for (int s = 0; s < samples; ++s) {
    gait.evaluate(gait.period * s / samples, r.data(), r_dot.data());
    for (unsigned I = 0; I < gait.n(); ++I) {
      amplitude = std::max(amplitude, std::abs(r[I] - gait.center[I]));
      rate = std::max(rate, std::abs(r_dot[I]));
    }
  }
  return {amplitude, rate};
}

// The optimiser's view: the free coefficients x, the metric M (diagonal), the residual rows and their Jacobian.
class GaitProblem {
 public:
  GaitProblem(GaitReconstruction& reconstruction, const GaitRequest& req) : rec_(reconstruction), req_(req) {
    gait_ = req.initial;
    const std::size_t h = gait_.cosine.size(), n = gait_.n();
    const double w = gait_.omega(), T = gait_.period;
    for (std::size_t c = 0; c < 2 * h; ++c) {
      const double k = static_cast<double>(c % static_cast<std::size_t>(gait_.harmonics) + 1);
      free_.push_back(c);
      metric_.push_back(0.5 * T * k * k * w * w);
    }
    for (std::size_t I = 0; I < n && req.free_center; ++I) {
      free_.push_back(2 * h + I);
      metric_.push_back(0.5 * T * w * w);
    }
    size0_ = gait_.cost();
    set_coarse(false);
  }

  std::size_t size() const { return free_.size(); }
  Eigen::VectorXd x() const {
    const std::vector<double> all = gait_.coefficients();
    Eigen::VectorXd v(static_cast<long>(size()));
    for (std::size_t i = 0; i < size(); ++i) v[static_cast<long>(i)] = all[free_[i]];
    return v;
  }
  FourierGait gait_at(const Eigen::VectorXd& x) const {
    FourierGait g = gait_;
    std::vector<double> all = g.coefficients();
    for (std::size_t i = 0; i < size(); ++i) all[free_[i]] = x[static_cast<long>(i)];
    g.set_coefficients(all);
    return g;
  }
  void set(const Eigen::VectorXd& x) { gait_ = gait_at(x); }
  const FourierGait& gait() const { return gait_; }
  Eigen::VectorXd metric() const {
    return Eigen::Map<const Eigen::VectorXd>(metric_.data(), static_cast<long>(size()));
  }

  double cost(const Eigen::VectorXd& x) const { return gait_at(x).cost(); }
  /// ∇C on the free coefficients (r̄ costs nothing).
  Eigen::VectorXd cost_gradient(const Eigen::VectorXd& x) const {
    Eigen::VectorXd g(static_cast<long>(size()));
    const std::size_t h = gait_.cosine.size();
    for (std::size_t i = 0; i < size(); ++i)
      g[static_cast<long>(i)] = free_[i] < 2 * h ? 2 * metric_[i] * x[static_cast<long>(i)] : 0.0;
    return g;
  }
  /// For pseudo-holonomic loops: x with its harmonics scaled onto the cost of the initial path (the cost is a
  /// quadratic form in them), so that the cost row of the residual holds exactly and steps cannot overshoot it.
  Eigen::VectorXd held(Eigen::VectorXd x) const {
    if (!req_.pseudo_holonomic) return x;
    const double c = cost(x);
    if (!(c > 0)) return x;
    const double s = std::sqrt(size0_ / c);
    const std::size_t h = gait_.cosine.size();
    for (std::size_t i = 0; i < size(); ++i)
      if (free_[i] < 2 * h) x[static_cast<long>(i)] *= s;
    return x;
  }
  bool within_limits(const Eigen::VectorXd& x) const {
    const auto [amplitude, rate] = extent(gait_at(x));
    return amplitude <= req_.max_amplitude && rate <= req_.max_rate;
  }

  /// The residual rows (e, and for pseudo-holonomic loops C/C₀ − 1) and, with `jacobian`, their Jacobian.
  struct Value {
    Eigen::VectorXd e;
    Eigen::MatrixXd J;
    GaitPhase phase;
  };
  /// A trial point whose reconstruction fails (a non-finite state: the path left the shape space where 𝒜 is
  /// defined) gets an infinite residual, so that the optimiser rejects it; `strict` throws the InputError instead.
  Value evaluate(const Eigen::VectorXd& x, bool jacobian, bool strict = false) {
    ++evaluations_;
    Value v;
    try {
      v.phase = rec_(gait_at(x), req_.target, steps_, jacobian);
    } catch (const InputError&) {
      if (strict) throw;
      const long rows = static_cast<long>(req_.target.size()) + (req_.pseudo_holonomic ? 1 : 0);
      v.e = Eigen::VectorXd::Constant(rows, std::numeric_limits<double>::infinity());
      v.J = Eigen::MatrixXd::Zero(rows, static_cast<long>(size()));
      return v;
    }
    const long m = static_cast<long>(v.phase.residual.size()), rows = m + (req_.pseudo_holonomic ? 1 : 0);
    v.e.resize(rows);
    for (long a = 0; a < m; ++a) v.e[a] = v.phase.residual[static_cast<std::size_t>(a)];
    if (req_.pseudo_holonomic) v.e[m] = cost(x) / size0_ - 1;
    if (!jacobian) return v;
    const std::size_t N = gait_.coefficients().size();
    v.J.resize(rows, static_cast<long>(size()));
    for (long a = 0; a < m; ++a)
      for (std::size_t i = 0; i < size(); ++i)
        v.J(a, static_cast<long>(i)) = v.phase.jacobian[static_cast<std::size_t>(a) * N + free_[i]];
    if (req_.pseudo_holonomic) v.J.row(m) = cost_gradient(x).transpose() / size0_;
    return v;
  }
  long evaluations() const { return evaluations_; }
  /// RKMK4 steps per evaluation: the request's, or a quarter of them while searching (set_coarse).
  void set_coarse(bool coarse) { steps_ = coarse ? std::max(100, req_.steps_per_cycle / 4) : req_.steps_per_cycle; }

 private:
  GaitReconstruction& rec_;
  const GaitRequest& req_;
  FourierGait gait_;
  std::vector<std::size_t> free_;
  std::vector<double> metric_;
  double size0_ = 1;
  long evaluations_ = 0;
  int steps_ = 0;
};

// The step of least M-norm with J δ = −e, damped: δ = −M⁻¹Jᵀ (J M⁻¹ Jᵀ + μ I)⁻¹ e.
Eigen::VectorXd least_norm_step(const Eigen::MatrixXd& J, const Eigen::VectorXd& e, const Eigen::VectorXd& metric,
                                double mu) {
  const Eigen::MatrixXd JW = J * metric.cwiseInverse().asDiagonal();
  Eigen::MatrixXd S = JW * J.transpose();
  S.diagonal().array() += mu;
  const Eigen::VectorXd y = S.completeOrthogonalDecomposition().solve(e);
  return -(JW.transpose() * y);
}

}  // namespace

void check_gait_request(const Model& model, const GaitRequest& req) {
  if (!model.bundle) throw InputError("gait: '" + model.source_path + "' is not a bundle model");
  check_conserved_momentum(model, "'hamel gait'");
  const FourierGait& g = req.initial;
  if (req.target.size() != model.bundle->group_velocity.size())
    throw InputError("--target: expected " + std::to_string(model.bundle->group_velocity.size()) + " values");
  if (!(g.period > 0) || !std::isfinite(g.period)) throw InputError("--period: expected a positive time");
  if (g.harmonics < 1 || g.harmonics > 20) throw InputError("--harmonics: expected 1 to 20");
  if (g.center.size() != model.coordinates.size())
    throw InputError("--center: expected " + std::to_string(model.coordinates.size()) + " values");
  if (req.steps_per_cycle < 4 || req.steps_per_cycle > 1000000)
    throw InputError("--steps-per-cycle: expected 4 to 1000000");
  if (req.max_iterations < 0) throw InputError("--max-iterations: expected at least 0");
  if (!(req.tolerance > 0)) throw InputError("--tolerance: expected a positive number");
  if (!(req.max_amplitude > 0)) throw InputError("--max-amplitude: expected a positive bound");
  if (!(req.max_rate > 0)) throw InputError("--max-rate: expected a positive bound");
}

GaitPhase gait_phase(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                     const FourierGait& gait, const std::vector<double>& target, int steps, bool sensitivities) {
  if (!d.bundle) throw InputError("gait: '" + model.source_path + "' is not a bundle model");
  GaitReconstruction rec(model, d, parameters);
  return rec(gait, target, steps, sensitivities);
}

GaitResult design_gait(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                       const GaitRequest& req) {
  check_gait_request(model, req);
  if (!d.bundle) throw InputError("gait: '" + model.source_path + "' is not a bundle model");
  GaitReconstruction rec(model, d, parameters);
  // The phase of a loop changes sign with its direction, and Gauss–Newton cannot turn a loop round without
  // shrinking it through r = const (where the Jacobian vanishes): start on the direction that is nearer. The phase
  // of a small loop grows with the square of its size: scale the start so that its phase is about the target's.
  GaitRequest oriented = req;
  if (!req.pseudo_holonomic) {
    FourierGait reversed = req.initial;
    for (double& b : reversed.sine) b = -b;
    const GaitPhase forward = rec(req.initial, req.target, req.steps_per_cycle, false);
    const GaitPhase backward = rec(reversed, req.target, req.steps_per_cycle, false);
    const bool flip = norm(backward.residual) < norm(forward.residual);
    if (flip) oriented.initial = reversed;
    const double reached = norm(flip ? backward.log_end : forward.log_end), wanted = norm(req.target);
    if (reached > 0) {
      const double s = std::clamp(std::sqrt(wanted / reached), 0.25, 4.0);
      FourierGait scaled = oriented.initial;
      for (double& a : scaled.cosine) a *= s;
      for (double& b : scaled.sine) b *= s;
      if (extent(scaled).first <= req.max_amplitude && extent(scaled).second <= req.max_rate) oriented.initial = scaled;
    }
  }
  GaitProblem problem(rec, oriented);
  GaitResult out;
  out.initial_cost = oriented.initial.cost();
  const Eigen::VectorXd M = problem.metric();
  Eigen::VectorXd x = problem.x();
  if (!problem.within_limits(x))
    throw InputError("--amplitude: the initial path exceeds --max-amplitude or --max-rate; expected a smaller one");
  problem.set_coarse(true);
  GaitProblem::Value v = problem.evaluate(x, true, true);

  // Stage 1: reach the target (Levenberg–Marquardt, least M-norm steps).
  double mu = 1e-3 * std::max(1e-300, (v.J * M.cwiseInverse().asDiagonal() * v.J.transpose()).trace());
  out.stop_reason = "iteration limit while reaching the target";
  while (v.e.norm() > req.tolerance) {
    if (out.target_iterations >= req.max_iterations) break;
    ++out.target_iterations;
    bool accepted = false;
    for (int tries = 0; tries < 30 && !accepted; ++tries) {
      const Eigen::VectorXd trial = problem.held(x + least_norm_step(v.J, v.e, M, mu));
      if (!problem.within_limits(trial)) {
        mu *= 4;
        continue;
      }
      GaitProblem::Value w = problem.evaluate(trial, true);
      if (w.e.norm() < v.e.norm()) {
        x = trial;
        v = std::move(w);
        mu = std::max(mu / 3, 1e-30);
        accepted = true;
      } else {
        mu *= 4;
      }
    }
    if (!accepted) {
      out.stop_reason = "no step reduces the residual (a local minimum of |e|, or the limits bind)";
      break;
    }
  }
  out.reached = v.e.norm() <= req.tolerance;

  // Stage 2: lower the cost on {e = 0}: the projected gradient, then Gauss–Newton restoration of the target.
  const auto projected = [&](const GaitProblem::Value& at, const Eigen::VectorXd& g) {
    const Eigen::VectorXd Wg = M.cwiseInverse().cwiseProduct(g);
    const Eigen::MatrixXd JW = at.J * M.cwiseInverse().asDiagonal();
    const Eigen::VectorXd y = (JW * at.J.transpose()).completeOrthogonalDecomposition().solve(at.J * Wg);
    return Eigen::VectorXd(-(Wg - JW.transpose() * y));
  };
  const auto m_norm = [&](const Eigen::VectorXd& d) { return std::sqrt(d.dot(M.cwiseProduct(d))); };
  if (out.reached) {
    out.stop_reason = "target reached";
    double alpha = 0.5;
    bool converged_cost = false;
    while (req.minimise_cost && !req.pseudo_holonomic) {
      const Eigen::VectorXd g = problem.cost_gradient(x);
      const Eigen::VectorXd d = projected(v, g);
      const double scale = m_norm(M.cwiseInverse().cwiseProduct(g));
      out.optimality = scale > 0 ? m_norm(d) / scale : 0;
      if (out.optimality <= req.optimality_tolerance) {
        out.stationary = true;
        out.stop_reason = "target reached, cost stationary";
        break;
      }
      if (out.cost_iterations >= req.max_iterations) {
        out.stop_reason = "target reached, iteration limit while lowering the cost";
        break;
      }
      ++out.cost_iterations;
      bool accepted = false;
      for (; alpha > 1e-6 && !accepted; alpha *= 0.5) {
        Eigen::VectorXd trial = x + alpha * d;
        GaitProblem::Value w = problem.evaluate(trial, true);
        for (int k = 0; k < 8 && std::isfinite(w.e.norm()) && w.e.norm() > req.tolerance; ++k) {
          trial += least_norm_step(w.J, w.e, M, 0.0);
          w = problem.evaluate(trial, true);
        }
        if (w.e.norm() <= req.tolerance && problem.cost(trial) < problem.cost(x) && problem.within_limits(trial)) {
          converged_cost = problem.cost(x) - problem.cost(trial) <= 1e-12 * problem.cost(x);
          x = trial;
          v = std::move(w);
          accepted = true;
        }
      }
      if (!accepted) {
        out.stop_reason = "target reached, no cost-lowering step found (the limits bind or the cost is stationary)";
        break;
      }
      if (converged_cost) {
        out.stop_reason = "target reached, the cost no longer decreases (relative change below 1e-12)";
        break;
      }
      alpha = std::min(1.0, 4 * alpha);  // the loop halved it once more after the accepted trial
    }
  }
  // Both stages ran with a quarter of the steps: restore the target with the requested steps (a few Gauss–Newton
  // steps from a point whose residual is the difference of the two discretizations).
  problem.set_coarse(false);
  v = problem.evaluate(x, true, true);
  // Gauss–Newton converges quadratically: continue while it still halves |e|, to the rounding level.
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd trial = problem.held(x + least_norm_step(v.J, v.e, M, 0.0));
    GaitProblem::Value w = problem.evaluate(trial, true);
    if (!(w.e.norm() < v.e.norm())) break;
    const bool halved = w.e.norm() < 0.5 * v.e.norm();
    x = trial;
    v = std::move(w);
    if (!halved) break;
  }
  if (out.reached && v.e.norm() > req.tolerance) out.stop_reason += "; lost when refined to the requested steps";
  out.reached = v.e.norm() <= req.tolerance;
  problem.set(x);
  out.gait = problem.gait();
  out.phase = v.phase;
  out.phase.variation.clear();
  out.phase.jacobian.clear();
  out.error = norm(out.phase.residual);
  out.cost = out.gait.cost();
  out.phase_evaluations = problem.evaluations();
  return out;
}

std::vector<double> curvature_height(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                                     const std::vector<double>& base, unsigned i, unsigned j, unsigned alpha,
                                     const std::vector<double>& xs, const std::vector<double>& ys) {
  ConnectionField field(model, d, parameters, true);
  const bool right = model.bundle->right;
  std::vector<double> out;
  out.reserve(xs.size() * ys.size());
  std::vector<double> r = base;
  with_group(model.bundle->group, [&](auto tag) {
    using G = typename decltype(tag)::type;
    constexpr std::size_t m = G::dim;
    for (double y : ys)
      for (double x : xs) {
        r[i] = x;
        r[j] = y;
        field.evaluate(r.data());
        typename G::Vector Ai, Aj;
        for (unsigned a = 0; a < m; ++a) Ai[a] = field.A(a, i), Aj[a] = field.A(a, j);
        const typename G::Vector bracket = lie::mat_vec<m>(G::ad(Ai), Aj);
        const double curl = field.dA(alpha, j, i) - field.dA(alpha, i, j);
        out.push_back(-curl + (right ? -1.0 : 1.0) * bracket[alpha]);
      }
    return 0;
  });
  return out;
}

}  // namespace hamel
