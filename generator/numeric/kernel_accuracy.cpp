#include "numeric/kernel_accuracy.hpp"

#include "algebra/operations.hpp"
#include "numeric/graph_evaluator.hpp"
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

GiNaC::numeric exact_rational(double v) {
  if (!std::isfinite(v)) throw std::domain_error("exact_rational: not a finite number");
  if (v == 0) return 0;
  int e = 0;
  const double m = std::frexp(v, &e);  // v = m 2^e, 0.5 ≤ |m| < 1
  const auto mantissa = static_cast<long>(std::ldexp(m, 53));
  return numeric(mantissa) * GiNaC::pow(numeric(2), numeric(e - 53));
}

namespace {

numeric to_float(const numeric& v) {
  if (!v.is_rational()) return v;
  return ex_to<numeric>(v.evalf());
}

}  // namespace

GiNaC::numeric high_precision(double v) { return to_float(exact_rational(v)); }

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

numeric integer_power(const numeric& base, const numeric& exponent) {
  // CLN's expt with an integer exponent is exact repeated squaring; a negative one divides.
  if (exponent.is_negative() && base.is_zero()) throw std::domain_error("high precision: 0 to a negative power");
  return GiNaC::pow(base, exponent);
}

numeric power(const numeric& base, const numeric& exponent) {
  if (exponent.is_integer()) return integer_power(base, exponent);
  if (base.is_negative()) throw std::domain_error("high precision: negative base of a fractional power");
  if (base.is_zero()) {
    if (exponent.is_negative()) throw std::domain_error("high precision: 0 to a negative power");
    return 0;
  }
  if ((2 * exponent).is_integer()) return integer_power(GiNaC::sqrt(to_float(base)), 2 * exponent);
  return GiNaC::exp(to_float(exponent) * GiNaC::log(to_float(base)));
}

// The evaluators compute on CLN's reals (what a real GiNaC::numeric holds) with the operations GiNaC::numeric calls
// for +, −, ×, /, integer powers and abs; everything else goes through GiNaC::numeric.
cln::cl_R real_of(const numeric& v) { return cln::the<cln::cl_R>(v.to_cl_N()); }
numeric numeric_of(const cln::cl_R& v) { return numeric(cln::cl_N(v)); }

// base^exponent for an exact exponent, as GiNaC::pow of numerics gives it.
cln::cl_R power(const cln::cl_R& base, const numeric& exponent) {
  if (!exponent.is_integer()) return real_of(power(numeric_of(base), exponent));
  if (exponent.is_equal(1)) return base;
  if (cln::zerop(base)) {
    if (exponent.is_negative()) throw std::domain_error("high precision: 0 to a negative power");
    if (exponent.is_zero()) return real_of(integer_power(numeric_of(base), exponent));  // GiNaC's own error
    return 0;
  }
  return cln::expt(base, cln::the<cln::cl_I>(exponent.to_cl_N()));
}

// An elementary function of the model language (algebra/operations.hpp) in high precision.
cln::cl_R apply_function(const Function& f, const cln::cl_R& argument) {
  return real_of(f.evaluate_exactly(to_float(numeric_of(argument))));
}

cln::cl_R divide(const cln::cl_R& a, const cln::cl_R& b) {
  if (cln::zerop(b)) throw std::domain_error("high precision: division by zero");
  return a / b;
}

}  // namespace

