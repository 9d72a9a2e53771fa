"""Writes the profile curves of examples/anim/face.toml (run: python3 face_profiles.py).

Each profile is a horizontal section of a head at height z (centimetres): the ellipse
x = rx sin(phi), y = ry cos(phi) (the back at phi = 0, the front of the face at phi = pi, facing
-y), with the face's features added to the front half as Gaussian bumps in x (positive: towards
the viewer). 72 points at equal steps of phi, read by a `samples` curve with `param = "uniform"`,
so the point at phi is the curve's point at v = phi.
"""

import math

N = 72
# name, z, rx, ry, features [(height, x centre, width)]
SECTIONS = [
    ("chin_under", 0.0, 4.0, 5.0, [(0.8, 0.0, 2.0)]),
    ("chin", 2.0, 5.4, 6.5, [(1.0, 0.0, 2.2)]),
    ("lower_lip", 4.2, 6.2, 7.5, [(1.0, 0.0, 1.9)]),
    ("mouth", 5.2, 6.5, 7.8, [(0.55, 0.0, 2.1)]),
    ("upper_lip", 6.2, 6.7, 8.0, [(1.1, 0.0, 1.8)]),
    ("nose_base", 7.6, 6.9, 8.2, [(2.3, 0.0, 1.0), (0.8, 1.3, 0.7), (0.8, -1.3, 0.7)]),
    ("nose_bridge", 9.4, 7.1, 8.4, [(1.8, 0.0, 0.75), (0.5, 4.0, 1.5), (0.5, -4.0, 1.5)]),
    ("eyes", 11.2, 7.3, 8.5, [(1.0, 0.0, 0.8), (-1.0, 3.1, 1.2), (-1.0, -3.1, 1.2)]),
    ("brow", 12.8, 7.4, 8.6, [(0.5, 3.1, 1.7), (0.5, -3.1, 1.7), (0.2, 0.0, 0.8)]),
    ("forehead", 16.5, 7.2, 8.5, []),
]


def front(phi):
    """1 on the front of the face, 0 at the sides and back (C1 in between)."""
    c = -math.cos(phi)
    s = min(1.0, max(0.0, (c - 0.3) / 0.5))
    return s * s * (3 - 2 * s)


def section(z, rx, ry, feats):
    pts = []
    for k in range(N):
        phi = 2 * math.pi * k / N
        x = rx * math.sin(phi)
        y = ry * math.cos(phi)
        bump = sum(h * math.exp(-(((x - c) / w) ** 2)) for h, c, w in feats)
        pts.append((x, y - front(phi) * bump, z))
    return pts


def main():
    for name, z, rx, ry, feats in SECTIONS:
        print(f"[curves.{name}]")
        print('type = "samples"')
        print('param = "uniform"')
        print("points = [")
        for x, y, zz in section(z, rx, ry, feats):
            print(f"  [{x:.4f}, {y:.4f}, {zz:.4f}],")
        print("]\n")
    # Where the expressions act: v of the mouth corners (x = +-2.6) and the brows (x = +-3.1).
    for name, rx, x in [("mouth", 6.5, 2.6), ("brow", 7.4, 3.1)]:
        a = math.asin(x / rx)
        print(f"# {name}: x = +{x} at v = {math.pi - a:.4f}, x = -{x} at v = {math.pi + a:.4f}")


main()
