// `hamel emit MODEL -o DIR`: the model's kernels as a C++ header and source in DIR.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "cli/pipeline.hpp"
#include "derive/derivation.hpp"
#include "emit/kernel_registry.hpp"
#include "emit/kernels.hpp"
#include "emit/package_writer.hpp"
#include "model/input_error.hpp"
#include "model/load_model.hpp"
#include "report/progress.hpp"

#include <algorithm>
#include <iostream>
#include <set>

namespace hamel::cli {

namespace {

struct EmitOptions {
  PipelineOptions in;
  std::string output, kernels, jacobian_solve;
  EmitSettings settings;
};

// --kernels a,b,c: the kernels to build, each a known name.
std::set<std::string> parse_kernels(const std::string& list) {
  std::set<std::string> out;
  for (const std::string& name : split_list(list)) {
    if (!is_kernel_name(name))
      throw InputError("--kernels: unknown kernel '" + name +
                       "'; expected a comma-separated list of: " + kernel_names());
    out.insert(name);
  }
  return out;
}

std::size_t total_operations(const KernelSet& kernels) {
  std::vector<int> all;
  for (const Kernel& k : kernels.kernels) all.insert(all.end(), k.outputs.begin(), k.outputs.end());
  return static_cast<std::size_t>(kernels.graph.count(kernels.graph.schedule(all)).total());
}

// The options as given, for the package's stamp (emit's defaults left out, so that they read as typed).
std::string given_options(const EmitOptions& opt) {
  std::string s;
  const auto add = [&](const std::string& flag, const std::string& value) {
    if (!value.empty()) s += (s.empty() ? "" : " ") + flag + " " + value;
  };
  add("--form", opt.in.form);
  add("--fold", opt.in.fold);
  for (const std::string& p : opt.in.params) add("--param", p);
  add("--kernels", opt.kernels);
  add("--dynamics", opt.in.dynamics);
  add("--jacobian-solve", opt.jacobian_solve);
  if (opt.settings.split_statements != EmitSettings{}.split_statements)
    add("--split", std::to_string(opt.settings.split_statements));
  if (opt.settings.share_statements != EmitSettings{}.share_statements)
    add("--share", std::to_string(opt.settings.share_statements));
  if (opt.settings.share_ratio != kShareRatioAuto) add("--share-ratio", std::to_string(opt.settings.share_ratio));
  if (opt.settings.inline_calls) s += std::string(s.empty() ? "" : " ") + "--inline";
  if (opt.settings.python) s += std::string(s.empty() ? "" : " ") + "--python";
  return s;
}

// --jacobian-solve: how a kinematic tree's Jacobian solves M y = b for its columns.
ColumnSolve column_solve(const std::string& name) {
  if (name.empty() || name == "auto") return ColumnSolve::smaller;
  if (name == "ldlt") return ColumnSolve::ldlt;
  if (name == "aba") return ColumnSolve::articulated;
  throw InputError("--jacobian-solve: unknown solve '" + name + "'; expected auto, ldlt or aba");
}

void run(EmitOptions opt) {
  opt.settings.options = given_options(opt);
  const ColumnSolve solve = column_solve(opt.jacobian_solve);  // a wrong value fails before any work
  Pipeline pipeline(opt.in);
  pipeline.dynamics().column_solve = solve;
  const Target& target = pipeline.target();
  std::set<std::string> selected = target.kernels;
  if (!opt.kernels.empty()) {
    if (target.scene)
      throw InputError(
          "--kernels: a scene chooses its kernels by its `compute` tasks; give the model instead of "
          "the scene, or drop --kernels");
    selected = parse_kernels(opt.kernels);
  }
  const Model& model = target.model;
  check_package_folder(opt.output, model.name);  // a refused folder fails now, not after a long derivation
  const Derivation& derivation = pipeline.derivation();
  const KernelSet kernels = [&] {
    KernelSet set = pipeline.kernels(selected);
    // A kernel with a constant beyond the range of a double is refused when asked for (--kernels, a scene)
    // and left out of the default set with a note; nothing is written when it is refused.
    for (const std::string& note : drop_unrepresentable(set, !selected.empty(), printable(opt.in.file)))
      std::cerr << note << "\n";
    return set;
  }();
  progress::Step writing("printing the C++ package");
  EmittedPackage package = emit_cpp(model, derivation, kernels, opt.settings);
  if (target.scene) {
    // Pruning report: operations of the scene's kernels (shared subexpressions counted once) against all
    // kernels of the same model, form and fixed parameters. (Unfolded symbolic derivations of models with
    // many parameters can take very long, so folding is not undone for the comparison.)
    const std::size_t full = total_operations(pipeline.kernels());
    const std::string full_model = load_model(target.scene->model_path).name;
    const std::size_t pruned = total_operations(kernels);
    std::string kernel_list;
    for (const Kernel& k : kernels.kernels) kernel_list += (kernel_list.empty() ? "" : ", ") + k.name;
    const std::string note = "// Scene " + target.scene->name + " on " + full_model + ": kernels " + kernel_list +
                             "; " + std::to_string(pruned) + " operations, against " + std::to_string(full) +
                             " for all kernels of the model with the same fixed parameters.\n";
    const std::size_t at = package.header.find("//\n");
    package.header.insert(at == std::string::npos ? 0 : at, note);
    std::cerr << "hamel: scene " << target.scene->name << ": " << pruned << " operations (full model: " << full
              << ")\n";
  }
  write_package(package, opt.output);
  std::string files;
  for (const EmittedFile& f : package.files()) files += (files.empty() ? "" : ", ") + f.name;
  std::cerr << "hamel: wrote " << printable(opt.output) << "/: " << files << " ("
            << (package.source.size() + 500) / 1000 << " kB of C++";
  if (package.shared_stages > 0)
    std::cerr << ", " << package.shared_stages << " shared stage" << (package.shared_stages > 1 ? "s" : "")
              << " at --share-ratio " << package.share_ratio;
  std::cerr << ")\n";
  // What one call of each kernel executes as printed (with its shared stages and calls).
  for (const auto& [name, c] : package.operations)
    std::cerr << "  " << name << ": " << c.total() << " operations (" << c.add << " add, " << c.mul << " mul, " << c.div
              << " div, " << c.call << " call)\n";
}

}  // namespace

Run add_emit_command(CLI::App& app) {
  auto opt = std::make_shared<EmitOptions>();
  CLI::App* cmd = app.add_subcommand("emit", "Emit flat, branch-free C++ kernels for a model");
  add_pipeline_options(cmd, opt->in);
  cmd->add_option("-o,--output", opt->output, "Output folder (replaced atomically)")->required();
  std::string on_request;
  for (const KernelSpec& k : kernel_registry())
    if (!k.by_default) on_request += (on_request.empty() ? "" : ", ") + std::string(k.name);
  cmd->add_option("--kernels", opt->kernels,
                  "Only these kernels, comma-separated (e.g. rhs,mass_matrix; default: all the model has, except "
                  "those built only when named: " +
                      on_request +
                      "). The jacobian of a large kinematic tree is by far its biggest kernel. input_jacobian "
                      "(d(x')/d(in), the B beside jacobian's A for MPC) and parameter_jacobian (d(x')/dp by the "
                      "parameters not folded, for system identification) are solved as the jacobian's columns "
                      "(e.g. --kernels rhs,jacobian,input_jacobian for a linearized A and B at any state; "
                      "docs/emit.md). Known: " +
                      kernel_names());
  // A whole number of `what`, 0 or more; `zero` says what 0 means.
  const auto whole_number = [](const std::string& what, const std::string& zero) {
    return CLI::Validator(
        [what, zero](std::string& value) {
          const bool digits = !value.empty() && value.size() <= 9 &&
                              std::all_of(value.begin(), value.end(), [](char c) { return c >= '0' && c <= '9'; });
          return digits ? std::string()
                        : "expected a whole number of " + what + ", 0 or more (0: " + zero + "), got '" + value + "'";
        },
        "", what);
  };
  cmd->add_option("--split", opt->settings.split_statements,
                  "Print a kernel of more than N operations as functions of at most N operations each, called in turn "
                  "(an optimizing compiler's register allocation grows faster than linearly with the length of one "
                  "function; 0: never split; on a microcontroller 1000 halves the stack a part takes in double, "
                  "docs/firmware.md)")
      ->default_val(opt->settings.split_statements)
      ->check(whole_number("operations", "never split"))
      ->type_name("N");
  cmd->add_option("--share", opt->settings.share_statements,
                  "Print work that several kernels use (N or more operations used by the same kernels) once, as a "
                  "function shared_<k> that each of them calls before its own work, instead of in every kernel "
                  "(0: never). With --jacobian-solve ldlt, the 30-joint chain's jacobian then calls rhs's recursion "
                  "instead of holding a copy")
      ->default_val(opt->settings.share_statements)
      ->check(whole_number("operations", "never"))
      ->type_name("N");
  // --share-ratio takes `auto` too, read as kShareRatioAuto.
  const auto ratio = [whole_number](std::string& value) {
    if (value == "auto") {
      value = std::to_string(kShareRatioAuto);
      return std::string();
    }
    return whole_number("operations per value", "any")(value).empty()
               ? std::string()
               : "expected auto or a whole number of operations per value, 0 or more (0: any), got '" + value + "'";
  };
  cmd->add_option(
         "--share-ratio", opt->settings.share_ratio,
         "Share such work only when its function computes at least R operations per value it leaves to "
         "later work, which every caller stores and reads back. auto (default): " +
             std::to_string(kShareRatioSmall) + ", or " + std::to_string(kShareRatioLarge) +
             " when the kernels print " + std::to_string(kLargePackage) +
             " operations or more together (about 15 s of g++ -O2 unshared; 7 makes mass_matrix 5-21 % slower on "
             "the large chains and trees measured). 0: any (the smallest package; energy and rhs then run "
             "slower too). docs/emit.md. A kernel that would read less than a tenth of a shared function's values "
             "computes that work itself")
      ->default_str("auto")
      ->transform(CLI::Validator(ratio, "", "operations per value"))
      ->type_name("R|auto");
  cmd->add_option(
      "--jacobian-solve", opt->jacobian_solve,
      "Kinematic trees: how the jacobian solves M y = b for its columns: ldlt (the LDL^T of M, few operations "
      "for bushy trees), aba (the articulated-body recursion, fewer operations for long chains) or auto "
      "(default: aba when its program has at most 0.9 of ldlt's operations)");
  cmd->add_flag("--inline", opt->settings.inline_calls,
                "Print the jacobian's solve inline in every column instead of as one function (jacobian_column) called "
                "per two columns: the flat program, 1.1-1.75x the code and 1.2-2x the compile time, between 2 % faster "
                "and 13 % slower "
                "on the models measured (docs/benchmarks.md)");
  cmd->add_flag("--python", opt->settings.python,
                "Also a Python module: DIR/<name>.py (NumPy, ctypes) and DIR/<name>_python.cpp, built by the package's "
                "CMakeLists.txt as lib<name>_python into the build folder, where `import <name>` then finds both. "
                "Every kernel takes and returns NumPy arrays, one state or a batch of N (x of shape (N, n_state)) in "
                "one call; rhs_status raises StatusError for a bad state. Example: hamel emit "
                "models/double_pendulum.yaml -o dp --python && cmake -S dp -B dp-build && cmake --build dp-build && "
                "PYTHONPATH=dp-build python3 -c 'import double_pendulum'. docs/python.md");
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
