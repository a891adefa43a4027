// Runs every registered kernel benchmark (Google Benchmark's usual flags apply) and then prints two
// Markdown tables: ns per call of each kernel for each package, and the coupled Euler-Poincare against the
// decoupled Lagrange-Poincare form of the same model (packages <model>_ep and <model>_lp). With
// --benchmark_repetitions the median is used.
#include "registry.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

// Console output as usual, and the time per call of every benchmark kept for the summary.
class Collector : public benchmark::ConsoleReporter {
 public:
  Collector() : ConsoleReporter(OO_Tabular) {}  // no colour codes: the output is kept as a text file
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      const std::string name = r.run_name.function_name;
      const double ns = r.GetAdjustedRealTime();  // unit: ns (set per benchmark)
      if (r.run_type == Run::RT_Aggregate) {
        if (r.aggregate_name == "median") median_[name] = ns;
      } else if (!single_.count(name)) {
        single_[name] = ns;
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  bool has(const std::string& name) const { return median_.count(name) || single_.count(name); }
  double ns(const std::string& name) const {
    auto m = median_.find(name);
    return m != median_.end() ? m->second : single_.at(name);
  }

 private:
  std::map<std::string, double> median_, single_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);

  // Packages in registration order; kernels in the order of their first appearance (the emitter's order).
  std::vector<std::string> packages, kernel_order;
  std::map<std::string, int> temporaries;
  for (const auto& k : hamel_bench::kernels()) {
    if (packages.empty() || packages.back() != k.package) packages.push_back(k.package);
    if (std::find(kernel_order.begin(), kernel_order.end(), k.kernel) == kernel_order.end())
      kernel_order.push_back(k.kernel);
    temporaries[k.package + "/" + k.kernel] = k.n_temporaries;
  }

  std::printf("\n## ns per call (-O2, median when repeated)\n\n| Package |");
  for (const std::string& k : kernel_order) std::printf(" %s |", k.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < kernel_order.size(); ++i) std::printf("---:|");
  std::printf("\n");
  for (const std::string& p : packages) {
    std::printf("| %s |", p.c_str());
    for (const std::string& k : kernel_order) {
      const std::string name = p + "/" + k;
      if (collector.has(name))
        std::printf(" %.1f |", collector.ns(name));
      else
        std::printf(" %s |", temporaries.count(name) ? "?" : "-");
    }
    std::printf("\n");
  }

  std::printf("\n## Euler-Poincare (ep, coupled) vs Lagrange-Poincare (lp, locked velocity)\n\n");
  std::printf("| Model | Kernel | ep ns | lp ns | ep/lp | ep temporaries | lp temporaries |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|\n");
  for (const std::string& p : packages) {
    if (p.size() < 3 || p.compare(p.size() - 3, 3, "_ep") != 0) continue;
    const std::string model = p.substr(0, p.size() - 3), lp = model + "_lp";
    for (const char* k : {"rhs", "jacobian", "mass_matrix", "forcing"}) {
      const std::string a = p + "/" + k, b = lp + "/" + k;
      if (!collector.has(a) || !collector.has(b)) continue;
      std::printf("| %s | %s | %.1f | %.1f | %.2f | %d | %d |\n", model.c_str(), k, collector.ns(a), collector.ns(b),
                  collector.ns(a) / collector.ns(b), temporaries[a], temporaries[b]);
    }
  }
  benchmark::Shutdown();
  return 0;
}
