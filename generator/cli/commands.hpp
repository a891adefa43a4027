// The verbs of the `hamel` command line; each registers its options on a CLI11 subcommand and
// returns the function that runs it (exit status 0; errors are thrown).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <stdexcept>

namespace hamel::cli {

using Run = std::function<void()>;

/// A run that failed for a reason the user can act on but that is not bad input (an integration that
/// stopped): main prints "hamel: <what>" and exits with status 1, without the "internal error" label.
class RunFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Run add_derive_command(CLI::App& app);
Run add_emit_command(CLI::App& app);
Run add_simulate_command(CLI::App& app);
Run add_phase_command(CLI::App& app);
Run add_gait_command(CLI::App& app);
Run add_accuracy_command(CLI::App& app);
Run add_report_command(CLI::App& app);
Run add_import_command(CLI::App& app);
Run add_linearize_command(CLI::App& app);
Run add_animate_command(CLI::App& app);

}  // namespace hamel::cli
