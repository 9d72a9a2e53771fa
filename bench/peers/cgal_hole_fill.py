#!/usr/bin/env python3
"""CGAL's hole filling on the meshes of hole_cases.py:
Polygon_mesh_processing::triangulate_refine_and_fair_hole (Liepa's method: a minimal-weight
triangulation of the hole, refined to the density of the boundary, then faired), through the
cgal-swig-bindings (`pip install cgal`, module CGAL.CGAL_Polygon_mesh_processing, on a
Polyhedron_3).

usage: cgal_hole_fill.py CASE.obj CASE.json [--repeat K] [--density D] [--continuity C]
                         [--triangulate-only]

Prints one JSON object on a line. Exit status 0, 1 if the fill failed (the line says
"done": false and why), 2 on a usage error (or the bindings missing).

The call: triangulate_refine_and_fair_hole(P, h, faces_out, vertices_out, D, C) on the mesh
read from an OFF copy of CASE.obj (vertices in the OBJ's order), h a border halfedge of the
hole (the meshes have one); D the density control factor (default sqrt 2, CGAL's default),
C the fairing continuity (default 1, CGAL's default: tangential continuity, the fairing
solves the bilaplacian; 0 would be the Laplacian, 2 the triple Laplacian). CGAL knows nothing
of the removed connectivity: it makes its own triangles and vertices. Everything outside the
hole stays as it was. With --triangulate-only the call is triangulate_hole(P, h, faces_out)
alone (no new vertices), the step CGAL's documentation gives times for (0.03, 0.035, 0.06 and
0.4 s for 565, 774, 967 and 7657 boundary vertices); its deviation figures are then those of
the boundary vertices themselves, so only its time means anything.

Figures (distances in the mesh's units, angles in radians):
- fill_median_s, fill_min_s: median and minimum over K runs (default 3) of the wall time of the
  call alone; each run reads a fresh mesh outside the timed call.
- new_vertices, new_faces: the patch's size.
- truth_dev_max, truth_dev_rms: the distance | |x - c| - r | to the truth sphere of the patch's
  new vertices, largest and root-mean-square.
- normal_jump_max, normal_jump_rms: at each vertex v of the hole's boundary loop, the angle
  atan2(|a x b|, a . b) between a = the sum over the patch's triangles at v of
  (p1 - p0) x (p2 - p0) (area-weighted normal) and b = the same sum over the mesh's own
  triangles at v; largest and RMS over the loop (the same definition as igl_hole_fill.py).
- flipped_faces: the fill's triangles whose normal (p1 - p0) x (p2 - p0) points towards the
  sphere's centre (makes an angle over 90 degrees with the outward normal at its centroid): a
  fold in the fill; 0 for a good one.
- boundary_dev: 0 by construction (the hole's boundary vertices do not move), so not printed.
"""
import json
import math
import os
import statistics
import sys
import tempfile
import time

import numpy as np

try:
    from CGAL import CGAL_Polygon_mesh_processing as PMP
    from CGAL.CGAL_Polyhedron_3 import Polyhedron_3
except ImportError as e:  # pragma: no cover - depends on the environment
    print(f"cgal_hole_fill.py: the CGAL Python bindings are missing (pip install cgal): {e}",
          file=sys.stderr)
    sys.exit(2)


def read_obj(path):
    verts, faces, raw = [], [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                parts = line.split()[1:4]
                raw.append(parts)
                verts.append([float(x) for x in parts])
            elif line.startswith("f "):
                faces.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64), raw


def write_off(path, raw, F):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(raw)} {len(F)} 0\n")
        f.write("".join(" ".join(p) + "\n" for p in raw))
        f.write("".join(f"3 {a} {b} {c}\n" for a, b, c in F.tolist()))


def load(off, n_expected, V):
    P = Polyhedron_3(off)
    if P.size_of_vertices() != n_expected:
        raise RuntimeError(f"CGAL read {P.size_of_vertices()} vertices, expected {n_expected}")
    border = [h for h in P.halfedges() if h.is_border()]
    if not border:
        raise RuntimeError("no border halfedge: the mesh has no hole")
    return P, border[0]


def point(v):
    p = v.point()
    return (p.x(), p.y(), p.z())


