// hamel: symbolic–numeric generator for the Hamel equations of constrained and floating multibody
// systems (Müller, Proc. R. Soc. A 479, 2023). Exit status: 0 success, 2 input error, 1 internal error.
#include "cli/commands.hpp"
#include "emit/package_writer.hpp"
#include "model/input_error.hpp"
#include "report/atomic_file.hpp"
#include "report/progress.hpp"
#include "report/temporaries.hpp"

#include <ginac/ginac.h>
#include <csignal>
#include <iostream>
#include <map>
#include <stdexcept>

int main(int argc, char** argv) {
  hamel::install_cleanup_signal_handlers();
  // A closed pipe on stdout is a failed write (exit 1, "cannot write standard output"), not death by SIGPIPE: the
  // streams' state is checked on every flush (report/atomic_file.hpp).
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"hamel: derive Hamel coefficients and equations of motion, emit C++ kernels, simulate"};
  app.set_version_flag("--version", std::string("hamel ") + hamel::generator_version());
  app.require_subcommand(1);
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress messages on stderr (steps that run over a second say what they do)");
  app.fallthrough();
  std::map<const CLI::App*, hamel::cli::Run> runs;
  for (auto add : {hamel::cli::add_derive_command, hamel::cli::add_emit_command, hamel::cli::add_simulate_command,
                   hamel::cli::add_phase_command, hamel::cli::add_gait_command, hamel::cli::add_report_command,
                   hamel::cli::add_accuracy_command, hamel::cli::add_import_command, hamel::cli::add_linearize_command,
                   hamel::cli::add_animate_command}) {
    hamel::cli::Run run = add(app);
    runs[app.get_subcommands({}).back()] = run;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  hamel::progress::set_enabled(!quiet);
  try {
    for (const auto& [cmd, run] : runs)
      if (cmd->parsed()) run();
    // Output that did not arrive (a full disk, a closed pipe) is a failure, not a success.
    hamel::flush_stdout_or_throw();
    return 0;
  } catch (const hamel::OutputError& e) {
    std::cerr << "hamel: " << e.what() << "\n";
    return 1;
  } catch (const hamel::InputError& e) {
    std::cerr << hamel::printable(e.headline()) << "\n";
    for (const std::string& note : e.notes()) std::cerr << "  " << hamel::printable(note) << "\n";
    return 2;
  } catch (const GiNaC::pole_error& e) {
    // A denominator that simplifies to zero: the loader finds those written in the model (x/(sin(x)^2+cos(x)^2-1),
    // with file:line and key); one that arises only while deriving still is bad input.
    std::cerr << "hamel: error: an expression of the model divides by zero once simplified (" << e.what()
              << "); expected denominators that are not identically zero\n";
    return 2;
  } catch (const std::domain_error& e) {
    if (std::string(e.what()).find("division by zero") == std::string::npos) {
      std::cerr << "hamel: internal error: " << e.what() << "\n";
      return 1;
    }
    std::cerr << "hamel: error: an expression of the model divides by zero once simplified (" << e.what()
              << "); expected denominators that are not identically zero\n";
    return 2;
  } catch (const hamel::cli::RunFailed& e) {
    std::cerr << "hamel: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hamel: internal error: " << e.what() << "\n";
    return 1;
  }
}
