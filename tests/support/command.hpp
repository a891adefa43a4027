// What the command-line tests share: the repository's files (HAMEL_SOURCE_DIR, which ctest sets), running a
// shell command and capturing its standard output with its exit status, and reading a file whole.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hamel::test {

/// The repository's root: HAMEL_SOURCE_DIR, which ctest sets, else the one the test was built from (test discovery
/// runs the binary without ctest's environment; tests/CMakeLists.txt defines HAMEL_SOURCE_DIR_DEFAULT).
inline std::string source_dir() {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return dir ? dir : HAMEL_SOURCE_DIR_DEFAULT;
}

/// A file of the repository, e.g. source("models/double_pendulum.yaml").
inline std::string source(const std::string& relative) { return source_dir() + "/" + relative; }

struct Outcome {
  int status;       ///< exit status, or −1 when the command did not exit normally
  std::string out;  ///< standard output (stderr only where the command redirects it)
};

/// Runs `command` through the shell.
inline Outcome run(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  std::size_t got;
  while ((got = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), got);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

/// The whole content of a file (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace hamel::test
