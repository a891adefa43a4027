#include "numeric/kernel_accuracy.hpp"

#include "algebra/operations.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/kernel_references.hpp"
#include "report/progress.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

namespace hamel {

using GiNaC::ex;
using GiNaC::ex_to;
using GiNaC::is_a;
using GiNaC::numeric;

double ulp_of(double y) {
  y = std::fabs(y);
  if (!(y >= std::numeric_limits<double>::min())) return std::numeric_limits<double>::denorm_min();
  if (!std::isfinite(y)) return std::numeric_limits<double>::infinity();
  return std::ldexp(1.0, std::ilogb(y) - 52);
}

double ulp_error(double computed, const GiNaC::numeric& reference, double floor) {
  if (!std::isfinite(computed)) return std::numeric_limits<double>::infinity();
  const double diff = GiNaC::abs(exact_rational(computed) - reference).to_double();
  if (diff == 0) return 0;
  const double magnitude = std::max(GiNaC::abs(reference).to_double(), floor);
  return diff / ulp_of(magnitude);
}

// ---------------------------------------------------------------------------------------------------------

namespace {

struct Point {
  double t = 0;
  std::vector<double> x, in;
};

// A point's arguments in high precision.
struct HighPrecisionPoint {
  numeric t;
  std::vector<numeric> x, in;
  explicit HighPrecisionPoint(const Point& pt) : t(high_precision(pt.t)) {
    for (double v : pt.x) x.push_back(high_precision(v));
    for (double v : pt.in) in.push_back(high_precision(v));
  }
};

// One measurement (measure_kernel_accuracy): the references, the kernels measured, and what is kept across points.
class AccuracyRun {
 public:
  AccuracyRun(const Model& model, const Derivation& derivation, const KernelSet& kernels, const std::vector<double>& p,
              const AccuracySettings& settings, const std::string& label);
  std::vector<KernelAccuracy> run();

 private:
  struct Measured {
    const Kernel* kernel;
    const KernelReferences::Entry* ref;
    GraphEvaluator fast;
    HighPrecisionGraphEvaluator slow;
    std::size_t result;  ///< index into `result_`
  };
  // A kernel's errors at one point.
  struct Errors {
    std::size_t m = 0;  ///< position in `measured_` (and `first_`)
    std::vector<numeric> ref, graph50;
    std::vector<double> computed, ulps, evaluation;
    double floor = 0;
    std::vector<double> scale;  ///< max(|ref|, floor): κ's denominators
  };
  struct Candidate {  ///< a kernel's eval-only errors at a point, for eval/cond
    int point;
    Point pt;
    std::vector<double> evaluation, scale;
    double largest = 0;  ///< of evaluation: eval/cond ≤ eval-only (κ ≥ 0)
  };
  struct WorstPoint {
    bool set = false;
    Point pt;
    std::size_t output = 0;
    double scale = 0;
  };

  Point sample();
  std::vector<Errors> errors_at(const Point& pt);
  void record(int point, const Point& pt, const Errors& e);
  std::vector<double> condition_numbers(Measured& km, const Point& pt, const std::vector<double>& scale,
                                        const std::function<bool(const std::vector<double>&)>& done);
  void deferred_condition_numbers();

