#!/usr/bin/python3
"""SymPy peer of the scaling benchmark: Kane's equations of a floating-base tree (sympy.physics.mechanics).

  sympy_kane.py SPEC.json [--states STATES.txt] [--no-cse]

SPEC.json is written by models.py. Generalized speeds are hamel's quasi-velocities: u = (w, v, q_dot)
with (w, v) the base frame's body twist (angular velocity of the base frame B and velocity of its origin,
both resolved in B) and the joint rates; coordinates are the joint angles only (the base pose is ignorable:
zero gravity, no forces, so M and f do not depend on it; it is left out, which only helps SymPy).
Every number is an exact Rational from the same decimal strings hamel reads.

Prints one JSON object per line as it goes, so a parent that kills it at a timeout keeps what was done:
  {"stage": "derive", "seconds": ..}                        KanesMethod + kanes_equations (mass_matrix, forcing)
  {"stage": "count_ops", "seconds": .., "ops_mass_matrix": .., "ops_forcing": ..}
  {"stage": "cse", "seconds": .., "ops_cse": .., "n_subexpressions": ..}     cse of M and f together
  {"stage": "accelerations", "rows": [[u_dot...], ...]}    with --states: M^-1 f at each state
                                                            (state line: quat(4) p(3) q(n) w(3) v(3) q_dot(n))
"""
import argparse
import json
import sys
import time

import sympy as sp
from sympy.physics.mechanics import (KanesMethod, Point, ReferenceFrame, RigidBody, dynamicsymbols,
                                     inertia)


def emit(obj):
    print(json.dumps(obj), flush=True)


def build(spec):
    R = sp.Rational
    n = spec["n"]
    q = dynamicsymbols(f"q1:{n + 1}")
    qd = dynamicsymbols(f"q1:{n + 1}", 1)
    u = dynamicsymbols(f"u1:{n + 7}")
    N = ReferenceFrame("N")
    B = ReferenceFrame("B")
    B.set_ang_vel(N, u[0] * B.x + u[1] * B.y + u[2] * B.z)
    O = Point("O")
    O.set_vel(N, u[3] * B.x + u[4] * B.y + u[5] * B.z)

    def vec(frame, v):
        return R(v[0]) * frame.x + R(v[1]) * frame.y + R(v[2]) * frame.z

    def body(name, frame, origin, b):
        G = origin.locatenew(name + "_cm", vec(frame, b["com"]))
        G.v2pt_theory(origin, N, frame)
        I = b["inertia"]
        dy = inertia(frame, R(I[0][0]), R(I[1][1]), R(I[2][2]), R(I[0][1]), R(I[1][2]), R(I[0][2]))
        return RigidBody(name, G, frame, R(b["mass"]), (dy, G))

    frames = {"base": (B, O)}
    bodies = [body("base", B, O, spec["base"])]
    for i, b in enumerate(spec["bodies"]):
        P, Po = frames[b["parent"]]
        C = ReferenceFrame(b["name"])
        C.orient_axis(P, vec(P, b["axis"]), q[i])
        J = Po.locatenew(b["name"] + "_o", vec(P, b["offset"]))
        J.v2pt_theory(Po, N, P)
        frames[b["name"]] = (C, J)
        bodies.append(body(b["name"], C, J, b))
    kd = [qd[i] - u[6 + i] for i in range(n)]
    km = KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
    km.kanes_equations(bodies, [])
    return q, u, km.mass_matrix, km.forcing


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("spec")
    ap.add_argument("--states")
    ap.add_argument("--no-cse", action="store_true")
    a = ap.parse_args()
    with open(a.spec) as f:
        spec = json.load(f)
    n = spec["n"]

    t0 = time.perf_counter()
    q, u, M, F = build(spec)
    emit({"stage": "derive", "seconds": time.perf_counter() - t0, "sympy": sp.__version__})

    t0 = time.perf_counter()
    ops_m = sum(sp.count_ops(e) for e in M)
    ops_f = sum(sp.count_ops(e) for e in F)
    emit({"stage": "count_ops", "seconds": time.perf_counter() - t0, "ops_mass_matrix": int(ops_m),
          "ops_forcing": int(ops_f)})

    if not a.no_cse:
        t0 = time.perf_counter()
        repl, red = sp.cse(list(M) + list(F))
        ops = sum(sp.count_ops(r) for _, r in repl) + sum(sp.count_ops(e) for e in red)
        emit({"stage": "cse", "seconds": time.perf_counter() - t0, "ops_cse": int(ops),
              "n_subexpressions": len(repl)})

    if a.states:
        import numpy as np
        syms = sp.symbols(f"x0:{2 * n + 6}")
        sub = dict(zip(list(q) + list(u), syms))
        fM = sp.lambdify(syms, M.xreplace(sub), "numpy")
        fF = sp.lambdify(syms, F.xreplace(sub), "numpy")
        rows = []
        for line in open(a.states):
            vals = [float(v) for v in line.split()]
            if not vals:
                continue
            x = vals[7:]
            ud = np.linalg.solve(np.array(fM(*x), float), np.array(fF(*x), float).reshape(-1))
            rows.append([float(v) for v in ud])
        emit({"stage": "accelerations", "rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
