// The firmware check (issue 47): emitted packages and the runtime as firmware uses them, with Debian's
// arm-none-eabi-gcc and qemu-system-arm.
// - A small (double_pendulum) and a large (space_robot) shipped package compile for a Cortex-M4F in float and a
//   Cortex-M7 in double under strict flags; their objects call nothing but the C library's memory functions and
//   libm of their own precision (no heap, exceptions, unwinding, stdio, and in float no double function or
//   soft-float double helper __aeabi_d*), and no kernel has a conditional branch or an IT block.
// - Square roots: with -fno-math-errno (set by every emitted CMakeLists.txt) a kernel taking sqrt stays branch-free;
//   without it GCC adds a compare, a branch and a libm call (the reason for the flag).
// - A float package integrates with the runtime's RK4, DOPRI5, DOP853 and Radau5 (package Jacobian and finite
//   differences) on a Cortex-M4F under QEMU (mps2-an386) in a heap-free image, and a double one on a Cortex-M7
//   (mps2-an500); both agree with the same program built for the host to a few ulps of the state.
// - Stack: the Whipple bicycle (emitted with --split 1000) runs every kernel's work-space form in at most 2 KB of
//   stack on the M4F in float and on the M7 in double, and it and double_pendulum take at most the stack
//   docs/firmware.md documents for them, kernel by kernel (its table, tools/firmware-table.sh), so the page cannot go
//   stale.
// Without the toolchain or QEMU the cases skip (GTEST_SKIP); tools/install-deps.sh installs them for CI.
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using hamel::test::Outcome;
using hamel::test::slurp;
using hamel::test::source;

Outcome run(const std::string& command) { return hamel::test::run(command + " 2>&1"); }

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

const std::string gxx = HAMEL_ARM_GXX, nm = HAMEL_ARM_NM, objdump = HAMEL_ARM_OBJDUMP, qemu = HAMEL_QEMU_ARM;

bool have_toolchain() { return !gxx.empty() && !nm.empty() && !objdump.empty(); }

#define REQUIRE_TOOLCHAIN() \
  if (!have_toolchain()) GTEST_SKIP() << "arm-none-eabi-gcc not found (tools/install-deps.sh installs it)"
#define REQUIRE_QEMU() \
  REQUIRE_TOOLCHAIN(); \
  if (qemu.empty()) GTEST_SKIP() << "qemu-system-arm not found (tools/install-deps.sh installs it)"

/// A fresh folder for one test, removed when the object goes out of scope.
class Scratch {
 public:
  explicit Scratch(const std::string& name)
      : dir_(fs::temp_directory_path() / ("hamel_firmware_test_" + std::to_string(::getpid())) / name) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
    fs::remove(dir_.parent_path(), ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  std::string path() const { return dir_.string(); }

 private:
  fs::path dir_;
};

/// A Cortex-M target: its flags, its QEMU machine and the scalar type its packages are built with.
struct Target {
  std::string name, flags, machine, real;
};
const Target m4f{"m4f", "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb", "mps2-an386", "float"};
const Target m7{"m7", "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb", "mps2-an500", "double"};

// What a firmware engineer compiles with: warnings as errors (with -Wdouble-promotion: no float silently widened to
// double), no exceptions or RTTI, and the two flags the emitted CMakeLists.txt sets.
const std::string strict =
    "-std=c++17 -O2 -Wall -Wextra -Werror -pedantic -Wdouble-promotion -fno-exceptions -fno-rtti "
    "-fno-math-errno -ffp-contract=off -ffunction-sections -fdata-sections";

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string real_define(const std::string& package, const Target& t) {
  return "-DHAMEL_" + upper(package) + "_REAL=" + t.real;
}

/// Symbols of an object or image: nm's undefined ones (`undefined`) or all.
std::vector<std::string> symbols(const std::string& file, bool undefined) {
  const Outcome o = run(quote(nm) + (undefined ? " -u " : " ") + quote(file));
  EXPECT_EQ(o.status, 0) << o.out;
  std::vector<std::string> names;
  std::istringstream lines(o.out);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t space = line.find_last_of(' ');
    if (!line.empty()) names.push_back(space == std::string::npos ? line : line.substr(space + 1));
  }
  return names;
}

