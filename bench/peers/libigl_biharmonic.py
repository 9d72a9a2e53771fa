#!/usr/bin/env python3
"""Peer of benches/fd.rs: the biharmonic grid problem on [0, 1]^2 solved by libigl.

The same 256 x 256 grid of squares (each split into two triangles), the same manufactured
biharmonic solution X(u, v) = (e^u cos v, u e^v sin u, (u^2 + v^2)(u - v)/2). libigl's
`igl.harmonic(V, F, b, bc, k=2)` minimises the discrete biharmonic energy (cotangent Laplacian,
lumped mass) with Dirichlet values at the vertices `b`; the clamped conditions (X and its
cross-boundary derivative) are given the usual libigl way, as exact values on the two outermost
rings of vertices. That is more data than the finite-difference patch gets (X and the
cross-boundary derivative), so the script also solves with the second ring set from the same data
the finite differences see, X + h dX/dn (first-order in h), and reports both errors.
Timed: the `igl.harmonic` call (assembly, factorisation and solve for the three columns);
reported: the median and minimum of the runs and the largest vertex error.

With --periodic: the patch periodic in v of benches/fd.rs, on [0, 1] x [0, 2 pi), with
Y(u, v) = (e^u cos v, u e^{2u} sin 2v, u^3 - u^2 + cosh u cos v) (biharmonic for a = 1). The
grid of n x n squares is wrapped around v into the cylinder of radius 1 (x, y) = (cos v, sin v),
z = u: intrinsically the flat strip, so libigl's cotangent biharmonic is the same operator; the
rings u = 0, h and u = 1 - h, 1 are fixed (exact, and from Y + h dY/du).

Usage: python3 bench/peers/libigl_biharmonic.py [n] [runs] [--periodic]
"""
import sys
import time

import numpy as np
import igl


def exact_u(u, v):
    return np.stack(
        [np.exp(u) * np.cos(v), np.exp(v) * (np.sin(u) + u * np.cos(u)),
         (3 * u * u - 2 * u * v + v * v) / 2.0],
        axis=1,
    )


def exact_v(u, v):
    return np.stack(
        [-np.exp(u) * np.sin(v), u * np.exp(v) * np.sin(u), (-u * u + 2 * u * v - 3 * v * v) / 2.0],
        axis=1,
    )


def second_ring_from_derivatives(V, b, n, truth):
    """Values on the second ring from the boundary value and the inward derivative."""
    h = 1.0 / n
    bc = truth[b].copy()
    i, j = np.divmod(b, n + 1)
    for k, (ii, jj) in enumerate(zip(i, j)):
        # The nearest side: step inward from its boundary node.
        d = [(ii, 0), (n - ii, 1), (jj, 2), (n - jj, 3)]
        dist, side = min(d)
        if dist != 1:
            continue
        u0, v0 = V[b[k]]
        if side == 0:
            p, g = (0.0, v0), exact_u(np.array([0.0]), np.array([v0]))[0]
        elif side == 1:
            p, g = (1.0, v0), -exact_u(np.array([1.0]), np.array([v0]))[0]
        elif side == 2:
            p, g = (u0, 0.0), exact_v(np.array([u0]), np.array([0.0]))[0]
        else:
            p, g = (u0, 1.0), -exact_v(np.array([u0]), np.array([1.0]))[0]
        bc[k] = exact(np.array([p[0]]), np.array([p[1]]))[0] + h * g
    return bc


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


def periodic_exact(u, v):
    return np.stack(
        [np.exp(u) * np.cos(v), u * np.exp(2 * u) * np.sin(2 * v),
         u ** 3 - u * u + np.cosh(u) * np.cos(v)],
        axis=1,
    )


def periodic_exact_u(u, v):
    return np.stack(
        [np.exp(u) * np.cos(v), (1 + 2 * u) * np.exp(2 * u) * np.sin(2 * v),
         3 * u * u - 2 * u + np.sinh(u) * np.cos(v)],
        axis=1,
    )


def periodic_main(n, runs):
    """n intervals in u, n nodes around v; vertex (i, j) is i * n + j."""
    u = np.repeat(np.arange(n + 1) / n, n)
    v = np.tile(np.arange(n) * 2 * np.pi / n, n + 1)
    V = np.stack([np.cos(v), np.sin(v), u], axis=1)
    idx = np.arange((n + 1) * n).reshape(n + 1, n)
    nxt = np.roll(idx, -1, axis=1)
    a, b, c, d = idx[:-1].ravel(), idx[1:].ravel(), nxt[1:].ravel(), nxt[:-1].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)
    i = np.arange((n + 1) * n) // n
    b_idx = np.nonzero(np.minimum(i, n - i) <= 1)[0].astype(np.int64)
    truth = periodic_exact(u, v)
    bc = truth[b_idx]
    times = []
    W = None
    for _ in range(runs):
        t0 = time.perf_counter()
        W = igl.harmonic(V, F, b_idx, bc, 2)
        times.append(time.perf_counter() - t0)
    err = np.max(np.linalg.norm(W - truth, axis=1))
    # The second rings from the data the finite differences see: Y and dY/du at u = 0, 1.
    bc2 = bc.copy()
    h = 1.0 / n
    ib = i[b_idx]
    vb = v[b_idx]
    first = ib == 1
    last = ib == n - 1
    bc2[first] = periodic_exact(np.zeros(first.sum()), vb[first]) + h * periodic_exact_u(
        np.zeros(first.sum()), vb[first])
    bc2[last] = periodic_exact(np.ones(last.sum()), vb[last]) - h * periodic_exact_u(
        np.ones(last.sum()), vb[last])
    W2 = igl.harmonic(V, F, b_idx, bc2, 2)
    err2 = np.max(np.linalg.norm(W2 - truth, axis=1))
    times.sort()
    print(
        f"libigl harmonic k=2 periodic {n}x{n} (cylinder): median {1e3 * times[len(times) // 2]:.1f} ms, "
        f"min {1e3 * times[0]:.1f} ms, max vertex error {err:.3e} (exact second ring), "
        f"{err2:.3e} (second ring from Y and dY/du)"
    )


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    n = int(args[0]) if len(args) > 0 else 256
    runs = int(args[1]) if len(args) > 1 else 5
    if "--periodic" in sys.argv[1:]:
        periodic_main(n, runs)
        return
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
    W2 = igl.harmonic(V, F, b, second_ring_from_derivatives(V, b, n, truth), 2)
    err2 = np.max(np.linalg.norm(W2 - truth, axis=1))
    times.sort()
    print(
        f"libigl harmonic k=2 {n}x{n}: median {1e3 * times[len(times) // 2]:.1f} ms, "
        f"min {1e3 * times[0]:.1f} ms, max vertex error {err:.3e} (exact second ring), "
        f"{err2:.3e} (second ring from X and dX/dn)"
    )


if __name__ == "__main__":
    main()
