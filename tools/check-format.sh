#!/usr/bin/env bash
# Checks that the C++ sources of the generator, runtime, tests, tools and benchmarks follow .clang-format (Debian's
# clang-format 14, which tools/install-deps.sh installs); exit 1 naming the files that do not.
#   tools/check-format.sh          check (ctest runs this as sources_follow_clang_format)
#   tools/check-format.sh --fix    reformat those files in place
# Emitted packages (generated/, build folders) are printed by hamel and not checked.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format > /dev/null || { echo "check-format.sh: clang-format not found (tools/install-deps.sh installs it)" >&2; exit 1; }
mapfile -t files < <(find benchmarks generator runtime tests tools -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) | sort)
if [[ ${1:-} == --fix ]]; then
  clang-format -i "${files[@]}"
  exit 0
fi
# One run over every file; the files named in its diagnostics (file:line:col: error: ...) are the ones that differ.
if report=$(clang-format --dry-run --Werror "${files[@]}" 2>&1); then
  echo "check-format.sh: ${#files[@]} files follow .clang-format"
  exit 0
fi
mapfile -t bad < <(grep -oE '^[^:]+:[0-9]+:[0-9]+: error' <<< "$report" | cut -d: -f1 | sort -u)
echo "check-format.sh: ${#bad[@]} of ${#files[@]} files differ from .clang-format (tools/check-format.sh --fix):" >&2
if ((${#bad[@]})); then printf '  %s\n' "${bad[@]}" >&2; else echo "$report" >&2; fi
exit 1
