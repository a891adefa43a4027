#include "emit/package_kernels.hpp"

#include "emit/shared_stages.hpp"
#include "emit/subroutine_calls.hpp"

#include <string>

namespace hamel {

namespace {

bool is_checked_rhs(const KernelSet& kernels, const Kernel& k) {
  return k.name == "rhs" && !kernels.rhs_pivots.empty();
}

// The units of the kernels' sharing plan: what each kernel's function computes (with calls, its stage before them;
// the checked rhs also the pivots), whether that is its out[], in order (a stage may then write them there), and
// their names.
struct Units {
  std::vector<std::vector<int>> outputs;
  std::vector<char> writes_out;
  std::vector<std::string> names;
};

Units units_of(const KernelSet& kernels, const std::vector<Kernel>& list, const Sizes& s) {
  Units units;
  for (const Kernel& k : list) {
    const bool called = k.calls && s.calls;
    units.outputs.push_back(called ? stage_before_calls(k, *k.calls).kernel.outputs : k.outputs);
    if (is_checked_rhs(kernels, k))
      units.outputs.back().insert(units.outputs.back().end(), kernels.rhs_pivots.begin(), kernels.rhs_pivots.end());
    units.writes_out.push_back(!called && !is_checked_rhs(kernels, k));
    units.names.push_back(k.name);
  }
  return units;
}

// rhs_status needs the pivots of rhs's solve, intermediate values of rhs: rhs_with_pivots computes both. When rhs is
// long enough to be split, rhs calls it with a scratch array for the pivots, so that the package holds and compiles
// rhs once; a shorter rhs keeps its own copy, which saves the call (2-8 ns, 1-4 % of a rhs of 700-1 400 operations,
// docs/benchmarks.md). The same holds when rhs calls shared stages.
std::string print_rhs_with_pivots(const KernelSet& kernels, const Kernel& rhs, const Sizes& s, const UnitStages& stages,
                                  PrintedKernel& printed) {
  const bool shared = printed.parts > 1 || stages.reads;
  Kernel checked = rhs;
  checked.name = "rhs_with_pivots";
  for (std::size_t k = 0; k < kernels.rhs_pivots.size(); ++k) {
    checked.outputs.push_back(kernels.rhs_pivots[k]);
    checked.output_names.push_back("pivot " + std::to_string(k));
  }
  Destination two = to_two_arrays(checked, rhs.outputs.size(), "pivots");
  two.internal = true;
  const PrintedKernel with_pivots = stages.reads ? print_after_stages(kernels.graph, checked, s, two, stages)
                                                 : print_program(kernels.graph, checked, s, two);
  if (shared) {
    printed.text =
        kernel_comment(rhs, s, "out[" + std::to_string(rhs.outputs.size()) + "]", ": rhs_with_pivots", printed.ops) +
        signature(rhs) +
        " {\n"
        "  real pivots[n_pivots_rhs];  // computed on the way, not checked (rhs_status checks them)\n"
        "  rhs_with_pivots(t, x, p, in, out, pivots);\n"
        "}\n";
    // rhs_with_pivots split into parts passes their values in the caller's work space, and so may rhs.
    printed.work = with_pivots.work;
    if (with_pivots.work > 0)
      printed.text +=
          "\nvoid rhs_work(real t, const real* x, const real* p, const real* in, real* out, real* work) {\n"
          "  real pivots[n_pivots_rhs];\n"
          "  rhs_with_pivots_work(t, x, p, in, out, pivots, work);\n"
          "}\n";
  }
  return with_pivots.text;
}

// prepare_parameters and the prepared kernels, whose p is the prepared parameters, with stages of their own.
void print_prepared(PackageKernels& out, const KernelSet& kernels, const Sizes& s, const EmitSettings& settings) {
  const KernelSet::Prepared& prepared = *kernels.prepared;
  Kernel prepare = prepared.prepare;
  prepare.name = "prepare_parameters_kernel";
  out.prepare_text = print_kernel(kernels.graph, prepare, s).text;
  out.n_prepared = static_cast<int>(prepared.prepare.outputs.size());
  Sizes wide = s;
  wide.n_p = out.n_prepared;
  const Units units = units_of(kernels, prepared.kernels, s);
  const SharingPlan sharing =
      plan_shared_stages(kernels.graph, units.outputs, settings.share_statements, out.share_ratio, units.writes_out);
  const PrintedStages stages = print_stages(kernels.graph, sharing, wide, "prepared_", units.names);
  out.prepared_stage_text = stages.text;
  out.shared_stages += static_cast<int>(sharing.stages.size());
  for (std::size_t i = 0; i < prepared.kernels.size(); ++i)
    out.prepared.push_back(print_kernel(kernels.graph, prepared.kernels[i], wide, stages.units[i]));
  out.operations.emplace_back("prepare_parameters", kernels.graph.count(kernels.graph.schedule(prepare.outputs)));
  for (const PrintedKernel& k : out.prepared) out.operations.emplace_back(k.name, k.ops);
}

}  // namespace

PackageKernels print_package_kernels(const KernelSet& kernels, const Sizes& s, const EmitSettings& settings) {
  PackageKernels out;
  const Units units = units_of(kernels, kernels.kernels, s);
  for (const std::vector<int>& unit : units.outputs)
    out.statements += kernels.graph.count(kernels.graph.schedule(unit)).total();
  out.share_ratio = settings.share_ratio != kShareRatioAuto    ? settings.share_ratio
                    : out.statements >= settings.large_package ? kShareRatioLarge
                                                               : kShareRatioSmall;
  const SharingPlan sharing =
      plan_shared_stages(kernels.graph, units.outputs, settings.share_statements, out.share_ratio, units.writes_out);
  const PrintedStages stages = print_stages(kernels.graph, sharing, s, "", units.names);
  out.stage_text = stages.text;
  out.shared_stages = static_cast<int>(sharing.stages.size());
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    out.printed.push_back(print_kernel(kernels.graph, kernels.kernels[i], s, stages.units[i]));
  for (std::size_t i = 0; i < kernels.kernels.size(); ++i)
    if (is_checked_rhs(kernels, kernels.kernels[i]))
      out.rhs_with_pivots = print_rhs_with_pivots(kernels, kernels.kernels[i], s, stages.units[i], out.printed[i]);
  for (const PrintedKernel& k : out.printed) out.operations.emplace_back(k.name, k.ops);
  out.n_prepared = s.n_p;
  if (kernels.prepared) print_prepared(out, kernels, s, settings);
  return out;
}

}  // namespace hamel
