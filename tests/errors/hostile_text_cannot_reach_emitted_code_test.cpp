// Safe output: no text from a model file reaches emitted code except validated identifiers and
// generated numbers. Hostile names are rejected with exit status 2 and a one-line message; hostile
// descriptions and file names (comment terminators, newlines, carriage returns, backslash line splices,
// the trigraph ??/) yield code that compiles, with trigraphs enabled too, and carries no injected line.
#include "run_hamel.hpp"

#include <gtest/gtest.h>

#include <vector>

#ifndef HAMEL_CXX
#define HAMEL_CXX "c++"
#endif

namespace {

using namespace hamel_test;

std::string model_text(const std::string& name_line, const std::string& extra = "") {
  return name_line + "\n" + extra +
         "parameters: {m: 1}\n"
         "coordinates: [x]\n"
         "quasi_velocities: {names: [u], A: [[1]]}\n"
         "lagrangian: \"m/2*x_dot^2\"\n";
}

// Compiles `source` (with `include_dir` on the include path) in the strictest and the most permissive
// modes that matter: C++17 with warnings as errors, and C++11 in GNU mode with trigraphs on.
void expect_compiles(const fs::path& source, const fs::path& include_dir, const fs::path& scratch) {
  for (const std::string flags :
       {"-std=c++17 -Wall -Wextra -pedantic -Werror", "-std=gnu++11 -trigraphs -Wall -Wextra -Werror"}) {
    const Outcome r = run_command(std::string(HAMEL_CXX) + " " + flags + " -fsyntax-only -I" +
                                      shell_quote(include_dir.string()) + " " + shell_quote(source.string()),
                                  scratch);
    EXPECT_EQ(r.status, 0) << flags << " " << source << "\n" << r.err;
  }
}

// Every line that mentions the payload's marker word is a // comment with no way to continue.
void expect_no_injection(const std::string& code, const std::string& marker) {
  std::istringstream lines(code);
  std::string line;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.find('\r'), std::string::npos);
    if (!line.empty()) {
      EXPECT_NE(line.back(), '\\') << line;
    }
    EXPECT_EQ(line.find("?\?/"), std::string::npos) << line;
    if (line.find(marker) != std::string::npos) {
      EXPECT_EQ(line.rfind("//", 0), 0u) << "injected: " << line;
    }
  }
}

TEST(HostileText, HostileNamesAreRejectedWithOneLineMessages) {
  const fs::path dir = scratch_dir("hostile_names");
  const std::vector<std::string> names = {
      R"(name: "x; int injected_1; namespace y")",
      R"(name: "sleigh\nint injected_2;")",
      R"(name: "sleigh */ int injected_3; /*")",
      R"(name: "sleigh\\")",
      "name: \"sl\\x1b[31meigh\"",
      "name: \"sl\\reigh\"",
      "name: sleigh?\?/",
      "name: linux",
      "name: std",
      "name: main",
      "name: floor",
      "name: NAN",
      "name: class",
      "name: _Sleigh",
      "name: a__b",
      "name: \"\\u00e9t\\u00e9\"",
      "name: \"\"",
  };
  for (const std::string& name : names) {
    spit(dir / "m.yaml", model_text(name));
    const Outcome r =
        hamel("emit " + shell_quote((dir / "m.yaml").string()) + " -o " + shell_quote((dir / "out").string()), dir);
    EXPECT_EQ(r.status, 2) << name << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir / "out")) << name;
    EXPECT_EQ(r.err.find("\x1b"), std::string::npos) << "escape sequences must be shown escaped: " << r.err;
    EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(": error: 'name': "), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  }
  fs::remove_all(dir);
}

TEST(HostileText, HostileDescriptionAndFileNameCannotInjectCode) {
  const fs::path dir = scratch_dir("hostile_description");
  const std::string description =
      "description: \"*/ int injected_d1 = 1; /*\\n#error injected_d2\\n"
      "a comment ending in a splice \\\\\\nint injected_d3;\\n"
      "a trigraph splice ?\?/\\nint injected_d4;\\r#error injected_d5\\n"
      "// \\\\\\n int injected_d6;\"\n";
  // A file name cannot hold '/', so neither "*/" nor "??/"; the rest of the payload fits.
  const std::string file_name = "evil * int injected_f1; \\\n#error injected_f2\r#error injected_f3 \\\n.yaml";
  spit(dir / file_name, model_text("name: hostile", description));
  const Outcome r =
      hamel("emit " + shell_quote((dir / file_name).string()) + " -o " + shell_quote((dir / "out").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file : {"hostile.hpp", "hostile.cpp"}) {
    SCOPED_TRACE(file);
    expect_no_injection(slurp(dir / "out" / file), "injected");
  }
  spit(dir / "use.cpp",
       "#include <cmath>\n#include \"hostile.hpp\"\n"
       "int main() { double out[1]; hostile::energy(0, nullptr, hostile::default_parameters, nullptr, out); }\n");
  expect_compiles(dir / "out" / "hostile.cpp", dir / "out", dir);
  expect_compiles(dir / "use.cpp", dir / "out", dir);
  fs::remove_all(dir);
}

TEST(HostileText, NamesLikeEmittedInternalsStillCompile) {
  const fs::path dir = scratch_dir("internal_names");
  for (const std::string name : {"real", "rhs", "energy", "n_state", "hamel", "cmath", "x", "HAMEL_REAL"}) {
    SCOPED_TRACE(name);
    const fs::path out = dir / ("out_" + name);
    spit(dir / "m.yaml", model_text("name: " + name));
    const Outcome r = hamel("emit " + shell_quote((dir / "m.yaml").string()) + " -o " + shell_quote(out.string()), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    spit(out / "use.cpp",
         "#include <cmath>\n#include \"" + name + ".hpp\"\nint main() { return " + name + "::n_state - 2; }\n");
    expect_compiles(out / (name + ".cpp"), out, dir);
    expect_compiles(out / "use.cpp", out, dir);
  }
  fs::remove_all(dir);
}

}  // namespace
