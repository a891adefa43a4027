// `hamel derive MODEL [--param n=v ...] [--at n=v,...] [--json | --latex]`: the derived quantities as expressions,
// with numbers where --at (and parameter values) determine them; report/derivation_report.hpp prints them.
#include "algebra/high_precision.hpp"
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "derive/derivation.hpp"
#include "derive/riemann.hpp"
#include "model/expression_parser.hpp"
#include "model/input_error.hpp"
#include "rbd/aba.hpp"
#include "report/derivation_report.hpp"

#include <nlohmann/json.hpp>

#include <iostream>
#include <map>
#include <memory>
#include <optional>

namespace hamel::cli {

namespace {

struct DeriveOptions {
  PipelineOptions in;
  std::vector<std::string> at;
  std::string curvature_sign = "paper";
  bool json = false, latex = false, inline_all = false, riemann = false;
};

// The values --at gives, with the parameters', as what every printed entry's number is computed from: a 50-digit
// evaluation (algebra/high_precision.hpp, which adds and multiplies in structural order, so the double printed is
// the same in every run) rounded to double. With --at every intermediate counts through its definition; without,
// the output is symbolic but for the parameters. --at takes every name the output lists as coordinate or
// quasi-velocity (for bundle models the shape rates r_dot and the shifted group velocities of the form), inputs,
// the group velocity and t.
ValueOf values_at(const Model& model, const std::vector<double>& params, const std::map<std::string, double>& at,
                  const Derivation& d, const Intermediates& program, bool riemann) {
  const HamelSystem& sys = d.system;
  const HamelEquations& eq = d.equations;
  std::map<GiNaC::ex, GiNaC::numeric, GiNaC::ex_is_less> values;
  const auto number = [](double v) { return GiNaC::ex_to<GiNaC::numeric>(exact_number(v)); };
  for (std::size_t k = 0; k < model.parameters.size(); ++k) values[model.parameters[k].symbol] = number(params[k]);
  GiNaC::symtab table = model.symbols();
  for (const auto& r : model.rates) table.erase(r.get_name());
  for (const auto& q : sys.coordinates) table[q.get_name()] = q;
  for (const auto& u : sys.velocities) table[u.get_name()] = u;
  for (const auto& [name, v] : at) {
    auto it = table.find(name);
    if (it == table.end())
      throw InputError("--at: " + quote(name) + " is not a coordinate, quasi-velocity, input or t of model '" +
                       model.name + "'");
    values[it->second] = number(v);
  }
  auto evaluator = std::make_shared<HighPrecisionExpressionEvaluator>(50);
  if (!at.empty()) {
    values[model.time] = number(at.count("t") ? at.at("t") : 0.0);
    evaluator->define(program);
  }
  evaluator->assign(values);
  if (riemann && !at.empty()) {  // the Riemannian quantities are in q_dot = B(q) u (qadot)
    for (std::size_t a = 0; a < model.rates.size(); ++a) try {
        values[model.rates[a]] = evaluator->value(eq.kinematics[a]);
      } catch (const std::exception&) {  // no value at this point: the rate stays a symbol
      }
    evaluator->assign(values);
  }
  return [evaluator](const GiNaC::ex& e) -> std::optional<double> {
    try {
      return evaluator->value(e).to_double();
    } catch (const std::exception&) {  // a symbol without a value, or a pole at this point
      return std::nullopt;
    }
  };
}

void run(const DeriveOptions& opt) {
  if (opt.latex && (opt.json || opt.riemann || !opt.at.empty()))
    throw InputError(std::string("--latex: cannot be combined with ") + (opt.json ? "--json"
                                                                         : opt.riemann
                                                                             ? "--riemann (text and JSON only)"
                                                                             : "--at (values are text and JSON only)"));
  PipelineOptions in = opt.in;
  in.announce = false;  // the derivation is what derive prints
  Pipeline pipeline(in);
  const Model& model = pipeline.loaded();
  const std::vector<double>& params = pipeline.parameters();
  const std::map<std::string, double> at = parse_assignments(opt.at, "--at");

  if (opt.curvature_sign != "paper" && opt.curvature_sign != "gauge")
    throw InputError("--curvature-sign: expected 'paper' (B = gamma, the default) or 'gauge' (B = -gamma), got '" +
                     opt.curvature_sign + "'");
  const Model& folded = pipeline.model();
  const Derivation& d = pipeline.derivation();
  const HamelEquations& eq = d.equations;
  // The program grows (a copy: eq's stays as derived) by u̇ where rhs computes it by the articulated-body algorithm
  // (the route of every verb, emit/equations_of_motion.hpp), then with --riemann by the Riemannian quantities.
  Intermediates program = eq.intermediates;
  std::vector<GiNaC::ex> accelerations;
  if (pipeline.acceleration_route() == AccelerationRoute::articulated)
    accelerations = rbd::forward_dynamics(*eq.tree, rbd::Namer<GiNaC::ex>([&program](const GiNaC::ex& e) {
                      return program.define(e);
                    })).accelerations;
  const std::size_t derived = program.size();
  std::optional<RiemannGeometry> riemann;
  if (opt.riemann) riemann = derive_riemann(folded, program);
  const ExpressionDisplay display{opt.inline_all ? &program : nullptr};
  const CurvatureSign sign = opt.curvature_sign == "gauge" ? CurvatureSign::gauge : CurvatureSign::paper;
  if (opt.latex) {
    print_derivation_latex(std::cout, model, d, sign, display);
    return;
  }

  const ValueOf values = values_at(model, params, at, d, program, opt.riemann);
  nlohmann::json j =
      derivation_json(model, d, accelerations, riemann ? &*riemann : nullptr, program, derived, sign, display, values);
  if (opt.json) {
    std::cout << j.dump(2) << "\n";
    return;
  }
  print_derivation_text(std::cout, std::move(j), model, d);
}

}  // namespace

Run add_derive_command(CLI::App& app) {
  auto opt = std::make_shared<DeriveOptions>();
  CLI::App* cmd =
      app.add_subcommand("derive", "Derive B, the Hamel coefficients and the equations of motion of a model");
  add_pipeline_options(cmd, opt->in);
  cmd->add_option(
      "--at", opt->at,
      "Values name=value,... of coordinates, quasi-velocities, inputs and t: every entry then also carries its number");
  cmd->add_option("--curvature-sign", opt->curvature_sign,
                  "Bundle models: paper (B = gamma, default) or gauge (B = -gamma, Rem. remSign)");
  cmd->add_flag("--json", opt->json, "Print JSON instead of text");
  cmd->add_flag("--latex", opt->latex,
                "Print a LaTeX fragment instead of text (amsmath; the paper's notation, intermediate symbols as "
                "'where' definitions)");
  cmd->add_flag("--riemann", opt->riemann,
                "Models in general coordinates without constraints, L = 1/2 g_ab(q) q_dot^a q_dot^b - V: also the "
                "metric, Christoffel symbols, Riemann-Christoffel tensor and the covariant linearization (JSON key "
                "'riemann')");
  cmd->add_flag("--inline", opt->inline_all,
                "Print every expression with the intermediate symbols expanded (for small models; expressions that "
                "would exceed 20000 nodes keep their intermediates)");
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
