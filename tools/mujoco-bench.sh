#!/usr/bin/env bash
# Shipped floating-base models and closed-loop linkages side by side with MuJoCo (docs/benchmarks.md, "Against MuJoCo: shipped and imported
# robots"): for each model, `hamel emit --fold all --kernels rhs,jacobian`, one Google Benchmark binary
# (tools/mujoco-bench/bench.cpp, g++ -O2) with mj_forward, mjd_transitionFD and the emitted rhs and jacobian,
# after a check that rhs agrees with mj_forward at 20 random states. Closed-loop linkages on a fixed base (an
# <equality><connect> in MuJoCo) use tools/mujoco-bench/bench_loop.cpp instead: MuJoCo's loop is soft, so their
# check solves the rigid loop from MuJoCo's mass matrix, bias forces and the loop's Jacobian with Lagrange
# multipliers at 20 random states on the loop (tolerance 1e-8, relative), and mj_forward is timed with MuJoCo's
# constraint solver for the loop. Prints a Markdown table (medians).
#   tools/mujoco-bench.sh [--repetitions N]     default 9, interleaved in random order
# Needs build/bin/hamel, libmujoco-dev, libbenchmark-dev, libeigen3-dev (bench_loop) and python3
# (tools/install-deps.sh --scaling).
set -euo pipefail
cd "$(dirname "$0")/.."
reps=9
if [[ ${1:-} == --repetitions ]]; then reps=$2; fi
hamel=${HAMEL:-build/bin/hamel}
work=build/mujoco-bench
mkdir -p "$work"
humanoid=/usr/share/mujoco/model/humanoid/humanoid.xml
"$hamel" -q import "$humanoid" -o "$work/humanoid_gravity.yaml" --name humanoid_gravity --ignore contacts,limits
"$hamel" -q import tests/loops/slider_crank.xml -o "$work/slider_crank.yaml" > "$work/slider_crank.import.log" 2>&1 ||
  { cat "$work/slider_crank.import.log" >&2; exit 1; }
# name | hamel model | MJCF | bench source (bench: floating base; bench_loop: closed loop on a fixed base)
cases=("humanoid_gravity $work/humanoid_gravity.yaml $humanoid bench"
       "quadrotor_slung_load models/quadrotor_slung_load.yaml tools/mujoco-bench/quadrotor_slung_load.xml bench"
       "satellite_thrusters models/satellite_thrusters.yaml tools/mujoco-bench/satellite_thrusters.xml bench"
       "slider_crank $work/slider_crank.yaml tests/loops/slider_crank.xml bench_loop"
       "four_bar_tree models/four_bar_tree.yaml tools/mujoco-bench/four_bar_tree.xml bench_loop")
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(git rev-parse --short HEAD), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)," \
  "$(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| model | dof | hamel rhs ns | mj_forward ns | rhs / mj_forward | hamel jacobian ns | mjd_transitionFD ns | jacobian / transitionFD | rhs vs mj_forward |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for c in "${cases[@]}"; do
  read -r name yaml xml source <<< "$c"
  "$hamel" -q emit "$yaml" -o "$work/$name" --fold all --kernels rhs,jacobian > "$work/$name.log" 2>&1 ||
    { cat "$work/$name.log" >&2; exit 1; }
  g++ -std=c++17 -O2 -DPKG="$name" -DPKG_NAME="\"$name\"" -DPKG_HEADER="\"$name.hpp\"" -I"$work/$name" \
    -I/usr/include/eigen3 "tools/mujoco-bench/$source.cpp" "$work/$name/$name.cpp" -o "$work/bench_$name" \
    -lmujoco -lbenchmark -lpthread
  report=$("$work/bench_$name" "$xml" check 20) ||
    { echo "mujoco-bench.sh: $name disagrees with MuJoCo: $report" >&2; exit 1; }
  echo "$report" > "$work/$name.check"
  agreement=${report##*difference }
  if [[ $source == bench_loop ]]; then agreement="$agreement (rigid loop)"; fi
  "$work/bench_$name" "$xml" --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
    --benchmark_min_time=0.1 --benchmark_out="$work/$name.json" --benchmark_out_format=json > /dev/null 2>&1
  dof=$(grep -o 'n_independent = [0-9]*' "$work/$name/$name.hpp" | grep -o '[0-9]*$')
  /usr/bin/python3 - "$work/$name.json" "$name" "$dof" "$agreement" << 'PY'
import json, statistics, sys
runs = json.load(open(sys.argv[1]))["benchmarks"]
med = {}
for name in ("mujoco_forward", "mujoco_transitionFD", "hamel_rhs", "hamel_jacobian"):
    times = [b["cpu_time"] for b in runs if b["name"] == "BM_" + name and b.get("run_type") == "iteration"]
    med[name] = statistics.median(times)
print(f"| {sys.argv[2]} | {sys.argv[3]} | {med['hamel_rhs']:.0f} | {med['mujoco_forward']:.0f} | "
      f"{med['hamel_rhs'] / med['mujoco_forward']:.2f} | {med['hamel_jacobian']:.0f} | {med['mujoco_transitionFD']:.0f} | "
      f"{med['hamel_jacobian'] / med['mujoco_transitionFD']:.3f} | {sys.argv[4]} |")
PY
done
