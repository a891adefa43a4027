"""The Python side of tools/python-bench.sh: per package, N random states (and inputs), then in rounds the C++
loop (bench_<name>, the same states, one output array reused) and one batch call of the emitted module
(pkg.rhs(0.0, X, None, U), all its argument handling included): returning a new output array, and writing into one
reused as the C++ loop does (out=); each the best of `passes` passes. Prints a Markdown table of the best ns per state
over all rounds and the ratios Python / C++.

    /usr/bin/python3 tools/python-bench/bench.py --build DIR --n 10000 --rounds 5 --passes 200 name ...
"""

import argparse
import importlib
import os
import subprocess
import sys
import time

import numpy as np


def python_ns_per_state(kernel, X, U, passes, out=None):
    best = float("inf")
    for _ in range(passes):
        start = time.perf_counter()
        kernel(0.0, X, None, U, out=out)
        best = min(best, time.perf_counter() - start)
    return best / len(X) * 1e9


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", required=True)
    parser.add_argument("--n", type=int, default=10000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--passes", type=int, default=200)
    parser.add_argument("names", nargs="+")
    args = parser.parse_args()
    print("| package | kernel | C++ loop ns/state | Python batch ns/state | Python / C++ | Python, out= ns/state | "
          "Python out= / C++ |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for name in args.names:
        folder = os.path.join(args.build, name)
        sys.path.insert(0, folder)
        pkg = importlib.import_module(name)
        rng = np.random.default_rng(49)
        X = rng.uniform(-1, 1, (args.n, pkg.n_state))
        U = rng.uniform(-1, 1, (args.n, pkg.n_inputs)) if pkg.n_inputs else None
        states, inputs = os.path.join(folder, "states.bin"), os.path.join(folder, "inputs.bin")
        X.tofile(states)
        (U if U is not None else np.empty(0)).tofile(inputs)
        best = {}
        for _ in range(args.rounds):
            out = subprocess.run([os.path.join(args.build, "bench_" + name), states, inputs, str(args.n),
                                  str(args.passes)], check=True, stdout=subprocess.PIPE, text=True).stdout
            for line in out.splitlines():
                kernel, ns = line.split()
                best[(kernel, "C++")] = min(best.get((kernel, "C++"), float("inf")), float(ns))
            for kernel in ("rhs", "jacobian"):
                function = getattr(pkg, kernel)
                ns = python_ns_per_state(function, X, U, args.passes)
                best[(kernel, "Python")] = min(best.get((kernel, "Python"), float("inf")), ns)
                out = np.empty((args.n,) + pkg.kernels[kernel][0])
                ns = python_ns_per_state(function, X, U, args.passes, out)
                best[(kernel, "out")] = min(best.get((kernel, "out"), float("inf")), ns)
        for kernel in ("rhs", "jacobian"):
            c, p, o = best[(kernel, "C++")], best[(kernel, "Python")], best[(kernel, "out")]
            print(f"| {name} | {kernel} | {c:.1f} | {p:.1f} | {p / c:.3f} | {o:.1f} | {o / c:.3f} |")


if __name__ == "__main__":
    main()
