// Temporary files and folders hamel creates next to an output (`FILE.tmp-PID-N`, `DIR.tmp-PID-N`) are
// registered here, so that SIGINT, SIGTERM and SIGHUP remove them before the process exits (status 128 +
// signal: 130, 143, 129), and a later run removes those a killed process (SIGKILL) left behind.
#pragma once

#include <string>

namespace hamel {

/// Installs the SIGINT/SIGTERM/SIGHUP handlers that remove the registered temporaries and _exit(128 + sig).
void install_cleanup_signal_handlers();

/// A fresh temporary name beside `target`: "<target>.tmp-<pid>-<random>".
std::string temporary_name_for(const std::string& target);

/// Registers a temporary file or folder (a flat folder: its entries are unlinked, then it is removed) for
/// removal on a signal; returns a slot for unregister_temporary, or -1 when all slots are taken.
int register_temporary(const std::string& path, bool is_folder);
void unregister_temporary(int slot);

/// Removes "<target>.tmp-<pid>-<n>" and "<target>.old-<pid>-<n>" siblings of `target` whose process <pid>
/// no longer runs: debris of a run that was killed without a chance to clean up.
void sweep_stale_temporaries(const std::string& target);

}  // namespace hamel