HighPrecisionGraphEvaluator::HighPrecisionGraphEvaluator(const ExpressionGraph& graph, std::vector<int> outputs,
                                                         int digits)
    : graph_(graph),
      outputs_(std::move(outputs)),
      schedule_(graph.schedule(outputs_)),
      digits_(digits),
      values_(static_cast<std::size_t>(graph.size())) {}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate(double t, const double* x, const double* p,
                                                                  const double* in) {
  const DigitsGuard digits(digits_);
  int nx = 0, np = 0, nin = 0;
  for (int i : schedule_) {
    const Node& n = graph_.node(i);
    if (n.op != Op::input) continue;
    if (n.argument == Argument::state) nx = std::max(nx, n.index + 1);
    if (n.argument == Argument::parameter) np = std::max(np, n.index + 1);
    if (n.argument == Argument::input) nin = std::max(nin, n.index + 1);
  }
  const auto convert = [](const double* v, int count) {
    std::vector<numeric> out;
    for (int k = 0; k < count; ++k) out.push_back(high_precision(v[k]));
    return out;
  };
  return evaluate(high_precision(t), convert(x, nx), convert(p, np), convert(in, nin));
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate(const numeric& t, const std::vector<numeric>& x,
                                                                  const std::vector<numeric>& p,
                                                                  const std::vector<numeric>& in) {
  const auto reals = [](const std::vector<numeric>& v) {
    std::vector<cln::cl_R> out;
    out.reserve(v.size());
    for (const numeric& e : v) out.push_back(real_of(e));
    return out;
  };
  arguments_ = {std::vector<cln::cl_R>{real_of(t)}, reals(x), reals(p), reals(in)};
  run(schedule_, nullptr);
  return outputs();
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::evaluate_moved(Argument argument, int index,
                                                                        const numeric& value) {
  const auto key = std::make_pair(argument, index);
  auto it = dependents_.find(key);
  if (it == dependents_.end()) {
    // The scheduled nodes that depend on this argument, in schedule order (operands before users).
    std::vector<char> depends(values_.size(), 0);
    std::vector<int> list;
    for (int i : schedule_) {
      const Node& n = graph_.node(i);
      const bool d = n.op == Op::input      ? n.argument == argument && n.index == index
                     : n.op == Op::constant ? false
                                            : depends[static_cast<std::size_t>(n.a)] ||
                                                  (n.b >= 0 && depends[static_cast<std::size_t>(n.b)]);
      if (d) depends[static_cast<std::size_t>(i)] = 1, list.push_back(i);
    }
    it = dependents_.emplace(key, std::move(list)).first;
  }
  const std::vector<int>& moved = it->second;
  std::vector<cln::cl_R> saved;
  saved.reserve(moved.size());
  for (int i : moved) saved.push_back(values_[static_cast<std::size_t>(i)]);
  const auto restore = [&] {
    for (std::size_t k = 0; k < moved.size(); ++k) values_[static_cast<std::size_t>(moved[k])] = saved[k];
  };
  const cln::cl_R moved_value = real_of(value);
  const Moved change{argument, index, &moved_value};
  try {
    run(moved, &change);
  } catch (...) {
    restore();
    throw;
  }
  std::vector<numeric> out = outputs();
  restore();
  return out;
}

std::vector<GiNaC::numeric> HighPrecisionGraphEvaluator::outputs() const {
  std::vector<numeric> out;
  out.reserve(outputs_.size());
  for (int o : outputs_) out.push_back(numeric_of(values_[static_cast<std::size_t>(o)]));
  return out;
}

void HighPrecisionGraphEvaluator::run(const std::vector<int>& schedule, const Moved* moved) {
  const DigitsGuard digits(digits_);
  interpret(
      graph_, schedule, values_,
      [&](const Node& n) -> const cln::cl_R& {
        auto it = constants_.find(n.value);
        if (it == constants_.end()) it = constants_.emplace(n.value, real_of(high_precision(n.value))).first;
        return it->second;
      },
      [&](Argument argument, int index) -> const cln::cl_R& {
        if (moved && moved->argument == argument && moved->index == index) return *moved->value;
        const std::vector<cln::cl_R>& array = arguments_[static_cast<std::size_t>(argument)];
        return array.at(argument == Argument::time ? 0 : static_cast<std::size_t>(index));
      },
      [&](const Node& n, const cln::cl_R& a, const cln::cl_R& b) {
        return evaluate_in<cln::cl_R>(
            n.op, a, b, divide,
            [&](const cln::cl_R& x, const cln::cl_R& y) {
              // A constant exponent is the double the emitter prints, taken exactly (1.5: a square root cubed).
              const Node& exponent = graph_.node(n.b);
              return exponent.op == Op::constant ? power(x, exact_rational(exponent.value))
                                                 : real_of(power(numeric_of(x), numeric_of(y)));
            },
            [](Op f, const cln::cl_R& x) { return apply_function(*function_of(f), x); });
      });
}

// ---------------------------------------------------------------------------------------------------------

void HighPrecisionExpressionEvaluator::assign(const std::map<ex, numeric, GiNaC::ex_is_less>& values) {
  const DigitsGuard digits(digits_);
  values_.clear();
  for (const auto& [symbol, v] : values) values_[symbol] = real_of(to_float(v));
  ++generation_;
}

void HighPrecisionExpressionEvaluator::define(const Intermediates& intermediates) {
  for (const Intermediates::Definition& d : intermediates.definitions()) definitions_[d.symbol] = d.value;
  number_.clear();  // compiled symbols may now be intermediates
  nodes_.clear();
  ++generation_;
}

GiNaC::numeric HighPrecisionExpressionEvaluator::value(const ex& e) {
  const int node = compile(e);
  const DigitsGuard digits(digits_);
  return numeric_of(eval(node, false));
}

GiNaC::numeric HighPrecisionExpressionEvaluator::magnitude(const ex& e) {
  const int node = compile(e);
  const DigitsGuard digits(digits_);
  return numeric_of(eval(node, true));
}

int HighPrecisionExpressionEvaluator::compile(const ex& e) {
  if (auto it = number_.find(e); it != number_.end()) return it->second;
  Node node{Kind::number, {}, e, nullptr, 0};
  if (is_a<numeric>(e)) {
    if (!ex_to<numeric>(e).is_real()) throw std::logic_error("high precision: complex number in an expression");
    node.number = real_of(ex_to<numeric>(e));
  } else if (is_a<GiNaC::symbol>(e)) {
    // An intermediate is its definition's node: the size of its definition, like the graph's node.
    if (auto def = definitions_.find(e); def != definitions_.end()) {
      const int n = compile(def->second);
      number_.emplace(e, n);
      return n;
    }
    node.kind = Kind::symbol;
  } else if (is_a<GiNaC::constant>(e)) {
    node.kind = Kind::constant;
  } else if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e) || is_a<GiNaC::power>(e)) {
    node.kind = is_a<GiNaC::add>(e) ? Kind::add : is_a<GiNaC::mul>(e) ? Kind::mul : Kind::power;
    for (std::size_t i = 0; i < e.nops(); ++i) node.operands.push_back(compile(e.op(i)));
  } else if (is_a<GiNaC::function>(e)) {
    const std::string name = ex_to<GiNaC::function>(e).get_name();
    const Function* f = function_named(name);
    if (e.nops() != 1 || !f) throw std::logic_error("high precision: function '" + name + "' is not supported");
    node.kind = Kind::function;
    node.function = f;
    node.operands.push_back(compile(e.op(0)));
  } else {
    throw std::logic_error("high precision: unsupported expression type");
  }
  nodes_.push_back(std::move(node));
  const int n = static_cast<int>(nodes_.size()) - 1;
  number_.emplace(e, n);
  return n;
}

