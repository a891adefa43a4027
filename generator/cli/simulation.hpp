// `hamel simulate`'s integration as a function, for the verbs that run it (simulate writes the CSV to a file;
// animate reads it back and plays it).
#pragma once

#include "cli/pipeline.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace hamel::cli {

struct SimulateOptions {
  PipelineOptions in;
  double t_end = 0;  // 0: not given
  std::string integrator;
  double dt = 0;
  double tol = 0;
  std::vector<std::string> init, inputs;
  std::string input_file, monitors;
  double sample = 0;
  std::string out = "-";
  bool dt_given = false, tol_given = false, sample_given = false;  // on the command line
};

/// Registers simulate's options of the integration (--t-end, --integrator, --dt, --tol, --init, --input, --input-file,
/// --sample) on `cmd`; the function returned records, once the command line is parsed, which of them were given.
std::function<void()> add_simulate_options(CLI::App* cmd, SimulateOptions& opt);

/// Integrates `pipeline`'s model as `hamel simulate` does (its defaults, checks and summary on stderr) and writes the
/// CSV to the stream `open` returns, called once the run's inputs are read (an output may not replace an input,
/// report/atomic_file.hpp): `check` is called after every row (to stop on a failed write), `on_success` when the
/// integration reached the end, before the summary. A failed integration throws RunFailed after printing where.
void simulate(const SimulateOptions& given, Pipeline& pipeline, const std::function<std::ostream&()>& open,
              const std::function<void()>& check, const std::function<void()>& on_success);

}  // namespace hamel::cli