// Never in firmware: the heap, exceptions and unwinding, RTTI, stdio.
const std::regex forbidden(
    "malloc|_malloc_r|calloc|realloc|free|_free_r|_sbrk|_sbrk_r|_Zn[wa].*|_Zd[la].*|__cxa_.*|_Unwind_.*|"
    "__gxx_personality.*|__aeabi_unwind_cpp_pr.*|_ZTI.*|_ZTS.*|printf|_printf_r|puts|fwrite|fputs|_write|_write_r");
// Double arithmetic in software (the soft-float helpers), or double libm functions, in a float build.
const std::regex double_precision(
    "__aeabi_d.*|__aeabi_[fil]2d|__aeabi_ul2d|__(add|sub|mul|div|extendsf|truncdfsf)[a-z]*df[a-z0-9]*|"
    "(sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|exp|expm1|log|log1p|log10|pow|sqrt|cbrt|hypot|fabs|floor|ceil|"
    "fmod|fmax|fmin|round|trunc|copysign|__ieee754_[a-z0-9]*[^f]|__kernel_(sin|cos|tan|rem_pio2))");

/// The symbols of `names` that firmware must not have (for a float build also double-precision ones).
std::vector<std::string> unwanted(const std::vector<std::string>& names, bool float_build) {
  std::vector<std::string> bad;
  for (const std::string& n : names)
    if (std::regex_match(n, forbidden) || (float_build && std::regex_match(n, double_precision))) bad.push_back(n);
  return bad;
}

/// Functions of an object (demangled names) with conditional branches or IT blocks, and how many.
std::map<std::string, int> branching_functions(const std::string& object) {
  const Outcome o = run(quote(objdump) + " -d --no-show-raw-insn -C " + quote(object));
  EXPECT_EQ(o.status, 0) << o.out;
  static const std::regex function("^[0-9a-f]+ <(.*)>:$");
  static const std::regex conditional(
      "^\\s+[0-9a-f]+:\\s+(b(eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le)(\\.w|\\.n)?|cbn?z|it[te]*)\\s.*");
  std::map<std::string, int> found;
  std::string current;
  std::istringstream lines(o.out);
  std::smatch m;
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_match(line, m, function))
      current = m[1];
    else if (std::regex_match(line, conditional))
      ++found[current];
  }
  return found;
}

