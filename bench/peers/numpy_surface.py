#!/usr/bin/env python3
"""The benchmark surface of BENCHMARKS.md computed with NumPy, the way a good NumPy user writes it.

Biharmonic (a = 2), 12 Fourier modes, the four boundary curves of
crates/testkit/src/curves.rs (same linear congruential numbers). Solve each mode's 4×4
system in the bounded basis e^{an(u-1)}, u e^{an(u-1)}, e^{-anu}, u e^{-anu}; then basis tables in
u (mode functions and their u-derivatives) and in v (cos nv, sin nv), and matrix products for X,
X_u, X_v; unit normals; float32 positions and normals, as pdeshape's meshes store them.

Usage: python3 bench/peers/numpy_surface.py [repeats]   (needs numpy)
Prints the median wall time of solve + tessellate at 256x512 and 1024x1024.
"""
import sys
import time

import numpy as np

A = 2.0
MODES = 12


def lcg_values(count, seed=12345):
    state = seed
    out = []
    for _ in range(count):
        state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        out.append(((state >> 11) / float(1 << 53)) * 2.0 - 1.0)
    return out


def conditions():
    vals = iter(lcg_values(4 * MODES * 6))
    curves = []
    for base, radius in [((0, 0, 0), 1.0), ((0, 0, 2), 0.5), ((0, 0, 1), 0.6), ((0, 0, 2), -0.3)]:
        cos = np.zeros((MODES, 3))
        sin = np.zeros((MODES, 3))
        for n in range(1, MODES + 1):
            s = 0.2 / (n * n)
            c = np.array([next(vals) * s for _ in range(3)])
            d = np.array([next(vals) * s for _ in range(3)])
            if n == 1:
                c[0] += radius
                d[1] += radius
            cos[n - 1] = c
            sin[n - 1] = d
        curves.append((np.array(base, float), cos, sin))
    return curves  # order: X(0), X_u(0), X(1), X_u(1)


def basis(n, u, d):
    """d-th derivatives (d = 0, 1) of the four basis functions at the points u (shape (len(u), 4))."""
    k = A * n
    ep = np.exp(k * (u - 1.0))
    em = np.exp(-k * u)
    if d == 0:
        return np.stack([ep, u * ep, em, u * em], axis=-1)
    return np.stack([k * ep, ep + k * u * ep, -k * em, em - k * u * em], axis=-1)


def solve(curves):
    # Spine: cubic with A0(0), A0'(0), A0(1), A0'(1).
    m0 = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, 1, 1, 1], [0, 1, 2, 3]], float)
    a0 = np.linalg.solve(m0, np.stack([c[0] for c in curves]))
    us = np.array([0.0, 0.0, 1.0, 1.0])
    ds = [0, 1, 0, 1]
    coef = []
    for n in range(1, MODES + 1):
        m = np.stack([basis(n, us[i:i + 1], ds[i])[0] for i in range(4)])
        rhs = np.stack([np.concatenate([c[1][n - 1], c[2][n - 1]]) for c in curves])
        coef.append(np.linalg.solve(m, rhs))  # 4 x 6: A_n (x,y,z), B_n (x,y,z)
    return a0, coef


def tessellate(a0, coef, nu, nv):
    u = np.linspace(0.0, 1.0, nu)
    v = 2.0 * np.pi * np.arange(nv) / nv
    n = np.arange(1, MODES + 1)
    nv_ = np.outer(n, v)
    vt = np.vstack([np.ones((1, nv)), np.cos(nv_), np.sin(nv_)])  # (2M+1) x nv
    # u-tables: every mode function and its u-derivative at every u, from one (M·nu x 4) basis
    # table per derivative and one product with the stacked coefficients.
    k = A * n[:, None]  # M x 1
    ep = np.exp(k * (u[None, :] - 1.0))
    em = np.exp(-k * u[None, :])
    uu = u[None, :]
    b0 = np.stack([ep, uu * ep, em, uu * em], axis=-1)  # M x nu x 4
    b1 = np.stack([k * ep, ep + k * uu * ep, -k * em, em - k * uu * em], axis=-1)
    c = np.stack(coef)  # M x 4 x 6
    f0 = np.matmul(b0, c)  # M x nu x 6
    f1 = np.matmul(b1, c)
    powers = np.stack([np.ones_like(u), u, u * u, u ** 3], axis=-1)
    dpowers = np.stack([np.zeros_like(u), np.ones_like(u), 2 * u, 3 * u * u], axis=-1)
    s0 = powers @ a0  # nu x 3
    s1 = dpowers @ a0
    # Row coefficients of the nine quantities (X, X_u, X_v; x, y, z) against [1, cos nv, sin nv].
    rows = np.zeros((9, nu, 2 * MODES + 1))
    nn = n[:, None]
    for comp in range(3):
        rows[comp, :, 0] = s0[:, comp]
        rows[comp, :, 1:MODES + 1] = f0[:, :, comp].T
        rows[comp, :, MODES + 1:] = f0[:, :, 3 + comp].T
        rows[3 + comp, :, 0] = s1[:, comp]
        rows[3 + comp, :, 1:MODES + 1] = f1[:, :, comp].T
        rows[3 + comp, :, MODES + 1:] = f1[:, :, 3 + comp].T
        rows[6 + comp, :, 1:MODES + 1] = (nn * f0[:, :, 3 + comp]).T
        rows[6 + comp, :, MODES + 1:] = (-nn * f0[:, :, comp]).T
    q = (rows.reshape(9 * nu, -1) @ vt).reshape(9, nu, nv)  # one matrix product
    x, y, z, xu, yu, zu, xv, yv, zv = q
    nx = yu * zv - zu * yv
    ny = zu * xv - xu * zv
    nz = xu * yv - yu * xv
    inv = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
    pos = np.empty((nu, nv, 3), np.float32)
    nrm = np.empty((nu, nv, 3), np.float32)
    pos[..., 0], pos[..., 1], pos[..., 2] = x, y, z
    nrm[..., 0], nrm[..., 1], nrm[..., 2] = nx * inv, ny * inv, nz * inv
    return pos, nrm


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    curves = conditions()
    a0, coef = solve(curves)
    x, _ = tessellate(a0, coef, 5, 8)
    # Boundary check: X(0, v_j) equals the first curve.
    v = 2.0 * np.pi * np.arange(8) / 8
    base, cos, sin = curves[0]
    n = np.arange(1, MODES + 1)
    ref = base + np.cos(np.outer(v, n)) @ cos + np.sin(np.outer(v, n)) @ sin
    assert np.abs(x[0] - ref).max() < 1e-5, "boundary condition check failed"
    print(f"numpy {np.__version__}")
    for nu, nv in [(256, 512), (1024, 1024)]:
        times = []
        for _ in range(repeats if nu == 256 else max(5, repeats // 3)):
            t0 = time.perf_counter()
            a0, coef = solve(curves)
            out = tessellate(a0, coef, nu, nv)
            times.append(time.perf_counter() - t0)
            del out  # freeing the result is not timed (as in the Rust benchmark)
        print(f"{nu}x{nv}: median {1e3 * float(np.median(times)):.2f} ms (min {1e3 * min(times):.2f}, n = {len(times)})")


if __name__ == "__main__":
    main()
