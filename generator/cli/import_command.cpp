// `hamel import FILE.urdf|FILE.xml -o MODEL.yaml`: a robot description as a hamel kinematic-tree model.
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "import/tree_import.hpp"
#include "model/input_error.hpp"
#include "model/input_file.hpp"
#include "model/load_model.hpp"
#include "report/atomic_file.hpp"

#include <fstream>
#include <iostream>
#include <sstream>

namespace hamel::cli {

namespace {

struct ImportCliOptions {
  std::string input, output, name, ignore;
  bool floating = false;
};

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// URDF or MJCF: by extension, else by the root element.
bool is_urdf(const std::string& path) {
  if (ends_with(path, ".urdf")) return true;
  if (ends_with(path, ".xml") || ends_with(path, ".mjcf")) return false;
  const std::string text = InputFile(path, "robot file", kMaxRobotFileBytes).read_all();
  const std::size_t robot = text.find("<robot"), mujoco = text.find("<mujoco");
  if (robot == std::string::npos && mujoco == std::string::npos)
    throw InputError(SourceLocation{path, 0, 0}, "",
                     "neither URDF (<robot>) nor MJCF (<mujoco>); expected a .urdf or MuJoCo .xml file");
  return robot < mujoco;
}

void run(const ImportCliOptions& opt) {
  ImportOptions options;
  options.floating = opt.floating;
  options.name = opt.name;
  for (const std::string& c : opt.ignore.empty() ? std::vector<std::string>{} : split_list(opt.ignore)) {
    const auto& known = ignorable_categories();
    if (std::find(known.begin(), known.end(), c) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw InputError("--ignore: unknown category " + quote(c) + "; expected a comma-separated list of: " + list);
    }
    options.ignore.insert(c);
  }
  note_input_file(opt.input, "the robot file");  // -o must not replace it
  // Warnings repeat names from the file: escaped as errors are (no escape sequence reaches the terminal).
  const Warn warn = [](const std::string& w) { std::cerr << "hamel: warning: " << printable(w) << "\n"; };
  const ImportedTree tree =
      is_urdf(opt.input) ? import_urdf(opt.input, options, warn) : import_mjcf(opt.input, options, warn);
  check_imported_tree(tree);  // bad numbers are the robot file's, named there
  const std::string yaml = tree_model_yaml(tree);
  // What we write must load: a failure here is ours, not the user's.
  try {
    (void)load_model_from_text(yaml, opt.output);
  } catch (const InputError& e) {
    // A loop that closes the tree rigidly (or cannot close) is the file's: say so, with the way out.
    const std::string what = e.what();
    if (!tree.loops.empty() && what.find("'loops") != std::string::npos)
      throw InputError(SourceLocation{opt.input, 0, 0}, "equality",
                       "the file's connect/weld constraints, as closed loops of the imported tree, are refused: " +
                           what.substr(what.find("'loops")) + "; pass --ignore equality to cut the loops open");
    throw std::runtime_error(std::string("the imported model does not load: ") + e.what());
  }
  if (opt.output == "-")
    std::cout << yaml;
  else
    write_file_atomically(opt.output, yaml, "-o");
  std::cerr << "hamel: imported " << tree.name << " (" << tree.bodies.size() << " joints, "
            << (tree.floating ? "floating base '" + tree.base_name + "'" : std::string("fixed base")) << ", "
            << tree.inputs.size() << " inputs)" << (opt.output == "-" ? "" : " into " + opt.output) << "\n";
}

}  // namespace

Run add_import_command(CLI::App& app) {
  auto opt = std::make_shared<ImportCliOptions>();
  CLI::App* cmd =
      app.add_subcommand("import", "Turn a URDF or MJCF robot file into a hamel kinematic-tree model (docs/import.md)");
  cmd->add_option("file", opt->input, "Robot file: .urdf (urdfdom) or MuJoCo .xml (MJCF, compiled by MuJoCo)")
      ->required();
  cmd->add_option("-o,--output", opt->output, "Model file to write (YAML, schema 1), or - for stdout")->required();
  cmd->add_flag("--floating", opt->floating,
                "URDF: the root link is a floating base (SE3); default: fixed to the world. MJCF: a body with "
                "<freejoint/> floats");
  cmd->add_option("--name", opt->name, "Model name (a C++ identifier; default: the robot's name)");
  cmd->add_option("--ignore", opt->ignore,
                  "Leave these out with a warning instead of failing (comma-separated): contacts, tendons, "
                  "equality, limits, gravity, actuators, friction, fluid");
  return [opt] { run(*opt); };
}

}  // namespace hamel::cli
