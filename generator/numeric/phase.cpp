#include "numeric/phase.hpp"

#include "emit/expression_graph.hpp"
#include "emit/kernels.hpp"
#include "model/input_error.hpp"
#include "numeric/connection_field.hpp"
#include "numeric/graph_evaluator.hpp"

#include <hamel/runtime/ldlt.hpp>
#include <hamel/runtime/lie/rkmk.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

namespace hamel {

namespace lie = runtime::lie;

namespace {

// Numeric evaluation of A(r), L(r) (ConnectionField) along the path r(t), ṙ(t) (an expression graph of its own).
class BundleFunctions {
 public:
  BundleFunctions(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                  const std::vector<GiNaC::ex>& path)
      : field_(model, d, parameters), p_(parameters) {
    std::map<GiNaC::ex, int, GiNaC::ex_is_less> leaves;
    leaves[model.time] = graph_.input(Argument::time, 0);
    for (std::size_t k = 0; k < model.parameters.size(); ++k)
      leaves[model.parameters[k].symbol] = graph_.input(Argument::parameter, static_cast<int>(k));
    std::vector<int> curve;
    for (const auto& r : path) curve.push_back(graph_.from_expression(r, leaves));
    for (const auto& r : path) curve.push_back(graph_.from_expression(r.diff(model.time), leaves));
    curve_ = std::make_unique<GraphEvaluator>(graph_, curve);
    x_.resize(2 * field_.n());
  }

  bool has_locked_inertia() const { return field_.has_locked_inertia(); }

  /// Evaluates at time t with the shape on the path, or frozen at the path's r(0) with ṙ = 0.
  void at(double t, bool frozen) {
    curve_->evaluate(frozen ? 0.0 : t, nullptr, p_.data(), nullptr, x_.data());
    if (frozen)
      for (unsigned I = 0; I < n(); ++I) x_[n() + I] = 0;
    field_.evaluate(x_.data());
  }
  double A(unsigned a, unsigned I) const { return field_.A(a, I); }
  double L(unsigned a, unsigned b) const { return field_.L(a, b); }
  double r_dot(unsigned I) const { return x_[n() + I]; }
  unsigned m() const { return field_.m(); }
  unsigned n() const { return field_.n(); }

