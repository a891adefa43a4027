// The kernels hamel can emit, in one table: name, what it computes (with the paper's equation; the emitted
// comment and README line), and whether it is built by default or only when named. build_kernels takes its
// names and summaries from here; `emit --kernels`, scene tasks and `simulate` name kernels that must be in
// it (an unknown name is an input error for users and a logic error inside hamel).
#pragma once

#include <string>
#include <vector>

namespace hamel {

struct KernelSpec {
  const char* name;
  const char* summary;  ///< what it computes and which equation; a kernel may append how (e.g. rhs)
  bool by_default;      ///< built when no kernel is named (if the model has it); else only when named
  /// Zero by construction: its outputs show the rounding of what it checks, so they are printed as derived, not
  /// replaced by 0 where they vanish identically (emit/zero_test.hpp).
  bool residual = false;
};

/// Every kernel, in the order of the emitted kernel_table.
const std::vector<KernelSpec>& kernel_registry();

/// The entry named `name`; throws std::logic_error for a name that is not registered.
const KernelSpec& kernel_spec(const std::string& name);

/// True when `name` is a registered kernel.
bool is_kernel_name(const std::string& name);

/// The registered names, comma-separated (for messages and --help).
std::string kernel_names();

}  // namespace hamel
