// Printing a KernelSet as a C++ header and source: flat, branch-free, no heap, no exceptions, only
// <cmath>. Scalar type selectable at compile time through HAMEL_<NAME>_REAL (default double).
#pragma once

#include "derive/derivation.hpp"
#include "emit/kernels.hpp"
#include "model/model.hpp"

#include <string>

namespace hamel {

struct EmittedPackage {
  std::string header_name, header;
  std::string source_name, source;
};

EmittedPackage emit_cpp(const Model& model, const Derivation& derivation, const KernelSet& kernels);

/// Writes the package into `directory` atomically: a temporary sibling folder is filled and renamed;
/// an existing folder is replaced only once the new one is complete.
void write_package(const EmittedPackage& package, const std::string& directory);

/// The generator's version string, stamped into every emitted file.
const char* generator_version();

}  // namespace hamel
