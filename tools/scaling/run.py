#!/usr/bin/python3
"""Scaling benchmark of hamel against SymPy (derivation) and MuJoCo (run time) on floating-base trees.

  run.py [--max-n N] [--ns 1,2,4,8,16,30] [--topologies chain,tree] [--timeout S] [--out DIR]
         [--hamel PATH] [--states K] [--no-hamel] [--no-sympy] [--repetitions R] [--interleave]

For every topology and n (models.py), one after the other (never two heavy processes at once):
  hamel   `hamel emit MODEL -o DIR --fold all`: wall time, peak RSS (/usr/bin/time), the operation counts
          stated in the emitted .cpp (kernels rhs, mass_matrix, forcing); then `--kernels rhs,mass_matrix`
          (same kernels, checked by their operation counts) compiled with g++ -O2 (the compile time; with
          --compile-all the whole package instead); ns per call of rhs and mass_matrix (Google Benchmark,
          harness.cpp, median of --repetitions R, default 5; with --interleave the repetitions of all
          benchmarks run in random order, so a burst of load on a noisy host reaches hamel and MuJoCo alike).
  SymPy   sympy_kane.py in a subprocess with a timeout: KanesMethod + kanes_equations time, count_ops of
          M and f, and after cse; peak RSS. After a timeout the larger n of that topology are skipped.
  MuJoCo  ns per call of mj_forward, and of its dynamics core alone (kinematics, CRB, factorM, RNE, solve:
          harness.cpp mujoco_core), in the same binary and run as the hamel kernels.
  check   accelerations at K random states: hamel rhs, MuJoCo (qacc mapped to hamel's coordinates), the
          numpy Newton-Euler reference (newton_euler.py) and SymPy (M^-1 f, when it finished);
          relative error max_states ||a - a_MuJoCo||_inf / ||a_MuJoCo||_inf.
Writes DIR/scaling.csv, DIR/scaling.md and DIR/figures/*.svg (report.py); models, packages and binaries
under DIR/work/.
"""
import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import models  # noqa: E402
import newton_euler  # noqa: E402
import report  # noqa: E402

COLUMNS = [
    "topology", "n", "dof",
    "hamel_status", "hamel_emit_s", "hamel_peak_mb", "hamel_ops_rhs", "hamel_ops_mass_matrix",
    "hamel_ops_forcing", "hamel_tmp_rhs", "hamel_source_bytes", "hamel_emit_rhs_mm_s", "hamel_compiled_bytes",
    "hamel_compile_s",
    "hamel_rhs_ns", "hamel_mass_matrix_ns",
    "sympy_status", "sympy_derive_s", "sympy_peak_mb", "sympy_ops_mass_matrix", "sympy_ops_forcing",
    "sympy_ops_cse", "sympy_cse_s", "sympy_timeout_s",
    "mujoco_forward_ns", "mujoco_core_ns",
    "err_hamel_mujoco", "err_numpy_mujoco", "err_sympy_mujoco", "err_core_mujoco",
    "ratio_hamel_over_sympy_derive", "ratio_hamel_over_mujoco_ns", "ratio_hamel_over_mujoco_core_ns",
]


def log(msg):
    print(msg, flush=True)


def run_measured(cmd, timeout=None, stdout_path=None, stderr_path=None):
    """Runs cmd (stdout and stderr to files); returns (status, wall seconds, peak RSS MB, stdout text).

    status: ok | timeout | exit N. The peak RSS comes from /usr/bin/time (%M), which forks from a small
    process: wait4 on a child forked from this Python would report Python's own RSS (the kernel keeps the
    pre-exec high-water mark). A time limit is enforced by coreutils timeout under /usr/bin/time, so the
    peak of a killed run is still reported.
    """
    tmp = stdout_path or os.path.join(WORK_TMP[0], "stdout.txt")
    mem = os.path.join(WORK_TMP[0], "maxrss.txt")
    full = ["/usr/bin/time", "-f", "%M", "-o", mem]
    if timeout is not None:
        full += ["timeout", "--foreground", "-s", "KILL", f"{timeout:g}"]
    full += cmd
    with open(tmp, "w") as out, open(stderr_path or os.devnull, "w") as err:
        t0 = time.perf_counter()
        code = subprocess.run(full, stdout=out, stderr=err).returncode
        wall = time.perf_counter() - t0
    if code == 0:
        status = "ok"
    elif timeout is not None and wall >= timeout and code in (124, 137, -9):
        status = "timeout"
    else:
        status = f"exit {code}"
    kb = None
    with open(mem) as f:
        for line in f:
            if line.strip().isdigit():
                kb = int(line)
    with open(tmp) as f:
        text = f.read()
    return status, wall, (kb / 1024.0 if kb is not None else None), text


