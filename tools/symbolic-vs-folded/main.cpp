// Symbolic against folded parameters: for every model whose two packages are linked in (see
// tools/symbolic-vs-folded.sh), checks that the rhs with p[] read at run time agrees with the rhs emitted
// with --fold all at 20 pseudo-random states and the default parameters (max over the states of
// ||rhs_sym - rhs_fold||_inf / ||rhs_fold||_inf, limit 1e-12), then times both rhs in one Google Benchmark
// run at one fixed pseudo-random state (CPU time) and prints a Markdown table with the ratio symbolic/folded.
// A symbolic package with prepared parameters also registers rhs_prepared (variant "prepared", its p[] the
// prepared array P): checked and timed the same way, and the ratio judged is then prepared/folded.
//   symbolic_vs_folded [--check-only] [google-benchmark flags...]
// Exit status: 0, or 1 when a model disagrees (or a package is missing its partner).
#include "registry.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

constexpr int n_check_states = 20;
constexpr double tolerance = 1e-12;
constexpr double half_width = 0.45;  // state entries in [-0.45, 0.45], as in benchmarks/ (docs/benchmarks.md)
constexpr double input_value = 0.1;

std::vector<double> random_state(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> d(-half_width, half_width);
  std::vector<double> x(n);
  for (double& v : x) v = d(rng);
  return x;
}

std::vector<double> call(const svf::Package& k, const std::vector<double>& x) {
  std::vector<double> p(k.default_parameters, k.default_parameters + k.n_parameters);
  std::vector<double> in(std::max(1, k.n_inputs), input_value);
  std::vector<double> out(k.n_out, 0.0);
  k.rhs(0.0, x.data(), p.data(), in.data(), out.data());
  return out;
}

struct Pair {
  const svf::Package* symbolic = nullptr;
  const svf::Package* folded = nullptr;
  const svf::Package* prepared = nullptr;  // rhs_prepared of the symbolic package, if it has one
  double max_relative = 0.0;
  bool ok = true;
};

// Console output as usual; the CPU time per call of every benchmark kept (the median when repeated). CPU
// time, not wall time: on a shared machine the wall time includes the time the process waited for a core.
class Collector : public benchmark::ConsoleReporter {
 public:
  Collector() : ConsoleReporter(OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      const std::string name = r.run_name.function_name;
      if (r.run_type == Run::RT_Aggregate) {
        if (r.aggregate_name == "median") median_[name] = r.GetAdjustedCPUTime();
      } else if (!single_.count(name)) {
        single_[name] = r.GetAdjustedCPUTime();
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  bool has(const std::string& n) const { return median_.count(n) || single_.count(n); }
  double ns(const std::string& n) const {
    auto m = median_.find(n);
    return m != median_.end() ? m->second : single_.at(n);
  }

 private:
  std::map<std::string, double> median_, single_;
};

}  // namespace

int main(int argc, char** argv) {
  bool check_only = false;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--check-only") == 0)
      check_only = true;
    else
      args.push_back(argv[i]);
  }
  int n_args = static_cast<int>(args.size());

  // Pair the packages by model, in registration order.
  std::vector<std::string> models;
  std::map<std::string, Pair> pairs;
  for (const svf::Package& k : svf::packages()) {
    if (!pairs.count(k.model)) models.push_back(k.model);
    (k.variant == "symbolic" ? pairs[k.model].symbolic
     : k.variant == "folded" ? pairs[k.model].folded
                             : pairs[k.model].prepared) = &k;
  }
  std::sort(models.begin(), models.end());