  const Model& model_;
  const HamelEquations& eq_;
  const HamelSystem& sys_;
  const std::vector<double>& p_;
  const AccuracySettings& settings_;
  const std::string& label_;
  const KernelReferences refs_;
  const std::size_t n_, d_, nx_;
  std::vector<std::string> state_names_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{-1.0, 1.0};
  std::vector<Measured> measured_;
  std::vector<KernelAccuracy> result_;
  // The 50-digit graph of every measured kernel at once: kernels share most of their nodes (the jacobian holds the
  // rhs), so one evaluation per point serves all; `first_` is each kernel's first output.
  std::vector<std::size_t> first_;
  std::unique_ptr<HighPrecisionGraphEvaluator> joint_;
  HighPrecisionExpressionEvaluator exact_;
  DigitsGuard digits_;
  numeric step_;
  std::vector<numeric> P_;
  // Unless settings.condition_at_every_point, κ is formed after all points, and only where it can change what is
  // reported: at each kernel's worst error, and for eval/cond at the points whose eval-only errors could beat the
  // largest eval/cond (deferred_condition_numbers).
  bool deferred_;
  std::vector<std::vector<Candidate>> candidates_;
  std::vector<WorstPoint> worst_at_;
};

AccuracyRun::AccuracyRun(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                         const std::vector<double>& p, const AccuracySettings& settings, const std::string& label)
    : model_(model),
      eq_(derivation.equations),
      sys_(derivation.system),
      p_(p),
      settings_(settings),
      label_(label),
      refs_([&] {
        progress::Step step("forming the 50-digit references of " + model.name + " (the jacobian's by the chain rule)");
        return kernel_references(model, derivation);
      }()),
      n_(refs_.n),
      d_(refs_.d),
      nx_(refs_.nx),
      rng_(settings.seed),
      exact_(settings.digits),
      digits_(settings.digits),
      deferred_(settings.condition && !settings.condition_at_every_point) {
  if (p.size() != model.parameters.size()) throw std::logic_error("measure_kernel_accuracy: wrong parameter count");

  // State and input names, for pinned values and reports.
  for (const auto& q : sys_.coordinates) state_names_.push_back(q.get_name());
  for (int I : eq_.independent) state_names_.push_back(sys_.velocities[static_cast<std::size_t>(I)].get_name());
  for (const auto& [name, v] : settings.fixed) {
    bool known = name == "t";
    for (const auto& s : state_names_) known = known || s == name;
    for (const auto& u : model.inputs) known = known || u.get_name() == name;
    if (!known) throw std::invalid_argument("'" + name + "' is not a state variable, input or t of the model");
    (void)v;
  }

  for (const Kernel& k : kernels.kernels) {
    KernelAccuracy a;
    a.kernel = k.name;
    a.outputs = k.outputs.size();
    auto it = refs_.kernels.find(k.name);
    if (it == refs_.kernels.end()) {  // a kernel this module does not know yet: reported, not measured
      a.has_reference = false;
      result_.push_back(a);
      continue;
    }
    const std::size_t want = it->second.kind == KernelReferences::Kind::direct ? it->second.expressions.size()
                             : it->second.kind == KernelReferences::Kind::rhs  ? n_ + d_
                                                                               : nx_ * nx_;
    if (want != k.outputs.size())
      throw std::logic_error("kernel accuracy: reference of " + k.name + " has " + std::to_string(want) +
                             " entries, the kernel " + std::to_string(k.outputs.size()));
    measured_.push_back({&k, &it->second, GraphEvaluator(kernels.graph, k.outputs),
                         HighPrecisionGraphEvaluator(kernels.graph, k.outputs, settings.digits), result_.size()});
    result_.push_back(a);
  }
  std::vector<int> all_outputs;
  for (const Measured& km : measured_) {
    first_.push_back(all_outputs.size());
    all_outputs.insert(all_outputs.end(), km.kernel->outputs.begin(), km.kernel->outputs.end());
  }
  joint_ = std::make_unique<HighPrecisionGraphEvaluator>(kernels.graph, all_outputs, settings.digits);
  exact_.define(refs_.intermediates);
  step_ = GiNaC::pow(numeric(10), numeric(-(settings.digits / 2)));
  for (double v : p) P_.push_back(high_precision(v));
  candidates_.resize(measured_.size());
  worst_at_.resize(measured_.size());
}

Point AccuracyRun::sample() {
  Point pt;
  pt.t = 0.5 * (1 + unit_(rng_));
  pt.x.resize(nx_);
  for (std::size_t k = 0; k < nx_; ++k)
    pt.x[k] = unit_(rng_) * (k < n_ ? settings_.coordinate_range : settings_.velocity_range);
  pt.in.resize(model_.inputs.size());
  for (double& v : pt.in) v = unit_(rng_) * settings_.velocity_range;
  for (std::size_t k = 0; k < nx_; ++k)
    if (auto it = settings_.fixed.find(state_names_[k]); it != settings_.fixed.end()) pt.x[k] = it->second;
  for (std::size_t k = 0; k < model_.inputs.size(); ++k)
    if (auto it = settings_.fixed.find(model_.inputs[k].get_name()); it != settings_.fixed.end()) pt.in[k] = it->second;
  if (auto it = settings_.fixed.find("t"); it != settings_.fixed.end()) pt.t = it->second;
  return pt;
}

std::vector<AccuracyRun::Errors> AccuracyRun::errors_at(const Point& pt) {
  const std::size_t n = n_, d = d_, nx = nx_;
  std::map<ex, numeric, GiNaC::ex_is_less> values;
  values[model_.time] = exact_rational(pt.t);
  for (std::size_t a = 0; a < n; ++a) values[sys_.coordinates[a]] = exact_rational(pt.x[a]);
  for (std::size_t i = 0; i < d; ++i)
    values[sys_.velocities[static_cast<std::size_t>(eq_.independent[i])]] = exact_rational(pt.x[n + i]);
  for (int alpha : sys_.constrained) values[sys_.velocities[static_cast<std::size_t>(alpha)]] = 0;
  for (std::size_t k = 0; k < model_.parameters.size(); ++k)
    values[model_.parameters[k].symbol] = exact_rational(p_[k]);
  for (std::size_t k = 0; k < model_.inputs.size(); ++k) values[model_.inputs[k]] = exact_rational(pt.in[k]);
  exact_.assign(values);
  const double* in = pt.in.empty() ? nullptr : pt.in.data();
  const HighPrecisionPoint hp(pt);

  // The accelerations in 50 digits, shared by rhs and jacobian.
  std::vector<numeric> accel;
  std::vector<std::vector<numeric>> M(d, std::vector<numeric>(d));
  const auto accelerations = [&]() -> const std::vector<numeric>& {
    if (accel.empty() && d > 0) {
      std::vector<numeric> f(d);
      for (std::size_t i = 0; i < d; ++i) {
        f[i] = exact_.value(refs_.forcing[i]);
        for (std::size_t j = 0; j < d; ++j) M[i][j] = exact_.value(refs_.mass[i][j]);
      }
      accel = solve(M, f);
    }
    return accel;
  };

  // The joint graph's outputs at the point. A pole anywhere in it: every kernel on its own (below).
  std::vector<numeric> joint_base;
  try {
    joint_base = joint_->evaluate(hp.t, hp.x, P_, hp.in);
  } catch (const std::exception&) {
    joint_base.clear();
  }

  std::vector<Errors> errors;
  for (std::size_t m = 0; m < measured_.size(); ++m) {
    Measured& km = measured_[m];
    KernelAccuracy& acc = result_[km.result];
    const std::size_t outputs = km.kernel->outputs.size();
    if (outputs == 0) continue;
    std::vector<numeric> ref(outputs);
    try {
      switch (km.ref->kind) {
        case KernelReferences::Kind::direct:
          for (std::size_t i = 0; i < outputs; ++i) ref[i] = exact_.value(km.ref->expressions[i]);
          break;
        case KernelReferences::Kind::rhs: {
          for (std::size_t a = 0; a < n; ++a) ref[a] = exact_.value(refs_.kinematics[a]);
          const std::vector<numeric>& u = accelerations();
          for (std::size_t i = 0; i < d; ++i) ref[n + i] = u[i];
          break;
        }
        case KernelReferences::Kind::jacobian: {
          const std::vector<numeric>& u = accelerations();
          for (std::size_t k = 0; k < nx; ++k) {
            for (std::size_t a = 0; a < n; ++a) ref[a * nx + k] = exact_.value(refs_.kinematics_by_x[k][a]);
            std::vector<numeric> b(d);
            for (std::size_t i = 0; i < d; ++i) {
              b[i] = exact_.value(refs_.forcing_by_x[k][i]);
              for (std::size_t j = 0; j < d; ++j) b[i] -= exact_.value(refs_.mass_by_x[k][i][j]) * u[j];
            }
            const std::vector<numeric> du = d > 0 ? solve(M, b) : std::vector<numeric>{};
            for (std::size_t i = 0; i < d; ++i) ref[(n + i) * nx + k] = du[i];
          }
          break;
        }
      }
    } catch (const std::domain_error&) {
      ++acc.skipped;
      continue;
    } catch (const std::runtime_error&) {  // CLN: division by an inexact zero
      ++acc.skipped;
      continue;
    }
    Errors e;
    e.m = m;
    e.ref = std::move(ref);
    e.computed.resize(outputs);
    km.fast.evaluate(pt.t, pt.x.data(), p_.data(), in, e.computed.data());
    // This kernel's 50-digit graph values (empty where that fails).
    if (!joint_base.empty()) {
      const auto begin = joint_base.begin() + static_cast<std::ptrdiff_t>(first_[m]);
      e.graph50.assign(begin, begin + static_cast<std::ptrdiff_t>(outputs));
    } else {
      try {
        e.graph50 = km.slow.evaluate(hp.t, hp.x, P_, hp.in);
      } catch (const std::exception&) {
        e.graph50.clear();
      }
    }

    double scale = 0;
    bool zero_kernel = false;
    for (const numeric& r : e.ref) scale = std::max(scale, GiNaC::abs(r).to_double());
    if (km.ref->kind == KernelReferences::Kind::direct) {
      // A kernel that is zero here (the constraint residual is zero everywhere): its reference is 50-digit
      // noise, and the scale is the size of the terms that cancel.
      double terms = 0;
      for (std::size_t i = 0; i < outputs; ++i)
        terms = std::max(terms, exact_.magnitude(km.ref->expressions[i]).to_double());
      if (scale <= 1e-30 * terms) zero_kernel = true, scale = terms;
    }
    e.floor = zero_kernel ? scale : settings_.floor_fraction * scale;
    for (std::size_t i = 0; i < outputs; ++i) {
      const double ulps = ulp_error(e.computed[i], e.ref[i], e.floor);
      e.ulps.push_back(ulps);
      if (!e.graph50.empty()) e.evaluation.push_back(ulp_error(e.computed[i], e.graph50[i], e.floor));
      e.scale.push_back(std::max(GiNaC::abs(e.ref[i]).to_double(), e.floor));
    }
    errors.push_back(std::move(e));
  }
  return errors;
}

void AccuracyRun::record(int point, const Point& pt, const Errors& e) {
  Measured& km = measured_[e.m];
  KernelAccuracy& acc = result_[km.result];
  const std::size_t outputs = e.ref.size();
  // κ at every point (for the test of the deferred κ below): all arguments moved.
  std::vector<double> condition;
  if (settings_.condition && !deferred_ && !e.graph50.empty())
    condition = condition_numbers(km, pt, e.scale, [](const auto&) { return false; });
  if (condition.empty()) condition.assign(outputs, 0.0);

  ++acc.points;
  for (std::size_t i = 0; i < outputs; ++i) {
    const double ulps = e.ulps[i];
    ++acc.values;
    acc.sum_ulps += ulps;
    if (ulps > acc.worst_ulps || (std::isinf(ulps) && !std::isinf(acc.worst_ulps))) {
      acc.worst_ulps = ulps;
      acc.worst_output = km.kernel->output_names[i];
      acc.worst_setting = label_;
      acc.worst_time = pt.t;
      acc.worst_state = pt.x;
      acc.worst_double = e.computed[i];
      acc.worst_reference = e.ref[i].to_double();
      acc.condition_at_worst = condition[i];  // 0 here when deferred (below)
      worst_at_[e.m] = {true, pt, i, e.scale[i]};
    }
    if (!e.graph50.empty()) {
      const double ev = e.evaluation[i];
      acc.worst_evaluation_ulps = std::max(acc.worst_evaluation_ulps, ev);
      const double excess = ev / std::max(1.0, condition[i]);
      if (settings_.condition && !deferred_ && excess > acc.worst_excess) {
        acc.worst_excess = excess;
        acc.worst_excess_output = km.kernel->output_names[i];
      }
    }
  }
  if (deferred_ && !e.graph50.empty()) {
    Candidate c{point, pt, e.evaluation, e.scale, 0};
    for (double ev : e.evaluation) c.largest = std::max(c.largest, ev);
    candidates_[e.m].push_back(std::move(c));
  }
}

// κ_i = Σ_k |∂f_i/∂a_k| |a_k| / max(|f_i|, floor) over the arguments a = (t, x, in; the nonzero ones), by forward
// differences of the kernel's own 50-digit graph (the same operations as the joint graph's, so the same values)
// with relative steps of 1e-25 (exact to about 20 digits), one moved argument at a time until done(κ so far), a
// lower bound of κ, says enough; empty at a pole.
std::vector<double> AccuracyRun::condition_numbers(Measured& km, const Point& pt, const std::vector<double>& scale,
                                                   const std::function<bool(const std::vector<double>&)>& done) {
  const HighPrecisionPoint hp(pt);
  std::vector<numeric> base;
  try {
    base = km.slow.evaluate(hp.t, hp.x, P_, hp.in);
  } catch (const std::exception&) {
    return {};
  }
  struct Move {
    Argument argument;
    int index;
    numeric value;
  };
  std::vector<Move> moves;
  if (!hp.t.is_zero()) moves.push_back({Argument::time, 0, hp.t});
  for (std::size_t k = 0; k < hp.x.size(); ++k)
    if (!hp.x[k].is_zero()) moves.push_back({Argument::state, static_cast<int>(k), hp.x[k]});
  for (std::size_t k = 0; k < hp.in.size(); ++k)
    if (!hp.in[k].is_zero()) moves.push_back({Argument::input, static_cast<int>(k), hp.in[k]});
  std::vector<numeric> sensitivity(base.size(), numeric(0));
  std::vector<double> kappa(base.size(), 0.0);
  for (const Move& mv : moves) {
    const numeric h = GiNaC::abs(mv.value) * step_;
    std::vector<numeric> moved;
    try {
      moved = km.slow.evaluate_moved(mv.argument, mv.index, mv.value + h);
    } catch (const std::exception&) {
      moved.clear();
    }
    for (std::size_t i = 0; i < moved.size(); ++i) {
      sensitivity[i] += GiNaC::abs(moved[i] - base[i]) / h * GiNaC::abs(mv.value);
      kappa[i] = sensitivity[i].to_double() / scale[i];
    }
    if (done(kappa)) break;
  }
  return kappa;
}

// After all points: κ at each kernel's worst error, in full, and eval/cond = max over the values of eval-only /
// max(1, κ). Since κ ≥ 0, a point's eval-only errors bound what it can give: the points are taken largest bound
// first, each only until its partial κ shows it cannot beat the largest so far, and none once the bound is below
// it. Ties go to the earlier point and output, as in point order. The same table as κ at every point.
void AccuracyRun::deferred_condition_numbers() {
  for (std::size_t m = 0; m < measured_.size(); ++m) {
    KernelAccuracy& acc = result_[measured_[m].result];
    const WorstPoint& w = worst_at_[m];
    if (w.set) {
      std::vector<double> scale(measured_[m].kernel->outputs.size(), 1.0);
      scale[w.output] = w.scale;
      const std::vector<double> kappa = condition_numbers(measured_[m], w.pt, scale, [](const auto&) { return false; });
      acc.condition_at_worst = kappa.empty() ? 0.0 : kappa[w.output];
    }
    std::vector<Candidate>& list = candidates_[m];
    std::stable_sort(list.begin(), list.end(),
                     [](const Candidate& a, const Candidate& b) { return a.largest > b.largest; });
    double best = 0;
    std::pair<int, std::size_t> best_at{-1, 0};  // (point, output); -1: none yet
    const auto beats = [&](double excess, int point, std::size_t i) {
      return excess > best || (excess == best && best_at.first >= 0 && std::make_pair(point, i) < best_at);
    };
    for (const Candidate& c : list) {
      if (c.largest < best) break;
      const auto excesses = [&](const std::vector<double>& kappa, auto&& visit) {
        for (std::size_t i = 0; i < c.evaluation.size(); ++i) visit(c.evaluation[i] / std::max(1.0, kappa[i]), i);
      };
      const std::vector<double> kappa = condition_numbers(measured_[m], c.pt, c.scale, [&](const auto& partial) {
        bool open = false;
        excesses(partial, [&](double excess, std::size_t i) { open = open || beats(excess, c.point, i); });
        return !open;
      });
      if (kappa.empty()) continue;
      excesses(kappa, [&](double excess, std::size_t i) {
        if (beats(excess, c.point, i)) best = excess, best_at = {c.point, i};
      });
    }
    acc.worst_excess = best;
    acc.worst_excess_output = best_at.first >= 0 ? measured_[m].kernel->output_names[best_at.second] : "";
  }
}

std::vector<KernelAccuracy> AccuracyRun::run() {
  progress::Step evaluating("evaluating " + std::to_string(measured_.size()) + " kernels of " + model_.name + " at " +
                            std::to_string(settings_.points) + " points in " + std::to_string(settings_.digits) +
                            " digits" + (label_.empty() || label_ == "base" ? "" : " (" + label_ + ")"));
  for (int point = 0; point < settings_.points; ++point) {
    evaluating.detail("point " + std::to_string(point + 1) + " of " + std::to_string(settings_.points));
    const Point pt = sample();
    for (const Errors& e : errors_at(pt)) record(point, pt, e);
  }
  if (deferred_) {
    evaluating.detail("condition numbers");
    deferred_condition_numbers();
  }
  return result_;
}

}  // namespace

std::vector<KernelAccuracy> measure_kernel_accuracy(const Model& model, const Derivation& derivation,
                                                    const KernelSet& kernels, const std::vector<double>& p,
                                                    const AccuracySettings& settings, const std::string& label) {
  return AccuracyRun(model, derivation, kernels, p, settings, label).run();
}

void merge_accuracy(std::vector<KernelAccuracy>& into, const std::vector<KernelAccuracy>& more) {
  for (const KernelAccuracy& m : more) {
    auto it = std::find_if(into.begin(), into.end(), [&](const KernelAccuracy& a) { return a.kernel == m.kernel; });
    if (it == into.end()) {
      into.push_back(m);
      continue;
    }
    KernelAccuracy& a = *it;
    a.points += m.points;
    a.skipped += m.skipped;
    a.values += m.values;
    a.sum_ulps += m.sum_ulps;
    a.worst_evaluation_ulps = std::max(a.worst_evaluation_ulps, m.worst_evaluation_ulps);
    if (m.worst_excess > a.worst_excess) {
      a.worst_excess = m.worst_excess;
      a.worst_excess_output = m.worst_excess_output;
    }
    if (m.worst_ulps > a.worst_ulps) {
      a.worst_ulps = m.worst_ulps;
      a.worst_output = m.worst_output;
      a.worst_setting = m.worst_setting;
      a.worst_time = m.worst_time;
      a.worst_state = m.worst_state;
      a.worst_double = m.worst_double;
      a.worst_reference = m.worst_reference;
      a.condition_at_worst = m.condition_at_worst;
    }
  }
}

}  // namespace hamel
