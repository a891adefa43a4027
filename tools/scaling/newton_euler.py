#!/usr/bin/python3
"""Independent numerical reference for the scaling models: recursive Newton-Euler in body twists (numpy).

Generalized velocity nu = (w, v, q_dot): (w, v) the base frame's body twist (angular, then linear
velocity of the base origin, both resolved in the base frame), as in hamel's state. Child pose relative
to its parent: (I, offset) * exp(q * (axis, 0)). Body twists V = (omega, v) in each body's own frame:
  V_c = Ad(g_pc^-1) V_p + S q_dot,   Vdot_c = Ad(g_pc^-1) Vdot_p + ad(V_c) S q_dot + S q_ddot
  F_c = G Vdot_c - ad(V_c)^T G V_c + sum over children Ad(g_ck^-1)^T F_k;  tau = S^T F_c, base wrench F_0.
Forward dynamics: bias c = RNEA(nu, nudot = 0), mass matrix columns = RNEA(0, e_k) - ... (zero velocity),
nudot = -M^-1 c (no applied forces, zero gravity).
"""
import numpy as np


def hat(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def rot(axis, q):
    a = np.asarray(axis, float)
    K = hat(a)
    return np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * (K @ K)


def Ad(R, p):
    """Adjoint of g = (R, p) on twists (omega, v)."""
    A = np.zeros((6, 6))
    A[:3, :3] = R
    A[3:, 3:] = R
    A[3:, :3] = hat(p) @ R
    return A


def ad(V):
    A = np.zeros((6, 6))
    A[:3, :3] = hat(V[:3])
    A[3:, 3:] = hat(V[:3])
    A[3:, :3] = hat(V[3:])
    return A


def spatial_inertia(mass, com, I):
    m = float(mass)
    c = np.array([float(x) for x in com])
    Ic = np.array([[float(x) for x in r] for r in I])
    C = hat(c)
    G = np.zeros((6, 6))
    G[:3, :3] = Ic - m * C @ C
    G[:3, 3:] = m * C
    G[3:, :3] = -m * C
    G[3:, 3:] = m * np.eye(3)
    return G


class Tree:
    def __init__(self, spec):
        self.n = spec["n"]
        names = ["base"] + [b["name"] for b in spec["bodies"]]
        index = {nm: k for k, nm in enumerate(names)}
        self.parent = [-1] + [index[b["parent"]] for b in spec["bodies"]]
        self.G = [spatial_inertia(spec["base"]["mass"], spec["base"]["com"], spec["base"]["inertia"])]
        self.axis = [None]
        self.offset = [None]
        for b in spec["bodies"]:
            self.G.append(spatial_inertia(b["mass"], b["com"], b["inertia"]))
            self.axis.append(np.array([float(x) for x in b["axis"]]))
            self.offset.append(np.array([float(x) for x in b["offset"]]))

    def rnea(self, q, nu, nudot):
        n = self.n
        N = n + 1
        V = [None] * N
        A = [None] * N
        X = [None] * N  # Ad(g_pc^-1)
        S = [None] * N
        V[0] = nu[:6].copy()
        A[0] = nudot[:6].copy()
        for k in range(1, N):
            R = rot(self.axis[k], q[k - 1])
            # g_pc = (R, offset); g_pc^-1 = (R^T, -R^T offset)
            X[k] = Ad(R.T, -R.T @ self.offset[k])
            S[k] = np.concatenate([self.axis[k], np.zeros(3)])
            p = self.parent[k]
            qd, qdd = nu[5 + k], nudot[5 + k]
            V[k] = X[k] @ V[p] + S[k] * qd
            A[k] = X[k] @ A[p] + ad(V[k]) @ S[k] * qd + S[k] * qdd
        F = [self.G[k] @ A[k] - ad(V[k]).T @ self.G[k] @ V[k] for k in range(N)]
        for k in range(N - 1, 0, -1):
            F[self.parent[k]] = F[self.parent[k]] + X[k].T @ F[k]
        tau = np.zeros(6 + n)
        tau[:6] = F[0]
        for k in range(1, N):
            tau[5 + k] = S[k] @ F[k]
        return tau

    def mass_matrix(self, q):
        m = 6 + self.n
        M = np.zeros((m, m))
        z = np.zeros(m)
        for j in range(m):
            e = np.zeros(m)
            e[j] = 1
            M[:, j] = self.rnea(q, z, e)
        return M

    def accelerations(self, q, nu):
        """nudot = (w_dot, v_dot, q_ddot)."""
        c = self.rnea(q, nu, np.zeros(6 + self.n))
        return np.linalg.solve(self.mass_matrix(q), -c)

    def kinetic_energy(self, q, nu):
        M = self.mass_matrix(q)
        return 0.5 * nu @ M @ nu