/// The package's kernels must be branch-free: only rhs_status (checks) and rk4_step (loops over the state) branch.
std::vector<std::string> branching_kernels(const std::string& object) {
  std::vector<std::string> bad;
  for (const auto& [name, count] : branching_functions(object))
    if (name.find("::rhs_status(") == std::string::npos && name.find("::rk4_step(") == std::string::npos)
      bad.push_back(name + " (" + std::to_string(count) + ")");
  return bad;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

TEST(Firmware, EmittedBuildsSetTheFirmwareFlags) {
  int packages = 0;
  for (const auto& entry : fs::directory_iterator(source("generated"))) {
    if (!entry.is_directory()) continue;
    ++packages;
    const std::string cmake = slurp(entry.path() / "CMakeLists.txt"), readme = slurp(entry.path() / "README.md");
    EXPECT_NE(cmake.find("PRIVATE -fno-math-errno -ffp-contract=off)"), std::string::npos) << entry.path();
    EXPECT_NE(readme.find("`-fno-math-errno`"), std::string::npos) << entry.path();
    EXPECT_NE(readme.find("`-ffp-contract=off`"), std::string::npos) << entry.path();
    // GCC's first scheduling pass off: what keeps long kernels' stack small on Arm (WorkSpaceForms... below).
    int sources = 0;
    for (const auto& file : fs::directory_iterator(entry.path())) {
      if (file.path().extension() != ".cpp") continue;
      // The Python module's batch loops (emit --python, <name>_python.cpp) run on the host only: no kernel there.
      const std::string stem = file.path().stem().string();
      if (stem.size() > 7 && stem.compare(stem.size() - 7, 7, "_python") == 0) continue;
      ++sources;
      EXPECT_NE(slurp(file.path()).find("#pragma GCC optimize(\"no-schedule-insns\")"), std::string::npos)
          << file.path();
    }
    EXPECT_EQ(sources, 1) << entry.path();
  }
  EXPECT_GE(packages, 20);
}

TEST(Firmware, KernelsCompileStrictWithNothingForbiddenAndNoBranch) {
  REQUIRE_TOOLCHAIN();
  Scratch dir("kernels");
  // Both targets of a package compile at once (the large one takes ~20 s each).
  for (const char* package : {"double_pendulum", "space_robot"}) {
    const std::string cpp = source("generated/" + std::string(package) + "/" + package + ".cpp");
    std::string both;
    for (const Target* t : {&m4f, &m7})
      both += quote(gxx) + " " + strict + " " + t->flags + " " + real_define(package, *t) + " -c " + quote(cpp) +
              " -o " + quote(dir.path() + "/" + package + "." + t->name + ".o") + " > " +
              quote(dir.path() + "/" + package + "." + t->name + ".log") + " 2>&1 & ";
    const Outcome compiled = run("(" + both + "wait)");
    ASSERT_EQ(compiled.status, 0) << compiled.out;
    for (const Target* t : {&m4f, &m7}) {
      SCOPED_TRACE(std::string(package) + " on " + t->name + " (" + t->real + ")");
      const std::string object = dir.path() + "/" + package + "." + t->name + ".o";
      ASSERT_TRUE(fs::exists(object)) << slurp(dir.path() + "/" + package + "." + t->name + ".log");
      EXPECT_EQ(slurp(dir.path() + "/" + package + "." + t->name + ".log"), "");  // not even a warning
      const std::vector<std::string> calls = symbols(object, true);
      EXPECT_EQ(joined(unwanted(calls, t->real == "float")), "");
      // Only memory functions and libm of the package's precision: sinf/cosf in float, sin/cos in double.
      for (const std::string& c : calls)
        EXPECT_TRUE(std::regex_match(
            c, std::regex(t->real == "float" ? "mem(cpy|set|move)|[a-z0-9]+f" : "mem(cpy|set|move)|[a-z0-9]+")))
            << c;
      EXPECT_EQ(joined(branching_kernels(object)), "");
      std::printf("%s on %s: calls %s; kernels branch-free\n", package, t->name.c_str(), joined(calls).c_str());
    }
  }
}

// A pendulum with a potential whose force takes a square root of the state: sqrt in rhs, jacobian and energy.
const char* sqrt_model = R"yaml(schema: 1
name: sqrt_pendulum
description: a pendulum in a potential k sqrt(1 + theta^2), for square roots in kernels
parameters:
  k: 2.0
coordinates: [theta]
quasi_velocities:
  names: [omega]
  A:
    - [1]
lagrangian: "1/2*theta_dot^2 - k*sqrt(1 + theta^2)"
)yaml";

