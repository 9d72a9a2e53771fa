#!/usr/bin/env python3
"""The three-level scheme (6) of the dynamic-curve paper on its §3.3 experiment, written
straightforwardly with NumPy and scipy.linalg.solve_banded, for BENCHMARKS.md.

Same discretisation as crates/geometry/src/dynamic (see its module documentation): a = 1,
b = x/2 at the midpoints, d = x at the nodes, coefficients frozen at level n, the averaged terms
(X^{n+1} + X^{n-1})/2, Taylor start for level 1, positions at rows 0 and J, third-order one-sided
slope rows at 1 and J-1 eliminated exactly, one pentadiagonal solve per step for X_2 .. X_{J-2}.
Vectorised per step (no Python loop over nodes).

Usage: python3 bench/peers/numpy_dynamic.py [repeats]   (needs numpy, scipy)
Prints, for J = 30, L = 450 and J = 2000, L = 30000 (T = 15), the median wall time of a run and
the discrete L2 error at T against the exact solution (1 + e^-t) sin(pi u).
"""
import sys
import time

import numpy as np
from scipy.linalg import solve_banded

PI = np.pi
T_END = 15.0


def force(u, t):
    s = 1.0 + np.exp(-t)
    return s * s * (np.sin(PI * u) ** 2 - np.cos(PI * u) ** 2) * (2 * PI**4 + 0.5 * PI**2)


def stencil(x, u, h):
    """The five weights w[k, j-2] of Lambda at rows j = 2 .. J-2 (frozen at level x)."""
    d = x                      # d = x at the nodes
    bh = 0.25 * (x[1:] + x[:-1])  # b = x/2 at the midpoints, x averaged
    ih2, ih4 = 1.0 / (h * h), 1.0 / (h ** 4)
    j = np.arange(2, len(x) - 2)
    bm, bp = bh[j - 1], bh[j]
    dm, d0, dp = d[j - 1], d[j], d[j + 1]
    return np.array([
        dm * ih4,
        -bm * ih2 - 2.0 * (d0 + dm) * ih4,
        (bm + bp) * ih2 + (dp + 4.0 * d0 + dm) * ih4,
        -bp * ih2 - 2.0 * (dp + d0) * ih4,
        dp * ih4,
    ])


def apply(w, x):
    n = len(x)
    return (w[0] * x[0:n - 4] + w[1] * x[1:n - 3] + w[2] * x[2:n - 2]
            + w[3] * x[3:n - 1] + w[4] * x[4:n])


def ends(t):
    s = 1.0 + np.exp(-t)
    return 0.0, 0.0, PI * s, -PI * s


def impose_ends(x, t, h):
    p0, p1, s0, s1 = ends(t)
    jn = len(x) - 1
    x[0], x[jn] = p0, p1
    x[1] = (6 * h * s0 + 11 * p0 + 9 * x[2] - 2 * x[3]) / 18
    x[jn - 1] = (11 * p1 + 9 * x[jn - 2] - 2 * x[jn - 3] - 6 * h * s1) / 18


def run(jn, steps):
    h, dt = 1.0 / jn, T_END / steps
    u = np.arange(jn + 1) * h
    a = 1.0
    x0 = 2.0 * np.sin(PI * u)
    v0 = -np.sin(PI * u)
    w = stencil(x0, u, h)
    inner = slice(2, jn - 1)
    x1 = np.zeros(jn + 1)
    xtt = force(u[inner], 0.0) - a * v0[inner] - apply(w, x0)
    x1[inner] = x0[inner] + dt * v0[inner] + 0.5 * dt * dt * xtt
    impose_ends(x1, dt, h)
    prev, cur = x0, x1
    n = jn - 3
    half = 0.5 * dt * dt
    ad = 0.5 * a * dt
    ab = np.zeros((5, n))
    for level in range(1, steps):
        t = level * dt
        p0, p1, s0, s1 = ends(t + dt)
        w = stencil(cur, u, h)
        rhs = 2 * cur[inner] - (1 - ad) * prev[inner] - half * apply(w, prev) \
            + dt * dt * force(u[inner], t)
        # Matrix entries val[k, i] for row i (X_{i+2}), column i + k - 2.
        val = half * w
        val[2] += 1.0 + ad
        # End elimination: X_0 = p0, X_1 = left + X_2/2 - X_3/9 (and the mirror at the end).
        left = (6 * h * s0 + 11 * p0) / 18
        right = (11 * p1 - 6 * h * s1) / 18
        rhs[0] -= val[0, 0] * p0 + val[1, 0] * left
        rhs[1] -= val[0, 1] * left
        rhs[-1] -= val[4, -1] * p1 + val[3, -1] * right
        rhs[-2] -= val[4, -2] * right
        # Diagonal storage for solve_banded: ab[2 + r - c, c] = A[r, c].
        ab[:] = 0.0
        for k in range(5):
            off = k - 2  # column = row + off
            if off >= 0:
                ab[2 - off, off:] = val[k, :n - off]
            else:
                ab[2 - off, :n + off] = val[k, -off:]
        # Folded end columns: row 0 gets val[1,0]·(1/2, -1/9) on columns 0, 1; row 1 gets
        # val[0,1]·(1/2, -1/9); mirrored at the end.
        ab[2, 0] += 0.5 * val[1, 0]
        ab[1, 1] += -val[1, 0] / 9
        ab[3, 0] += 0.5 * val[0, 1]
        ab[2, 1] += -val[0, 1] / 9
        ab[2, n - 1] += 0.5 * val[3, n - 1]
        ab[3, n - 2] += -val[3, n - 1] / 9
        ab[1, n - 1] += 0.5 * val[4, n - 2]
        ab[2, n - 2] += -val[4, n - 2] / 9
        nxt = np.empty(jn + 1)
        nxt[inner] = solve_banded((2, 2), ab, rhs, overwrite_ab=False, check_finite=False)
        impose_ends(nxt, t + dt, h)
        prev, cur = cur, nxt
    return cur


def l2_error(x):
    jn = len(x) - 1
    h = 1.0 / jn
    u = np.arange(jn + 1) * h
    e = x - (1 + np.exp(-T_END)) * np.sin(PI * u)
    return np.sqrt(np.sum(e * e) * h)


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    for jn, steps, reps in [(30, 450, repeats), (2000, 30000, max(1, repeats // 5))]:
        times = []
        for _ in range(reps):
            t0 = time.perf_counter()
            cpu0 = time.process_time()
            x = run(jn, steps)
            times.append((time.perf_counter() - t0, time.process_time() - cpu0))
        wall = float(np.median([t[0] for t in times]))
        cpu = float(np.median([t[1] for t in times]))
        print(f"J = {jn}, L = {steps}: median wall {wall:.4e} s, CPU {cpu:.4e} s "
              f"({reps} runs), L2 error at T = 15: {l2_error(x):.6e}")


if __name__ == "__main__":
    main()