WORK_TMP = ["/tmp"]


def random_states(n, k, seed):
    rng = np.random.default_rng([seed, n])
    rows = []
    for _ in range(k):
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        pos = rng.uniform(-1, 1, 3)
        x = np.concatenate([rng.uniform(-np.pi, np.pi, n), rng.uniform(-1, 1, 6), rng.uniform(-1, 1, n)])
        rows.append(np.concatenate([quat, pos, x]))
    return np.array(rows)


def rel_err(a, ref):
    return max(float(np.max(np.abs(x - r)) / np.max(np.abs(r))) for x, r in zip(a, ref))


OPS_RE = re.compile(r"/\* (\w+): .*ops: (\d+) add, (\d+) mul, (\d+) div, (\d+) call \*/")
TMP_RE = re.compile(r"constexpr int n_temporaries_(\w+) = (\d+);")


def parse_ops(pkg_dir, name):
    ops, tmps = {}, {}
    with open(os.path.join(pkg_dir, name + ".cpp")) as f:
        for line in f:
            m = OPS_RE.search(line)
            if m:
                ops[m.group(1)] = sum(int(m.group(i)) for i in range(2, 6))
    with open(os.path.join(pkg_dir, name + ".hpp")) as f:
        for m in TMP_RE.finditer(f.read()):
            tmps[m.group(1)] = int(m.group(2))
    return ops, tmps


def bench(binary, xml, repetitions=5, interleave=False):
    status, _, _, out = run_measured(
        [binary, "bench", xml, "--benchmark_format=json", f"--benchmark_repetitions={repetitions}",
         "--benchmark_min_time=0.1", "--benchmark_report_aggregates_only=true"]
        + (["--benchmark_enable_random_interleaving=true"] if interleave else []))
    if status != "ok":
        raise RuntimeError(f"{binary} bench: {status}")
    res = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            assert b["time_unit"] == "ns"
            res[b["run_name"]] = b["real_time"]
    return res


def check(binary, xml, states_path):
    status, _, _, out = run_measured([binary, "check", xml, states_path])
    if status != "ok":
        raise RuntimeError(f"{binary} check: {status}")
    rows = {"mujoco": [], "mujoco_core": [], "hamel": []}
    for line in out.splitlines():
        parts = line.split()
        if parts:
            rows[parts[0]].append([float(v) for v in parts[1:]])
    return (np.array(rows["mujoco"]), np.array(rows["mujoco_core"]),
            np.array(rows["hamel"]) if rows["hamel"] else None)