TEST(Firmware, SquareRootsAreBranchFreeWithoutMathErrno) {
  REQUIRE_TOOLCHAIN();
  Scratch dir("sqrt");
  std::ofstream(dir.path() + "/sqrt_pendulum.yaml") << sqrt_model;
  const Outcome e = run(quote(HAMEL_BINARY) + " emit " + quote(dir.path() + "/sqrt_pendulum.yaml") + " -o " +
                        quote(dir.path() + "/pkg"));
  ASSERT_EQ(e.status, 0) << e.out;
  ASSERT_NE(slurp(dir.path() + "/pkg/sqrt_pendulum.cpp").find("std::sqrt"), std::string::npos);
  for (const Target* t : {&m4f, &m7}) {
    SCOPED_TRACE(t->name);
    const std::string base = quote(gxx) + " " + t->flags + " " + real_define("sqrt_pendulum", *t) + " -c " +
                             quote(dir.path() + "/pkg/sqrt_pendulum.cpp") + " -o ";
    const std::string with = dir.path() + "/with." + t->name + ".o",
                      without = dir.path() + "/without." + t->name + ".o";
    const Outcome a = run(base + quote(with) + " " + strict);
    ASSERT_EQ(a.status, 0) << a.out;
    EXPECT_EQ(joined(branching_kernels(with)), "");
    const std::vector<std::string> calls = symbols(with, true);
    for (const std::string& c : calls) EXPECT_EQ(c.find("sqrt"), std::string::npos) << c;  // the FPU's vsqrt
    // The same without -fno-math-errno: a branch around a libm call that would set errno.
    std::string errno_flags = strict;
    errno_flags.replace(errno_flags.find("-fno-math-errno"), std::strlen("-fno-math-errno"), "-fmath-errno");
    const Outcome b = run(base + quote(without) + " " + errno_flags);
    ASSERT_EQ(b.status, 0) << b.out;
    EXPECT_NE(joined(branching_kernels(without)), "");
  }
}

// The kernels by inputs and parameters (built only when named) of a tree whose parameters reach every part of the
// recursion, their columns solved by the articulated-body recursion as called functions, split into parts: strict,
// nothing forbidden, no branch, in float and double.
TEST(Firmware, KernelsByInputsAndParametersCompileStrictWithNoBranch) {
  REQUIRE_TOOLCHAIN();
  Scratch dir("by_inputs_and_parameters");
  const Outcome e =
      run(quote(HAMEL_BINARY) + " -q emit " + quote(source("tests/kernels/sensitivity/sensitivity_arm.yaml")) + " -o " +
          quote(dir.path() + "/pkg") +
          " --kernels rhs,input_jacobian,parameter_jacobian --jacobian-solve aba --split 40 2>&1");
  ASSERT_EQ(e.status, 0) << e.out;
  const std::string cpp = slurp(dir.path() + "/pkg/sensitivity_arm.cpp");
  ASSERT_NE(cpp.find("input_jacobian_column("), std::string::npos) << "no called solve: this test would not test it";
  for (const Target* t : {&m4f, &m7}) {
    SCOPED_TRACE(t->name);
    const std::string object = dir.path() + "/arm." + t->name + ".o";
    const Outcome c = run(quote(gxx) + " " + strict + " " + t->flags + " " + real_define("sensitivity_arm", *t) +
                          " -c " + quote(dir.path() + "/pkg/sensitivity_arm.cpp") + " -o " + quote(object) + " 2>&1");
    ASSERT_EQ(c.status, 0) << c.out;
    EXPECT_EQ(c.out, "");  // not even a warning
    EXPECT_EQ(joined(unwanted(symbols(object, true), t->real == "float")), "");
    EXPECT_EQ(joined(branching_kernels(object)), "");
  }
}

/// Per kernel, as tests/firmware/measure.cpp prints it: n_work, stack, stack of the work-space form, instructions.
using KernelFigures = std::map<std::string, std::vector<unsigned long>>;

