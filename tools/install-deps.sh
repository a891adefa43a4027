#!/usr/bin/env bash
# Installs the Debian packages hamel needs to build and test (skips what is already installed).
set -euo pipefail
# clang is installed for the generated-package tests (they build emitted code with g++ and clang++); clang-format
# for the test that the sources follow .clang-format (tools/check-format.sh).
# With --fuzz it also installs libFuzzer and the clang sanitizer runtimes (tools/fuzz.sh only).
# `hamel import` links urdfdom (URDF) and MuJoCo (MJCF); its tests read MuJoCo's sample humanoid.
# The firmware check (tests/firmware) cross-compiles emitted packages for Cortex-M4F and M7 with the bare-metal GCC,
# newlib and its C++ library, and runs them under QEMU's MPS2 boards.
# Emitted packages' Python modules (emit --python, docs/python.md) need python3 and NumPy; their tests (tests/python)
# and the example (examples/python) also SciPy and pytest. Scripts use /usr/bin/python3, Debian's, which has them.
# `hamel animate` inlines three.js (libjs-three) into its pages; its test loads them in Chromium's headless shell
# (chromium-headless-shell: the browser without its GTK desktop parts).
packages=(build-essential cmake pkg-config libginac-dev libcln-dev libeigen3-dev libgtest-dev
          libyaml-cpp-dev nlohmann-json3-dev libcli11-dev clang clang-format liburdfdom-dev libmujoco-dev libmujoco-samples
          gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm
          python3 python3-numpy python3-scipy python3-pytest libjs-three chromium-headless-shell)
# With --scaling it also installs the peers of the scaling benchmark (tools/scaling.sh): SymPy, numpy,
# matplotlib, MuJoCo and Google Benchmark.
if [ "${1:-}" = "--fuzz" ]; then
  packages+=(libclang-rt-dev llvm)
fi
if [ "${1:-}" = "--scaling" ]; then
  packages+=(python3 python3-sympy python3-numpy python3-matplotlib libbenchmark-dev)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo_cmd=""
[ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo_cmd apt-get update -qq
$sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
