#!/usr/bin/env bash
# Measures emitted kernels on Cortex-M under QEMU and writes the table of docs/firmware.md (between its
# "firmware-table" markers): per kernel, code size, stack (of the kernel and of its work-space form) and instructions
# per call, on a Cortex-M4F in float, a Cortex-M7 in double, and a Cortex-M4F in double (software double, for the
# float/double choice). Needs arm-none-eabi-gcc, newlib and qemu-system-arm (tools/install-deps.sh) and the built
# generator (tools/build.sh), which emits the Whipple bicycle (models/whipple_bicycle.yaml, --fold all --split 1000) beside the
# shipped packages. Takes a few minutes (the bicycle's 1.4 MB package is compiled three times).
#   tools/firmware-table.sh            rewrite the table in docs/firmware.md
#   tools/firmware-table.sh --print    print it instead
# How: tests/firmware/measure.cpp with the package, compiled with the flags of docs/firmware.md (-O2), linked into an
# image for QEMU's MPS2 board (tests/firmware/mps2.ld, startup.cpp), run with -icount shift=0 (one nanosecond of
# virtual time per instruction; SysTick calibrated on a loop of known length). Stack: painting, including the libm
# calls a kernel makes. Code: the sizes (nm -S) of the kernel's functions (itself, its _work form, its parts, its
# stage and column functions; rhs also rhs_with_pivots), not counting libm or stages shared with other kernels.
set -euo pipefail
cd "$(dirname "$0")/.."
export LC_ALL=C  # sort and join agree on the order
print=0
[[ ${1:-} == --print ]] && print=1
for tool in arm-none-eabi-g++ arm-none-eabi-nm qemu-system-arm; do
  command -v "$tool" > /dev/null || { echo "firmware-table.sh: $tool not found (tools/install-deps.sh)" >&2; exit 2; }
done
hamel=${HAMEL:-build/bin/hamel}
[[ -x $hamel ]] || { echo "firmware-table.sh: no generator at $hamel (tools/build.sh)" >&2; exit 2; }

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
# --split 1000: parts of at most 1000 operations, as docs/firmware.md advises for large kernels in double (the same
# options as tests/firmware, which checks the bicycle's figures against this table).
"$hamel" emit models/whipple_bicycle.yaml -o "$scratch/whipple_bicycle" --fold all --split 1000 > /dev/null 2>&1

flags="-std=c++17 -O2 -Wall -Wextra -Werror -pedantic -Wdouble-promotion -fno-exceptions -fno-rtti -fno-math-errno
       -ffp-contract=off -ffunction-sections -fdata-sections"
m4="-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb"
m7="-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb"
fw=tests/firmware

# measure PACKAGE_DIR NAME CONFIG: CONFIG is m4f (float), m7 (double) or m4d (double on the M4F);
# writes $scratch/NAME.CONFIG: "kernel n_work stack stack_work instructions code" per line.
measure() {
  local dir=$1 name=$2 config=$3 cpu real machine
  case $config in
    m4f) cpu=$m4 real=float machine=mps2-an386 ;;
    m7) cpu=$m7 real=double machine=mps2-an500 ;;
    m4d) cpu=$m4 real=double machine=mps2-an386 ;;
  esac
  local macro
  macro=HAMEL_$(echo "$name" | tr '[:lower:]' '[:upper:]')_REAL
  local out=$scratch/$name.$config
  # shellcheck disable=SC2086  # flag lists are words
  arm-none-eabi-g++ $flags $cpu -D"$macro=$real" -c "$dir/$name.cpp" -I"$dir" -o "$out.o"
  # shellcheck disable=SC2086
  arm-none-eabi-g++ $flags $cpu -D"$macro=$real" -I"$dir" -I$fw -DPACKAGE="$name" "-DPACKAGE_HEADER=\"$name.hpp\"" \
    $fw/measure.cpp $fw/startup.cpp "$out.o" -nostartfiles -T $fw/mps2.ld -Wl,--gc-sections \
    --specs=nano.specs --specs=rdimon.specs -lm -o "$out.elf"
  # Semihosting output goes to QEMU's stderr; the lines of five fields are the program's.
  timeout 600 qemu-system-arm -M "$machine" -icount shift=0 -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -kernel "$out.elf" 2>&1 | awk 'NF == 5' > "$out.run"
  # Code bytes per kernel from the object's function sizes.
  arm-none-eabi-nm -S -C -t d --defined-only "$out.o" | awk -v kernels="$(cut -d' ' -f1 "$out.run" | tr '\n' ' ')" '
    BEGIN { n = split(kernels, k, " ") }
    $3 ~ /^[Tt]$/ {
      name = $0; sub(/^[0-9]+ [0-9]+ [Tt] /, "", name); gsub(/\(anonymous namespace\)::/, "", name)
      sub(/\(.*/, "", name); sub(/.*::/, "", name)
      size = $2 + 0
      for (i = 1; i <= n; ++i) {
        base = k[i]
        if (name == base || name ~ ("^" base "_(work|part[0-9]+|stage.*|column.*|own.*)$") ||
            (base == "rhs" && name ~ /^rhs_with_pivots/)) code[base] += size
      }
    }
    END { for (i = 1; i <= n; ++i) print k[i], code[k[i]] + 0 }' > "$out.code"
  join <(sort "$out.run") <(sort "$out.code") > "$out"
}

table() {
  echo "| package | kernel | work (reals) | M4F float: code B | stack B (_work) | instructions | M7 double: code B | stack B (_work) | instructions | M4F double: instructions (x float) |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
  local dir name
  for entry in "generated/double_pendulum double_pendulum" "generated/satellite_se3 satellite_se3" \
               "generated/space_robot space_robot" "$scratch/whipple_bicycle whipple_bicycle"; do
    read -r dir name <<< "$entry"
    for config in m4f m7 m4d; do measure "$dir" "$name" $config & done
    wait
    # shellcheck disable=SC2016
    join "$scratch/$name.m4f" "$scratch/$name.m7" | join - "$scratch/$name.m4d" |
      awk -v pkg="$name" '{ printf "| %s | `%s` | %s | %s | %s (%s) | %s | %s | %s (%s) | %s | %s (%.0fx) |\n",
                             pkg, $1, $2, $6, $3, $4, $5, $11, $8, $9, $10, $15, ($5 > 0 ? $15 / $5 : 0) }'
  done
}

result=$(table)
if ((print)); then
  echo "$result"
  exit 0
fi
doc=docs/firmware.md
begin='<!-- firmware-table begin: tools/firmware-table.sh -->'
end='<!-- firmware-table end -->'
grep -qF "$begin" "$doc" || { echo "firmware-table.sh: no table markers in $doc" >&2; exit 1; }
awk -v begin="$begin" -v end="$end" -v table="$result" '
  $0 == begin { print; print table; skip = 1; next }
  $0 == end { skip = 0 }
  !skip { print }' "$doc" > "$scratch/doc" && mv "$scratch/doc" "$doc"
echo "firmware-table.sh: wrote the table of $doc"
