"""Reference minima of the vesicle bending energy at fixed reduced volume (c0 = 0) among
axisymmetric shapes, by an independent method: the profile of the shape as a radial function
rho(theta) = exp(sum_k a_k P_k(cos theta)) (Legendre modes, a star-shaped surface of revolution),
its energy F = (1/2) ∫(C1 + C2)² dA and reduced volume nu = V / (4π R0³/3), R0 = √(A/4π), by
Gauss–Legendre quadrature, minimised with SciPy's SLSQP under the constraint nu = target. Reported
as F / 8π (1 for a sphere). The Ritz value of this family is an upper bound of the axisymmetric
minimum and converges to it as modes are added (the table shows two mode counts).

Usage: python3 bench/peers/vesicle_reference.py
"""

import numpy as np
from numpy.polynomial import legendre as L
from scipy.optimize import minimize

N_QUAD = 200
X, W = L.leggauss(N_QUAD)
THETA = np.arccos(-X)  # 0..π
WT = W  # d(cos θ) weights; integrals over θ use sin θ dθ = d(−cos θ)


def shape(a):
    """Returns (area, volume, energy) of the profile rho(θ) = exp(Σ a_k P_k(cos θ))."""
    c = np.cos(THETA)
    s = np.sin(THETA)
    coef = np.concatenate([[0.0], a])
    g = L.legval(c, coef)
    dg_dc = L.legval(c, L.legder(coef))
    d2g_dc2 = L.legval(c, L.legder(coef, 2))
    rho = np.exp(g)
    # derivatives in θ: d/dθ = −sin θ d/dc
    g1 = -s * dg_dc
    g2 = s * s * d2g_dc2 - c * dg_dc
    rho1 = rho * g1
    rho2 = rho * (g2 + g1 * g1)
    r = rho * s
    z = rho * c
    rt = rho1 * s + rho * c
    zt = rho1 * c - rho * s
    rtt = rho2 * s + 2 * rho1 * c - rho * s
    ztt = rho2 * c - 2 * rho1 * s - rho * c
    sp = np.sqrt(rt * rt + zt * zt)
    k1 = (rt * ztt - zt * rtt) / sp**3
    k2 = zt / (r * sp)
    # the measure dθ = dc / sin θ
    dtheta = WT / s
    area = np.sum(dtheta * 2 * np.pi * r * sp)
    volume = np.sum(dtheta * np.pi * r * r * (-zt))
    energy = 0.5 * np.sum(dtheta * (k1 + k2) ** 2 * 2 * np.pi * r * sp)
    return area, abs(volume), energy


def nu_of(a):
    area, volume, _ = shape(a)
    r0 = np.sqrt(area / (4 * np.pi))
    return volume / (4 * np.pi / 3 * r0**3)


def energy_of(a):
    return shape(a)[2] / (8 * np.pi)


def solve(target, modes, prolate=True):
    best = None
    for amp in (0.1, 0.2, 0.35, 0.5):
        a0 = np.zeros(modes)
        a0[1] = amp if prolate else -amp  # P2: prolate (+) or oblate (−)
        r = minimize(
            energy_of,
            a0,
            method="SLSQP",
            constraints=[{"type": "eq", "fun": lambda a: nu_of(a) - target}],
            options={"maxiter": 500, "ftol": 1e-12},
        )
        if r.success and abs(nu_of(r.x) - target) < 1e-8:
            if best is None or r.fun < best.fun:
                best = r
    return best


if __name__ == "__main__":
    np.seterr(all="ignore")  # SLSQP's trial steps may overflow exp(); those points are refused
    print("nu     modes  prolate F/8pi  oblate F/8pi")
    for target in (0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6):
        for modes in (8, 14):
            p = solve(target, modes, True)
            o = solve(target, modes, False)
            fmt = lambda r: f"{r.fun:.5f}" if r is not None else "  —  "
            print(f"{target:.2f}   {modes:5d}  {fmt(p):>13}  {fmt(o):>12}")
