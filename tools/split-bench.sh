#!/usr/bin/env bash
# Long kernels printed whole against split (emit --split, docs/benchmarks.md "Long kernels split into
# parts"): compile time and run time side by side. Not part of the test suite.
#   tools/split-bench.sh [--kernels LIST] [--split N] [--out DIR] [MODEL.yaml ...]
# Without models: the scaling benchmark's 30-joint chain and 30-body binary tree (tools/scaling/models.py,
# needs /usr/bin/python3 with numpy). For each model the kernels (default rhs,mass_matrix) are emitted
# twice with --fold all, with --split 0 and with --split N (default: emit's default), as two packages of the
# same model under two names; g++ -O2 -c of each is timed (one at a time), and one Google Benchmark binary
# (tools/split-bench/harness.cpp) first checks that every kernel is bit-identical whole and split on 20
# random states, then times both. Results: DIR/results.md (default build-split-bench/).
# HAMEL=<binary> selects the generator (default build/bin/hamel).
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${HAMEL:-$PWD/build/bin/hamel}
kernels=rhs,mass_matrix
split=
out=$PWD/build-split-bench
models=()
while (($#)); do
  case $1 in
    --kernels) kernels=$2; shift 2 ;;
    --split) split=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) models+=("$1"); shift ;;
  esac
done
[[ -x $hamel ]] || { echo "split-bench.sh: no generator at $hamel (run tools/build.sh --target hamel)" >&2; exit 2; }
mkdir -p "$out"
if ((${#models[@]} == 0)); then
  for topology in chain tree; do
    /usr/bin/python3 tools/scaling/models.py --topology $topology --n 30 --out "$out" > /dev/null
    models+=("$out/${topology}_30.yaml")
  done
fi
split_flag=()
[[ -n $split ]] && split_flag=(--split "$split")
results=$out/results.md
{
  echo "# split-bench: $(date -u +%Y-%m-%dT%H:%MZ), $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores"
  echo "# $(g++ --version | head -1); kernels $kernels; split ${split:-default}; load $(cut -d' ' -f1-3 /proc/loadavg)"
} | tee "$results"
for model in "${models[@]}"; do
  name=$(sed -n 's/^name:[[:space:]]*//p' "$model" | head -1)
  dir=$out/$name
  rm -rf "$dir" && mkdir -p "$dir"
  for variant in whole split; do
    sed "s/^name:.*/name: ${name}_$variant/" "$model" > "$dir/${name}_$variant.yaml"
    flags=(--split 0)
    [[ $variant == split ]] && flags=("${split_flag[@]}")
    "$hamel" emit "$dir/${name}_$variant.yaml" --fold all --kernels "$kernels" "${flags[@]}" \
      -o "$dir/${name}_$variant" 2> "$dir/emit_$variant.log"
    src=$dir/${name}_$variant/${name}_$variant.cpp
    seconds=$( { /usr/bin/time -f '%e %M' g++ -std=c++17 -O2 -c "$src" -o "$dir/$variant.o"; } 2>&1 | tail -1)
    echo "$name $variant: $(wc -c < "$src") bytes of C++, g++ -O2 -c: ${seconds% *} s, ${seconds#* } KB peak" | tee -a "$results"
  done
  g++ -std=c++17 -O2 -DWHOLE="${name}_whole" -DSPLIT="${name}_split" \
    -DWHOLE_HEADER="\"${name}_whole/${name}_whole.hpp\"" -DSPLIT_HEADER="\"${name}_split/${name}_split.hpp\"" \
    -I"$dir" tools/split-bench/harness.cpp "$dir/whole.o" "$dir/split.o" -lbenchmark -lpthread -o "$dir/bench"
  "$dir/bench" --benchmark_repetitions=5 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true \
    --benchmark_color=false 2>&1 | grep -E "split-bench|median" | tee -a "$results"
done
