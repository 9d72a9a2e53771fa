"""Reference minima of the vesicle energy F = ½∫(C1 + C2 − C0)² dA (bending rigidity 1) at fixed
reduced volume nu = V / (4π R0³/3), R0 = √(A/4π), and reduced spontaneous curvature c0 = C0 R0,
among axisymmetric shapes of genus 0, on every branch: prolate, oblate, discocyte and
stomatocyte (the last is not star-shaped, so bench/peers/vesicle_reference.py cannot hold it).

The profile is parametrised by arc length s ∈ [0, 1] (the scale is free: F and nu do not depend
on it) and the angle ψ(s) of its tangent with the horizontal, as in the shape equations of
Seifert, Berndl & Lipowsky (Phys. Rev. A 44, 1182, 1991): r' = cos ψ, z' = −sin ψ, from the north
pole (ψ = 0) to the south pole (ψ = π). Here ψ is a Ritz sum

    ψ(s) = π s + Σ_{k=1..K} b_k sin(kπ s),

which meets ψ(0) = 0, ψ(1) = π (horizontal tangent planes at both poles); the profile closes on
the axis when r(1) = ∫₀¹ cos ψ ds = 0 (a constraint). The principal curvatures are C1 = ψ' (the
meridian's) and C2 = sin ψ / r (the parallel's); both are +1/R on a sphere of radius R, the same
convention as pdeshape's `helfrich` (C1 + C2 = −2H with H relative to the outward normal).
Area A = 2π∫r ds, volume V = π∫r² sin ψ ds, F = π∫(C1 + C2 − C0)² r ds, C0 = c0 / R0, reported
as F/8π (1 for a sphere at c0 = 0). Integrals by Gauss–Legendre quadrature; r(s) by the exact
integral of the Chebyshev interpolant of cos ψ. Minimised with SciPy's SLSQP under the
constraints r(1) = 0 and nu = target, from starting coefficients on each branch; the branch
of the result is read from its profile (`classify`). A Ritz value is an upper bound of the
minimum over axisymmetric shapes on that branch and converges to it as K grows; the table gives
two K so the convergence can be read.

Usage: python3 bench/peers/vesicle_shapes.py [c0 ...]   (default 0; a markdown table)
"""

import sys

import numpy as np
from numpy.polynomial import chebyshev as C
from numpy.polynomial import legendre as L
from scipy.optimize import minimize

N_QUAD = 300
XQ, WQ = L.leggauss(N_QUAD)
S = 0.5 * (XQ + 1.0)  # Gauss nodes on [0, 1]
W = 0.5 * WQ
N_CHEB = 256
XC = np.cos(np.pi * (np.arange(N_CHEB) + 0.5) / N_CHEB)  # Chebyshev points of the first kind
SC = 0.5 * (XC + 1.0)


def psi_of(b, s):
    k = np.arange(1, len(b) + 1)
    arg = np.pi * np.outer(s, k)
    psi = np.pi * s + np.sin(arg) @ b
    dpsi = np.pi + (np.cos(arg) * (np.pi * k)) @ b
    return psi, dpsi


def _integral_map(s):
    """The matrix taking the values of f at the Chebyshev points to ∫₀^s f at the points s (exact
    for the interpolant of degree N_CHEB − 1)."""
    v = C.chebvander(XC, N_CHEB - 1)
    m = np.linalg.solve(v, np.eye(N_CHEB))  # values → coefficients
    out = np.empty((len(s), N_CHEB))
    for j in range(N_CHEB):
        out[:, j] = C.chebval(2.0 * s - 1.0, C.chebint(m[:, j], lbnd=-1.0) * 0.5)
    return out


INT_Q = _integral_map(S)
INT_END = _integral_map(np.array([1.0]))
INT_PLOT = _integral_map(np.linspace(0.0, 1.0, 801))


def profile(b, which):
    """r(s), z(s) at the quadrature nodes (which = INT_Q), the end or the plotting points."""
    psi_c, _ = psi_of(b, SC)
    return which @ np.cos(psi_c), -(which @ np.sin(psi_c))


def measures(b, c0):
    psi, dpsi = psi_of(b, S)
    r, _ = profile(b, INT_Q)
    area = 2 * np.pi * np.sum(W * r)
    volume = np.pi * np.sum(W * r * r * np.sin(psi))
    r0 = np.sqrt(area / (4 * np.pi))
    nu = volume / (4 * np.pi / 3 * r0**3)
    m = dpsi + np.sin(psi) / r - c0 / r0
    f = np.pi * np.sum(W * m * m * r) / (8 * np.pi)
    return f, nu


