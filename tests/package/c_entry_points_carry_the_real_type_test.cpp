// The C entry points' linked names carry the scalar type (<name>.h maps <name>_rhs to <name>_rhs_double or
// <name>_rhs_float): a C caller compiled for one type against the package compiled for the other fails to link,
// naming the missing symbol, instead of passing doubles where the library reads floats (which ran and printed
// 1.9e-60 for 0.245 before, issue 47). Callers with the library's type link and get the C++ kernel's values. The
// committed generated/double_pendulum package, compiled with g++ and called from C11 with gcc.
#include "package_support.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hamel::package_test {
namespace {

const char* caller = R"(#include "double_pendulum.h"

#include <stdio.h>

int main(void) {
  const REAL x[DOUBLE_PENDULUM_N_STATE] = {0.3, -0.7, 0.1, -0.2};
  const REAL p[DOUBLE_PENDULUM_N_PARAMETERS] = {1.0, 1.5, 0.8, 0.6, 9.81};
  REAL out[DOUBLE_PENDULUM_N_OUT_RHS];
  double_pendulum_rhs(0, x, p, NULL, out);
  printf("%.9g %.9g\n", (double)out[2], (double)out[3]);
  return 0;
}
)";

// The same rhs from the C++ entry point, in the library's type.
const char* cxx_caller = R"(#include "double_pendulum.hpp"

#include <cstdio>

int main() {
  const double_pendulum::real x[double_pendulum::n_state] = {0.3, -0.7, 0.1, -0.2};
  const double_pendulum::real p[double_pendulum::n_parameters] = {1.0, 1.5, 0.8, 0.6, 9.81};
  double_pendulum::real out[double_pendulum::n_out_rhs];
  double_pendulum::rhs(0, x, p, nullptr, out);
  std::printf("%.9g %.9g\n", (double)out[2], (double)out[3]);
  return 0;
}
)";

struct Built {
  Outcome link{-1, {}};     // linking the C caller (type `caller_real`) with the library (type `library_real`)
  Outcome run{-1, {}};      // running it, when it linked
  Outcome cxx_run{-1, {}};  // the C++ caller of the same library
};

Built build(const Scratch& dir, const std::string& caller_real, const std::string& library_real) {
  const std::string d = quote(dir.path().string());
  const std::string package = quote(source("generated/double_pendulum"));
  const std::string tag = caller_real + "_" + library_real;
  Built b;
  const Outcome lib = run("cd " + d + " && g++ -std=c++17 -O1 -Wall -Wextra -Werror -pedantic -I" + package +
                          " -DHAMEL_DOUBLE_PENDULUM_REAL=" + library_real + " -c " + package +
                          "/double_pendulum.cpp -o lib_" + tag + ".o");
  EXPECT_EQ(lib.status, 0) << lib.out;
  const Outcome c =
      run("cd " + d + " && gcc -std=c11 -Wall -Wextra -Werror -pedantic -I" + package + " -DREAL=" + caller_real +
          " -DHAMEL_DOUBLE_PENDULUM_REAL=" + caller_real + " -c main.c -o main_" + tag + ".o");
  EXPECT_EQ(c.status, 0) << c.out;
  b.link = run("cd " + d + " && g++ main_" + tag + ".o lib_" + tag + ".o -o c_" + tag + " -lm");
  if (b.link.status == 0) b.run = run("cd " + d + " && ./c_" + tag);
  const Outcome cxx =
      run("cd " + d + " && g++ -std=c++17 -I" + package + " -DHAMEL_DOUBLE_PENDULUM_REAL=" + library_real +
          " main.cpp lib_" + tag + ".o -o cxx_" + tag + " -lm && ./cxx_" + tag);
  EXPECT_EQ(cxx.status, 0) << cxx.out;
  b.cxx_run = cxx;
  return b;
}

TEST(CEntryPoints, MismatchedRealTypeFailsToLinkAndMatchingOneGivesTheKernel) {
  Scratch dir("c_real_type");
  std::ofstream(dir.path() / "main.c") << caller;
  std::ofstream(dir.path() / "main.cpp") << cxx_caller;

  for (const char* real : {"double", "float"}) {
    SCOPED_TRACE(real);
    const Built same = build(dir, real, real);
    ASSERT_EQ(same.link.status, 0) << same.link.out;
    EXPECT_EQ(same.run.status, 0) << same.run.out;
    EXPECT_EQ(same.run.out, same.cxx_run.out);  // the C entry point is the kernel
  }
  const Built float_caller = build(dir, "float", "double");
  EXPECT_NE(float_caller.link.status, 0) << float_caller.link.out;
  EXPECT_NE(float_caller.link.out.find("double_pendulum_rhs_float"), std::string::npos) << float_caller.link.out;
  const Built double_caller = build(dir, "double", "float");
  EXPECT_NE(double_caller.link.status, 0) << double_caller.link.out;
  EXPECT_NE(double_caller.link.out.find("double_pendulum_rhs_double"), std::string::npos) << double_caller.link.out;
}

}  // namespace
}  // namespace hamel::package_test
