#!/usr/bin/env bash
# hamel's emitted kernels against DART and MuJoCo, side by side in one binary per robot (docs/benchmarks.md,
# "Against DART and MuJoCo"; issue 48): rhs, jacobian and mass_matrix on the floating chains and binary trees of
# tools/scaling/models.py (n revolute joints, full inertias, no gravity) and on MuJoCo's humanoid imported with
# `hamel import`.
#
# For each robot: `hamel emit --fold all --kernels rhs,jacobian,mass_matrix`; one Google Benchmark binary
# (tools/peer-bench/bench.cpp, g++ -O2, with tools/peer-bench/peers.cpp) holding the package, MuJoCo (the MJCF)
# and DART (a skeleton built from MuJoCo's compiled model of the same MJCF). It first checks agreement at 20
# random states (u̇ and M against both peers to 1e-9, the Jacobian's u̇ rows against centred differences of
# both peers' forward dynamics to 1e-5) and stops on a disagreement; then times, repetitions interleaved in random
# order:
#   hamel     rhs, jacobian, mass_matrix
#   DART      forward: Skeleton::computeForwardDynamics (articulated bodies); mass matrix: getMassMatrix;
#             jacobian: DART 6.12 has no derivative of its forward dynamics, so forward differences of
#             computeForwardDynamics, 1 + n_state calls (what a DART user writes)
#   MuJoCo    forward: mj_forward, and its smooth dynamics alone (mj_fwdPosition, mj_fwdVelocity,
#             mj_fwdActuation, mj_fwdAcceleration); mass matrix: mj_kinematics, mj_comPos, mj_crb, mj_fullM;
#             jacobian: forward differences of mj_forwardSkip (the position stage skipped for velocity columns,
#             1 + n_state calls), and mjd_transitionFD (centred, of the discrete step) for reference
# The peers' calls include storing the state in the library, and every timed loop switches between two states.
# Prints Markdown tables: ratios of minima hamel/peer, minima in ns (CPU time), agreement.
#
#   tools/peer-bench.sh [--repetitions N] [--ns 4,8,16,30] [--no-humanoid]
#     --repetitions N   interleaved repetitions of each benchmark (default 10: 16 minutes on the 2-core host at
#                       load 9-16, most of it compiling; a rerun compiles only what changed)
#     --min-time S      Google Benchmark's --benchmark_min_time per repetition (default 0.05)
#     --ns LIST         joint counts of the chains and trees (default 4,8,16,30)
#     --no-humanoid     leave the humanoid out
#     --package-flags F the emitted package's g++ flags (default "-O2"; e.g. "-O2 -march=native": the peers are
#                       Debian's builds for generic x86-64 whatever this says)
# Needs build/bin/hamel (or HAMEL=<binary>) and Debian's libdart-dev, libmujoco-dev, libmujoco-samples,
# libbenchmark-dev, libeigen3-dev, python3-numpy; as root it installs the missing ones with apt-get.
# Work files in build/peer-bench/.
set -euo pipefail
cd "$(dirname "$0")/.."
reps=10
min_time=0.05
ns=4,8,16,30
humanoid=1
package_flags=-O2
while (($#)); do
  case $1 in
    --repetitions) reps=$2; shift 2 ;;
    --min-time) min_time=$2; shift 2 ;;
    --ns) ns=$2; shift 2 ;;
    --no-humanoid) humanoid=0; shift ;;
    --package-flags) package_flags=$2; shift 2 ;;
    *) echo "peer-bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
hamel=${HAMEL:-build/bin/hamel}
py=/usr/bin/python3
[[ -x $hamel ]] || { echo "peer-bench.sh: no generator at $hamel (tools/build.sh --target hamel)" >&2; exit 2; }

