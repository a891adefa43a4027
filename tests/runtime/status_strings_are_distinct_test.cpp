// SPDX-License-Identifier: MIT
// describe() gives every status its own non-empty message.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "hamel/runtime/status.hpp"

namespace {

using hamel::runtime::describe;
using hamel::runtime::Status;

TEST(RuntimeStatus, EveryStatusHasADistinctDescription) {
  const Status all[] = {Status::ok,
                        Status::step_size_underflow,
                        Status::non_finite_state,
                        Status::newton_failure,
                        Status::singular_mass_matrix,
                        Status::too_many_steps,
                        Status::invalid_argument,
                        Status::projection_failure,
                        Status::singular_constraint_jacobian};
  std::set<std::string> seen;
  for (const Status s : all) {
    const std::string text = describe(s);
    EXPECT_FALSE(text.empty());
    EXPECT_NE(text, "unknown status");
    seen.insert(text);
  }
  EXPECT_EQ(seen.size(), std::size(all));
  EXPECT_STREQ(describe(Status::step_size_underflow), "step size underflow");
}

}  // namespace
