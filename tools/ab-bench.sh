#!/usr/bin/env bash
# One model's kernels emitted two ways, A and B, compiled and timed side by side (docs/benchmarks.md). Not part
# of the test suite.
#   tools/ab-bench.sh [--kernels LIST] [--a-label L] [--a-flags "F"] [--a-hamel BIN] [--b-label L]
#                     [--b-flags "F"] [--b-hamel BIN] [--tolerance T] [--compiles N] [--bench-runs N]
#                     [--out DIR] [MODEL.yaml ...]
# A and B differ by emit flags (e.g. --split 0 against --split 2000: tools/split-bench.sh) or by generator
# binary (a build of another commit against this one). Each is emitted with --fold all as a package of the
# model under the name <model>_<label>; g++ -O2 -c of each is timed, one at a time (--compiles N: N times each,
# A and B alternating, user seconds, every run and the best listed: on a shared host the same file's time moves by
# up to 30 % within minutes, and the best of several is the steadiest figure). One Google Benchmark binary
# (tools/ab-bench/harness.cpp) first checks on 20 random states that both packages agree (--tolerance 0, the
# default: bit for bit; otherwise the largest difference per kernel relative to its largest output), then
# times every kernel of both (--bench-runs N: the binary N times, each run's medians listed). Without models: the
# scaling benchmark's 30-joint chain and 30-body binary tree (tools/scaling/models.py, needs /usr/bin/python3 with
# numpy). Results: DIR/results.md (default build-ab-bench/).
# Defaults: kernels rhs,mass_matrix, labels a and b, no flags, both generators $HAMEL or build/bin/hamel.
set -euo pipefail
cd "$(dirname "$0")/.."
hamel_a=${HAMEL:-$PWD/build/bin/hamel}
hamel_b=$hamel_a
kernels=rhs,mass_matrix
label_a=a label_b=b flags_a= flags_b= tolerance=0 compiles=1 bench_runs=1
out=$PWD/build-ab-bench
models=()
while (($#)); do
  case $1 in
    --kernels) kernels=$2; shift 2 ;;
    --a-label) label_a=$2; shift 2 ;;
    --b-label) label_b=$2; shift 2 ;;
    --a-flags) flags_a=$2; shift 2 ;;
    --b-flags) flags_b=$2; shift 2 ;;
    --a-hamel) hamel_a=$2; shift 2 ;;
    --b-hamel) hamel_b=$2; shift 2 ;;
    --tolerance) tolerance=$2; shift 2 ;;
    --compiles) compiles=$2; shift 2 ;;
    --bench-runs) bench_runs=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,/^# Defaults/p' "$0"; exit 0 ;;
    -*) echo "ab-bench.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) models+=("$1"); shift ;;
  esac
done
for h in "$hamel_a" "$hamel_b"; do
  [[ -x $h ]] || { echo "ab-bench.sh: no generator at $h (run tools/build.sh --target hamel)" >&2; exit 2; }
done
[[ $label_a != "$label_b" ]] || { echo "ab-bench.sh: --a-label and --b-label must differ" >&2; exit 2; }
for n in "$compiles" "$bench_runs"; do
  [[ $n =~ ^[1-9][0-9]*$ ]] || { echo "ab-bench.sh: --compiles and --bench-runs take a whole number >= 1, got '$n'" >&2; exit 2; }
done
mkdir -p "$out"
if ((${#models[@]} == 0)); then
  for topology in chain tree; do
    /usr/bin/python3 tools/scaling/models.py --topology $topology --n 30 --out "$out" > /dev/null
    models+=("$out/${topology}_30.yaml")
  done
fi
results=$out/results.md
{
  echo "# ab-bench: $(date -u +%Y-%m-%dT%H:%MZ), $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores"
  echo "# $(g++ --version | head -1); kernels $kernels; load $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "# A = $label_a: $hamel_a emit ${flags_a:-(no flags)}; B = $label_b: $hamel_b emit ${flags_b:-(no flags)}"
} | tee "$results"
for model in "${models[@]}"; do
  name=$(sed -n 's/^name:[[:space:]]*//p' "$model" | head -1)
  dir=$out/$name
  rm -rf "$dir" && mkdir -p "$dir"
  for side in a b; do
    if [[ $side == a ]]; then label=$label_a hamel=$hamel_a flags=$flags_a; else label=$label_b hamel=$hamel_b flags=$flags_b; fi
    sed "s/^name:.*/name: ${name}_$label/" "$model" > "$dir/${name}_$label.yaml"
    # shellcheck disable=SC2086  # the flags are words
    "$hamel" emit "$dir/${name}_$label.yaml" --fold all --kernels "$kernels" $flags -o "$dir/${name}_$label" \
      2> "$dir/emit_$label.log"
  done
  # g++ -O2 -c of A and B in turn, `compiles` times; the user seconds of every run, the best, the peak memory.
  declare -A runs=() peak=()
  for ((c = 0; c < compiles; ++c)); do
    for side in a b; do
      if [[ $side == a ]]; then label=$label_a; else label=$label_b; fi
      src=$dir/${name}_$label/${name}_$label.cpp
      measured=$( { /usr/bin/time -f '%U %M' g++ -std=c++17 -O2 -c "$src" -o "$dir/$side.o"; } 2>&1 | tail -1)
      runs[$side]+="${measured% *} "
      peak[$side]=${measured#* }
    done
  done
  for side in a b; do
    if [[ $side == a ]]; then label=$label_a; else label=$label_b; fi
    src=$dir/${name}_$label/${name}_$label.cpp
    best=$(tr ' ' '\n' <<< "${runs[$side]}" | sed '/^$/d' | sort -g | head -1)
    echo "$name $label: $(wc -c < "$src") bytes of C++, g++ -O2 -c: $best s user (best of $compiles: ${runs[$side]% }), ${peak[$side]} KB peak" | tee -a "$results"
  done
  g++ -std=c++17 -O2 -DA="${name}_$label_a" -DB="${name}_$label_b" -DA_LABEL="\"$label_a\"" -DB_LABEL="\"$label_b\"" \
    -DA_HEADER="\"${name}_$label_a/${name}_$label_a.hpp\"" -DB_HEADER="\"${name}_$label_b/${name}_$label_b.hpp\"" \
    -DTOLERANCE="$tolerance" -I"$dir" tools/ab-bench/harness.cpp "$dir/a.o" "$dir/b.o" -lbenchmark -lpthread -o "$dir/bench"
  for ((r = 1; r <= bench_runs; ++r)); do
    ((bench_runs == 1)) || echo "run $r of $bench_runs" | tee -a "$results"
    "$dir/bench" --benchmark_repetitions=5 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true \
      --benchmark_color=false 2>&1 | grep -E "ab-bench|median" | tee -a "$results"
  done
done
