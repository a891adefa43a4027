// A model from models/ with its parameters folded (defaults, overridden by name), derived, its kernels built
// and evaluated by GraphEvaluator (what `hamel simulate` integrates), and integrated by name through
// hamel::integrate. Shared by the stiff and extreme scene tests.
#pragma once

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/fold_parameters.hpp"
#include "model/load_model.hpp"
#include "numeric/graph_evaluator.hpp"
#include "numeric/integrators.hpp"
#include "support/command.hpp"

#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hamel::test {

using hamel::test::source_dir;

/// The integrators every scene runs with: fixed-step RK4, the two adaptive explicit ones and the implicit one.
inline const std::vector<std::string>& scene_integrators() {
  static const std::vector<std::string> names{"rk4", "dopri5", "dop853", "radau5"};
  return names;
}

class SceneModel {
 public:
  explicit SceneModel(const std::string& file, const std::map<std::string, double>& parameters = {})
      : model_(load_model(source_dir() + "/models/" + file)) {
    std::map<std::string, double> all;
    for (const auto& q : model_.parameters) {
      auto it = parameters.find(q.symbol.get_name());
      all[q.symbol.get_name()] = it == parameters.end() ? q.default_value : it->second;
      p_.push_back(all[q.symbol.get_name()]);
    }
    if (all.size() != model_.parameters.size() || parameters.size() > all.size())
      throw std::invalid_argument("unknown parameter for " + file);
    derivation_ = derive(fold_parameters(model_, all));
    in_.assign(model_.inputs.size(), 0.0);  // inputs stay zero: the scenes are free motions
    kernels_ = build_kernels(model_, derivation_);
    for (const auto& q : derivation_.system.coordinates) names_.push_back(q.get_name());
    for (int I : derivation_.equations.independent)
      names_.push_back(derivation_.system.velocities[static_cast<std::size_t>(I)].get_name());
    rhs_ = std::make_unique<GraphEvaluator>(kernels_.graph, kernels_.get("rhs").outputs);
    jacobian_ = std::make_unique<GraphEvaluator>(kernels_.graph, kernels_.get("jacobian").outputs);
    energy_ = std::make_unique<GraphEvaluator>(kernels_.graph, kernels_.get("energy").outputs);
  }
  SceneModel(const SceneModel&) = delete;
  SceneModel& operator=(const SceneModel&) = delete;

  std::size_t size() const { return names_.size(); }
  std::size_t index(const std::string& name) const {
    for (std::size_t k = 0; k < names_.size(); ++k)
      if (names_[k] == name) return k;
    throw std::invalid_argument("no state variable " + name);
  }
  /// A state with the named entries set and the others zero.
  std::vector<double> state(const std::map<std::string, double>& values) const {
    std::vector<double> x(size(), 0.0);
    for (const auto& [name, v] : values) x[index(name)] = v;
    return x;
  }

  void rhs(double t, const double* x, double* dx) { rhs_->evaluate(t, x, p_.data(), inputs(), dx); }
  void jacobian(double t, const double* x, double* J) { jacobian_->evaluate(t, x, p_.data(), inputs(), J); }
  double energy(const double* x) {
    double e = 0;
    energy_->evaluate(0, x, p_.data(), inputs(), &e);
    return e;
  }
  /// The constraint residual kernel (A^alpha_a(q) q_dot^a along the kinematics); empty without constraints.
  std::vector<double> constraint_residual(const double* x) {
    const auto& outputs = kernels_.get("constraint_residual").outputs;
    if (!residual_) residual_ = std::make_unique<GraphEvaluator>(kernels_.graph, outputs);
    std::vector<double> r(outputs.size());
    residual_->evaluate(0, x, p_.data(), inputs(), r.data());
    return r;
  }

  /// Integrates from t = 0 with `integrator` at `setting` (tolerance or step), observing every `sample`
  /// (0: every step).
  runtime::IntegrationResult run(const std::string& integrator, double setting, const std::vector<double>& x0,
                                 double t_end, double sample, const ObserveFunction& observe) {
    return integrate(
        integrator, setting, [this](double t, const double* x, double* dx) { rhs(t, x, dx); },
        [this](double t, const double* x, double* J) { jacobian(t, x, J); }, x0, 0.0, t_end, sample, observe);
  }

  /// The spectral radius of the emitted Jacobian at x, by power iteration on J² (whose dominant eigenvalues
  /// are real, −ω², for the oscillations ±iω of a mechanical system).
  double spectral_radius(const std::vector<double>& x) {
    const std::size_t n = size();
    std::vector<double> J(n * n), v(n), w(n), u(n);
    jacobian(0, x.data(), J.data());
    for (std::size_t i = 0; i < n; ++i) v[i] = 1.0 + 0.1 * static_cast<double>(i);
    const auto apply = [&](const std::vector<double>& a, std::vector<double>& b) {
      for (std::size_t i = 0; i < n; ++i) {
        b[i] = 0;
        for (std::size_t j = 0; j < n; ++j) b[i] += J[i * n + j] * a[j];
      }
    };
    const auto norm = [](const std::vector<double>& a) {
      double s = 0;
      for (double e : a) s += e * e;
      return std::sqrt(s);
    };
    double rho2 = 0;
    for (int iteration = 0; iteration < 60; ++iteration) {
      apply(v, u);
      apply(u, w);
      const double nv = norm(v), nw = norm(w);
      if (!(nw > 0)) break;
      rho2 = nw / nv;
      for (std::size_t i = 0; i < n; ++i) v[i] = w[i] / nw;
    }
    return std::sqrt(rho2);
  }

  /// A fixed RK4 step for a run from x0 to t_end: `fraction` / ρ with the largest spectral radius of the
  /// Jacobian at every step of a dop853 run (RK4 is stable up to |h λ| = 2.8 on the imaginary axis), at most `cap`.
  double stable_rk4_step(const std::vector<double>& x0, double t_end, double cap, double fraction = 0.5) {
    double rho = spectral_radius(x0);
    run("dop853", 1e-10, x0, t_end, 0.0,
        [&](double, const double* x) { rho = std::max(rho, spectral_radius(std::vector<double>(x, x + size()))); });
    return rho > 0 ? std::min(cap, fraction / rho) : cap;
  }

  const Derivation& derivation() const { return derivation_; }

 private:
  Model model_;
  const double* inputs() const { return in_.empty() ? nullptr : in_.data(); }

  std::vector<double> p_, in_;
  Derivation derivation_;
  KernelSet kernels_;
  std::vector<std::string> names_;
  std::unique_ptr<GraphEvaluator> rhs_, jacobian_, energy_, residual_;
};

inline bool finite(const std::vector<double>& x) {
  for (double v : x)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace hamel::test
