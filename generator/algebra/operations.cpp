#include "algebra/operations.hpp"

#include <cmath>
#include <stdexcept>

namespace hamel {

namespace {

using GiNaC::numeric;

numeric exact_log(const numeric& x) {
  if (!x.is_positive()) throw std::domain_error("high precision: log of a non-positive number");
  return GiNaC::log(x);
}
numeric exact_asin(const numeric& x) {
  if (GiNaC::abs(x) > 1) throw std::domain_error("high precision: asin outside [-1, 1]");
  return GiNaC::asin(x);
}
numeric exact_sqrt(const numeric& x) {
  if (x.is_negative()) throw std::domain_error("high precision: sqrt of a negative number");
  return GiNaC::sqrt(x);
}
numeric exact_acos(const numeric& x) {
  if (GiNaC::abs(x) > 1) throw std::domain_error("high precision: acos outside [-1, 1]");
  return GiNaC::acos(x);
}

}  // namespace

const std::vector<Function>& functions() {
  using D = double (*)(double);
  static const std::vector<Function> table = {
      {"sin", Op::sin, "std::sin", static_cast<D>(std::sin), [](const numeric& x) { return GiNaC::sin(x); }},
      {"cos", Op::cos, "std::cos", static_cast<D>(std::cos), [](const numeric& x) { return GiNaC::cos(x); }},
      {"tan", Op::tan, "std::tan", static_cast<D>(std::tan), [](const numeric& x) { return GiNaC::tan(x); }},
      {"asin", Op::asin, "std::asin", static_cast<D>(std::asin), exact_asin},
      {"acos", Op::acos, "std::acos", static_cast<D>(std::acos), exact_acos},
      {"atan", Op::atan, "std::atan", static_cast<D>(std::atan), [](const numeric& x) { return GiNaC::atan(x); }},
      {"sinh", Op::sinh, "std::sinh", static_cast<D>(std::sinh), [](const numeric& x) { return GiNaC::sinh(x); }},
      {"cosh", Op::cosh, "std::cosh", static_cast<D>(std::cosh), [](const numeric& x) { return GiNaC::cosh(x); }},
      {"tanh", Op::tanh, "std::tanh", static_cast<D>(std::tanh), [](const numeric& x) { return GiNaC::tanh(x); }},
      {"exp", Op::exp, "std::exp", static_cast<D>(std::exp), [](const numeric& x) { return GiNaC::exp(x); }},
      {"log", Op::log, "std::log", static_cast<D>(std::log), exact_log},
      {"sqrt", Op::sqrt, "std::sqrt", static_cast<D>(std::sqrt), exact_sqrt},
      {"abs", Op::abs, "std::fabs", static_cast<D>(std::fabs), [](const numeric& x) { return GiNaC::abs(x); }},
  };
  return table;
}

const Function* function_named(const std::string& name) {
  for (const Function& f : functions())
    if (name == f.name) return &f;
  return nullptr;
}

const Function* function_of(Op op) {
  for (const Function& f : functions())
    if (f.op == op) return &f;
  return nullptr;
}

double evaluate(Op op, double a, double b) {
  return evaluate_in<double>(
      op, a, b, [](double x, double y) { return x / y; }, [](double x, double y) { return std::pow(x, y); },
      [](Op f, double x) {
        if (const Function* function = function_of(f)) return function->evaluate(x);
        throw std::logic_error("evaluate: not an operation");
      });
}

}  // namespace hamel
