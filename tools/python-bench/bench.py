"""The Python side of tools/python-bench.sh: per package, N random states (and inputs), then in rounds the C++
loop (bench_<name>, the same states) and one batch call of the emitted module (pkg.rhs(0.0, X, None, U), all its
argument handling included), each the best of `passes` passes, both ways: writing into one output array reused by
every pass (C++; Python's out=), and into a new array per pass (C++: new double[]; Python: the array it returns).
Prints a Markdown table of the best ns per state over all rounds and the ratios Python / C++ of each way. Times are
CPU times of the process (user and system, page faults included; C++: CLOCK_PROCESS_CPUTIME_ID, Python:
time.process_time), so that what the shared machine gives to other processes is left out.

    /usr/bin/python3 tools/python-bench/bench.py --build DIR --n 10000 --rounds 7 --passes 40 name ...
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
        start = time.process_time()
        kernel(0.0, X, None, U, out=out)
        best = min(best, time.process_time() - start)
    return best / len(X) * 1e9


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", required=True)
    parser.add_argument("--n", type=int, default=10000)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--passes", type=int, default=40)
    parser.add_argument("names", nargs="+")
    args = parser.parse_args()
    print("| package | kernel | outputs/state | C++ loop, reused out | Python, out= | ratio | C++ loop, new out | "
          "Python, returned | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
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
                kernel, how, ns = line.split()
                best[(kernel, "C++ " + how)] = min(best.get((kernel, "C++ " + how), float("inf")), float(ns))
            for kernel in ("rhs", "jacobian"):
                function = getattr(pkg, kernel)
                ns = python_ns_per_state(function, X, U, args.passes)
                best[(kernel, "Python")] = min(best.get((kernel, "Python"), float("inf")), ns)
                out = np.empty((args.n,) + pkg.kernels[kernel][0])
                ns = python_ns_per_state(function, X, U, args.passes, out)
                best[(kernel, "out")] = min(best.get((kernel, "out"), float("inf")), ns)
        for kernel in ("rhs", "jacobian"):
            reused, new = best[(kernel, "C++ reused")], best[(kernel, "C++ new")]
            out, returned = best[(kernel, "out")], best[(kernel, "Python")]
            width = getattr(pkg, "n_out_" + kernel)
            print(f"| {name} | {kernel} | {width} | {reused:.1f} | {out:.1f} | {out / reused:.3f} | {new:.1f} | "
                  f"{returned:.1f} | {returned / new:.3f} |")


if __name__ == "__main__":
    main()
