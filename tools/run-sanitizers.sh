#!/usr/bin/env bash
# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer: configures build-asan/
# with -fsanitize=address,undefined -fno-omit-frame-pointer (the default compiler, GCC on Debian; no
# extra packages), builds everything, including the hamel binary that the CLI, catalogue and
# emitted-kernel tests run, and runs ctest. Any sanitizer report fails the run: UBSan halts on the first
# error, ASan aborts, LeakSanitizer checks at exit (tools/lsan-suppressions.txt lists what CLN and GiNaC
# keep for the whole process). Extra arguments go to ctest, except --tiers T1,T2: build and run only those test tiers
# (HAMEL_TEST_TIERS; default all: unit,reference,slow). Measured times are in docs/errors.md and .ci/run.
#
# Optimization -O1 with line tables (-g1), the usual level for sanitizer builds: the sanitized objects compile about
# 3x faster than at the plain build's -O2 -g (one heavy test source, 113 s against 349 s), and the stack traces
# still name file and line. -DNDEBUG as in the plain build.
set -euo pipefail
cd "$(dirname "$0")/.."
tiers="unit;reference;slow"
args=()
while [ $# -gt 0 ]; do
  if [ "$1" = "--tiers" ]; then tiers="${2//,/;}"; shift 2; else args+=("$1"); shift; fi
done
bash tools/install-deps.sh
# The build runs the sanitized hamel too (it emits the test models' kernels), so the options apply to it.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tools/lsan-suppressions.txt:print_suppressions=0}
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DHAMEL_TEST_TIERS="$tiers" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > build-asan.configure.log 2>&1 ||
  { cat build-asan.configure.log; exit 1; }
rm -f build-asan.configure.log
cmake --build build-asan -j"$(nproc)"
cd build-asan
# Every test of the tiers built runs, GeneratedPackages.RegenerateByteIdentically too: the sanitized hamel lays out its code and
# data differently, and emission does not depend on that (docs/errors.md, "Emission independent of the address
# layout").
ctest --output-on-failure -j"$(nproc)" ${args[@]+"${args[@]}"}