def flipped(V, F, center):
    """Triangles of F whose normal points into the sphere (towards its centre)."""
    nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return int(np.sum(np.sum(nrm * (V[F].mean(axis=1) - center), axis=1) <= 0.0))


def normal_jump(V, F_fill, F_mesh, loop):
    a = np.zeros((len(V), 3))
    b = np.zeros((len(V), 3))
    for F, acc in ((F_fill, a), (F_mesh, b)):
        nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        for k in range(3):
            np.add.at(acc, F[:, k], nrm)
    a, b = a[loop], b[loop]
    ang = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    return float(ang.max()), float(math.sqrt(np.mean(ang * ang)))


def main():
    args = sys.argv[1:]
    repeat, density, continuity, only = 3, math.sqrt(2.0), 1, False
    if "--triangulate-only" in args:
        only = True
        args.remove("--triangulate-only")
    try:
        for flag in ("--repeat", "--density", "--continuity"):
            if flag in args:
                i = args.index(flag)
                val = args[i + 1]
                del args[i:i + 2]
                if flag == "--repeat":
                    repeat = int(val)
                elif flag == "--density":
                    density = float(val)
                else:
                    continuity = int(val)
    except (IndexError, ValueError):
        repeat = 0
    if len(args) != 2 or repeat < 1 or continuity not in (0, 1, 2):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    obj, meta_path = args
    V, F, raw = read_obj(obj)
    with open(meta_path) as f:
        meta = json.load(f)
    loop = np.array(meta["boundary"], dtype=np.int64)
    truth = meta["truth"]
    center = np.asarray(truth["center"], dtype=np.float64)
    out = {"case": os.path.basename(obj).rsplit(".", 1)[0],
           "peer": "CGAL triangulate_hole" if only else "CGAL triangulate_refine_and_fair_hole",
           "setting": "default" if only else f"density {density:.4g}, continuity {continuity}",
           "boundary_vertices": len(loop)}
    tmp = tempfile.mkdtemp(prefix="cgal_hole_fill_")
    off = os.path.join(tmp, "mesh.off")
    write_off(off, raw, F)
    times = []
    try:
        for _ in range(repeat):
            P, h = load(off, len(V), V)
            faces_out, verts_out = [], []
            t0 = time.perf_counter()
            if only:
                PMP.triangulate_hole(P, h, faces_out)
            else:
                PMP.triangulate_refine_and_fair_hole(P, h, faces_out, verts_out, density, continuity)
            times.append(time.perf_counter() - t0)
        if not faces_out or not P.is_closed():
            raise RuntimeError(f"the hole is not closed ({len(faces_out)} faces added)")
        out["done"] = True
    except Exception as e:
        out["done"] = False
        out["error"] = f"{type(e).__name__}: {e}"
        print(json.dumps(out))
        sys.exit(1)
    finally:
        os.remove(off)
        os.rmdir(tmp)
    out["fill_median_s"] = statistics.median(times)
    out["fill_min_s"] = min(times)
    out["new_vertices"] = len(verts_out)
    out["new_faces"] = len(faces_out)

    # Number the vertices: the OBJ's in their order (the polyhedron keeps the file's order;
    # checked), then the patch's new ones.
    allv = list(P.vertices())
    pts = np.array([point(v) for v in allv])
    if np.abs(pts[:len(V)] - V).max() != 0.0:
        raise RuntimeError("CGAL's vertex order is not the file's")
    for k, v in enumerate(allv):
        v.set_id(k)
    Ffill = []
    for fc in faces_out:
        e = fc.halfedge()
        Ffill.append([e.vertex().id(), e.next().vertex().id(), e.next().next().vertex().id()])
    Ffill = np.array(Ffill, dtype=np.int64)
    new = np.array([v.id() for v in verts_out], dtype=np.int64)
    if len(new):
        d = np.abs(np.linalg.norm(pts[new] - center, axis=1) - truth["radius"])
        out["truth_dev_max"] = float(d.max())
        out["truth_dev_rms"] = float(math.sqrt(np.mean(d * d)))
    else:
        out["truth_dev_max"] = out["truth_dev_rms"] = None
    out["normal_jump_max"], out["normal_jump_rms"] = normal_jump(pts, Ffill, F, loop)
    out["flipped_faces"] = flipped(pts, Ffill, center)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
