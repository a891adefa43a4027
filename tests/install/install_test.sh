#!/usr/bin/env bash
# `cmake --install` of the build tree into a scratch prefix, then a user's project (consumer/) that does
# find_package(hamel) and links hamel::runtime is configured, built and run against it; so is one that adds an
# emitted package and links its <model>::with_runtime.
set -euo pipefail
build=$1 source=$2 scratch=$3
rm -rf "$scratch"
cmake --install "$build" --prefix "$scratch/prefix" > "$scratch.install.log" 2>&1 || { cat "$scratch.install.log"; exit 1; }
test -f "$scratch/prefix/lib/cmake/hamel/hamelConfig.cmake"
test -x "$scratch/prefix/bin/hamel"
cmake -S "$source/consumer" -B "$scratch/consumer" -DCMAKE_PREFIX_PATH="$scratch/prefix" > /dev/null
cmake --build "$scratch/consumer" > /dev/null
"$scratch/consumer/consumer"
# An emitted package finds the installed hamel and offers <model>::with_runtime (its kernels stay dependency-free).
"$scratch/prefix/bin/hamel" emit "$source/../../models/double_pendulum.yaml" -o "$scratch/double_pendulum" 2> /dev/null
cmake -S "$source/consumer_package" -B "$scratch/consumer_package" -DCMAKE_PREFIX_PATH="$scratch/prefix" \
  -DHAMEL_PACKAGE="$scratch/double_pendulum" > /dev/null
cmake --build "$scratch/consumer_package" > /dev/null
"$scratch/consumer_package/package_consumer"
rm -rf "$scratch" "$scratch.install.log"
