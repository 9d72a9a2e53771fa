#!/usr/bin/env python3
"""Meshes of the unit sphere with one hole, for hole-filling peers (igl_hole_fill.py,
cgal_hole_fill.py) and pdeshape's hole filling.

usage: hole_cases.py OUTDIR [--seed S]

Writes, for each case, OUTDIR/<name>.obj (the mesh with the hole) and OUTDIR/<name>.json, and
prints one line a case (name, boundary vertices, mesh size). Exit status 0, or 2 on a usage
error. Deterministic for a given seed (default 1).

Cases: sphere_hole_565, sphere_hole_1000, sphere_hole_7657, holes of about 565, 1000 and 7657
boundary vertices (CGAL documents triangulate_hole times of 0.03, 0.035, 0.06 and 0.4 s for
holes of 565, 774, 967 and 7657 boundary vertices). Every hole is the geodesic disc of radius
rho = 0.5 rad about the same centre c = (0.3, -0.2, 0.93)/|.|; what differs is how finely the
mesh resolves its boundary, so the three are also a refinement study of one hole.

The mesh. A uniform mesh cannot give these boundaries at a reasonable size: a hole boundary of
7657 vertices needs edges about 2 pi sin(rho) / 7657 long, and a uniform sphere mesh that fine
has tens of millions of triangles (and the hole alone millions). So the mesh is graded: its
target edge length is h(d) = min(0.04, h_b + 0.25 |d - rho|), d the geodesic distance from c,
finest (h_b) at the hole's rim and coarser away from it, inside the hole too. It is built as
rings of vertices at constant d about c (a pole vertex at c and at -c, consecutive rings about
(sqrt 3 / 2) h apart, each ring with round(2 pi sin d / h) vertices equally spaced at a random
phase), consecutive rings joined by the usual zipper triangulation (triangles oriented
outward). Then it is made irregular: every vertex is moved in its tangent plane by a seeded random
step, uniform in the disc of radius 0.25 h, and projected back onto the sphere,
so every vertex lies on the unit sphere (to rounding). h_b is set, by a few regenerations, so
that the boundary has the wanted number of vertices within 2 %.

The hole: every triangle whose centroid (projected onto the sphere) lies within geodesic
distance rho of c is removed; then, so that the hole is a disc with a simple boundary loop,
the removed triangles are cut down to the connected (by edges) part containing c, kept
triangles cut off from the rest of the mesh are removed too, and at a boundary vertex the
boundary passes twice (a pinch) all kept triangles of that vertex are removed, until the
boundary is one simple loop. The rings next to the rim lie sqrt(3)/4 h_b either side of it, so
the rim crosses the strip of triangles between them and the perturbation decides triangle by
triangle which side each falls: the boundary is an irregular zigzag.

<name>.obj: the mesh with the hole: the vertices used by the kept triangles ("v x y z", %.17g),
then the kept triangles ("f a b c", 1-based, counter-clockwise seen from outside the sphere).

<name>.json:
    {"truth": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
     "boundary_vertices": B,                      # vertices on the hole's boundary loop
     "boundary": [i, ...],                        # that loop: 0-based OBJ vertex indices, in
                                                  # the direction of the kept triangles' border
                                                  # edges (the hole on the left seen from
                                                  # outside the sphere)
     "removed": {"vertices": [[x, y, z], ...],    # the hole's interior vertices (used by no
                                                  # kept triangle), numbered after the OBJ's
                                                  # vertices: the first is index n_obj
                 "faces": [[a, b, c], ...]},      # the removed triangles, 0-based indices into
                                                  # [OBJ vertices; removed vertices], oriented
                                                  # as the OBJ's
     "hole": {"center": [x, y, z], "rho": r, "h_boundary": h_b, "seed": s},
     "mesh": {"vertices": n_obj, "faces": f_obj}}
The OBJ's triangles with the removed ones are the whole sphere mesh (a closed manifold).
"""
import json
import math
import os
import sys

import numpy as np

RHO = 0.5
CENTER = np.array([0.3, -0.2, 0.93]) / np.linalg.norm([0.3, -0.2, 0.93])
H_MAX = 0.04
GRADING = 0.25
JITTER = 0.25
TARGETS = [("sphere_hole_565", 565), ("sphere_hole_1000", 1000), ("sphere_hole_7657", 7657)]


def size(d, hb):
    return min(H_MAX, hb + GRADING * abs(d - RHO))


