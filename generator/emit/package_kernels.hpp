// The kernels of a package as C++ text: the work several kernels share planned as stages (emit/shared_stages.hpp)
// and printed once, every kernel printed after the stages it calls (emit/kernel_printer.hpp), rhs_with_pivots for
// rhs_status, and, with prepared parameters, prepare_parameters and the prepared kernels the same way. The package
// writer (emit/package_writer.hpp) puts the text into the package's source and its sizes into the header.
#pragma once

#include "emit/kernel_printer.hpp"
#include "emit/kernels.hpp"

#include <string>
#include <utility>
#include <vector>

namespace hamel {

/// --share-ratio auto (EmitSettings::share_ratio): a package whose kernels print fewer than kLargePackage statements
/// together shares only work of at least kShareRatioSmall statements per value it passes on, which costs no
/// measurable run time; a larger one also work of at least kShareRatioLarge per value: the composite inertias that
/// mass_matrix, connection, shape_inertia and a tree's jacobian all compute (9.5-10 per value on the scaling chains
/// and trees), for mass_matrix 5-21 % slower (docs/emit.md, "Large models: compile time against run time"). The
/// bound is where the unshared package takes about 15 s of g++ -O2 (0.1 ms per statement with the package's pass
/// options, package_writer.cpp: the 30-joint chain's 128 000 statements 13-14 s), so packages up to that size keep
/// every kernel's speed. The bias forces rhs, forcing and energy share (5 per value) stay unshared: with them,
/// energy ran 13-15 % and rhs 7-8 % slower.
constexpr int kShareRatioAuto = -1;
constexpr int kShareRatioSmall = 32;
constexpr int kShareRatioLarge = 7;
constexpr long kLargePackage = 150000;

/// How kernels are printed.
struct EmitSettings {
  /// A kernel of more than this many statements (operations) is split into functions of this many, called in
  /// turn and passing values through a stack array: g++ -O2 compiles the 30-joint chain's rhs and mass_matrix
  /// in 8.8 s instead of 66 s (docs/benchmarks.md, "Long kernels split into parts"). 0: never split.
  int split_statements = kSplitStatements;
  /// Work that several kernels use, at least this many statements used by the same kernels, is printed once as a
  /// function they all call (a shared stage, emit/shared_stages.hpp) instead of once in each. 0: never.
  int share_statements = 1000;
  /// ... and only when its shared function computes at least this many statements per value it leaves to later work
  /// (every caller stores and loads them all: a few statements per value made the kernels slower). 0: any.
  /// kShareRatioAuto: kShareRatioLarge when the kernels print at least `large_package` statements together (without
  /// shared stages: EmittedPackage::statements), else kShareRatioSmall.
  int share_ratio = kShareRatioAuto;
  long large_package = kLargePackage;
  /// Print every kernel flat, also one whose repeated solve is a subroutine (Kernel::calls): each call inline.
  bool inline_calls = false;
  /// Also a Python module: <name>.py, <name>_python.cpp and a shared library in CMakeLists.txt
  /// (emit/python_module.hpp).
  bool python = false;
  /// The options emit was given (without the model and -o), recorded in every file's first line: with the
  /// generator version and the model file's hash they say how to emit the package again.
  std::string options;
};

/// A package's kernels as text.
struct PackageKernels {
  std::string stage_text;               ///< the functions of the kernels' shared stages
  std::vector<PrintedKernel> printed;   ///< KernelSet::kernels, in order
  std::string rhs_with_pivots;          ///< rhs and the pivots of its solve, which rhs_status calls; or empty
  std::string prepare_text;             ///< prepare_parameters_kernel; empty without prepared parameters
  std::string prepared_stage_text;      ///< the functions of the prepared kernels' shared stages
  std::vector<PrintedKernel> prepared;  ///< KernelSet::prepared's kernels, in order
  int n_prepared = 0;                   ///< the prepared parameters' length (n_p without)
  int shared_stages = 0;                ///< functions shared_<k> and prepared_shared_<k>
  int share_ratio = 0;                  ///< the --share-ratio the stages were planned with (auto resolved)
  long statements = 0;                  ///< the statements the kernels print together without shared stages
  /// Per kernel (then prepare_parameters and the prepared kernels), the operations one call executes as printed.
  std::vector<std::pair<std::string, OpCounts>> operations;
};

/// The kernels of `kernels` printed with the argument sizes `s` and the settings' split, sharing and calls.
PackageKernels print_package_kernels(const KernelSet& kernels, const Sizes& s, const EmitSettings& settings);

}  // namespace hamel
