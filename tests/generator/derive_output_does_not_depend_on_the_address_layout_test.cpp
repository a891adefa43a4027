// What `hamel derive` prints — text, --json, --latex, with and without --at — depends only on the model. GiNaC keeps
// the terms of sums in an order that follows hash values that include addresses, and with address-space
// randomisation (on by default) the layout changes from run to run; the same derivation must still print byte for
// byte the same text in every run. Before derive printed in a structural order (algebra/expression_text.hpp) and its
// values were computed in one (algebra/high_precision.hpp), every model here printed differently in nearly every
// run unless the binary re-executed itself with randomisation off.
#include "support/command.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

using hamel::test::run;
using hamel::test::source;

std::string quote(const std::string& s) { return "'" + s + "'"; }

TEST(DeriveOutput, IsTheSameInEveryRunWhateverTheAddressLayout) {
  // The premise: the address layout does change between runs (else this test proves nothing).
  std::set<std::string> layouts;
  for (int r = 0; r < 3; ++r) layouts.insert(run("cat /proc/self/maps").out);
  ASSERT_GT(layouts.size(), 1u) << "the address layout was the same in every run (randomisation off on this machine? "
                                   "/proc/sys/kernel/randomize_va_space), so this test proves nothing";

  const std::map<std::string, std::string> at{
      {"double_pendulum", "theta1=0.3,theta2=-0.4,omega1=1.5,omega2=-0.5"},
      {"rolling_ball", "psi=0.3,theta=0.2,phi=0.1,x=0,y=0,vx=1,vy=2"},
      {"heavy_top", "a=0.11,b=0.12,c=0.13,wa=0.14,wb=0.15,wc=0.16,t=0.25"},
      {"rolling_disk_routh", "x=0.11,y=0.12,psi=0.13,theta=0.14,phi=0.15,w_psi=0.16,w_theta=0.17,w_phi=0.18"},
  };
  constexpr int runs = 6;
  for (const auto& [model, point] : at)
    for (const std::string& options :
         std::vector<std::string>{"", "--json --at " + point, "--latex", "--at " + point}) {
      SCOPED_TRACE(model + " " + options);
      std::set<std::string> printed;
      for (int r = 0; r < runs; ++r) {
        const hamel::test::Outcome o =
            run(quote(HAMEL_BINARY) + " -q derive " + quote(source("models/" + model + ".yaml")) + " " + options);
        ASSERT_EQ(o.status, 0) << o.out;
        ASSERT_FALSE(o.out.empty());
        printed.insert(o.out);
      }
      EXPECT_EQ(printed.size(), 1u) << printed.size() << " different outputs in " << runs << " runs";
    }
}

}  // namespace
