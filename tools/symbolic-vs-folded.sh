#!/usr/bin/env bash
# Symbolic against folded parameters (docs/benchmarks-notes.md, "Symbolic vs folded parameters"):
# emits each model twice (`hamel emit MODEL -o DIR` with p[] read at run time, and `--fold all`), compiles
# both packages at -O2 into one binary (namespaces renamed <model>_symbolic / <model>_folded, each package
# and its adapter its own translation unit), checks that the two rhs (and rhs_prepared, when the symbolic
# package has prepared parameters) agree to 1e-12 relative at 20 pseudo-random states with the default
# parameters, and times them in one Google Benchmark run.
# Not part of the test suite. Output in build-svf/ (results.txt ends with the Markdown table).
#   tools/symbolic-vs-folded.sh [--check-only] [google-benchmark flags...]
# HAMEL=<binary> selects the generator (default build/bin/hamel); MODELS="a b ..." the models (names in models/).
set -euo pipefail
[[ ${1:-} == -h || ${1:-} == --help ]] && { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }
cd "$(dirname "$0")/.."
repo=$PWD
hamel=${HAMEL:-$repo/build/bin/hamel}
[[ -x $hamel ]] || { echo "symbolic-vs-folded.sh: no generator at $hamel (tools/build.sh --target hamel)" >&2; exit 2; }
models=${MODELS:-"double_pendulum rolling_ball rolling_disk_routh falling_cat satellite_so3xr3 satellite_se3 planar_space_robot"}
out=${OUT:-$repo/build-svf}
src=$repo/tools/symbolic-vs-folded
rm -rf "$out"
mkdir -p "$out/obj"

echo "# machine: $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores; $(uptime | sed 's/.*load/load/')" \
  | tee "$out/results.txt"
echo "# compiler: $(g++ --version | head -1); generator: $hamel ($(git -C "$repo" rev-parse --short HEAD))" \
  | tee -a "$out/results.txt"

jobs=()
for model in $models; do
  for variant in symbolic folded; do
    label=${model}_${variant}
    dir=$out/emitted/$label
    flags=()
    [[ $variant == folded ]] && flags=(--fold all)
    echo "# hamel emit models/$model.yaml -o $dir ${flags[*]}" | tee -a "$out/results.txt"
    "$hamel" emit "models/$model.yaml" -o "$dir" "${flags[@]}" > "$out/emit_$label.log" 2>&1 \
      || { cat "$out/emit_$label.log"; exit 1; }
    # "  rhs: 52 operations (11 add, 34 mul, 3 div, 4 call)" -> "52 (11 add, 34 mul, 3 div, 4 call)"
    ops=$(sed -n 's/^  rhs: \([0-9]*\) operations \(.*\)$/\1 \2/p' "$out/emit_$label.log")
    echo "#   rhs: $ops operations" | tee -a "$out/results.txt"
    sed -e "s/@MODEL@/$model/g" -e "s/@LABEL@/$label/g" -e "s/@MODEL_NAME@/$model/g" -e "s/@VARIANT@/$variant/g" \
      -e "s/@OPERATIONS@/$ops/g" "$src/adapter.cpp.in" > "$out/adapter_$label.cpp"
    # The namespace and the C entry points <model>_<kernel> (declared in <model>.h) get the label.
    defs="-D$model=$label"
    for fn in $(grep -o "\b${model}_[a-z_]*(" "$dir/$model.h" | tr -d '(' | sort -u); do
      defs+=" -D$fn=${label}_${fn#"${model}"_}"
    done
    jobs+=("g++ -std=c++17 -O2 $defs -I$dir -c $dir/$model.cpp -o $out/obj/pkg_$label.o")
    jobs+=("g++ -std=c++17 -O2 $defs -I$dir -I$src -c $out/adapter_$label.cpp -o $out/obj/adapter_$label.o")
    # A symbolic package with prepared parameters: rhs_prepared as a third variant.
    if grep -q "prepare_parameters" "$dir/$model.hpp"; then
      ops=$(sed -n 's/^  rhs_prepared: \([0-9]*\) operations \(.*\)$/\1 \2/p' "$out/emit_$label.log")
      echo "#   rhs_prepared: $ops operations" | tee -a "$out/results.txt"
      sed -e "s/@MODEL@/$model/g" -e "s/@LABEL@/$label/g" -e "s/@MODEL_NAME@/$model/g" -e "s/@OPERATIONS@/$ops/g" \
        "$src/adapter_prepared.cpp.in" > "$out/adapter_${label}_prepared.cpp"
      jobs+=("g++ -std=c++17 -O2 $defs -I$dir -I$src -c $out/adapter_${label}_prepared.cpp -o $out/obj/adapter_${label}_prepared.o")
    fi
  done
done
start=$(date +%s)
printf '%s\n' "${jobs[@]}" | xargs -P 2 -I{} sh -c {}
g++ -std=c++17 -O2 -Wall -Wextra -pedantic -I"$src" "$src/main.cpp" "$out"/obj/*.o -lbenchmark -lpthread \
  -o "$out/symbolic_vs_folded"
echo "# build (g++ -O2, 2 jobs): $(( $(date +%s) - start )) s" | tee -a "$out/results.txt"
echo "# $(uptime | sed 's/.*load/load/')" | tee -a "$out/results.txt"
status=0
if [[ ${1:-} == --check-only ]]; then
  "$out/symbolic_vs_folded" --check-only | tee -a "$out/results.txt" || status=$?
else
  "$out/symbolic_vs_folded" --benchmark_repetitions=5 --benchmark_min_time=0.05 --benchmark_color=false \
    --benchmark_report_aggregates_only=true "$@" | tee -a "$out/results.txt" || status=$?
fi
echo "# $(uptime | sed 's/.*load/load/')" | tee -a "$out/results.txt"
exit "$status"