def ring_radii(hb):
    """Geodesic radii of the rings: two at rho -+ (sqrt 3 / 4) hb, then marching to 0 and pi."""
    step = math.sqrt(3.0) / 2.0
    inner = [RHO - step * hb / 2.0]
    while True:
        d = inner[-1]
        h = size(d - step * size(d, hb) / 2.0, hb)
        if d - step * h < 0.6 * h:
            break
        inner.append(d - step * h)
    outer = [RHO + step * hb / 2.0]
    while True:
        d = outer[-1]
        h = size(d + step * size(d, hb) / 2.0, hb)
        if math.pi - (d + step * h) < 0.6 * h:
            break
        outer.append(d + step * h)
    return inner[::-1] + outer


def zipper(a_idx, a_ang, b_idx, b_ang):
    """Triangles between ring A (smaller radius) and ring B: (A_i, B_j, A_i+1) or
    (A_i, B_j, B_j+1), counter-clockwise seen from outside."""
    na, nb = len(a_idx), len(b_idx)
    two_pi = 2.0 * math.pi
    # Start B at its vertex nearest A_0 in angle, with B's angles unwrapped about A_0's.
    j0 = int(np.argmin(np.abs((b_ang - a_ang[0] + math.pi) % two_pi - math.pi)))
    b_un = a_ang[0] + ((b_ang[(j0 + np.arange(nb)) % nb] - a_ang[0] + math.pi) % two_pi - math.pi)
    b_un = b_un[0] + np.concatenate([[0.0], np.cumsum((np.diff(b_un) % two_pi))])
    a_un = np.concatenate([a_ang, [a_ang[0] + two_pi]])
    b_un = np.concatenate([b_un, [b_un[0] + two_pi]])
    tris = []
    i = j = 0
    while i < na or j < nb:
        ai, ai1 = a_idx[i % na], a_idx[(i + 1) % na]
        bj, bj1 = b_idx[(j0 + j) % nb], b_idx[(j0 + j + 1) % nb]
        if j == nb or (i < na and a_un[i + 1] < b_un[j + 1]):
            tris.append((ai, bj, ai1))
            i += 1
        else:
            tris.append((ai, bj, bj1))
            j += 1
    return tris


