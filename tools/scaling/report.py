#!/usr/bin/python3
"""Tables and log-log figures of the scaling benchmark from its CSV (run.py calls it at the end).

  report.py SCALING.csv OUT_DIR     writes OUT_DIR/scaling.md and OUT_DIR/figures/scaling_{derive_time,
                                    ops,ns,memory}.svg
"""
import collections
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

matplotlib.rcParams["svg.hashsalt"] = "hamel-scaling"  # reproducible SVG ids
matplotlib.rcParams["svg.fonttype"] = "none"


def load(csv_path):
    with open(csv_path) as f:
        return [collections.defaultdict(str, r) for r in csv.DictReader(f)]


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def cell(v, digits=3, integer=False):
    x = num(v)
    if x is None:
        return v if v else "-"
    if integer:
        return f"{int(round(x)):,}".replace(",", " ")
    if x != 0 and abs(x) < 1e-3:
        return f"{x:.1e}"
    if abs(x) >= 100:
        return f"{int(round(x)):,}".replace(",", " ")
    return f"{x:.{digits}g}"


def series(rows, topo, key):
    pts = [(int(r["n"]), num(r[key])) for r in rows if r["topology"] == topo]
    return [(n, y) for n, y in pts if y is not None and y > 0]


def slope(pts):
    """Least-squares exponent of y ~ n^k over the points with n >= 2 (None with fewer than 2)."""
    pts = [(n, y) for n, y in pts if n >= 2]
    if len(pts) < 2:
        return None
    xs = [math.log(n) for n, _ in pts]
    ys = [math.log(y) for _, y in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx


def last_slope(pts, shift=0):
    """Exponent between the last two points, against n + shift (shift 6: the degrees of freedom)."""
    if len(pts) < 2:
        return None
    (n0, y0), (n1, y1) = pts[-2], pts[-1]
    return math.log(y1 / y0) / math.log((n1 + shift) / (n0 + shift))


STYLE = {"chain": "-", "tree": "--"}
MARK = {"chain": "o", "tree": "s"}


def figure(rows, path, title, ylabel, curves, timeouts=None):
    """curves: [(label, key, color)]; timeouts: (label, key_status, timeout_y, color) marks timed-out n."""
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    allpts = []
    topos = sorted({r["topology"] for r in rows}, key=lambda t: ["chain", "tree"].index(t) if t in STYLE else 9)
    for label, key, color in curves:
        for topo in topos:
            pts = series(rows, topo, key)
            if not pts:
                continue
            allpts += pts
            ax.plot([p[0] for p in pts], [p[1] for p in pts], STYLE.get(topo, ":"), marker=MARK.get(topo, "^"),
                    color=color, label=f"{label}, {topo}", markersize=4)
    if timeouts:
        label, status_key, y_key, color = timeouts
        for topo in topos:
            hit = [r for r in rows if r["topology"] == topo and r[status_key].startswith("timeout")
                   and not num(r.get(y_key))]
            if hit:
                ys = [num(r.get("sympy_timeout_s")) or max(p[1] for p in allpts) for r in hit]
                ax.plot([int(r["n"]) for r in hit], ys, "x" if topo == "chain" else "+", color=color, markersize=10,
                        mew=2,
                        label=f"{label}: time limit ({ys[0]:g} s) reached, {topo}")
                allpts += [(int(r["n"]), y) for r, y in zip(hit, ys)]
    if allpts:
        n_min = min(p[0] for p in allpts)
        n_max = max(p[0] for p in allpts)
        y0 = sorted(p[1] for p in allpts if p[0] == n_min)[0]
        ns = [n_min, n_max]
        for k, ls in ((1, (0, (1, 2))), (2, (0, (4, 2))), (3, (0, (6, 2, 1, 2)))):
            ax.plot(ns, [y0 * (n / n_min) ** k for n in ns], linestyle=ls, color="0.6", linewidth=1)
            ax.annotate(f"n^{k}", (n_max, y0 * (n_max / n_min) ** k), color="0.4", fontsize=8,
                        xytext=(3, 0), textcoords="offset points", va="center")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ticks = sorted({int(r["n"]) for r in rows})
    ax.set_xticks(ticks)
    ax.set_xticklabels([str(t) for t in ticks])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("joints n (the base adds 6 degrees of freedom)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


def write(csv_path, out_dir):
    rows = load(csv_path)
    fig_dir = os.path.join(out_dir, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    figure(rows, os.path.join(fig_dir, "scaling_derive_time.svg"),
           "derivation: hamel emit --fold all (derive + emit) vs SymPy KanesMethod", "seconds",
           [("hamel emit, all kernels", "hamel_emit_s", "C0"),
            ("hamel emit --kernels rhs,mass_matrix", "hamel_emit_rhs_mm_s", "C9"),
            ("SymPy Kane (M and f)", "sympy_derive_s", "C3")],
           timeouts=("SymPy", "sympy_status", "sympy_derive_s", "C3"))
    figure(rows, os.path.join(fig_dir, "scaling_ops.svg"),
           "operation count (add + mul + div + call; SymPy: count_ops)", "operations",
           [("hamel rhs (M, f and the solve)", "hamel_ops_rhs", "C0"),
            ("hamel mass_matrix", "hamel_ops_mass_matrix", "C9"),
            ("hamel forcing", "hamel_ops_forcing", "C4"),
            ("SymPy M and f after cse", "sympy_ops_cse", "C3"),
            ("SymPy M, no cse", "sympy_ops_mass_matrix", "C1"),
            ("SymPy f, no cse", "sympy_ops_forcing", "C6")])
    figure(rows, os.path.join(fig_dir, "scaling_ns.svg"),
           "run time per call (g++ -O2, Google Benchmark median)", "ns per call",
           [("hamel rhs", "hamel_rhs_ns", "C0"), ("hamel mass_matrix", "hamel_mass_matrix_ns", "C9"),
            ("MuJoCo mj_forward", "mujoco_forward_ns", "C2"),
            ("MuJoCo dynamics core", "mujoco_core_ns", "C8")])
    figure(rows, os.path.join(fig_dir, "scaling_memory.svg"),
           "peak resident memory of the derivation (SymPy after a timeout: the peak until killed)", "MB",
           [("hamel emit", "hamel_peak_mb", "C0"), ("SymPy Kane (whole process)", "sympy_peak_mb", "C3")])

    md = []
    md.append("### Derivation: hamel vs SymPy\n")
    md.append("| topology | n | dof | hamel emit s | hamel MB | hamel emit rhs, M s | hamel ops rhs | hamel ops M | "
              "hamel ops f | SymPy | SymPy derive s | SymPy MB | SymPy ops M | SymPy ops f | "
              "SymPy ops M+f after cse | hamel/SymPy time |")
    md.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        md.append("| " + " | ".join([
            r["topology"], r["n"], r["dof"], cell(r["hamel_emit_s"]), cell(r["hamel_peak_mb"]),
            cell(r["hamel_emit_rhs_mm_s"]), cell(r["hamel_ops_rhs"], integer=True), cell(r["hamel_ops_mass_matrix"], integer=True),
            cell(r["hamel_ops_forcing"], integer=True), r["sympy_status"] or "-",
            cell(r["sympy_derive_s"]), cell(r["sympy_peak_mb"]), cell(r["sympy_ops_mass_matrix"], integer=True),
            cell(r["sympy_ops_forcing"], integer=True), cell(r["sympy_ops_cse"], integer=True), cell(r["ratio_hamel_over_sympy_derive"])]) + " |")
    md.append("\n### Run time and agreement: hamel vs MuJoCo\n")
    md.append("| topology | n | hamel .cpp bytes (all kernels) | rhs + mass_matrix .cpp bytes | g++ -O2 s | hamel rhs ns | hamel mass_matrix ns | "
              "MuJoCo mj_forward ns | MuJoCo core ns | hamel rhs / mj_forward | hamel rhs / core | "
              "rel. error hamel | rel. error numpy NE | rel. error SymPy |")
    md.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        md.append("| " + " | ".join([
            r["topology"], r["n"], cell(r["hamel_source_bytes"], integer=True), cell(r.get("hamel_compiled_bytes", ""), integer=True),
            cell(r["hamel_compile_s"]),
            cell(r["hamel_rhs_ns"]), cell(r["hamel_mass_matrix_ns"]), cell(r["mujoco_forward_ns"]),
            cell(r["mujoco_core_ns"]), cell(r["ratio_hamel_over_mujoco_ns"]),
            cell(r["ratio_hamel_over_mujoco_core_ns"]), cell(r["err_hamel_mujoco"], 2), cell(r["err_numpy_mujoco"], 2),
            cell(r["err_sympy_mujoco"], 2)]) + " |")
    md.append("\nRelative errors: max over the random states of ||a - a_MuJoCo||_inf / ||a_MuJoCo||_inf, "
              "a = (w_dot, v_dot, q_ddot). MuJoCo core: mj_kinematics, mj_comPos, mj_crb, mj_factorM, "
              "mj_comVel, mj_rne and mj_solveM alone (harness.cpp), which gives the same qacc as mj_forward "
              "(largest difference over all models in the CSV column err_core_mujoco: "
              + cell(str(max([num(r["err_core_mujoco"]) or 0 for r in rows] or [0])), 2) + ").\n")
    md.append("### Growth exponents k in y ~ n^k\n")
    md.append("Least squares over n >= 2, and between the last two measured n; the last column is the exponent "
              "against the number of degrees of freedom n + 6 between the last two n (the 6 base velocities "
              "flatten the curves against n at small n).\n")
    md.append("| quantity | topology | k (fit, n >= 2) | k (last two n) | range | k against n + 6 (last two) |")
    md.append("|---|---|---:|---:|---|---:|")
    for label, key in (("hamel emit time", "hamel_emit_s"), ("hamel emit time, rhs and M", "hamel_emit_rhs_mm_s"),
                       ("hamel ops f", "hamel_ops_forcing"), ("hamel ops rhs", "hamel_ops_rhs"),
                       ("hamel ops mass_matrix", "hamel_ops_mass_matrix"), ("hamel rhs ns", "hamel_rhs_ns"),
                       ("hamel mass_matrix ns", "hamel_mass_matrix_ns"), ("MuJoCo mj_forward ns", "mujoco_forward_ns"),
                       ("MuJoCo core ns", "mujoco_core_ns"),
                       ("SymPy derive time", "sympy_derive_s"), ("SymPy ops M", "sympy_ops_mass_matrix"),
                       ("SymPy ops f", "sympy_ops_forcing"), ("SymPy ops after cse", "sympy_ops_cse")):
        for topo in ("chain", "tree"):
            pts = series(rows, topo, key)
            k, k2 = slope(pts), last_slope(pts)
            if k is None:
                continue
            fitted = [p[0] for p in pts if p[0] >= 2]
            k3 = last_slope(pts, 6)
            md.append(f"| {label} | {topo} | {k:.2f} | {k2:.2f} | n = {fitted[0]}..{fitted[-1]} | {k3:.2f} |")
    text = "\n".join(md) + "\n"
    with open(os.path.join(out_dir, "scaling.md"), "w") as f:
        f.write(text)
    return text


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    print(write(sys.argv[1], sys.argv[2]))
