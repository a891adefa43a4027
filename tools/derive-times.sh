#!/usr/bin/env bash
# Derivation and emission time and peak memory of every shipped model, parameters symbolic (the default)
# and folded (--fold all), as a Markdown table on stdout: wall seconds, CPU seconds (user + system: what a loaded
# machine does not inflate) and peak MB (docs/benchmarks.md, "Generation time of the shipped models").
#   tools/derive-times.sh [HAMEL_BINARY] [TIMEOUT_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${1:-build/bin/hamel}
limit=${2:-60}
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
measure() {  # prints "wall seconds (CPU seconds), peak MB" or "timeout"/"error"
  local rc=0
  /usr/bin/time -f '%e %M %U %S' -o "$scratch/time" timeout "$limit" "$@" > /dev/null 2> "$scratch/err" || rc=$?
  if ((rc == 124)); then echo "> ${limit} s"; return; fi
  if ((rc != 0)); then echo "error"; return; fi
  awk '{printf "%.2f s (%.2f CPU), %.0f MB", $1, $3 + $4, $2 / 1024}' "$scratch/time"
}
echo "| model | derive, symbolic | derive, --fold all | emit, symbolic | emit, --fold all |"
echo "|---|---|---|---|---|"
for m in models/*.yaml; do
  name=$(basename "$m" .yaml)
  printf '| %s | %s | %s | %s | %s |\n' "$name" \
    "$(measure "$hamel" derive "$m")" "$(measure "$hamel" derive "$m" --fold all)" \
    "$(measure "$hamel" emit "$m" -o "$scratch/pkg_s")" "$(measure "$hamel" emit "$m" -o "$scratch/pkg_f" --fold all)"
done