  // Agreement at n_check_states states, default parameters.
  int failures = 0;
  std::printf("## agreement: rhs symbolic vs --fold all, %d states in [-%.2f, %.2f], default parameters\n\n",
              n_check_states, half_width, half_width);
  for (const std::string& m : models) {
    Pair& pr = pairs[m];
    if (!pr.symbolic || !pr.folded || pr.symbolic->n_state != pr.folded->n_state ||
        pr.symbolic->n_out != pr.folded->n_out) {
      std::printf("%-28s MISSING OR MISMATCHED PACKAGE\n", m.c_str());
      pr.ok = false;
      ++failures;
      continue;
    }
    std::mt19937_64 rng(12);
    for (int s = 0; s < n_check_states; ++s) {
      const std::vector<double> x = random_state(rng, pr.symbolic->n_state);
      const std::vector<double> b = call(*pr.folded, x);
      for (const svf::Package* k : {pr.symbolic, pr.prepared}) {
        if (!k) continue;
        const std::vector<double> a = call(*k, x);
        double diff = 0.0, scale = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) {
          diff = std::max(diff, std::fabs(a[i] - b[i]));
          scale = std::max(scale, std::fabs(b[i]));
        }
        const double rel = scale > 0.0 ? diff / scale : diff;
        pr.max_relative = std::isfinite(rel) ? std::max(pr.max_relative, rel) : INFINITY;
      }
    }
    pr.ok = pr.max_relative <= tolerance;
    if (!pr.ok) ++failures;
    std::printf("%-28s max relative difference %.2e  %s\n", m.c_str(), pr.max_relative, pr.ok ? "ok" : "FAIL");
  }
  std::printf("\n%s\n\n", failures ? "agreement: FAILED" : "agreement: all models within 1e-12");
  std::fflush(stdout);  // before Google Benchmark writes its context to stderr
  if (check_only) return failures ? 1 : 0;

  // Timing: both rhs of every model at one fixed state, back to back, in this one run.
  std::mt19937_64 rng(5);
  std::map<std::string, std::vector<double>> state;
  for (const std::string& m : models) {
    const Pair& pr = pairs[m];
    if (!pr.symbolic || !pr.folded) continue;
    state[m] = random_state(rng, pr.symbolic->n_state);
    for (const svf::Package* k : {pr.symbolic, pr.folded, pr.prepared}) {
      if (!k) continue;
      const std::vector<double>* x = &state[m];
      benchmark::RegisterBenchmark((m + "/" + k->variant).c_str(), [k, x](benchmark::State& st) {
        std::vector<double> p(k->default_parameters, k->default_parameters + k->n_parameters);
        std::vector<double> in(std::max(1, k->n_inputs), input_value);
        std::vector<double> out(k->n_out);
        const double* xp = x->data();
        for (auto _ : st) {
          k->rhs(0.0, xp, p.data(), in.data(), out.data());
          benchmark::DoNotOptimize(out.data());
          benchmark::ClobberMemory();
        }
      })->Unit(benchmark::kNanosecond);
    }
  }
  benchmark::Initialize(&n_args, args.data());
  if (benchmark::ReportUnrecognizedArguments(n_args, args.data())) return 2;
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);

  std::printf("\n## rhs: symbolic parameters vs --fold all (-O2, CPU time per call, median when repeated)\n\n");
  std::printf(
      "| model | symbolic ns | folded ns | symbolic/folded | prepared ns | prepared/folded | <= 1.5 | symbolic rhs "
      "operations | rhs_prepared operations | folded rhs operations | max rel. difference (%d states) |\n",
      n_check_states);
  std::printf("|---|---:|---:|---:|---:|---:|---|---|---|---|---:|\n");
  for (const std::string& m : models) {
    const Pair& pr = pairs[m];
    if (!pr.symbolic || !pr.folded) continue;
    const std::string s = m + "/symbolic", f = m + "/folded", p = m + "/prepared";
    if (!collector.has(s) || !collector.has(f)) continue;
    const double ratio = collector.ns(s) / collector.ns(f);
    const bool prepared = pr.prepared && collector.has(p);
    const double judged = prepared ? collector.ns(p) / collector.ns(f) : ratio;
    char prepared_ns[32] = "-", prepared_ratio[32] = "-";
    if (prepared) {
      std::snprintf(prepared_ns, sizeof prepared_ns, "%.1f", collector.ns(p));
      std::snprintf(prepared_ratio, sizeof prepared_ratio, "%.2f", judged);
    }
    std::printf("| %s | %.1f | %.1f | %.2f | %s | %s | %s | %s | %s | %s | %.1e |\n", m.c_str(), collector.ns(s),
                collector.ns(f), ratio, prepared_ns, prepared_ratio, judged <= 1.5 ? "yes" : "**no**",
                pr.symbolic->operations.c_str(), prepared ? pr.prepared->operations.c_str() : "-",
                pr.folded->operations.c_str(), pr.max_relative);
  }
  return failures ? 1 : 0;
}