def build_mesh(hb, rng):
    e1 = np.cross(CENTER, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(CENTER, e1)

    def at(d, phi):
        return (np.cos(d)[:, None] * CENTER[None, :]
                + np.sin(d)[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))

    radii = ring_radii(hb)
    verts = [CENTER[None, :]]
    hs = [np.array([size(0.0, hb)])]
    rings = []
    count = 1
    for d in radii:
        h = size(d, hb)
        n = max(6, int(round(2.0 * math.pi * math.sin(d) / h)))
        phi = (rng.uniform(0.0, 2.0 * math.pi) + 2.0 * math.pi * np.arange(n) / n) % (2.0 * math.pi)
        order = np.argsort(phi)
        phi = phi[order]
        verts.append(at(np.full(n, d), phi))
        hs.append(np.full(n, h))
        rings.append((np.arange(count, count + n), phi))
        count += n
    verts.append(-CENTER[None, :])
    hs.append(np.array([size(math.pi, hb)]))
    south = count
    V = np.concatenate(verts)
    H = np.concatenate(hs)
    faces = []
    first = rings[0][0]
    faces += [(0, first[k], first[(k + 1) % len(first)]) for k in range(len(first))]
    for (ia, pa), (ib, pb) in zip(rings[:-1], rings[1:]):
        faces += zipper(ia, pa, ib, pb)
    last = rings[-1][0]
    faces += [(last[k], south, last[(k + 1) % len(last)]) for k in range(len(last))]
    F = np.array(faces, dtype=np.int64)
    # Tangential jitter, uniform in the disc of radius JITTER h, then back onto the sphere.
    t1 = np.cross(V, np.where(np.abs(V[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]]))
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(V, t1)
    r = JITTER * H * np.sqrt(rng.uniform(size=len(V)))
    a = rng.uniform(0.0, 2.0 * math.pi, size=len(V))
    V = V + (r * np.cos(a))[:, None] * t1 + (r * np.sin(a))[:, None] * t2
    V /= np.linalg.norm(V, axis=1)[:, None]
    return V, F


def edge_faces(F):
    """Map from undirected edge (a, b), a < b, to the faces that use it."""
    e = {}
    for f, (a, b, c) in enumerate(F.tolist()):
        for u, v in ((a, b), (b, c), (c, a)):
            e.setdefault((min(u, v), max(u, v)), []).append(f)
    return e


def components(mask, F, edges):
    """Connected components (by shared edges) of the faces where mask is true: a label array,
    -1 off the mask."""
    label = np.full(len(F), -1)
    adj = [[] for _ in range(len(F))]
    for fs in edges.values():
        if len(fs) == 2:
            a, b = fs
            adj[a].append(b)
            adj[b].append(a)
    current = 0
    for s in range(len(F)):
        if not mask[s] or label[s] >= 0:
            continue
        label[s] = current
        stack = [s]
        while stack:
            f = stack.pop()
            for g in adj[f]:
                if mask[g] and label[g] < 0:
                    label[g] = current
                    stack.append(g)
        current += 1
    return label


def cut(V, F):
    edges = edge_faces(F)
    cen = V[F].mean(axis=1)
    cen /= np.linalg.norm(cen, axis=1)[:, None]
    dist = np.arccos(np.clip(cen @ CENTER, -1.0, 1.0))
    removed = dist < RHO
    lab = components(removed, F, edges)
    removed = lab == lab[int(np.argmin(dist))]
    for _ in range(100):
        kept_lab = components(~removed, F, edges)
        sizes = np.bincount(kept_lab[kept_lab >= 0])
        removed |= (kept_lab >= 0) & (kept_lab != int(np.argmax(sizes)))
        # Border edges, directed as in the kept faces.
        border = []
        for (a, b), fs in edges.items():
            if len(fs) == 2 and removed[fs[0]] != removed[fs[1]]:
                k = fs[0] if not removed[fs[0]] else fs[1]
                tri = F[k].tolist()
                i = tri.index(a)
                border.append((a, b) if tri[(i + 1) % 3] == b else (b, a))
        out_count = {}
        for a, _ in border:
            out_count[a] = out_count.get(a, 0) + 1
        pinched = [v for v, c in out_count.items() if c > 1]
        if not pinched:
            break
        touch = np.isin(F, pinched).any(axis=1)
        removed |= touch
    else:
        raise RuntimeError("could not make the hole's boundary a simple loop")
    nxt = dict(border)
    loop = [border[0][0]]
    while True:
        v = nxt[loop[-1]]
        if v == loop[0]:
            break
        loop.append(v)
    if len(loop) != len(border):
        raise RuntimeError(f"hole boundary is not one loop ({len(border)} edges, loop {len(loop)})")
    return removed, loop


def make_case(target, rng_seed):
    hb = 4.0 * math.pi * math.sin(RHO) / target
    for _ in range(8):
        rng = np.random.default_rng(rng_seed)
        V, F = build_mesh(hb, rng)
        removed, loop = cut(V, F)
        b = len(loop)
        if abs(b - target) <= 0.02 * target:
            return V, F, removed, loop, hb
        hb *= b / target
    raise RuntimeError(f"no mesh with about {target} boundary vertices (last {b})")


def write_case(out, name, V, F, removed, loop, hb, seed):
    kept = F[~removed]
    used = np.zeros(len(V), dtype=bool)
    used[kept.ravel()] = True
    inner = np.zeros(len(V), dtype=bool)
    inner[F[removed].ravel()] = True
    inner &= ~used
    n_obj = int(used.sum())
    new = np.full(len(V), -1)
    new[used] = np.arange(n_obj)
    new[inner] = n_obj + np.arange(int(inner.sum()))
    with open(os.path.join(out, name + ".obj"), "w") as f:
        f.write(f"# unit sphere with one hole: {name}\n")
        f.write("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in V[used].tolist()))
        f.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in new[kept].tolist()))
    meta = {
        "truth": {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0},
        "boundary_vertices": len(loop),
        "boundary": [int(new[v]) for v in loop],
        "removed": {"vertices": V[inner].tolist(), "faces": new[F[removed]].tolist()},
        "hole": {"center": CENTER.tolist(), "rho": RHO, "h_boundary": hb, "seed": seed},
        "mesh": {"vertices": n_obj, "faces": int(len(kept))},
    }
    with open(os.path.join(out, name + ".json"), "w") as f:
        json.dump(meta, f)
    return n_obj, len(kept), int(inner.sum()), int(removed.sum())


def check_closed(F):
    """Every undirected edge in exactly two faces, used once in each direction."""
    directed = set()
    for a, b, c in F.tolist():
        for e in ((a, b), (b, c), (c, a)):
            if e in directed:
                return False
            directed.add(e)
    return all((b, a) in directed for a, b in directed)


def main():
    args = sys.argv[1:]
    seed = 1
    if "--seed" in args:
        i = args.index("--seed")
        try:
            seed = int(args[i + 1])
        except (IndexError, ValueError):
            args = []
        else:
            del args[i:i + 2]
    if len(args) != 1:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    out = args[0]
    os.makedirs(out, exist_ok=True)
    for name, target in TARGETS:
        V, F, removed, loop, hb = make_case(target, seed)
        if not check_closed(F):
            raise RuntimeError(f"{name}: the sphere mesh is not a closed oriented manifold")
        n, f, ni, fr = write_case(out, name, V, F, removed, loop, hb, seed)
        print(f"{name}: boundary {len(loop)} vertices, mesh {n} vertices {f} faces, "
              f"hole {ni} interior vertices {fr} faces, h_b {hb:.3e}")


if __name__ == "__main__":
    main()
