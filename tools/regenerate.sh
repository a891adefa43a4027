#!/usr/bin/env bash
# Regenerates the packages listed in generated/packages.txt into generated/<folder> with `hamel emit`.
#   tools/regenerate.sh            rewrite generated/ (each folder is replaced atomically)
#   tools/regenerate.sh --check    emit into a scratch folder and report differences; exit 1 if any
# HAMEL=<binary> selects the generator (default build/bin/hamel; build it with tools/build.sh --target hamel).
# Folders under generated/ that the list does not name are reported as stale.
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${HAMEL:-build/bin/hamel}
check=0
if [[ ${1:-} == --check ]]; then check=1; fi
[[ -x $hamel ]] || { echo "regenerate.sh: no generator at $hamel (run tools/build.sh --target hamel)" >&2; exit 2; }

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
status=0
listed=()
while read -r folder source flags; do
  [[ -z ${folder} || ${folder} == \#* ]] && continue
  listed+=("$folder")
  if ((check)); then out=$scratch/$folder; else out=generated/$folder; fi
  # shellcheck disable=SC2086  # flags are words
  if ! "$hamel" emit "$source" -o "$out" $flags > "$scratch/log" 2>&1; then
    cat "$scratch/log" >&2
    echo "regenerate.sh: hamel emit $source $flags failed" >&2
    exit 1
  fi
  if ((check)); then
    if ! diff -r "$out" "generated/$folder" > /dev/null 2>&1; then
      echo "differs: generated/$folder (hamel emit $source $flags)"
      status=1
    fi
  else
    echo "wrote generated/$folder"
  fi
done < generated/packages.txt

for dir in generated/*/; do
  name=$(basename "$dir")
  if [[ ! " ${listed[*]} " == *" $name "* ]]; then
    echo "stale: generated/$name is not in generated/packages.txt" >&2
    status=1
  fi
done
exit $status
