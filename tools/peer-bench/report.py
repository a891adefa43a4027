#!/usr/bin/python3
"""Tables of tools/peer-bench.sh from its Google Benchmark JSON files: ratios of minima hamel/peer, then the
minima themselves (CPU time per call, ns).

  report.py WORK MODEL...     reads WORK/MODEL.json and WORK/MODEL.check for each MODEL
"""
import json
import os
import sys

PEERS = [  # column title, hamel kernel, peer benchmark
    ("rhs / DART forward", "hamel_rhs", "dart_forward"),
    ("rhs / MuJoCo", "hamel_rhs", "mujoco_best"),
    ("jacobian / DART FD", "hamel_jacobian", "dart_jacobian_fd"),
    ("jacobian / MuJoCo FD", "hamel_jacobian", "mujoco_jacobian_fd"),
    ("mass_matrix / DART", "hamel_mass_matrix", "dart_mass_matrix"),
    ("mass_matrix / MuJoCo", "hamel_mass_matrix", "mujoco_mass_matrix"),
]
LIMITS = {"hamel_rhs": 0.25, "hamel_jacobian": 0.5, "hamel_mass_matrix": 0.5}  # issue 48, "Done when"
ABSOLUTE = ["hamel_rhs", "dart_forward", "mujoco_forward", "mujoco_smooth", "hamel_jacobian", "dart_jacobian_fd",
            "mujoco_jacobian_fd", "mujoco_transitionFD", "hamel_mass_matrix", "dart_mass_matrix", "mujoco_mass_matrix"]


def minima(path):
    runs = json.load(open(path))["benchmarks"]
    out = {}
    for b in runs:
        if b.get("run_type") != "iteration":
            continue
        assert b["time_unit"] == "ns"
        name = b["run_name"] if "run_name" in b else b["name"]
        out[name] = min(out.get(name, float("inf")), b["cpu_time"])
    # MuJoCo's forward dynamics at its best: mj_forward or its smooth parts alone, whichever was faster
    out["mujoco_best"] = min(out["mujoco_forward"], out["mujoco_smooth"])
    return out, max(int(b.get("repetitions", 1)) for b in runs)


def main():
    work, names = sys.argv[1], sys.argv[2:]
    rows, reps = [], 0
    for name in names:
        t, r = minima(os.path.join(work, name + ".json"))
        reps = max(reps, r)
        check = open(os.path.join(work, name + ".check")).read().strip()
        rows.append((name, t, check))
    print(f"Ratios of minima over {reps} interleaved repetitions, hamel / peer (lower is better; MuJoCo's forward "
          "dynamics: the faster of mj_forward and its smooth parts; **bold**: above issue 48's bound, rhs 0.25, "
          "jacobian and mass_matrix 0.5):")
    print()
    print("| model | " + " | ".join(c for c, _, _ in PEERS) + " |")
    print("|---|" + "---:|" * len(PEERS))
    for name, t, _ in rows:
        cells = []
        for _, h, p in PEERS:
            r = t[h] / t[p]
            cells.append(f"**{r:.3f}**" if r > LIMITS[h] else f"{r:.3f}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    print()
    print("Minima, CPU ns per call:")
    print()
    print("| model | " + " | ".join(f"`{c}`" for c in ABSOLUTE) + " |")
    print("|---|" + "---:|" * len(ABSOLUTE))
    for name, t, _ in rows:
        print(f"| {name} | " + " | ".join(f"{t[c]:,.0f}".replace(",", " ") for c in ABSOLUTE) + " |")
    print()
    print("Agreement (largest differences relative to max(1, largest entry)):")
    print()
    for _, _, check in rows:
        print(f"- {check}")


if __name__ == "__main__":
    main()