const cln::cl_R& HighPrecisionExpressionEvaluator::eval(int index, bool absolute) {
  const std::size_t k = static_cast<std::size_t>(index);
  std::vector<cln::cl_R>& computed = computed_[absolute ? 1 : 0];
  std::vector<unsigned>& stamp = stamp_[absolute ? 1 : 0];
  if (stamp.size() < nodes_.size()) stamp.resize(nodes_.size(), 0), computed.resize(nodes_.size());
  if (stamp[k] == generation_) return computed[k];
  const Node& node = nodes_[k];
  cln::cl_R v;
  switch (node.kind) {
    case Kind::number:
      v = node.number;
      break;
    case Kind::symbol: {
      const auto it = values_.find(node.expression);
      if (it == values_.end())
        throw std::logic_error("high precision: no value for symbol '" +
                               ex_to<GiNaC::symbol>(node.expression).get_name() + "'");
      v = it->second;
      break;
    }
    case Kind::constant:
      v = real_of(ex_to<numeric>(node.expression.evalf()));
      break;
    case Kind::add:
      v = 0;
      for (int o : node.operands) v = v + eval(o, absolute);
      break;
    case Kind::mul:
      v = 1;
      for (int o : node.operands) v = v * eval(o, absolute);
      break;
    case Kind::power: {
      const Node& exponent = nodes_[static_cast<std::size_t>(node.operands[1])];
      if (exponent.kind != Kind::number) {
        v = real_of(power(numeric_of(eval(node.operands[0], false)), numeric_of(eval(node.operands[1], false))));
      } else {
        const numeric& y = ex_to<numeric>(exponent.expression);
        // A divisor enters at its true value: |1/x| is not bounded by 1/magnitude(x).
        v = power(eval(node.operands[0], absolute && y.is_positive()), y);
      }
      break;
    }
    case Kind::function:
      v = apply_function(*node.function, eval(node.operands[0], false));
      break;
  }
  if (absolute) v = cln::abs(v);
  computed[k] = v;
  stamp[k] = generation_;
  return computed[k];
}

