#!/usr/bin/env bash
# Benchmarks of the emitted kernels (docs/benchmarks.md): configures benchmarks/ on its own in build-bench/
# (Release, kernels at -O2), emits the ep/lp variants with an existing generator, builds, prints the compile
# time of every committed package and runs Google Benchmark; the Markdown summary at the end of
# build-bench/results.txt is what docs/benchmarks.md shows. Not part of the test suite.
#   tools/bench.sh [google-benchmark flags...]     e.g. --benchmark_filter=satellite
# HAMEL=<binary> selects the generator (default build/bin/hamel; tools/build.sh --target hamel builds it).
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${HAMEL:-$PWD/build/bin/hamel}
[[ -x $hamel ]] || { echo "bench.sh: no generator at $hamel (run tools/build.sh --target hamel)" >&2; exit 2; }
mkdir -p build-bench

echo "# machine: $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores" | tee build-bench/results.txt
echo "# compilers: $(g++ --version | head -1); $(clang++ --version 2>/dev/null | head -1 || echo no clang++)" \
  | tee -a build-bench/results.txt

echo "# compile time of each committed package (-O2 -c, seconds): g++ clang++" | tee -a build-bench/results.txt
for dir in generated/*/; do
  for src in "$dir"*.cpp; do
    [[ -e $src ]] || continue
    g=$( { /usr/bin/time -f %e g++ -std=c++17 -O2 -c "$src" -o /dev/null; } 2>&1 | tail -1)
    c=$( { /usr/bin/time -f %e clang++ -std=c++17 -O2 -c "$src" -o /dev/null; } 2>&1 | tail -1 || echo -)
    printf '#   %-40s %6s %6s  (%s bytes)\n' "$src" "$g" "$c" "$(wc -c < "$src")" | tee -a build-bench/results.txt
  done
done

cmake -S benchmarks -B build-bench -DCMAKE_BUILD_TYPE=Release -DHAMEL_EXECUTABLE="$hamel" > build-bench/configure.log 2>&1 \
  || { cat build-bench/configure.log; exit 1; }
start=$(date +%s)
cmake --build build-bench -j"$(nproc)" > build-bench/build.log 2>&1 || { cat build-bench/build.log; exit 1; }
echo "# benchmark build (emission of the ep/lp variants + compilation): $(( $(date +%s) - start )) s" \
  | tee -a build-bench/results.txt
build-bench/hamel_bench --benchmark_repetitions=5 --benchmark_min_time=0.05 --benchmark_color=false --benchmark_report_aggregates_only=true "$@" | tee -a build-bench/results.txt
