#!/usr/bin/env bash
# Side-by-side timing of an imported MJCF robot (docs/import.md): hamel import + emit, then one Google
# Benchmark binary with MuJoCo's mj_forward and the emitted rhs and mass_matrix (g++ -O2).
#   tools/import-bench.sh [MODEL.xml [import flags...]]   default: MuJoCo's sample humanoid
# Needs build/bin/hamel, libmujoco-dev and libbenchmark-dev (tools/install-deps.sh --scaling).
set -euo pipefail
cd "$(dirname "$0")/.."
xml=${1:-/usr/share/mujoco/model/humanoid/humanoid.xml}
shift || true
flags=("$@")
[ ${#flags[@]} -gt 0 ] || flags=(--ignore contacts,limits,gravity)
work=build/import-bench
mkdir -p "$work"
build/bin/hamel import "$xml" -o "$work/robot.yaml" --name robot "${flags[@]}"
build/bin/hamel emit "$work/robot.yaml" -o "$work/robot" --kernels rhs,mass_matrix
g++ -std=c++17 -O2 -DPKG=robot -DPKG_HEADER='"robot.hpp"' -I"$work/robot" tools/import/bench.cpp \
  "$work/robot/robot.cpp" -o "$work/bench" -lmujoco -lbenchmark -lpthread
"$work/bench" "$xml" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
