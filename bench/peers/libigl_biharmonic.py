#!/usr/bin/env python3
"""Peer of benches/fd.rs: the biharmonic grid problem on [0, 1]^2 solved by libigl.

The same 256 x 256 grid of squares (each split into two triangles), the same manufactured
biharmonic solution X(u, v) = (e^u cos v, u e^v sin u, (u^2 + v^2)(u - v)/2). libigl's
`igl.harmonic(V, F, b, bc, k=2)` minimises the discrete biharmonic energy (cotangent Laplacian,
lumped mass) with Dirichlet values at the vertices `b`; the clamped conditions (X and its
cross-boundary derivative) are given the usual libigl way, as exact values on the two outermost
rings of vertices. Timed: the `igl.harmonic` call (assembly, factorisation and solve for the three
columns); reported: the median and minimum of the runs and the largest vertex error.

Usage: python3 bench/peers/libigl_biharmonic.py [n] [runs]
"""
import sys
import time

import numpy as np
import igl


def exact(u, v):
    return np.stack(
        [np.exp(u) * np.cos(v), u * np.exp(v) * np.sin(u), (u * u + v * v) * (u - v) / 2.0],
        axis=1,
    )


def grid(n):
    t = np.linspace(0.0, 1.0, n + 1)
    uu, vv = np.meshgrid(t, t, indexing="ij")
    V = np.stack([uu.ravel(), vv.ravel()], axis=1)
    idx = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1)
    a = idx[:-1, :-1].ravel()
    b = idx[1:, :-1].ravel()
    c = idx[1:, 1:].ravel()
    d = idx[:-1, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)
    i, j = np.divmod(np.arange((n + 1) * (n + 1)), n + 1)
    ring = (np.minimum(i, n - i) <= 1) | (np.minimum(j, n - j) <= 1)
    bidx = np.nonzero(ring)[0].astype(np.int64)
    return V, F, bidx


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 256
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    V, F, b = grid(n)
    truth = exact(V[:, 0], V[:, 1])
    bc = truth[b]
    times = []
    W = None
    for _ in range(runs):
        t0 = time.perf_counter()
        W = igl.harmonic(V, F, b, bc, 2)
        times.append(time.perf_counter() - t0)
    err = np.max(np.linalg.norm(W - truth, axis=1))
    times.sort()
    print(
        f"libigl harmonic k=2 {n}x{n}: median {1e3 * times[len(times) // 2]:.1f} ms, "
        f"min {1e3 * times[0]:.1f} ms, max vertex error {err:.3e}"
    )


if __name__ == "__main__":
    main()
