"""The vesicle table of §7.5.2 on examples/vesicle_disc.toml: the gradient search (`pdeshape optimize
--method gradient`) from a start on each branch, continued in ν (each search starts at the previous
optimum, as the book does), annealing (`--method anneal`, the file's budget) on the same design
from the same start, and the reference minima of bench/peers/vesicle_shapes.py at the ν each
search found (the energy moves by about 2–3 × Δν, so the reference is solved at the ν found, not
at the target). The branch of a result is read from its mesh's profile (`shape`).

c0 ≠ 0: the objective is ½∫(C1 + C2 − c0/R0)² dA with R0 = √(A/4π) as a formula of the
design's variables (`4 mean_sq + 4 c0 mean / R0 + 4π c0²`, the code's H relative to the outward
normal, C1 + C2 = −2H, +2/R on a sphere), so the problem stays free of scale.

Usage: python3 bench/vesicle_branches.py PDESHAPE_BINARY [quick]   (a markdown table on stdout;
files in /tmp/vesicle_branches)
"""

import json
import math
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))
import vesicle_shapes as ref  # noqa: E402

EXAMPLE = open(os.path.join(HERE, "..", "examples", "vesicle_disc.toml")).read()
OUT = "/tmp/vesicle_branches"

# The file as written (a sphere): ring heights, radii and their derivative circles.
RING = {"n": (0.7071, 0.7071, 0.1517, 1.2625), "s": (-0.7071, 0.7071, -1.2625, 0.1517)}
EQ_AHEAD_Z = -0.7854
SPREAD = 0.5236


def initial(north, south, nring, sring, eq_t, spread_n=SPREAD, spread_s=SPREAD):
    """Parameter values of a start: the poles' heights; each ring's (r, z) and its derivative
    X_u = (tr, tz) in the meridian plane; the equator's derivative; the poles' spread radii."""
    v = {"north_z": north, "south_z": south, "a": 1.0}
    for d, spread in (("north", spread_n), ("south", spread_s)):
        v[f"{d}_spreadDx"] = v[f"{d}_spreadDy"] = spread / SPREAD
    for key, (r, z, tr, tz) in (("n", nring), ("s", sring)):
        z0, r0, za0, ra0 = RING[key]
        v[f"{key}ringDx"] = v[f"{key}ringDy"] = r / r0
        v[f"{key}ringTz"] = z - z0
        v[f"{key}ring_aheadDx"] = v[f"{key}ring_aheadDy"] = (r + tr) / ra0
        v[f"{key}ring_aheadTz"] = z + tz - za0
    v["equator_aheadDx"] = v["equator_aheadDy"] = 1.0 + eq_t[0]
    v["equator_aheadTz"] = eq_t[1] - EQ_AHEAD_Z
    return v


# The starts on each branch (the equator is the unit circle at z = 0 in all of them).
STARTS = {
    # poles at ±1.8, rings at ±1.2 of radius 0.75: an ellipsoid-like cigar
    "prolate": initial(1.8, -1.8, (0.75, 1.2, 0.4, -0.8), (0.75, -1.2, -0.4, -0.8), (0.0, -1.0), 0.3, 0.3),
    # poles at ±0.2 below rings at ±0.4 of radius 0.6 whose tangent rises outwards: two dimples
    "discocyte": initial(0.2, -0.2, (0.6, 0.4, 0.6, 0.2), (0.6, -0.4, -0.5, 0.2), (0.0, -0.6), 0.4, 0.4),
    # the north pole at −0.62 inside a cup whose neck (the northern ring, radius 0.31 at
    # z = 0.11) rises to a lip: a stomatocyte (the profile of the reference at ν = 0.65)
    "stomatocyte": initial(-0.62, -0.87, (0.31, 0.11, 0.0, 1.2), (0.75, -0.6, -0.5, -0.3), (0.0, -1.4), 0.4, 0.6),
}


def design(nu, c0, values):
    text = EXAMPLE.replace("equal = 0.8,", f"equal = {nu},")
    if c0 != 0.0:
        obj = f"4*mean_sq + 4*({c0})*mean/sqrt(area/(4*pi)) + 4*pi*({c0})^2"
        text = text.replace('objective = "helfrich"', f'objective = "{obj}"')
    for name, x in values.items():
        m = re.search(r'\{ name = "' + re.escape(name) + r'"([^}]*)\}', text)
        inner = re.sub(r", initial = [-0-9.e]+", "", m.group(1)).rstrip()
        text = text[: m.start()] + f'{{ name = "{name}"{inner}, initial = {x:.9f} }}' + text[m.end():]
    return text


