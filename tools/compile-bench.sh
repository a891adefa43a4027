#!/usr/bin/env bash
# Compile time of one model's package emitted several ways (docs/emit.md, "Large models: compile time against run
# time"). Each variant is emitted once, then `g++ -std=c++17 -O2 -c` of every variant is timed in turn, round after
# round (CPU seconds, user + system): on a shared host one compile can take 70 % longer than the same compile a
# minute later, so the best of the rounds is the steadiest figure, and every round is listed. Not part of the test
# suite.
#   tools/compile-bench.sh [--rounds N] [--out DIR] [--cxx "g++ -std=c++17 -O2"] [MODEL.yaml] [LABEL=FLAGS ...]
# Without a model: the scaling benchmark's 30-joint chain (tools/scaling/models.py, needs /usr/bin/python3 with
# numpy). Without variants: default (no flags), --share-ratio 32, --share-ratio 0, --split 1000,
# --kernels rhs,jacobian,mass_matrix,forcing and --kernels rhs,jacobian. Results: DIR/results.md (default
# build-compile-bench/).
# HAMEL=<binary> selects the generator (default build/bin/hamel).
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${HAMEL:-$PWD/build/bin/hamel}
rounds=4
out=build-compile-bench
cxx="g++ -std=c++17 -O2"
model=
variants=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --rounds) rounds=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --cxx) cxx=$2; shift 2 ;;
    -h|--help) sed -n '2,/^# HAMEL=/p' "$0"; exit 0 ;;
    -*) echo "compile-bench.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *=*) variants+=("$1"); shift ;;
    *) [[ -z $model ]] || { echo "compile-bench.sh: one model only, got $model and $1" >&2; exit 2; }
       model=$1; shift ;;
  esac
done
[[ -x $hamel ]] || { echo "compile-bench.sh: no generator at $hamel (run tools/build.sh --target hamel)" >&2; exit 2; }
[[ $rounds =~ ^[1-9][0-9]*$ ]] || { echo "compile-bench.sh: --rounds takes a whole number >= 1, got '$rounds'" >&2; exit 2; }
mkdir -p "$out"
if [[ -z $model ]]; then
  /usr/bin/python3 tools/scaling/models.py --topology chain --n 30 --out "$out" > /dev/null
  model=$out/chain_30.yaml
fi
[[ -f $model ]] || { echo "compile-bench.sh: no model file $model" >&2; exit 2; }
if [[ ${#variants[@]} -eq 0 ]]; then
  variants=("default=" "share-ratio-32=--share-ratio 32" "share-ratio-0=--share-ratio 0" "split-1000=--split 1000"
            "rhs-jacobian-M-f=--kernels rhs,jacobian,mass_matrix,forcing" "rhs-jacobian=--kernels rhs,jacobian")
fi

labels=()
declare -A source times
for v in "${variants[@]}"; do
  label=${v%%=*}
  flags=${v#*=}
  [[ $label =~ ^[A-Za-z0-9_.-]+$ ]] || { echo "compile-bench.sh: a label is letters, digits, . _ -: '$label'" >&2; exit 2; }
  echo "compile-bench.sh: emitting $label ($model ${flags:-no flags}) ..." >&2
  rm -rf "$out/$label"
  # shellcheck disable=SC2086  # the flags are words
  "$hamel" --quiet emit "$model" -o "$out/$label" $flags > /dev/null 2> "$out/$label.emit.log" \
    || { cat "$out/$label.emit.log" >&2; exit 1; }
  source[$label]=$(ls "$out/$label"/*.cpp)
  labels+=("$label")
done

for ((r = 1; r <= rounds; ++r)); do
  for label in "${labels[@]}"; do
    echo "compile-bench.sh: round $r of $rounds, $label ..." >&2
    # shellcheck disable=SC2086  # the compiler command is words
    t=$( { /usr/bin/time -f '%U %S' $cxx -c "${source[$label]}" -o "$out/$label.o"; } 2>&1 | tail -1 |
      awk '{ printf "%.2f", $1 + $2 }')
    times[$label]="${times[$label]:-} $t"
  done
done

{
  echo "# $(basename "$model" .yaml): \`$cxx -c\`, CPU seconds (user + system), best of $rounds rounds (every round)"
  echo "# machine: $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores; $(${cxx%% *} --version | head -1)"
  echo
  echo "| variant | emit flags | C++ bytes | best | rounds |"
  echo "|---|---|---:|---:|---|"
  for v in "${variants[@]}"; do
    label=${v%%=*}
    flags=${v#*=}
    best=$(tr ' ' '\n' <<< "${times[$label]}" | sed '/^$/d' | sort -g | head -1)
    printf '| %s | %s | %s | %s | %s |\n' "$label" "${flags:-}" "$(wc -c < "${source[$label]}")" "$best" \
      "$(sed 's/^ //; s/ /, /g' <<< "${times[$label]}")"
  done
} | tee "$out/results.md"
