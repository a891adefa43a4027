#!/usr/bin/env bash
# Fuzzes the model loader and expression front end with libFuzzer for a bounded time.
#   tools/fuzz.sh [seconds]      (default 60)
# Builds build-fuzz/bin/model_loader_fuzzer (tests/fuzz/) with clang (-fsanitize=fuzzer,address,undefined) in build-fuzz/,
# seeds build-fuzz/corpus/ with models/*.yaml and the error catalogue tests/errors/cases/*.yaml, and runs
# on both cores. The corpus grows across runs. A crash, leak, sanitizer report or hang leaves its input in
# build-fuzz/artifacts/ and makes the script fail; turn each one into a catalogue case
# (tests/errors/README.md) and fix it. Needs clang and libclang-rt-dev (tools/install-deps.sh --fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
bash tools/install-deps.sh --fuzz
flags="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1"
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS="$flags" -DHAMEL_BUILD_TESTS=OFF -DHAMEL_FUZZ=ON > build-fuzz.configure.log 2>&1 ||
  { cat build-fuzz.configure.log; exit 1; }
rm -f build-fuzz.configure.log
cmake --build build-fuzz -j"$(nproc)" --target model_loader_fuzzer
rm -rf build-fuzz/artifacts
mkdir -p build-fuzz/corpus build-fuzz/artifacts
cp models/*.yaml tests/errors/cases/*.yaml build-fuzz/corpus/
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tools/lsan-suppressions.txt:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
jobs=$(nproc)
echo "fuzz: running model_loader_fuzzer for ${seconds}s in ${jobs} forked worker(s)"
status=0
build-fuzz/bin/model_loader_fuzzer build-fuzz/corpus \
  -dict=tests/fuzz/model.dict -max_len=4096 -timeout=20 -rss_limit_mb=4096 \
  -max_total_time="$seconds" -fork="$jobs" \
  -artifact_prefix=build-fuzz/artifacts/ -print_final_stats=1 > build-fuzz/fuzz.log 2>&1 || status=$?
grep -E "^#[0-9]+|stat::|ERROR|SUMMARY|Test unit written|INFO: fuzzed for" build-fuzz/fuzz.log | tail -15 || true
if [ "$status" -ne 0 ] || ls build-fuzz/artifacts/* > /dev/null 2>&1; then
  echo "fuzz: FAILED (status $status); inputs in build-fuzz/artifacts/, log in build-fuzz/fuzz.log"
  exit 1
fi
echo "fuzz: no crash in ${seconds}s; corpus: $(ls build-fuzz/corpus | wc -l) inputs"