def run(binary, nu, c0, values, method, tag):
    os.makedirs(OUT, exist_ok=True)
    src = f"{OUT}/{tag}.toml"
    open(src, "w").write(design(nu, c0, values))
    best = f"{OUT}/{tag}_best.toml"
    extra = ["--evaluations", "400"] if method == "gradient" else []
    p = subprocess.run(
        [binary, "optimize", src, "-o", best, "--method", method, "--timings", *extra],
        capture_output=True, text=True, check=True,
    )
    tim = json.loads([line for line in p.stderr.splitlines() if line.startswith("{")][-1])
    line = [x for x in p.stdout.splitlines() if x.startswith("area =")][0]
    var = {k: float(v) for k, v in re.findall(r"(\w+) = (\S+?),?(?:\s|$)", line)}
    r0 = math.sqrt(var["area"] / (4 * math.pi))
    f = (4 * var["mean_sq"] + 4 * c0 * var["mean"] / r0 + 4 * math.pi * c0 * c0) / (16 * math.pi)
    table = re.findall(r"^(\w+)\s+(-?[0-9.]+)\s+(-?[0-9.]+)$", p.stdout, re.M)
    status = re.search(r"\((\w+)\); first-order", p.stdout)
    kind, ratio = shape(best.replace(".toml", ".obj"))
    return {
        "values": {n: float(b) for n, _, b in table},
        "nu": var["nu"], "F": f, "evaluations": tim["evaluations"], "ms": tim["search_ms"],
        "status": status.group(1) if status else "", "kind": kind, "ratio": ratio,
    }


def shape(obj):
    """prolate / oblate / discocyte / stomatocyte from the mesh (as the reference's `classify`):
    a pole below the highest point of the profile (above the lowest) is dimpled; a dimpled pole
    beyond the height of the widest circle folds the profile back."""
    v = np.array([list(map(float, x.split()[1:4])) for x in open(obj) if x.startswith("v ")])
    r, z = np.hypot(v[:, 0], v[:, 1]), v[:, 2]
    poles = z[r < 1e-9]
    zn, zs = poles.max(), poles.min()
    height = z.max() - z.min()
    zeq = z[np.argmax(r)]
    tol = 1e-3 * height
    dn, ds = zn < z.max() - tol, zs > z.min() + tol
    if (dn and zn < zeq) or (ds and zs > zeq):
        kind = "stomatocyte"
    elif dn or ds:
        kind = "discocyte"
    else:
        kind = "prolate" if height > 2 * r.max() else "oblate"
    return kind, height / (2 * r.max())


def reference(nu, c0, kind):
    """F/8π of the reference minimum at this ν on the branch of `kind`: 20 modes, 36 for the
    stomatocyte (its neck converges slowly: 1.98816, 1.98059, 1.97846, 1.97769 with 12, 20, 28,
    36 modes at ν = 0.6, c0 = 0); NaN where no start of the reference converged on the branch."""
    if kind == "prolate":
        r = ref.solve(nu, c0, 20, "prolate")
    elif kind == "stomatocyte":
        r = ref.solve(nu, c0, 36, "stomatocyte")
    else:
        both = [ref.solve(nu, c0, 20, b, ("oblate", "discocyte")) for b in ("oblate", "discocyte")]
        both = [x for x in both if x is not None]
        r = min(both, key=lambda x: x.fun) if both else None
    return r.fun if r is not None else float("nan")


PLAN = [
    # (c0, start, ν in the order of the continuation)
    (0.0, "prolate", [0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6]),
    (0.0, "discocyte", [0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6]),
    (0.0, "stomatocyte", [0.55, 0.575, 0.6, 0.625, 0.65]),
    (3.0, "prolate", [0.9, 0.8, 0.7]),
    (3.0, "discocyte", [0.9, 0.8, 0.7]),
    (-3.0, "prolate", [0.9, 0.8, 0.7]),
    (-3.0, "discocyte", [0.9, 0.8, 0.7]),
    (-3.0, "stomatocyte", [0.7, 0.8, 0.9]),
]

if __name__ == "__main__":
    np.seterr(all="ignore")
    binary = sys.argv[1]
    quick = len(sys.argv) > 2
    print("| c0 | start | target ν | gradient: ν, F/8π | branch (height/diameter) | reference minimum on that branch | above it | evaluations, time | annealing: ν, F/8π, branch | evaluations, time |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for c0, start, nus in PLAN:
        values = STARTS[start]
        for nu in nus[:2] if quick else nus:
            tag = f"{start}_{c0:g}_{nu}"
            g = run(binary, nu, c0, values, "gradient", tag + "_gradient")
            a = run(binary, nu, c0, values, "anneal", tag + "_anneal")
            m = reference(g["nu"], c0, g["kind"])
            print(
                f"| {c0:g} | {start} | {nu} | {g['nu']:.4f}, {g['F']:.4f} | {g['kind']} ({g['ratio']:.2f}) "
                f"| {m:.4f} | {100 * (g['F'] / m - 1):+.2f} % | {g['evaluations']} ({g['status']}), {g['ms'] / 1000:.2f} s "
                f"| {a['nu']:.4f}, {a['F']:.4f}, {a['kind']} | {a['evaluations']}, {a['ms'] / 1000:.2f} s |",
                flush=True,
            )
            values = g["values"]