/// Builds tests/firmware/measure.cpp with the package in `pkg` for each target (at once) and runs it under QEMU.
std::map<std::string, KernelFigures> measure_on(const std::vector<const Target*>& targets, const std::string& package,
                                                const std::string& pkg, const Scratch& dir) {
  const std::string fw = source("tests/firmware");
  std::string all;
  for (const Target* t : targets)
    all += quote(gxx) + " " + strict + " " + t->flags + " " + real_define(package, *t) + " -I" + quote(pkg) + " -I" +
           quote(fw) + " -DPACKAGE=" + package + " '-DPACKAGE_HEADER=\"" + package + ".hpp\"' " +
           quote(fw + "/measure.cpp") + " " + quote(fw + "/startup.cpp") + " " + quote(pkg + "/" + package + ".cpp") +
           " -nostartfiles -T " + quote(fw + "/mps2.ld") +
           " -Wl,--gc-sections --specs=nano.specs --specs=rdimon.specs -lm -o " +
           quote(dir.path() + "/" + package + "." + t->name + ".elf") + " > " +
           quote(dir.path() + "/" + package + "." + t->name + ".log") + " 2>&1 & ";
  const Outcome built = run("(" + all + "wait)");
  EXPECT_EQ(built.status, 0) << built.out;
  std::map<std::string, KernelFigures> figures;
  for (const Target* t : targets) {
    const std::string image = dir.path() + "/" + package + "." + t->name + ".elf";
    EXPECT_TRUE(fs::exists(image)) << slurp(dir.path() + "/" + package + "." + t->name + ".log");
    const Outcome measured = run("timeout 300 " + quote(qemu) + " -M " + t->machine +
                                 " -icount shift=0 -nographic -monitor none -serial none "
                                 "-semihosting-config enable=on,target=native -kernel " +
                                 quote(image));
    EXPECT_EQ(measured.status, 0) << measured.out;
    std::printf("%s on the %s in %s: kernel n_work stack stack_with_work instructions\n%s", package.c_str(),
                t->name.c_str(), t->real.c_str(), measured.out.c_str());
    std::istringstream lines(measured.out);
    std::string name;
    unsigned long n_work, stack, stack_work, instructions;
    while (lines >> name >> n_work >> stack >> stack_work >> instructions)
      figures[t->name][name] = {n_work, stack, stack_work, instructions};
  }
  return figures;
}

/// The table of docs/firmware.md (tools/firmware-table.sh) for `package`: per kernel and target (m4f, m7), the
/// documented work, stack and stack of the work-space form.
std::map<std::string, KernelFigures> documented(const std::string& package) {
  static const std::regex row(
      "^\\| (\\w+) \\| `(\\w+)` \\| (\\d+) \\| \\d+ \\| (\\d+) \\((\\d+)\\) \\| \\d+ \\| \\d+ \\| (\\d+) "
      "\\((\\d+)\\) \\|.*");
  std::map<std::string, KernelFigures> table;
  std::istringstream lines(slurp(source("docs/firmware.md")));
  std::smatch m;
  for (std::string line; std::getline(lines, line);) {
    if (!std::regex_match(line, m, row) || m[1] != package) continue;
    table["m4f"][m[2]] = {std::stoul(m[3]), std::stoul(m[4]), std::stoul(m[5])};
    table["m7"][m[2]] = {std::stoul(m[3]), std::stoul(m[6]), std::stoul(m[7])};
  }
  return table;
}

/// Every measured kernel has its row in docs/firmware.md, with its work space, and takes at most the documented
/// stack, with and without the caller's work space: the page cannot go stale.
void expect_documented(const std::map<std::string, KernelFigures>& measured, const std::string& package) {
  const std::map<std::string, KernelFigures> table = documented(package);
  for (const auto& [target, kernels] : measured) {
    for (const auto& [kernel, figures] : kernels) {
      SCOPED_TRACE(package + " " + kernel + " on " + target + " (tools/firmware-table.sh rewrites docs/firmware.md)");
      const auto t = table.find(target);
      ASSERT_TRUE(t != table.end() && t->second.count(kernel)) << "no row in docs/firmware.md";
      const std::vector<unsigned long>& doc = t->second.at(kernel);
      EXPECT_EQ(figures[0], doc[0]);  // n_work
      EXPECT_LE(figures[1], doc[1]);  // stack
      EXPECT_LE(figures[2], doc[2]);  // stack with the caller's work space
    }
  }
}

