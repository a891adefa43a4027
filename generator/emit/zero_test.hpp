// Values of a program that vanish identically, found exactly with high probability and printed as 0. A
// derivation can hold values that are zero as functions but not by their structure: a forward-mode Jacobian
// differentiates through every coordinate the program reads, also those the dynamics do not depend on (the
// Whipple bicycle's yaw and wheel angles: its accelerations read them through the bodies' poses, and the
// derivatives cancel). Those columns cost as much as any other; dropped, they cost nothing.
//
// The test is Schwartz–Zippel modulo the prime p = 2^61 − 1, as in algebra/identity_test but on the IR (the IR's
// interpreter, emit/interpreter.hpp, in residues): every argument (t, x, p, in) gets a random residue; sin and cos of
// an angle read a random point (c, s) of the circle c² + s² = 1, the angle being an integer combination of arguments
// and other nodes whose points multiply in the circle group (so sin² + cos² = 1 and the addition theorems hold
// exactly); any other function of a node (sqrt, exp, atan, abs, a non-integer power, …) is a free variable of its own.
// Constants are the doubles of the graph, read as the rationals they are. Reading a function as a free variable only
// forgets relations: a value zero in that freer model is zero for the program, so the test can miss a zero but not
// invent one. A value that is not zero vanishes at a random point with probability at most d/p for a rational function
// of degree d; the test asks three points (and a division by a residue 0 makes the answer "not shown zero").
#pragma once

#include "emit/expression_graph.hpp"

#include <array>
#include <memory>
#include <vector>

namespace hamel {

class ResidueArithmetic;
template <class Arithmetic>
class Interpreter;

/// "Is node i identically zero as a function of the arguments?" (see above). Shares the evaluations between calls;
/// the graph may grow between them.
class ZeroTest {
 public:
  explicit ZeroTest(const ExpressionGraph& g);
  ~ZeroTest();
  bool operator()(int node);

 private:
  std::array<std::unique_ptr<Interpreter<ResidueArithmetic>>, 3> points_;  ///< the IR in residues at three points
};

/// `outputs` with every operation that vanishes identically (ZeroTest) replaced by the constant 0 and the program
/// above rebuilt, so what only fed those values is gone.
std::vector<int> without_identical_zeros(ExpressionGraph& g, const std::vector<int>& outputs);

}  // namespace hamel
