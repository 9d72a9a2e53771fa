#!/usr/bin/env python3
"""The B-spline grid benchmark of BENCHMARKS.md computed with SciPy, the way a good SciPy user
writes it.

Bicubic B-spline surface with the 20 x 20 control net of crates/pdeshape/benches/spline.rs (same
linear congruential numbers) and uniform clamped knots on [0, 1]. Basis tables in u and v
(values and first derivatives, from scipy.interpolate.BSpline.design_matrix), then matrix
products Bu @ P @ Bv^T for X, X_u, X_v and unit normals, on a 512 x 512 grid.

Usage: python3 bench/peers/scipy_bspline_grid.py [repeats]   (needs numpy, scipy)
Prints the median and minimum wall time, and a few grid values to compare with pdeshape.
"""
import sys
import time

import numpy as np
from scipy.interpolate import BSpline

N = 20
P = 3
NU = NV = 512


def lcg_values(count, seed=2024):
    state = seed
    out = []
    for _ in range(count):
        state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        out.append(((state >> 11) / float(1 << 53)) * 2.0 - 1.0)
    return out


def net():
    z = lcg_values(N * N)
    ctrl = np.zeros((N, N, 3))
    for i in range(N):
        for j in range(N):
            ctrl[i, j] = (i / (N - 1), j / (N - 1), 0.2 * z[i * N + j])
    return ctrl


def knots():
    spans = N - P
    return np.concatenate([np.zeros(P + 1), np.arange(1, spans) / spans, np.ones(P + 1)])


def tables(t, x):
    """Values and first derivatives of the N basis functions at x: two (len(x), N) arrays."""
    eye = np.eye(N)
    b = BSpline(t, eye, P)
    return b(x), b.derivative(1)(x)


def grid(ctrl, t):
    us = np.linspace(0.0, 1.0, NU)
    vs = np.linspace(0.0, 1.0, NV)
    bu, dbu = tables(t, us)
    bv, dbv = tables(t, vs)
    # Per coordinate: (NU x N) @ (N x N) @ (N x NV) matrix products.
    x = np.empty((NU, NV, 3))
    xu = np.empty((NU, NV, 3))
    xv = np.empty((NU, NV, 3))
    for c in range(3):
        r = bu @ ctrl[:, :, c]
        x[:, :, c] = r @ bv.T
        xv[:, :, c] = r @ dbv.T
        xu[:, :, c] = (dbu @ ctrl[:, :, c]) @ bv.T
    n = np.cross(xu, xv)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    return x, n


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    ctrl, t = net(), knots()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        x, n = grid(ctrl, t)
        times.append(time.perf_counter() - t0)
    times.sort()
    print(f"scipy bicubic 20x20, 512x512 positions+normals: median {1e3 * times[len(times) // 2]:.2f} ms, "
          f"min {1e3 * times[0]:.2f} ms")
    for (i, j) in [(0, 0), (100, 300), (511, 511), (257, 33)]:
        print(f"X[{i},{j}] = {x[i, j, 0]:.17g} {x[i, j, 1]:.17g} {x[i, j, 2]:.17g}  "
              f"n = {n[i, j, 0]:.17g} {n[i, j, 1]:.17g} {n[i, j, 2]:.17g}")


if __name__ == "__main__":
    main()
