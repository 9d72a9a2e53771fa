#!/usr/bin/env python3
"""Peer of the BFS benchmark (crates/pdeshape/benches/bfs.rs): the clamped biharmonic problem
Δ²u = f on [0, 1]² with u* = sin²(πx) sin²(πy), on n × n Bogner–Fox–Schmit rectangles, solved by
scikit-fem (ElementQuadBFS, sparse direct solve). Prints the time (mesh + basis + assembly +
condensation + solve) and the L² error of u measured two ways: with scikit-fem's own shape
functions (global monomials, which lose accuracy on fine meshes) and with the solution's nodal
values (u, u_x, u_y, u_xy) put into element-local cubic Hermite shape functions.

Usage: python3 bench/peers/skfem_bfs.py [n ...]   (default: 32 64 128). Benchmark-only.
"""
import sys
import time

import numpy as np
from skfem import Basis, BilinearForm, ElementQuadBFS, LinearForm, MeshQuad, condense, solve
from skfem.helpers import dd, ddot

PI = np.pi


def s(t):
    c = np.cos(2 * PI * t)
    return (1 - c) / 2, 2 * PI**2 * c, -8 * PI**4 * c


def exact(x, y):
    return s(x)[0] * s(y)[0]


@BilinearForm
def bilaplace(u, v, w):
    # ∫ u_xx v_xx + 2 u_xy v_xy + u_yy v_yy (the §6 energy with a = 1)
    return ddot(dd(u), dd(v))


@LinearForm
def load(v, w):
    x, y = w.x
    a, b = s(x), s(y)
    return (a[2] * b[0] + 2 * a[1] * b[1] + a[0] * b[2]) * v


# 4-point Gauss–Legendre on [0, 1]
GX, GW = np.polynomial.legendre.leggauss(4)
GX, GW = (GX + 1) / 2, GW / 2


def hermite(t, h):
    """Cubic Hermite basis on [0, 1] scaled to an interval of length h: rows H0, h·H1, H2, h·H3."""
    return np.array([1 - 3 * t**2 + 2 * t**3, h * (t - 2 * t**2 + t**3), 3 * t**2 - 2 * t**3, h * (t**3 - t**2)])


def local_l2_error(mesh, basis, x, n):
    """L² error with the nodal dofs in element-local Hermite shape functions."""
    h = 1.0 / n
    ij = np.rint(mesh.p * n).astype(int)
    nodal = np.zeros((4, n + 1, n + 1))
    for k in range(4):
        nodal[k, ij[0], ij[1]] = x[basis.nodal_dofs[k]]
    hx = hermite(GX, h)  # (4, q)
    # value at Gauss points of every element, vectorised over elements (i, j)
    val = np.zeros((n, n, 4, 4))
    for a_ in range(2):
        for b_ in range(2):
            for p in range(2):
                for q in range(2):
                    k = p + 2 * q  # u, u_x, u_y, u_xy
                    c = nodal[k, a_:a_ + n, b_:b_ + n]  # (n, n)
                    bx = hx[2 * a_ + p]  # (q,)
                    by = hx[2 * b_ + q]
                    val += c[:, :, None, None] * bx[None, None, :, None] * by[None, None, None, :]
    xs = (np.arange(n)[:, None] + GX[None, :]) * h  # (n, q)
    ex = exact(xs[:, None, :, None], xs[None, :, None, :])
    w = GW[:, None] * GW[None, :] * h * h
    err2 = np.sum((val - ex) ** 2 * w[None, None, :, :])
    return np.sqrt(err2)


def run(n):
    t0 = time.perf_counter()
    grid = np.linspace(0, 1, n + 1)
    mesh = MeshQuad.init_tensor(grid, grid)
    basis = Basis(mesh, ElementQuadBFS())
    K = bilaplace.assemble(basis)
    f = load.assemble(basis)
    D = basis.get_dofs().all()
    x = solve(*condense(K, f, D=D))
    secs = time.perf_counter() - t0
    own = np.sqrt(
        np.sum(
            (basis.interpolate(x).value - exact(*basis.global_coordinates().value)) ** 2 * basis.dx
        )
    )
    local = local_l2_error(mesh, basis, x, n)
    return secs, K.shape[0], own, local


def main():
    ns = [int(a) for a in sys.argv[1:]] or [32, 64, 128]
    for n in ns:
        secs, dofs, own, local = run(n)
        print(
            f"skfem_bfs n = {n}: dofs {dofs}, time {secs:.3f} s, L2 error (skfem shape functions) "
            f"{own:.3e}, L2 error (element-local Hermite) {local:.3e}"
        )


if __name__ == "__main__":
    main()
