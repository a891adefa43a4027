// `hamel emit MODEL -o DIR`: the model's kernels as a C++ header and source in DIR.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "derive/derivation.hpp"
#include "emit/cpp_emitter.hpp"
#include "emit/kernels.hpp"
#include "model/load_model.hpp"

#include <iostream>

namespace hamel::cli {

namespace {

struct EmitOptions {
  std::string model, output, form, fold = "none";
  std::vector<std::string> params;
};

void run(const EmitOptions& opt) {
  const Model loaded = load_model(opt.model);
  const Model model = apply_fold(loaded, parameter_values(loaded, parse_assignments(opt.params, "--param")), opt.fold);
  std::cerr << "hamel: deriving " << model.name << " ...\n";
  const Derivation derivation = derive(model, DeriveSettings{opt.form});
  const KernelSet kernels = build_kernels(model, derivation);
  const EmittedPackage package = emit_cpp(model, derivation, kernels);
  write_package(package, opt.output);
  std::cerr << "hamel: wrote " << opt.output << "/" << package.header_name << " and " << opt.output << "/"
            << package.source_name << "\n";
  for (const Kernel& k : kernels.kernels) {
    const OpCounts c = kernels.graph.count(kernels.graph.schedule(k.outputs));
    std::cerr << "  " << k.name << ": " << c.total() << " operations (" << c.add << " add, " << c.mul << " mul, "
              << c.div << " div, " << c.call << " call)\n";
  }
}

}  // namespace

Run add_emit_command(CLI::App& app) {
  auto opt = std::make_shared<EmitOptions>();
  CLI::App* cmd = app.add_subcommand("emit", "Emit flat, branch-free C++ kernels for a model");
  cmd->add_option("model", opt->model, "Model file (YAML, schema 1)")->required();
  cmd->add_option("-o,--output", opt->output, "Output folder (replaced atomically)")->required();
  cmd->add_option("--form", opt->form, "Bundle models: ep, lp, ldap or momentum (see hamel derive --help)");
  cmd->add_option("--param", opt->params,
                  "Parameter value name=value for --fold (repeatable; defaults from the model)");
  cmd->add_option("--fold", opt->fold, fold_help())->capture_default_str();
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
