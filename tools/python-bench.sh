#!/usr/bin/env bash
# Batch evaluation from Python against the same loop in C++ (docs/benchmarks.md, "Python: batch calls against the
# C++ loop"): emits each package with `hamel emit --python`, builds its Python module and, against the package's
# static library, tools/python-bench/bench.cpp (the loop over N states a C++ caller writes), both Release (-O3) with
# the package's own flags; then tools/python-bench/bench.py times rhs and jacobian per state both ways on the same
# N random states (best pass of each, CPU time, over interleaved rounds) and prints a Markdown table.
#   tools/python-bench.sh [--n N] [--rounds R] [--passes P]     defaults 10000, 7, 40 (CPU ns per state, best pass)
# Needs build/bin/hamel and /usr/bin/python3 with NumPy (tools/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${HAMEL:-build/bin/hamel}
py=/usr/bin/python3
work=build/python-bench
mkdir -p "$work/src"
# name | model | emit flags
cases=("double_pendulum models/double_pendulum.yaml"
       "chaplygin_sleigh models/chaplygin_sleigh.yaml"
       "quadrotor_slung_load models/quadrotor_slung_load.yaml --fold all"
       "space_robot models/space_robot.yaml --fold all")
names=()
{
  echo "cmake_minimum_required(VERSION 3.13)"
  echo "project(python_bench LANGUAGES CXX)"
} > "$work/src/CMakeLists.txt"
for c in "${cases[@]}"; do
  read -r name yaml flags <<< "$c"
  # shellcheck disable=SC2086
  "$hamel" -q emit "$yaml" -o "$work/src/$name" --python $flags > "$work/$name.log" 2>&1 ||
    { cat "$work/$name.log" >&2; exit 1; }
  names+=("$name")
  cat >> "$work/src/CMakeLists.txt" << CMAKE
add_subdirectory($name)
add_executable(bench_$name $PWD/tools/python-bench/bench.cpp)
target_compile_definitions(bench_$name PRIVATE PKG=$name PKG_HEADER="$name.hpp")
target_link_libraries(bench_$name PRIVATE ${name}_kernels)
set_target_properties(bench_$name PROPERTIES RUNTIME_OUTPUT_DIRECTORY \${CMAKE_BINARY_DIR})
CMAKE
done
cmake -S "$work/src" -B "$work/build" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log" >&2; exit 1; }
cmake --build "$work/build" -j"$(nproc)" > "$work/build.log" 2>&1 || { cat "$work/build.log" >&2; exit 1; }
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(git rev-parse --short HEAD), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)," \
  "$(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(g++ --version | head -1), NumPy $($py -c 'import numpy; print(numpy.__version__)')"
echo
$py tools/python-bench/bench.py --build "$work/build" "$@" "${names[@]}"
