#!/usr/bin/env bash
# Scaling benchmark (docs/benchmarks-notes.md, "Scaling: kinematic trees"; headline tables in docs/benchmarks.md): hamel against SymPy
# (derivation) and MuJoCo (ns per call, agreement of accelerations) on floating-base serial chains and
# binary trees with n = 1, 2, 4, 8, 16, 30 revolute joints. A command, not a test; runs everything one
# process at a time. Installs nothing: it names what is missing and stops (exit 2).
#   tools/scaling.sh [--max-n N] [--timeout S] [--out DIR] [more tools/scaling/run.py flags]
#     --max-n N     largest n (default 30)
#     --timeout S   SymPy time limit per model in seconds (default 300); after a timeout, the larger n of
#                   that topology are skipped
#     --out DIR     output folder (default build-scaling): scaling.csv, scaling.md, figures/*.svg, work/
#     --docs        also copy scaling.csv, scaling.md to docs/benchmarks/ and the figures to docs/figures/
# HAMEL=<binary> selects the generator (default build/bin/hamel; tools/build.sh --target hamel builds it).
set -euo pipefail
cd "$(dirname "$0")/.."
py=/usr/bin/python3
hamel=${HAMEL:-$PWD/build/bin/hamel}

missing=()
[[ -x $py ]] || missing+=(python3)
if [[ -x $py ]]; then
  $py -c 'import sympy' 2>/dev/null || missing+=(python3-sympy)
  $py -c 'import numpy' 2>/dev/null || missing+=(python3-numpy)
  $py -c 'import matplotlib' 2>/dev/null || missing+=(python3-matplotlib)
fi
command -v g++ > /dev/null || missing+=(g++)
[[ -f /usr/include/mujoco/mujoco.h ]] || missing+=(libmujoco-dev)
[[ -f /usr/include/benchmark/benchmark.h ]] || missing+=(libbenchmark-dev)
if (( ${#missing[@]} )); then
  echo "scaling.sh: missing packages: ${missing[*]}" >&2
  echo "scaling.sh: install them with: bash tools/install-deps.sh --scaling (or apt-get install -y ${missing[*]})" >&2
  exit 2
fi
if [[ ! -x $hamel ]]; then
  echo "scaling.sh: no generator at $hamel; build it first with: tools/build.sh --target hamel" >&2
  exit 2
fi

echo "# machine: $(lscpu | sed -n 's/^Model name:[[:space:]]*//p'), $(nproc) cores; load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# $(g++ --version | head -1); sympy $($py -c 'import sympy; print(sympy.__version__)');" \
     "mujoco $(dpkg-query -W -f '${Version}' libmujoco-dev 2>/dev/null || echo '?');" \
     "benchmark $(dpkg-query -W -f '${Version}' libbenchmark-dev 2>/dev/null || echo '?'); hamel $hamel" \
     "($("$hamel" --version 2>/dev/null | head -1 || echo '?'), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?'))"
exec $py tools/scaling/run.py --hamel "$hamel" "$@"
