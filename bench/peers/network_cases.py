#!/usr/bin/env python3
"""Test networks for n-sided fills: closed-form boundary loops with the tangent planes a G1 fill
must meet, and the surface the loop was cut from (the truth), written as one JSON file a case.

usage: network_cases.py OUTDIR [--points M]

Writes OUTDIR/<name>.json for every case below (M points a side, default 65) and prints the
names. Exit status 0, or 2 on a usage error.

Format of a case file (a JSON object; every number a float, every vector three of them):

    {
      "name":   string,                      # the file's name without .json
      "sides":  [ side, ... ],               # 3 to 8 sides, in loop order
      "truth":  truth or null
    }
    side = {
      "points":  [[x, y, z], ...],           # M points, M >= 2, the same M for every side
      "normals": [[nx, ny, nz], ...] | null  # M unit vectors, or null for a position-only side
    }
    truth = {"type": "sphere",   "center": [x, y, z], "radius": r}
          | {"type": "plane",    "point": [x, y, z], "normal": [nx, ny, nz]}   # unit normal
          | {"type": "cylinder", "axis_point": [x, y, z], "axis_dir": [dx, dy, dz],  # unit
             "radius": r}

Rules every case keeps:
- side i's last point is side i+1's first point (and the last side's last point the first
  side's first point), the same floats;
- the points of a side are uniformly spaced in the curve's natural parameter (arc length for
  lines and circles, so also uniformly spaced in arc length here), the ends included;
- normals[j] is the unit normal at points[j] of the neighbouring surface, i.e. the tangent
  plane the fill must meet there for G1 continuity; it is perpendicular to the side's tangent.
  Its sign is the outward normal of the truth (sphere: radial; cylinder: away from the axis),
  and the loop runs counter-clockwise seen from that side (right-hand rule), so the loop's
  interior is on the left of each side. A comparison should treat normals as lines (the angle
  between n and ±m).
- All points lie on the truth exactly up to rounding (about 1e-16).

Cases:
- plane5: a convex, non-regular pentagon with straight sides in the tilted plane through
  (0.1, -0.2, 0.3) with normal (1, 2, 2)/3; normals = that normal; truth = the plane.
- sphere3: the octant x, y, z >= 0 of the unit sphere, bounded by three quarter great circles
  (1,0,0) -> (0,1,0) -> (0,0,1) -> (1,0,0); normals radial; truth = the unit sphere.
- sphereN_rR, N in {4, 5, 6}, R in {0.8, 0.4, 0.2, 0.1} (file names like sphere5_r0.2):
  N vertices at polar angle R (angular radius, radians) about the north pole (0, 0, 1) of the
  unit sphere, at azimuths 0.3 + 2 pi k / N (the 0.3 rad offset breaks the symmetry about the
  coordinate planes); sides = the shorter great-circle arcs between consecutive vertices;
  normals radial; truth = the unit sphere. A refinement study: a fill's distance to the sphere
  should fall as R falls (the sphere departs from the vertices' plane by about R^2 / 2).
- cylinders4: the rectangle x in [-1, 1], theta in [-0.5, 0.5] of the cylinder
  y = 3 sin(theta), z = -2 + 3 cos(theta) (y^2 + (z + 2)^2 = 9, axis along x through
  (0, 0, -2), radius 3), the band around its top line: sides = the generator theta = -0.5
  (x from -1 to 1), the circular arc x = 1 (theta from -0.5 to 0.5), the generator theta = 0.5
  (x from 1 to -1), the arc x = -1 (theta from 0.5 to -0.5); normals from the cylinder
  (0, sin theta, cos theta); truth = the cylinder.
"""
import json
import math
import os
import sys

import numpy as np


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def close_loop(sides):
    """Makes each side's last point the next side's first point (the same floats): the corners
    are taken from the sides' starts, so they are bit-identical."""
    n = len(sides)
    for i in range(n):
        sides[i]["points"][-1] = list(sides[(i + 1) % n]["points"][0])
    return sides


def side(points, normals):
    return {
        "points": [[float(c) for c in p] for p in points],
        "normals": None if normals is None else [[float(c) for c in unit(m)] for m in normals],
    }


