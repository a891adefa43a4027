// The package writer: a KernelSet as a self-contained C++ package, <name>.hpp (the ABI: sizes, names, declarations),
// <name>.cpp (the kernels as emit/package_kernels.hpp prints them, rhs_status, rk4_step, the C entry points), <name>.h
// (the C entry points), CMakeLists.txt and README.md (with emit --python also the Python module <name>.py and its
// batch entry points <name>_python.cpp, emit/python_module.hpp), written into its folder as one transaction
// (report/folder_transaction.hpp). Kernels are flat, branch-free, use no heap, no exceptions and no RTTI and need only
// <cmath>; the scalar type is selectable at compile time through HAMEL_<NAME>_REAL (default double). Every emitted file
// carries the MIT licence (SPDX), whatever the generator's licence.
//
// The layers below it: graph passes that plan what is printed (emit/shared_stages, emit/subroutine_calls,
// emit/kernel_parts, emit/statement_schedule), the one printing loop (emit/statement_printer), the functions around it
// (emit/kernel_printer) and a package's kernels as text (emit/package_kernels).
#pragma once

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "emit/package_kernels.hpp"
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
  std::vector<EmittedFile> extra;  ///< <name>.h, CMakeLists.txt, README.md (and <name>.py, <name>_python.cpp)
  /// Per kernel (then prepare_parameters and the prepared kernels), the operations one call executes as printed:
  /// with its shared stages and, for a kernel with calls, every call's (what each kernel's comment reports).
  std::vector<std::pair<std::string, OpCounts>> operations;
  int shared_stages = 0;  ///< functions shared_<k> (and prepared_shared_<k>) printed
  int share_ratio = 0;    ///< the --share-ratio the stages were planned with (auto resolved)
  long statements = 0;    ///< the statements the kernels print together without shared stages

  /// Every file of the package, header and source first.
  std::vector<EmittedFile> files() const;
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

/// The generator's version string, stamped into every emitted file.
const char* generator_version();

}  // namespace hamel