packages=(g++ python3 python3-numpy libdart-dev libmujoco-dev libmujoco-samples libbenchmark-dev libeigen3-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2> /dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "peer-bench.sh: missing packages: ${missing[*]} (apt-get install -y ${missing[*]})" >&2
    exit 2
  fi
  echo "peer-bench.sh: installing ${missing[*]}" >&2
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" > /dev/null
fi

work=build/peer-bench
mkdir -p "$work"
cxx=(g++ -std=c++17 -O2 -I/usr/include/eigen3 -Itools/peer-bench)
# DART's headers take most of a minute: peers.o is compiled once and again only when its sources change.
if [[ ! -f $work/peers.o || tools/peer-bench/peers.cpp -nt $work/peers.o || tools/peer-bench/peers.hpp -nt $work/peers.o ]]; then
  "${cxx[@]}" -c tools/peer-bench/peers.cpp -o "$work/peers.o"
fi

models=()
for topology in chain tree; do
  for n in ${ns//,/ }; do
    $py tools/scaling/models.py --topology "$topology" --n "$n" --out "$work" > /dev/null
    models+=("${topology}_$n")
  done
done
extra=()
if ((humanoid)); then
  # DART 6.12 has no joint armature: the humanoid's (0.01 on every hinge) is left out of all three.
  "$hamel" -q import /usr/share/mujoco/model/humanoid/humanoid.xml -o "$work/humanoid_full.yaml" --name humanoid \
    --ignore contacts,limits 2> "$work/humanoid.import.log"
  sed '/^ *armature:/d' "$work/humanoid_full.yaml" > "$work/humanoid.yaml"
  cp /usr/share/mujoco/model/humanoid/humanoid.xml "$work/humanoid.xml"
  models+=(humanoid)
fi

echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(git rev-parse --short HEAD), $(lscpu | sed -n 's/^Model name:[[:space:]]*//p')," \
  "$(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); $(g++ --version | head -1);" \
  "DART $(dpkg-query -W -f '${Version}' libdart-dev), MuJoCo $(dpkg-query -W -f '${Version}' libmujoco-dev)," \
  "Google Benchmark $(dpkg-query -W -f '${Version}' libbenchmark-dev); package $package_flags;" \
  "$reps repetitions, min time $min_time s"
for name in "${models[@]}"; do
  flags=()
  [[ $name == humanoid ]] && flags=(--zero-armature)
  "$hamel" -q emit "$work/$name.yaml" -o "$work/pkg/$name" --fold all --kernels rhs,jacobian,mass_matrix \
    > "$work/$name.emit.log" 2>&1 || { cat "$work/$name.emit.log" >&2; exit 1; }
  # The binary is rebuilt only when the package or the bench sources changed (a rerun with more repetitions
  # compiles nothing).
  stamp=$( (cat "$work/pkg/$name/$name.cpp" "$work/pkg/$name/$name.hpp" tools/peer-bench/bench.cpp \
    tools/peer-bench/peers.hpp "$work/peers.o"; echo "$package_flags") | sha256sum | cut -c1-16)
  if [[ ! -x $work/bench_$name || $(cat "$work/bench_$name.stamp" 2> /dev/null) != "$stamp" ]]; then
    # shellcheck disable=SC2086 # the flags are words
    g++ -std=c++17 $package_flags -c "$work/pkg/$name/$name.cpp" -o "$work/pkg/$name/$name.o"
    "${cxx[@]}" -DPKG="$name" -DPKG_NAME="\"$name\"" -DPKG_HEADER="\"$name.hpp\"" -I"$work/pkg/$name" \
      tools/peer-bench/bench.cpp "$work/pkg/$name/$name.o" "$work/peers.o" -o "$work/bench_$name" \
      -ldart -lmujoco -lbenchmark -lpthread
    echo "$stamp" > "$work/bench_$name.stamp"
  fi
  # DART warns about the massless bodies between a MuJoCo body's hinges on stderr: kept in a log.
  if ! "$work/bench_$name" "$work/$name.xml" "${flags[@]}" check 20 > "$work/$name.check" 2> "$work/$name.stderr"; then
    echo "peer-bench.sh: $name disagrees: $(cat "$work/$name.check")" >&2
    exit 1
  fi
  echo "# $(cat "$work/$name.check")"
  "$work/bench_$name" "$work/$name.xml" "${flags[@]}" --benchmark_repetitions="$reps" \
    --benchmark_enable_random_interleaving=true --benchmark_min_time="$min_time" \
    --benchmark_out="$work/$name.json" --benchmark_out_format=json > /dev/null 2>> "$work/$name.stderr"
done
echo "# done $(date -u '+%H:%M UTC'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
$py tools/peer-bench/report.py "$work" "${models[@]}"
