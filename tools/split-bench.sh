#!/usr/bin/env bash
# Long kernels printed whole against split (emit --split, docs/benchmarks.md "Long kernels split into
# parts"): compile time and run time side by side, every kernel checked bit-identical. Not part of the test
# suite.
#   tools/split-bench.sh [--kernels LIST] [--split N] [--out DIR] [MODEL.yaml ...]
# tools/ab-bench.sh with A = whole (--split 0) and B = split (--split N, default: emit's default); without
# models the scaling benchmark's chain 30 and tree 30. Results: DIR/results.md (default build-split-bench/).
set -euo pipefail
cd "$(dirname "$0")/.."
split_flags=
args=()
while (($#)); do
  case $1 in
    --split) split_flags="--split $2"; shift 2 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) args+=("$1"); shift ;;
  esac
done
exec tools/ab-bench.sh --out "$PWD/build-split-bench" --a-label whole --a-flags "--split 0" --b-label split \
  --b-flags "$split_flags" "${args[@]}"
