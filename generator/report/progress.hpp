// Progress of long steps on stderr: a step that has run for a second announces itself ("hamel: deriving
// the mechanical connection A = L^-1 K ... (1.0 s)"), and on completion says how long it took and the
// sizes it reached. Short runs print nothing. `--quiet` switches it off. A watcher thread does the
// announcing, so a step that hangs in one GiNaC call is still named.
#pragma once

#include <string>

namespace hamel::progress {

void set_enabled(bool enabled);

/// "hamel: <what> ..." on stderr now, unless progress is switched off: the start of a step that is long on large
/// models (a derivation, an integration), said at once so that the user knows what the command does first.
void say(const std::string& what);

/// Whether progress is switched on (no `--quiet`): for commands that report their progress through a stream.
bool enabled();

/// One step, from construction to destruction; steps nest (the innermost is the one announced).
class Step {
 public:
  explicit Step(std::string what);
  ~Step();
  Step(const Step&) = delete;
  Step& operator=(const Step&) = delete;
  /// Sizes so far ("412 intermediates"), shown when the step is announced or finishes.
  void detail(std::string text);

 private:
  int id_;
};

}  // namespace hamel::progress
