// Running build/bin/hamel (or $HAMEL_BINARY) from tests: exit status, stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hamel_test {

namespace fs = std::filesystem;

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void spit(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string hamel_binary() {
  const char* v = std::getenv("HAMEL_BINARY");
#ifdef HAMEL_BINARY
  return v && *v ? v : HAMEL_BINARY;
#else
  return v && *v ? v : "build/bin/hamel";
#endif
}

struct Outcome {
  int status = -1;
  std::string out, err;
};

/// Runs `command` (a shell command line) with stdout and stderr captured through files in `scratch`.
inline Outcome run_command(const std::string& command, const fs::path& scratch) {
  const fs::path out = scratch / ".stdout", err = scratch / ".stderr";
  const std::string line =
      command + " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string()) + " </dev/null";
  const int raw = std::system(line.c_str());
  Outcome r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

/// Runs hamel with `args` (already shell-quoted where needed).
inline Outcome hamel(const std::string& args, const fs::path& scratch) {
  return run_command(shell_quote(hamel_binary()) + " " + args, scratch);
}

/// A fresh, empty folder for one test.
inline fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hamel_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace hamel_test