def segment(a, b, m):
    t = np.linspace(0.0, 1.0, m)[:, None]
    pts = (1.0 - t) * a[None, :] + t * b[None, :]
    pts[0], pts[-1] = a, b
    return pts


def great_arc(a, b, m):
    """The shorter great-circle arc from unit a to unit b, uniform in angle."""
    a, b = unit(a), unit(b)
    theta = math.atan2(np.linalg.norm(np.cross(a, b)), float(np.dot(a, b)))
    t = np.linspace(0.0, 1.0, m)[:, None]
    pts = (np.sin((1.0 - t) * theta) * a[None, :] + np.sin(t * theta) * b[None, :]) / math.sin(theta)
    pts /= np.linalg.norm(pts, axis=1)[:, None]
    pts[0], pts[-1] = a, b
    return pts


def plane5(m):
    q = np.array([0.1, -0.2, 0.3])
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    e1 = unit(np.cross(n, [0.0, 0.0, 1.0]))
    e2 = np.cross(n, e1)
    # Convex, counter-clockwise about n, no two sides or angles equal.
    uv = [(0.0, 0.0), (1.3, -0.1), (1.7, 0.8), (0.8, 1.5), (-0.4, 0.9)]
    corners = [q + u * e1 + v * e2 for u, v in uv]
    sides = []
    for i in range(5):
        pts = segment(corners[i], corners[(i + 1) % 5], m)
        sides.append(side(pts, [n] * m))
    return close_loop(sides), {"type": "plane", "point": q.tolist(), "normal": n.tolist()}


SPHERE = {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0}


def sphere3(m):
    corners = [np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])]
    sides = []
    for i in range(3):
        pts = great_arc(corners[i], corners[(i + 1) % 3], m)
        sides.append(side(pts, pts))
    return close_loop(sides), SPHERE


def sphere_polygon(n, r, m):
    corners = []
    for k in range(n):
        phi = 0.3 + 2.0 * math.pi * k / n
        corners.append(np.array([math.sin(r) * math.cos(phi), math.sin(r) * math.sin(phi), math.cos(r)]))
    sides = []
    for i in range(n):
        pts = great_arc(corners[i], corners[(i + 1) % n], m)
        sides.append(side(pts, pts))
    return close_loop(sides), SPHERE


def cylinders4(m):
    radius, zc, th0 = 3.0, -2.0, 0.5

    def point(x, th):
        return np.array([x, radius * math.sin(th), zc + radius * math.cos(th)])

    def normal(th):
        return np.array([0.0, math.sin(th), math.cos(th)])

    s = np.linspace(0.0, 1.0, m)
    plan = [  # (x(s), theta(s)) of each side
        (lambda t: -1.0 + 2.0 * t, lambda t: -th0 + 0.0 * t),
        (lambda t: 1.0 + 0.0 * t, lambda t: -th0 + 2.0 * th0 * t),
        (lambda t: 1.0 - 2.0 * t, lambda t: th0 + 0.0 * t),
        (lambda t: -1.0 + 0.0 * t, lambda t: th0 - 2.0 * th0 * t),
    ]
    sides = []
    for fx, fth in plan:
        xs, ths = fx(s), fth(s)
        pts = [point(x, th) for x, th in zip(xs, ths)]
        sides.append(side(pts, [normal(th) for th in ths]))
    truth = {"type": "cylinder", "axis_point": [0.0, 0.0, zc], "axis_dir": [1.0, 0.0, 0.0],
             "radius": radius}
    return close_loop(sides), truth


def cases(m):
    yield "plane5", plane5(m)
    yield "sphere3", sphere3(m)
    for n in (4, 5, 6):
        for r in (0.8, 0.4, 0.2, 0.1):
            yield f"sphere{n}_r{r}", sphere_polygon(n, r, m)
    yield "cylinders4", cylinders4(m)


def main():
    args = sys.argv[1:]
    m = 65
    if "--points" in args:
        i = args.index("--points")
        try:
            m = int(args[i + 1])
        except (IndexError, ValueError):
            m = 0
        del args[i:i + 2]
    if len(args) != 1 or m < 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    out = args[0]
    os.makedirs(out, exist_ok=True)
    for name, (sides, truth) in cases(m):
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump({"name": name, "sides": sides, "truth": truth}, f)
        print(name)


if __name__ == "__main__":
    main()
