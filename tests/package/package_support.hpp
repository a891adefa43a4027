// Helpers of the package tests: running commands, scratch folders, reading files, emitting packages with
// the real `hamel` binary and building emitted packages as standalone CMake projects.
#pragma once

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

inline std::string source(const std::string& relative) {
  const char* dir = std::getenv("HAMEL_SOURCE_DIR");
  return std::string(dir ? dir : HAMEL_SOURCE_DIR_DEFAULT) + "/" + relative;
}

struct Outcome {
  int status;
  std::string out;  ///< stdout and stderr together
};

/// Runs `command` through the shell, capturing stdout and stderr.
inline Outcome run(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  std::size_t got;
  while ((got = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), got);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
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
