// The verbs of the `hamel` command line; each registers its options on a CLI11 subcommand and
// returns the function that runs it (exit status 0; errors are thrown).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace hamel::cli {

using Run = std::function<void()>;

Run add_derive_command(CLI::App& app);
Run add_emit_command(CLI::App& app);
Run add_simulate_command(CLI::App& app);
Run add_phase_command(CLI::App& app);
Run add_accuracy_command(CLI::App& app);
Run add_report_command(CLI::App& app);

}  // namespace hamel::cli
