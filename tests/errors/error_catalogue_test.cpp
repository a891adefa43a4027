// The catalogue of malformed inputs (tests/errors/cases/*.yaml, see tests/errors/README.md), run
// through the real binary: every case must exit with the status it expects (2), name the file, line
// and column (or, for command-line mistakes, the option), say what was wrong and what was expected on
// stderr, print nothing on stdout and write no output: the folder given to -o (or the file given to
// --out) does not exist afterwards and the scratch folder around it holds no temporary leftovers.
//
// A case is one file; its leading comment lines state the expectation:
//   # expect-line: 12          line of the error, or "none" for an error in a command-line value
//   # expect-column: 5         optional
//   # expect-key: lagrangian   optional; the key named in the message (quoted)
//   # expect-message: text     substring of the message; repeat the line for several substrings
//   # expect-args: ARGS        optional, default "emit {model} -o {out}"; {model} is the case file,
//                              {out} a path in an empty scratch folder that must stay unused
//   # expect-exit: 2           optional, default 2
// The build relinks this test when a case file is added (CMakeLists.txt), so a new file needs no
// other change.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#ifndef HAMEL_ERROR_CASES_DIR
#define HAMEL_ERROR_CASES_DIR "tests/errors/cases"
#endif

namespace {

namespace fs = std::filesystem;

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

fs::path cases_dir() {
  const char* source = std::getenv("HAMEL_SOURCE_DIR");
  return source ? fs::path(source) / "tests/errors/cases" : fs::path(HAMEL_ERROR_CASES_DIR);
}

std::string binary() {
#ifdef HAMEL_BINARY
  return env_or("HAMEL_BINARY", HAMEL_BINARY);
#else
  return env_or("HAMEL_BINARY", "build/bin/hamel");
#endif
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct Case {
  fs::path file;
  std::string line, column, key, args = "emit {model} -o {out}";
  int exit_status = 2;
  std::vector<std::string> messages;
  std::string problem;  // a malformed header
};

Case read_case(const fs::path& file) {
  Case c;
  c.file = file;
  std::istringstream in(slurp(file));
  std::string text;
  while (std::getline(in, text) && !text.empty() && text[0] == '#') {
    // "# expect-WHAT: VALUE"
    const std::size_t start = text.find_first_not_of("# \t");
    const std::size_t colon = text.find(':');
    if (start == std::string::npos || text.compare(start, 7, "expect-") != 0 || colon == std::string::npos) continue;
    const std::string what = text.substr(start + 7, colon - start - 7);
    std::string value = text.substr(colon + 1);
    value.erase(0, value.find_first_not_of(" \t"));
    value.erase(value.find_last_not_of(" \t\r") + 1);
    if (what == "line")
      c.line = value;
    else if (what == "column")
      c.column = value;
    else if (what == "key")
      c.key = value;
    else if (what == "message")
      c.messages.push_back(value);
    else if (what == "args")
      c.args = value;
    else if (what == "exit")
      c.exit_status = std::atoi(value.c_str());
    else
      c.problem = "unknown directive expect-" + what;
  }
  if (c.messages.empty()) c.problem = "no '# expect-message:' line";
  if (c.line.empty()) c.problem = "no '# expect-line:' line (a number, or none)";
  return c;
}

std::vector<fs::path> case_files() {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(cases_dir(), ec))
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

class ErrorCatalogue : public ::testing::TestWithParam<fs::path> {};

TEST_P(ErrorCatalogue, ExitsTwoNamesFileLineAndKeyWritesNothing) {
  const Case c = read_case(GetParam());
  ASSERT_TRUE(c.problem.empty()) << c.file << ": " << c.problem;

  const fs::path scratch =
      fs::temp_directory_path() / ("hamel_errors_" + std::to_string(::getpid()) + "_" + c.file.stem().string());
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  const fs::path out = scratch / "out";
  const std::string model = c.file.string();
  std::string args = replace_all(c.args, "{model}", shell_quote(model));
  args = replace_all(args, "{out}", shell_quote(out.string()));
  const std::string command = shell_quote(binary()) + " " + args + " >" + shell_quote((scratch / "stdout").string()) +
                              " 2>" + shell_quote((scratch / "stderr").string()) + " </dev/null";
  const int raw = std::system(command.c_str());
  const int status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  const std::string out_text = slurp(scratch / "stdout"), err = slurp(scratch / "stderr");
  SCOPED_TRACE("command: " + command + "\nstderr: " + err);

  EXPECT_EQ(status, c.exit_status);
  EXPECT_EQ(out_text, "") << "nothing may be printed on stdout";
  EXPECT_EQ(err.find("internal error"), std::string::npos);
  // The error is the line with ": error: " (emit may print progress before it).
  const std::size_t error_at = err.find(": error: ");
  const std::size_t line_start = error_at == std::string::npos ? 0 : err.rfind('\n', error_at) + 1;
  const std::string error_line = err.substr(line_start, err.find('\n', line_start) - line_start);
  if (c.line != "none") {
    std::string location = model + ":" + c.line + ":";
    if (!c.column.empty()) location += c.column + ":";
    EXPECT_EQ(error_line.rfind(location, 0), 0u) << "the error line must start with " << location;
  }
  if (!c.key.empty()) {
    EXPECT_NE(err.find("'" + c.key + "'"), std::string::npos) << "key " << c.key;
  }
  for (const std::string& m : c.messages) EXPECT_NE(err.find(m), std::string::npos) << "message " << m;

  // Nothing written: neither the output nor any temporary file next to it.
  EXPECT_FALSE(fs::exists(out)) << out;
  for (const auto& e : fs::directory_iterator(scratch)) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(name == "stdout" || name == "stderr") << "left behind: " << e.path();
  }
  fs::remove_all(scratch);
}

std::string case_name(const ::testing::TestParamInfo<fs::path>& info) {
  std::string name = info.param.stem().string();
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Cases, ErrorCatalogue, ::testing::ValuesIn(case_files()), case_name);

TEST(ErrorCatalogueSize, HasAtLeastFortyCases) { EXPECT_GE(case_files().size(), 40u) << cases_dir(); }

}  // namespace