// ---------------------------------------------------------------------------------------------------------

namespace {

std::vector<numeric> solve(std::vector<std::vector<numeric>> A, std::vector<numeric> b) {
  // Gaussian elimination with partial pivoting, in the current precision.
  const std::size_t n = b.size();
  for (std::size_t j = 0; j < n; ++j) {
    std::size_t pivot = j;
    for (std::size_t i = j + 1; i < n; ++i)
      if (GiNaC::abs(A[i][j]) > GiNaC::abs(A[pivot][j])) pivot = i;
    if (A[pivot][j].is_zero()) throw std::domain_error("high precision: singular mass matrix");
    std::swap(A[j], A[pivot]);
    std::swap(b[j], b[pivot]);
    for (std::size_t i = j + 1; i < n; ++i) {
      const numeric f = A[i][j] / A[j][j];
      if (f.is_zero()) continue;
      for (std::size_t k = j; k < n; ++k) A[i][k] -= f * A[j][k];
      b[i] -= f * b[j];
    }
  }
  std::vector<numeric> x(n);
  for (std::size_t i = n; i-- > 0;) {
    numeric s = b[i];
    for (std::size_t k = i + 1; k < n; ++k) s -= A[i][k] * x[k];
    x[i] = s / A[i][i];
  }
  return x;
}

// The symbolic expressions behind the kernels of build_kernels, in the same output order.
struct ReferenceSet {
  enum class Kind { direct, rhs, jacobian };
  struct Entry {
    Kind kind = Kind::direct;
    std::vector<ex> expressions;  // direct kernels
  };
  std::map<std::string, Entry> kernels;