 private:
  ConnectionField field_;
  std::vector<double> p_;
  ExpressionGraph graph_;
  std::unique_ptr<GraphEvaluator> curve_;
  std::vector<double> x_;
};

template <class G>
PhaseResult run(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                const PhaseRequest& req) {
  constexpr std::size_t m = G::dim;
  BundleFunctions f(model, d, parameters, req.path);
  const bool right = model.bundle->right;
  const lie::Trivialization side = right ? lie::Trivialization::right : lie::Trivialization::left;
  const bool with_momentum = req.momentum == PhaseMomentum::rest;
  if (with_momentum && !(model.bundle->mechanical && f.has_locked_inertia()))
    throw InputError("--momentum rest: needs a mechanical connection (the momentum Pi = L xi + K r_dot)");

  // μ: the conserved momentum. At rest (ξ = 0) at g = identity, Π⁰ = K ṙ(0) = L A ṙ(0), and μ = Π⁰.
  std::array<double, m> mu{};
  if (with_momentum) {
    f.at(0.0, false);
    for (unsigned a = 0; a < m; ++a)
      for (unsigned b = 0; b < m; ++b)
        for (unsigned I = 0; I < f.n(); ++I) mu[a] += f.L(a, b) * f.A(b, I) * f.r_dot(I);
  }

  // ξ(t, g): −A ṙ, plus L⁻¹ Π(g) with Π = Ad_gᵀ μ (left) or Ad_{g⁻¹}ᵀ μ (right).
  auto velocity = [&](bool frozen) {
    return [&, frozen](double t, const typename G::Element& g, double* xi) {
      f.at(t, frozen);
      for (unsigned a = 0; a < m; ++a) {
        xi[a] = 0;
        for (unsigned I = 0; I < f.n(); ++I) xi[a] -= f.A(a, I) * f.r_dot(I);
      }
      if (!with_momentum) return;
      const typename G::Matrix Ad = G::Ad(right ? G::inverse(g) : g);
      std::array<double, m * m> L;
      std::array<double, m> pi{};
      for (std::size_t a = 0; a < m; ++a) {
        for (std::size_t b = 0; b < m; ++b) {
          L[a * m + b] = f.L(static_cast<unsigned>(a), static_cast<unsigned>(b));
          pi[a] += Ad[b * m + a] * mu[b];
        }
      }
      if (runtime::ldlt_solve(L, pi) != runtime::Status::ok) {
        for (std::size_t a = 0; a < m; ++a) xi[a] = std::nan("");
        return;
      }
      for (std::size_t a = 0; a < m; ++a) xi[a] += pi[a];
    };
  };

  PhaseResult out;
  out.group = model.bundle->group;
  const double h = req.period / req.steps_per_cycle;
  const double sample = req.period / req.samples_per_cycle;
  auto integrate = [&](bool frozen, std::vector<GroupPose>* trajectory, std::vector<GroupPose>& ends) {
    typename G::Element g = G::identity();
    if (trajectory) trajectory->push_back(pose_of(0.0, g));
    for (int k = 1; k <= req.cycles; ++k) {
      const double t0 = (k - 1) * req.period, t1 = k * req.period;
      auto observe = [&](double t, const typename G::Element& e) {
        if (trajectory && t > t0) trajectory->push_back(pose_of(t, e));
      };
      const auto result = lie::integrate_rkmk4<G>(side, velocity(frozen), g, t0, t1, h, sample, observe);
      out.steps += result.stats.steps;
      if (result.status != runtime::Status::ok)
        throw InputError("phase: the reconstruction failed at t = " + std::to_string(result.t) + ": " +
                         std::string(runtime::describe(result.status)) +
                         " (is the locked inertia singular on the path, or the path not finite?)");
      g = result.g;
      ends.push_back(pose_of(t1, g));
    }
  };
  integrate(false, &out.trajectory, out.cycles);
  if (with_momentum) integrate(true, &out.dynamic_trajectory, out.dynamic);
  return out;
}

}  // namespace

void check_conserved_momentum(const Model& model, const std::string& verb) {
  // The phase rests on the conserved momentum of a symmetric system; gravity and applied wrenches change it.
  const bool gravity = model.bundle->tree && model.bundle->tree->has_gravity();
  if (gravity || !model.wrenches.empty()) {
    const std::string key = gravity ? "tree.gravity" : "wrenches";
    const auto where = model.locations.find(gravity ? "tree.gravity" : "wrenches");
    throw InputError(where != model.locations.end() ? where->second : SourceLocation{model.source_path, 0, 0}, key,
                     std::string(gravity ? "gravity breaks" : "applied wrenches break") +
                         " the symmetry of the floating base: its momentum is not conserved, so shape changes "
                         "do not determine its motion (the geometric phase); expected a model without them for " +
                         verb + ", or 'hamel simulate' for the motion under them");
  }
  if (model.bundle->nonholonomic) {
    // With constraints that leave group directions free, the momentum p along them is not conserved: it follows
    // the momentum equation, driven by the shape's velocity, so the group motion is not −A r_dot alone.
    const auto where = model.locations.find("constraints");
    throw InputError(where != model.locations.end() ? where->second : SourceLocation{model.source_path, 0, 0},
                     "constraints",
                     "the nonholonomic momentum along the free group directions is not conserved (it follows the "
                     "momentum equation), so a shape path alone does not give the motion; expected, instead of " +
                         verb +
                         ", 'hamel simulate' "
                         "with the shape driven by the inputs, or a model whose constraints fix the group velocity "
                         "(a kinematic connection)");
  }
}

void check_phase_request(const Model& model, const PhaseRequest& req) {
  if (!model.bundle) throw InputError("phase: '" + model.source_path + "' is not a bundle model");
  check_conserved_momentum(model, "'hamel phase'");
  if (req.path.size() != model.coordinates.size())
    throw InputError("--path: expected " + std::to_string(model.coordinates.size()) +
                     " expressions separated by ';' (one per shape coordinate of " + model.name + "), got " +
                     std::to_string(req.path.size()));
  if (!(req.period > 0) || !std::isfinite(req.period)) throw InputError("--period: expected a positive time");
  if (req.cycles < 1) throw InputError("--cycles: expected at least 1");
  if (req.steps_per_cycle < 1) throw InputError("--steps-per-cycle: expected at least 1");
  // 0 or a negative number of samples made the sampling interval infinite or negative, and every step was written.
  if (req.samples_per_cycle < 1) throw InputError("--samples-per-cycle: expected at least 1");
  // The limits of simulate (docs/errors.md, "Limits"): --cycles 1000000000 ran without bound.
  const double steps = static_cast<double>(req.cycles) * req.steps_per_cycle;
  const double rows = static_cast<double>(req.cycles) * std::min(req.samples_per_cycle, req.steps_per_cycle);
  const auto count = [](double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  };
  if (steps > 1e8)
    throw InputError("--cycles: " + std::to_string(req.cycles) + " cycles of " + std::to_string(req.steps_per_cycle) +
                     " steps are " + count(steps) +
                     " RKMK4 steps, more than the limit of 1e+08; expected fewer --cycles or --steps-per-cycle");
  if (rows > 1e7)
    throw InputError("--cycles: " + std::to_string(req.cycles) + " cycles of " + std::to_string(req.samples_per_cycle) +
                     " samples are " + count(rows) +
                     " trajectory rows, more than the limit of 1e+07; expected fewer --cycles or --samples-per-cycle");
}

const char* phase_form(const Model& model) {
  return model.bundle->tree ? "ep" : model.bundle->mechanical ? "momentum" : "ldap";
}

PhaseResult compute_phase(const Model& model, const Derivation& d, const std::vector<double>& parameters,
                          const PhaseRequest& req) {
  check_phase_request(model, req);
  if (!d.bundle) throw InputError("phase: '" + model.source_path + "' is not a bundle model");
  return with_group(model.bundle->group,
                    [&](auto tag) { return run<typename decltype(tag)::type>(model, d, parameters, req); });
}

}  // namespace hamel