def closure(b):
    return profile(b, INT_END)[0][0]


def classify(b):
    """prolate / oblate / discocyte / stomatocyte, from the profile: a pole below the highest
    point of the profile (above the lowest) by 10⁻³ of the height is dimpled; a dimpled pole
    beyond the height of the widest circle folds the profile back (stomatocyte); otherwise
    height against diameter. (An up–down asymmetric prolate shape, a pear, counts as prolate.)"""
    r, z = profile(b, INT_PLOT)
    zn, zs = z[0], z[-1]
    zmax, zmin, rmax = z.max(), z.min(), r.max()
    height = zmax - zmin
    zeq = z[np.argmax(r)]
    tol = 1e-3 * height
    dimple_n = zn < zmax - tol
    dimple_s = zs > zmin + tol
    if (dimple_n and zn < zeq) or (dimple_s and zs > zeq):
        return "stomatocyte"
    if dimple_n or dimple_s:
        return "discocyte"
    if height > 2 * rmax:
        return "prolate"
    return "oblate"


def starts(branch, k):
    """Starting coefficients on each branch (k coefficients): b2 > 0 makes the poles more curved
    (prolate), b2 < 0 flatter (oblate), b2 < −1/2 turns the tangent upwards at both poles
    (ψ'(0) = π(1 + 2 b2) < 0: two dimples, a discocyte), b1 < −1 at the north pole only, deep
    enough to fold the profile back (a stomatocyte)."""
    out = []
    for amp in (0.0, 0.5, 1.0) if branch != "stomatocyte" else (-0.4, 0.0, 0.25, 0.5, 1.0):
        b = np.zeros(k)
        if branch == "prolate":
            b[1] = 0.05 + 0.15 * amp
        elif branch == "oblate":
            b[1] = -0.05 - 0.15 * amp
        elif branch == "discocyte":
            b[1] = -0.6 - 0.2 * amp
        elif branch == "stomatocyte":
            b[0] = -2.0 - amp
        out.append(b)
    return out


def solve(target, c0, k, branch, accept=None):
    """The lowest minimum from the branch's starts whose shape is classified as one of `accept`
    (default: the branch itself); None if no start converged there."""
    accept = accept or (branch,)
    best = None
    cons = [
        {"type": "eq", "fun": lambda b: measures(b, c0)[1] - target},
        {"type": "eq", "fun": closure},
    ]
    for b0 in starts(branch, k):
        # The starting profiles are not closed: first the nearest coefficients that close the
        # profile at the reduced volume asked (the energy of an open profile means nothing).
        near = minimize(
            lambda b: np.sum((b - b0) ** 2), b0, method="SLSQP", constraints=cons
        )
        r = minimize(
            lambda b: measures(b, c0)[0],
            near.x,
            method="SLSQP",
            constraints=cons,
            options={"maxiter": 1000, "ftol": 1e-13},
        )
        inside = profile(r.x, INT_Q)[0]
        ok = (
            r.success
            and inside.min() > 0.0  # the profile meets the axis only at the poles
            and abs(measures(r.x, c0)[1] - target) < 1e-8
            and abs(closure(r.x)) < 1e-8
            and np.isfinite(r.fun)
        )
        if ok and classify(r.x) in accept and (best is None or r.fun < best.fun):
            best = r
    return best


def branch_minima(target, c0, k):
    """F/8π of the prolate, oblate-or-discocyte and stomatocyte minima (None where no start
    converged on the branch). The oblate shapes grow dimples continuously as nu falls, so the
    oblate and discocyte starts are one branch: the lower of the two."""
    both = ("oblate", "discocyte")
    flat = [solve(target, c0, k, b, both) for b in both]
    flat = [r for r in flat if r is not None]
    return (
        solve(target, c0, k, "prolate"),
        min(flat, key=lambda r: r.fun) if flat else None,
        solve(target, c0, k, "stomatocyte"),
    )


if __name__ == "__main__":
    np.seterr(all="ignore")  # SLSQP's trial steps may leave the domain; those points are refused
    c0s = [float(a) for a in sys.argv[1:]] or [0.0]
    print("| c0 | nu | K | prolate | oblate / discocyte | stomatocyte |")
    print("|---|---|---|---|---|---|")
    for c0 in c0s:
        for target in (0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6, 0.55):
            for k in (12, 20):
                row = [f"{r.fun:.5f}" if r is not None else "—" for r in branch_minima(target, c0, k)]
                print(f"| {c0:g} | {target:.2f} | {k} | " + " | ".join(row) + " |", flush=True)