TEST(Firmware, WorkSpaceFormsRunTheBicycleJacobianInTwoKilobytesOfStack) {
  REQUIRE_QEMU();
  Scratch dir("work");
  // --split 1000, as docs/firmware.md advises for large kernels in double and tools/firmware-table.sh emits it.
  const Outcome e = run(quote(HAMEL_BINARY) + " emit " + quote(source("models/whipple_bicycle.yaml")) +
                        " --fold all --split 1000 -o " + quote(dir.path() + "/whipple_bicycle"));
  ASSERT_EQ(e.status, 0) << e.out;
  const std::map<std::string, KernelFigures> measured =
      measure_on({&m4f, &m7}, "whipple_bicycle", dir.path() + "/whipple_bicycle", dir);
  for (const auto& [target, kernels] : measured) {
    ASSERT_TRUE(kernels.count("jacobian")) << target;
    for (const auto& [kernel, figures] : kernels) {
      SCOPED_TRACE(kernel + " on " + target);
      EXPECT_LE(figures[2], 2048u);  // the work-space form, with the caller's work space
      // A kernel with work keeps its n_work reals on the stack: the work-space form saves that much (to within the
      // 64 bytes by which the stack words a call happens to write may differ between the two).
      const unsigned long real_bytes = target == "m4f" ? 4 : 8;
      if (figures[0] > 0) {
        EXPECT_GE(figures[1] + 64, figures[2] + real_bytes * figures[0]);
      }
    }
    EXPECT_GE(kernels.at("jacobian")[0], 3000u);  // the case that matters: ~3000 values between its parts
  }
  expect_documented(measured, "whipple_bicycle");
}

TEST(Firmware, ShippedPackageTakesAtMostItsDocumentedStack) {
  REQUIRE_QEMU();
  Scratch dir("stack");
  expect_documented(measure_on({&m4f, &m7}, "double_pendulum", source("generated/double_pendulum"), dir),
                    "double_pendulum");
}

/// One line of the integration program's output: its label, status, steps, rhs evaluations and state bits.
struct Run {
  std::string label;
  std::vector<std::string> counts;  // status, steps, rhs evaluations
  std::vector<std::uint64_t> bits;
};

std::vector<Run> parse(const std::string& out) {
  std::vector<Run> runs;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    Run r;
    std::string w, status, steps_word, steps, rhs_word, rhs;
    if (!(words >> r.label >> status >> steps_word >> steps >> rhs_word >> rhs)) continue;
    r.counts = {status, steps, rhs};
    while (words >> w) r.bits.push_back(std::stoull(w, nullptr, 16));
    runs.push_back(r);
  }
  return runs;
}

template <class Real>
Real value(std::uint64_t bits) {
  Real v;
  if constexpr (sizeof(Real) == 4) {
    const auto b = static_cast<std::uint32_t>(bits);
    std::memcpy(&v, &b, 4);
  } else {
    std::memcpy(&v, &bits, 8);
  }
  return v;
}

/// The largest difference between two states, in ulps of the states' largest component.
template <class Real>
double ulps_apart(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  Real scale = 0, worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    scale = std::fmax(scale, std::fabs(value<Real>(a[i])));
    worst = std::fmax(worst, std::fabs(value<Real>(a[i]) - value<Real>(b[i])));
  }
  const Real ulp = std::nextafter(scale, Real(2) * scale + Real(1)) - scale;
  return static_cast<double>(worst / ulp);
}

