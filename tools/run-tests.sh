#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds everything, runs ctest. Arguments go to ctest, except
# --fast: only the unit tier (ctest -L '^unit$'; the tiers are described in tests/CMakeLists.txt).
set -euo pipefail
cd "$(dirname "$0")/.."
args=()
for a in "$@"; do
  if [ "$a" = "--fast" ]; then args+=(-L '^unit$'); else args+=("$a"); fi
done
bash tools/install-deps.sh
bash tools/build.sh
cd build
ctest --output-on-failure -j"$(nproc)" "${args[@]}"