def fmt(v):
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def hamel_supports_trees(hamel, probe_yaml):
    if not os.access(hamel, os.X_OK):
        return False, f"no generator at {hamel}"
    r = subprocess.run([hamel, "derive", probe_yaml], capture_output=True, text=True)
    if r.returncode != 0:
        return False, (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1]
    return True, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ns", default="1,2,4,8,16,30")
    ap.add_argument("--max-n", type=int, default=None)
    ap.add_argument("--topologies", default="chain,tree")
    ap.add_argument("--timeout", type=float, default=300.0, help="SymPy timeout per model, seconds")
    ap.add_argument("--hamel-timeout", type=float, default=3600.0)
    ap.add_argument("--out", default=os.path.join(ROOT, "build-scaling"))
    ap.add_argument("--hamel", default=os.path.join(ROOT, "build", "bin", "hamel"))
    ap.add_argument("--states", type=int, default=20)
    ap.add_argument("--seed", type=int, default=2026)
    ap.add_argument("--no-hamel", action="store_true")
    ap.add_argument("--docs", action="store_true",
                    help="also copy scaling.csv to docs/benchmarks/ and the figures to docs/figures/")
    ap.add_argument("--compile-all", action="store_true",
                    help="compile the whole emitted package (all kernels) instead of one with rhs and mass_matrix")
    ap.add_argument("--no-sympy", action="store_true")
    ap.add_argument("--dynamics", default=None, choices=["aba", "ldlt"],
                    help="hamel emit --dynamics (default: hamel's own default)")
    ap.add_argument("--repetitions", type=int, default=5,
                    help="Google Benchmark repetitions per kernel; the median is reported (default 5)")
    ap.add_argument("--interleave", action="store_true",
                    help="run the repetitions of hamel's kernels and MuJoCo's in random order "
                         "(--benchmark_enable_random_interleaving): ratios that a noisy host disturbs less")
    a = ap.parse_args()

    dyn = ["--dynamics", a.dynamics] if a.dynamics else []
    ns = [int(v) for v in a.ns.split(",")]
    if a.max_n is not None:
        ns = [v for v in ns if v <= a.max_n]
    topologies = a.topologies.split(",")
    out = os.path.abspath(a.out)
    work = os.path.join(out, "work")
    os.makedirs(work, exist_ok=True)
    WORK_TMP[0] = work
    cxx = ["g++", "-std=c++17", "-O2"]
    libs = ["-lmujoco", "-lbenchmark", "-lpthread"]
    harness = os.path.join(HERE, "harness.cpp")

    use_hamel = not a.no_hamel
    if use_hamel and os.access(a.hamel, os.X_OK):
        # one generator for the whole run, even if build/bin/hamel is rebuilt meanwhile
        copy = os.path.join(work, "hamel")
        shutil.copy2(a.hamel, copy)
        log(f"# hamel: {a.hamel} (modified {time.strftime('%Y-%m-%d %H:%M', time.localtime(os.path.getmtime(a.hamel)))}),"
            f" copied to {copy}")
        a.hamel = copy
    if use_hamel:
        models.write_all("chain", 1, os.path.join(work, "probe"))
        ok, why = hamel_supports_trees(a.hamel, os.path.join(work, "probe", "chain_1.yaml"))
        if not ok:
            log(f"# hamel: cannot derive a tree model ({why}); the hamel columns stay empty")
            use_hamel = False
    mj_only = os.path.join(work, "harness_mujoco")
    if not use_hamel:
        log("# compiling the MuJoCo-only harness")
        subprocess.run(cxx + [harness, "-o", mj_only] + libs, check=True)

    csv_path = os.path.join(out, "scaling.csv")
    rows = []
    sympy_stopped = {}
    t_start = time.time()
    for topo in topologies:
        for n in ns:
            tag = f"[{topo} n={n}]"
            spec, stem = models.write_all(topo, n, work)
            name = spec["name"]
            row = {"topology": topo, "n": n, "dof": n + 6}
            states = random_states(n, a.states, a.seed)
            states_path = stem + ".states.txt"
            np.savetxt(states_path, states, fmt="%.17g")
            ref = newton_euler.Tree(spec)
            a_ne = np.array([ref.accelerations(s[7:7 + n], s[7 + n:]) for s in states])

            binary = mj_only
            if use_hamel:
                pkg = os.path.join(work, "pkg", name)
                log(f"{tag} hamel emit --fold all ...")
                status, wall, mb, _ = run_measured(
                    [a.hamel, "emit", stem + ".yaml", "-o", pkg, "--fold", "all"] + dyn, timeout=a.hamel_timeout,
                    stderr_path=stem + ".hamel.log")
                row.update(hamel_status=status, hamel_emit_s=wall, hamel_peak_mb=mb)
                log(f"{tag} hamel emit: {status}, {wall:.2f} s, {fmt(mb)} MB")
                if status == "ok":
                    ops, tmps = parse_ops(pkg, name)
                    row.update(hamel_ops_rhs=ops.get("rhs"), hamel_ops_mass_matrix=ops.get("mass_matrix"),
                               hamel_ops_forcing=ops.get("forcing"), hamel_tmp_rhs=tmps.get("rhs"),
                               hamel_source_bytes=os.path.getsize(os.path.join(pkg, name + ".cpp")))
                    # the harness needs only rhs and mass_matrix; the whole package (jacobian and the bundle
                    # kernels included) takes minutes to compile at n = 30, so a second, smaller package
                    if a.compile_all:
                        src_dir = pkg
                    else:
                        src_dir = os.path.join(work, "pkg_rhs_mass_matrix", name)
                        st2, wall2, _, _ = run_measured(
                            [a.hamel, "emit", stem + ".yaml", "-o", src_dir, "--fold", "all",
                             "--kernels", "rhs,mass_matrix"] + dyn, timeout=a.hamel_timeout, stderr_path=stem + ".hamel2.log")
                        if st2 != "ok":
                            raise RuntimeError(f"hamel emit --kernels rhs,mass_matrix: {st2} (see {stem}.hamel2.log)")
                        row["hamel_emit_rhs_mm_s"] = wall2
                        ops2, _ = parse_ops(src_dir, name)
                        for k in ("rhs", "mass_matrix"):
                            if ops2.get(k) != ops.get(k):
                                raise RuntimeError(f"{k}: {ops2.get(k)} operations with --kernels, {ops.get(k)} without")
                    row["hamel_compiled_bytes"] = os.path.getsize(os.path.join(src_dir, name + ".cpp"))
                    log(f"{tag} g++ -O2 {name}.cpp ({row['hamel_compiled_bytes']} bytes) ...")
                    obj = os.path.join(work, name + ".o")
                    t0 = time.perf_counter()
                    subprocess.run(cxx + ["-c", os.path.join(src_dir, name + ".cpp"), "-o", obj], check=True)
                    row["hamel_compile_s"] = time.perf_counter() - t0
                    binary = os.path.join(work, "harness_" + name)
                    subprocess.run(cxx + [f"-DHAMEL_PKG={name}", f'-DHAMEL_HEADER="{name}.hpp"', "-I", src_dir,
                                          harness, obj, "-o", binary] + libs, check=True)
                    log(f"{tag} compiled in {row['hamel_compile_s']:.1f} s")
                else:
                    binary = mj_only
                    if not os.path.exists(mj_only):
                        subprocess.run(cxx + [harness, "-o", mj_only] + libs, check=True)

            log(f"{tag} accelerations at {a.states} states (MuJoCo{', hamel' if binary != mj_only else ''}, numpy)")
            a_mj, a_core, a_hm = check(binary, stem + ".xml", states_path)
            row["err_numpy_mujoco"] = rel_err(a_ne, a_mj)
            row["err_core_mujoco"] = rel_err(a_core, a_mj)
            if a_hm is not None:
                row["err_hamel_mujoco"] = rel_err(a_hm, a_mj)
            log(f"{tag} benchmark (Google Benchmark, median of {a.repetitions}"
                f"{', interleaved' if a.interleave else ''}) ...")
            res = bench(binary, stem + ".xml", a.repetitions, a.interleave)
            row["mujoco_forward_ns"] = res.get("mujoco_forward")
            row["mujoco_core_ns"] = res.get("mujoco_core")
            row["hamel_rhs_ns"] = res.get("hamel_rhs")
            row["hamel_mass_matrix_ns"] = res.get("hamel_mass_matrix")
            log(f"{tag} ns/call: mj_forward {fmt(row['mujoco_forward_ns'])}, MuJoCo core "
                f"{fmt(row['mujoco_core_ns'])}, hamel rhs {fmt(row['hamel_rhs_ns'])}, "
                f"mass_matrix {fmt(row['hamel_mass_matrix_ns'])}; rel. error vs MuJoCo: hamel "
                f"{fmt(row.get('err_hamel_mujoco'))}, numpy {fmt(row['err_numpy_mujoco'])}")

            if not a.no_sympy:
                if topo in sympy_stopped:
                    row["sympy_status"] = f"skipped (timeout at n={sympy_stopped[topo]})"
                    log(f"{tag} SymPy: skipped, it timed out at n={sympy_stopped[topo]}")
                else:
                    log(f"{tag} SymPy KanesMethod (timeout {a.timeout:.0f} s) ...")
                    status, wall, mb, text = run_measured(
                        ["/usr/bin/python3", os.path.join(HERE, "sympy_kane.py"), stem + ".json",
                         "--states", states_path], timeout=a.timeout, stdout_path=stem + ".sympy.jsonl",
                        stderr_path=stem + ".sympy.log")
                    stages = {}
                    for line in text.splitlines():
                        try:
                            d = json.loads(line)
                            stages[d["stage"]] = d
                        except (ValueError, KeyError):
                            pass
                    row["sympy_peak_mb"] = mb
                    if "derive" in stages:
                        row["sympy_derive_s"] = stages["derive"]["seconds"]
                    if "count_ops" in stages:
                        row["sympy_ops_mass_matrix"] = stages["count_ops"]["ops_mass_matrix"]
                        row["sympy_ops_forcing"] = stages["count_ops"]["ops_forcing"]
                    if "cse" in stages:
                        row["sympy_ops_cse"] = stages["cse"]["ops_cse"]
                        row["sympy_cse_s"] = stages["cse"]["seconds"]
                    if "accelerations" in stages:
                        row["err_sympy_mujoco"] = rel_err(np.array(stages["accelerations"]["rows"]), a_mj)
                    row["sympy_timeout_s"] = a.timeout
                    if status == "ok":
                        row["sympy_status"] = "ok"
                    else:
                        done = [s for s in ("derive", "count_ops", "cse", "accelerations") if s in stages]
                        row["sympy_status"] = f"{status}" + (f" after {done[-1]}" if done else " in derive")
                        if "derive" not in stages:
                            sympy_stopped[topo] = n
                    log(f"{tag} SymPy: {row['sympy_status']}, derive {fmt(row.get('sympy_derive_s'))} s, "
                        f"{fmt(mb)} MB, ops M {fmt(row.get('sympy_ops_mass_matrix'))}, f "
                        f"{fmt(row.get('sympy_ops_forcing'))}, cse {fmt(row.get('sympy_ops_cse'))}, "
                        f"rel. error vs MuJoCo {fmt(row.get('err_sympy_mujoco'))}")

            if row.get("hamel_emit_s") and row.get("sympy_derive_s"):
                row["ratio_hamel_over_sympy_derive"] = row["hamel_emit_s"] / row["sympy_derive_s"]
            if row.get("hamel_rhs_ns") and row.get("mujoco_forward_ns"):
                row["ratio_hamel_over_mujoco_ns"] = row["hamel_rhs_ns"] / row["mujoco_forward_ns"]
                row["ratio_hamel_over_mujoco_core_ns"] = row["hamel_rhs_ns"] / row["mujoco_core_ns"]
            rows.append(row)
            with open(csv_path, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(COLUMNS)
                for r in rows:
                    w.writerow([fmt(r.get(c)) for c in COLUMNS])
    log(f"# total {time.time() - t_start:.0f} s; {csv_path}")
    report.write(csv_path, out)
    log(f"# {os.path.join(out, 'scaling.md')}, {os.path.join(out, 'figures')}/")
    if a.docs:
        os.makedirs(os.path.join(ROOT, "docs", "benchmarks"), exist_ok=True)
        shutil.copy2(csv_path, os.path.join(ROOT, "docs", "benchmarks", "scaling.csv"))
        shutil.copy2(os.path.join(out, "scaling.md"), os.path.join(ROOT, "docs", "benchmarks", "scaling.md"))
        for f in sorted(os.listdir(os.path.join(out, "figures"))):
            shutil.copy2(os.path.join(out, "figures", f), os.path.join(ROOT, "docs", "figures", f))
        log("# copied to docs/benchmarks/scaling.{csv,md} and docs/figures/scaling_*.svg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