  std::size_t n = 0, d = 0, nx = 0;
  std::vector<ex> kinematics, forcing;
  std::vector<std::vector<ex>> mass;                    // d x d
  std::vector<std::vector<ex>> kinematics_by_x;         // [k][a]
  std::vector<std::vector<ex>> forcing_by_x;            // [k][i]
  std::vector<std::vector<std::vector<ex>>> mass_by_x;  // [k][i][j]
  Intermediates intermediates;                          // the derivation's, extended by the derivatives above
};

ReferenceSet references(const Model& model, const Derivation& derivation) {
  ReferenceSet r;
  const HamelEquations& eq = derivation.equations;
  const HamelSystem& sys = derivation.system;
  r.n = sys.coordinates.size();
  r.d = eq.independent.size();
  r.kinematics = eq.kinematics;
  r.forcing = eq.forcing;
  r.mass.assign(r.d, std::vector<ex>(r.d));
  for (unsigned i = 0; i < r.d; ++i)
    for (unsigned j = 0; j < r.d; ++j) r.mass[i][j] = eq.mass_matrix(i, j);

  using Kind = ReferenceSet::Kind;
  r.kernels["kinematics"] = {Kind::direct, eq.kinematics};
  {
    std::vector<ex> m;
    for (const auto& row : r.mass) m.insert(m.end(), row.begin(), row.end());
    r.kernels["mass_matrix"] = {Kind::direct, m};
  }
  r.kernels["forcing"] = {Kind::direct, eq.forcing};
  {
    std::vector<ex> g;
    for (const HamelCoefficient& h : sys.gamma) g.push_back(h.value);
    r.kernels["hamel_coefficients"] = {Kind::direct, g};
  }
  r.kernels["rhs"] = {Kind::rhs, {}};
  r.kernels["energy"] = {Kind::direct, {eq.energy_terms.at(0)}};
  if (!eq.constraint_residual.empty()) r.kernels["constraint_residual"] = {Kind::direct, eq.constraint_residual};
  if (derivation.bundle) {
    const BundleGeometry& geo = *derivation.bundle;
    const std::size_t m = model.bundle->group_velocity.size();
    r.kernels["group_velocity"] = {Kind::direct, derivation.group_velocity};
    std::vector<ex> conn, locked;
    for (unsigned a = 0; a < m && geo.connection_derived; ++a)
      for (unsigned I = 0; I < r.n; ++I) conn.push_back(geo.connection(a, I));
    // Trees: A = L⁻¹K is solved in the kernel, not formed symbolically; not measured (reported as such).
    if (r.n > 0 && geo.connection_derived) r.kernels["connection"] = {Kind::direct, conn};
    if (geo.quadratic) {
      for (unsigned a = 0; a < m; ++a)
        for (unsigned c = 0; c < m; ++c) locked.push_back(geo.L(a, c));
      r.kernels["locked_inertia"] = {Kind::direct, locked};
    }
    if (model.bundle->mechanical && r.n > 0 && geo.connection_derived) {
      std::vector<ex> shape;
      for (unsigned I = 0; I < r.n; ++I)
        for (unsigned J = 0; J < r.n; ++J) shape.push_back(geo.shape_inertia(I, J));
      r.kernels["shape_inertia"] = {Kind::direct, shape};
    }
  }

  // Jacobian: derivatives with respect to the state (q, u_I).
  std::vector<GiNaC::symbol> state(sys.coordinates.begin(), sys.coordinates.end());
  for (int I : eq.independent) state.push_back(sys.velocities[static_cast<std::size_t>(I)]);
  r.nx = state.size();
  r.kinematics_by_x.resize(r.nx);
  r.forcing_by_x.resize(r.nx);
  r.mass_by_x.resize(r.nx);
  r.intermediates = eq.intermediates;
  for (std::size_t k = 0; k < r.nx; ++k) r.mass_by_x[k].assign(r.d, std::vector<ex>(r.d));
  const auto differentiate = [&](const std::vector<ex>& expressions, std::vector<std::vector<ex>>& by_x) {
    for (const ex& e : expressions) {
      const std::vector<ex> d = r.intermediates.diff(e, state);
      for (std::size_t k = 0; k < r.nx; ++k) by_x[k].push_back(d[k]);
    }
  };
  differentiate(r.kinematics, r.kinematics_by_x);
  differentiate(r.forcing, r.forcing_by_x);
  for (std::size_t i = 0; i < r.d; ++i)
    for (std::size_t j = 0; j < r.d; ++j) {
      const std::vector<ex> by_x = r.intermediates.diff(r.mass[i][j], state);
      for (std::size_t k = 0; k < r.nx; ++k) r.mass_by_x[k][i][j] = by_x[k];
    }
  r.kernels["jacobian"] = {Kind::jacobian, {}};
  return r;
}

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
    const ReferenceSet::Entry* ref;
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
  const ReferenceSet refs_;
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
        return references(model, derivation);
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
    const std::size_t want = it->second.kind == ReferenceSet::Kind::direct ? it->second.expressions.size()
                             : it->second.kind == ReferenceSet::Kind::rhs  ? n_ + d_
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
        case ReferenceSet::Kind::direct:
          for (std::size_t i = 0; i < outputs; ++i) ref[i] = exact_.value(km.ref->expressions[i]);
          break;
        case ReferenceSet::Kind::rhs: {
          for (std::size_t a = 0; a < n; ++a) ref[a] = exact_.value(refs_.kinematics[a]);
          const std::vector<numeric>& u = accelerations();
          for (std::size_t i = 0; i < d; ++i) ref[n + i] = u[i];
          break;
        }
        case ReferenceSet::Kind::jacobian: {
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
    if (km.ref->kind == ReferenceSet::Kind::direct) {
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
