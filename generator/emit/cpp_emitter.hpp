// Printing a KernelSet as a self-contained C++ package: header, source, CMakeLists.txt and README.md.
// Kernels are flat, branch-free, use no heap, no exceptions and no RTTI and need only <cmath>; the scalar
// type is selectable at compile time through HAMEL_<NAME>_REAL (default double). Every emitted file
// carries the MIT licence (SPDX), whatever the generator's licence.
#pragma once

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"
#include "report/folder_transaction.hpp"

#include <string>
#include <utility>
#include <vector>

namespace hamel {

/// One file of a package.
using EmittedFile = FolderFile;

struct EmittedPackage {
  std::string header_name, header;
  std::string source_name, source;
  std::vector<EmittedFile> extra;  ///< CMakeLists.txt and README.md
  /// Per kernel (then prepare_parameters and the prepared kernels), the operations one call executes as printed:
  /// with its shared stages and, for a kernel with calls, every call's (what each kernel's comment reports).
  std::vector<std::pair<std::string, OpCounts>> operations;
  int shared_stages = 0;  ///< functions shared_<k> (and prepared_shared_<k>) printed
  int share_ratio = 0;    ///< the --share-ratio the stages were planned with (auto resolved)
  long statements = 0;    ///< the statements the kernels print together without shared stages

  /// Every file of the package, header and source first.
  std::vector<EmittedFile> files() const;
};

/// --share-ratio auto (EmitSettings::share_ratio): a package whose kernels print fewer than kLargePackage statements
/// together (about 6 s of g++ -O2) shares only work of at least kShareRatioSmall statements per value it passes on,
/// which costs no measurable run time; a larger one also work of at least kShareRatioLarge per value: the composite
/// inertias that mass_matrix, connection, shape_inertia and a tree's jacobian all compute (9.5-10 per value on the
/// scaling chains and trees). The 30-joint chain's package then compiles in 13 s instead of 18, for mass_matrix
/// 5-21 % slower (docs/emit.md, "Large models: compile time against run time"). The bias forces rhs, forcing and
/// energy share (5 per value) stay unshared: with them, energy ran 13-15 % and rhs 7-8 % slower.
constexpr int kShareRatioAuto = -1;
constexpr int kShareRatioSmall = 32;
constexpr int kShareRatioLarge = 7;
constexpr long kLargePackage = 50000;

/// How kernels are printed.
struct EmitSettings {
  /// A kernel of more than this many statements (operations) is split into functions of this many, called in
  /// turn and passing values through a stack array: g++ -O2 compiles the 30-joint chain's rhs and mass_matrix
  /// in 8.8 s instead of 66 s (docs/benchmarks.md, "Long kernels split into parts"). 0: never split.
  int split_statements = 2000;
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
  /// The options emit was given (without the model and -o), recorded in every file's first line: with the
  /// generator version and the model file's hash they say how to emit the package again.
  std::string options;
};

EmittedPackage emit_cpp(const Model& model, const Derivation& derivation, const KernelSet& kernels,
                        const EmitSettings& settings = {});

/// The checks write_package makes of `directory`, made before any derivation so that a refused folder fails
/// at once: a folder name, and, if the folder exists, one an earlier emit of a model `model_name` wrote.
/// Throws InputError as write_package does (which checks again when it writes).
void check_package_folder(const std::string& directory, const std::string& model_name);

/// Writes the package into `directory` atomically (report/folder_transaction.hpp): a temporary sibling folder is
/// filled and renamed; an existing folder is replaced only once the new one is complete.
void write_package(const EmittedPackage& package, const std::string& directory);

/// The most operations one printed statement holds: a statement read once, by a later statement of the same
/// function, and no output, is printed inside that statement's expression, not as a local of its own, up to this.
constexpr int kOperationsPerStatement = 16;

/// One kernel as emit_cpp prints it into the package source (with argument sizes n_x, n_p, n_in for its
/// comment): for tests of the printed text, e.g. that it does not depend on the order the graph was built in.
std::string kernel_text(const ExpressionGraph& graph, const Kernel& kernel, int n_x, int n_p, int n_in,
                        int split_statements = EmitSettings{}.split_statements);

/// The generator's version string, stamped into every emitted file.
const char* generator_version();

}  // namespace hamel