/// Builds tests/firmware/integrate.cpp with `package` for `t` (an image for QEMU) and for the host, runs both and
/// compares them.
template <class Real>
void integrate_on(const Target& t, const std::string& package, const Scratch& dir) {
  const std::string pkg = source("generated/" + package), fw = source("tests/firmware"),
                    runtime = source("runtime/include");
  const std::string common = real_define(package, t) + " -I" + quote(pkg) + " -I" + quote(runtime) + " -I" + quote(fw) +
                             " -DPACKAGE=" + package + " '-DPACKAGE_HEADER=\"" + package + ".hpp\"' " +
                             quote(fw + "/integrate.cpp") + " " + quote(pkg + "/" + package + ".cpp");
  const std::string image = dir.path() + "/" + package + "." + t.name + ".elf";
  const Outcome built = run(quote(gxx) + " " + strict + " " + t.flags + " " + common + " " +
                            quote(fw + "/startup.cpp") + " -nostartfiles -T " + quote(fw + "/mps2.ld") +
                            " -Wl,--gc-sections --specs=nano.specs --specs=rdimon.specs -lm -o " + quote(image));
  ASSERT_EQ(built.status, 0) << built.out;
  // The whole image: kernels, runtime, libm, start-up. Nothing of the heap, exceptions or stdio; in float nothing of
  // double precision either.
  EXPECT_EQ(joined(unwanted(symbols(image, false), t.real == "float")), "");

  const std::string host = dir.path() + "/" + package + "." + t.name + ".host";
  const Outcome host_built = run("g++ " + strict + " " + common + " " + quote(fw + "/host.cpp") + " -o " + quote(host));
  ASSERT_EQ(host_built.status, 0) << host_built.out;
  const Outcome on_host = run(quote(host));
  ASSERT_EQ(on_host.status, 0) << on_host.out;
  const Outcome on_qemu = run("timeout 120 " + quote(qemu) + " -M " + t.machine +
                              " -nographic -monitor none -serial none -semihosting-config enable=on,target=native "
                              "-kernel " +
                              quote(image));
  ASSERT_EQ(on_qemu.status, 0) << on_qemu.out;
  std::printf("%s on %s under QEMU %s (%s):\n%s", package.c_str(), t.name.c_str(), t.machine.c_str(), t.real.c_str(),
              on_qemu.out.c_str());

  const std::vector<Run> target = parse(on_qemu.out), reference = parse(on_host.out);
  ASSERT_EQ(target.size(), 6u) << on_qemu.out;
  ASSERT_EQ(reference.size(), target.size()) << on_host.out;
  for (std::size_t i = 0; i < target.size(); ++i) {
    SCOPED_TRACE(target[i].label);
    EXPECT_EQ(target[i].label, reference[i].label);
    EXPECT_EQ(target[i].counts[0], "0");  // Status::ok
    EXPECT_EQ(target[i].counts, reference[i].counts);
    ASSERT_EQ(target[i].bits.size(), reference[i].bits.size());
    // Same IEEE arithmetic in the same order (-ffp-contract=off), but the C libraries' sin, cos and pow (newlib's
    // against glibc's) may round differently, and the methods carry that into the state: RK4 and the package's
    // rk4_step by at most an ulp, DOPRI5 and Radau5 with the package's jacobian by a few (a step size one ulp apart).
    // Two carry more (measured: float 15 and 2, double 24 and 15 ulps): DOP853, whose 12 stages per step all pass
    // through sin and cos, and Radau5 with finite differences, whose Jacobian divides rhs differences by
    // sqrt(eps), so that an ulp of libm becomes a different Newton iteration, converged to within its tolerance.
    const std::string label = target[i].label;
    const double bound = label == "dop853" || label == "radau5_fd" ? 64.0 : 4.0;
    const double ulps = ulps_apart<Real>(target[i].bits, reference[i].bits);
    std::printf("  %-10s %s vs host: %.2f ulps of the largest component (at most %.0f)\n", label.c_str(),
                t.real.c_str(), ulps, bound);
    EXPECT_LE(ulps, bound);
  }
}

TEST(Firmware, FloatPackageIntegratesOnCortexM4FLikeOnTheHost) {
  REQUIRE_QEMU();
  Scratch dir("m4f");
  integrate_on<float>(m4f, "double_pendulum", dir);
}

TEST(Firmware, DoublePackageIntegratesOnCortexM7LikeOnTheHost) {
  REQUIRE_QEMU();
  Scratch dir("m7");
  integrate_on<double>(m7, "double_pendulum", dir);
}

}  // namespace
