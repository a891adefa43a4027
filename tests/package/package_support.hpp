// Helpers of the package tests: running commands, scratch folders, reading files, emitting packages with
// the real `hamel` binary and building emitted packages as standalone CMake projects.
#pragma once

#include "support/command.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace hamel::package_test {

namespace fs = std::filesystem;

// The repository's files, running a command and reading a file whole: as every command-line test does
// (support/command.hpp); the package tests capture stderr with stdout.
using hamel::test::Outcome;
using hamel::test::slurp;
using hamel::test::source;

/// Runs `command` through the shell, capturing stdout and stderr.
inline Outcome run(const std::string& command) { return hamel::test::run(command + " 2>&1"); }

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// A fresh folder for one test, removed when the object goes out of scope.
class Scratch {
 public:
  explicit Scratch(const std::string& name)
      : dir_(fs::temp_directory_path() / ("hamel_package_test_" + std::to_string(::getpid())) / name) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
    fs::remove(dir_.parent_path(), ec);  // only when empty
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return dir_; }

 private:
  fs::path dir_;
};

/// `hamel emit SOURCE -o OUT FLAGS`; returns the combined output on failure for the assertion message.
inline Outcome emit(const std::string& source_file, const std::string& flags, const fs::path& out) {
  return run(quote(HAMEL_BINARY) + " emit " + quote(source_file) + " -o " + quote(out.string()) + " " + flags);
}

/// Configures and builds the CMake project in `project` into `build` with compiler `cxx`, CXXFLAGS `flags`
/// and the cache entries `defines`.
inline Outcome cmake_build(const std::string& project, const fs::path& build, const std::string& cxx,
                           const std::string& flags, const std::map<std::string, std::string>& defines) {
  std::string configure = quote(HAMEL_CMAKE) + " -S " + quote(project) + " -B " + quote(build.string()) +
                          " -DCMAKE_CXX_COMPILER=" + quote(cxx) + " -DCMAKE_CXX_FLAGS=" + quote(flags) +
                          " -DCMAKE_BUILD_TYPE=";
  for (const auto& [name, value] : defines) configure += " -D" + name + "=" + quote(value);
  const Outcome c = run(configure);
  if (c.status != 0) return {c.status, "configure failed:\n" + c.out};
  const Outcome b = run(quote(HAMEL_CMAKE) + " --build " + quote(build.string()) + " -j2");
  if (b.status != 0) return {b.status, "build failed:\n" + b.out};
  return b;
}

/// A line of generated/packages.txt: the folder under generated/, the model or scene file (relative to the
/// repository) and the `hamel emit` flags.
struct ListedPackage {
  std::string folder, source, flags;
};

inline std::vector<ListedPackage> listed_packages() {
  std::vector<ListedPackage> list;
  std::istringstream lines(slurp(source("generated/packages.txt")));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    ListedPackage p;
    if (!(words >> p.folder) || p.folder[0] == '#') continue;
    words >> p.source;
    for (std::string w; words >> w;) p.flags += (p.flags.empty() ? "" : " ") + w;
    list.push_back(p);
  }
  return list;
}

inline ListedPackage listed_package(const std::string& folder) {
  for (const ListedPackage& p : listed_packages())
    if (p.folder == folder) return p;
  ADD_FAILURE() << folder << " is not listed in generated/packages.txt";
  return {};
}

/// The flags firmware would use; the package must compile cleanly with them.
constexpr const char* strict_flags = "-O2 -fno-exceptions -fno-rtti -Wall -Wextra -Werror -pedantic";

}  // namespace hamel::package_test
