// A pass over a kernel whose repeated solve is a subroutine (Kernel::calls, a Jacobian's column solves): what the
// kernel computes before its calls, as a program of its own (the stage <kernel>_stage), where it leaves each call's
// arguments, and where the calls leave their results.
#pragma once

#include "emit/expression_graph.hpp"

#include <cstddef>
#include <vector>

namespace hamel {

/// Where a Subroutine's calls leave their results: the subroutine writes them into out[] itself, at the offsets of
/// the first call's results from its first result (a Jacobian's columns: out[0], out[1], out[nx], out[nx + 1], ...),
/// and each call is given out + its first result. Throws std::logic_error unless every call's results lie in that
/// pattern.
std::vector<int> result_offsets(const Subroutine& sub);

/// The stage of a kernel with calls: the outputs no call gives (`direct`: their positions in the kernel's outputs),
/// then the values the calls share, then every call's arguments in turn, lane by lane (`slot`: the position in
/// scratch[] of each output after the direct ones, where a call's arguments lie as its lanes read them). Computing
/// one lane's arguments before the next keeps the stage's depth-first order column by column: with the arguments in
/// their interleaved order instead, g++ -O2 took 7 s longer on the 30-joint chain's rhs and jacobian.
struct StageBeforeCalls {
  Kernel kernel;
  std::vector<std::size_t> direct, slot;
};

/// Kernel k's stage before the calls of `sub`, its subroutine.
StageBeforeCalls stage_before_calls(const Kernel& k, const Subroutine& sub);

}  // namespace hamel
