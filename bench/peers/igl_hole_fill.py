#!/usr/bin/env python3
"""libigl's biharmonic hole fill on the meshes of hole_cases.py: the hole re-filled with its
removed connectivity, the interior vertices unknown, solved by igl.harmonic(V, F, b, bc, k=2).

usage: igl_hole_fill.py CASE.obj CASE.json [--repeat K] [--full]

Prints one JSON object on a line. Exit status 0, 1 if the fill failed (the line says
"done": false and why), 2 on a usage error.

The problem. The unknowns are the hole's interior vertices (the json's removed.vertices);
every other vertex is fixed at its position: the hole's boundary loop and the ring of vertices
next to it (the usual way of giving libigl's biharmonic a C1 condition: values on two rings),
and the rest of the mesh. igl.harmonic with k = 2 minimises the discrete biharmonic energy
x' L' M^-1 L x (L the cotangent Laplacian, M the Voronoi mass matrix) over the unknowns.
- Solved on a band, not the whole mesh (unless --full): the removed triangles plus every kept
  triangle with a vertex on the hole's boundary. The minimiser is the same as on the whole mesh
  with everything outside fixed: the energy terms that involve an unknown are the rows of L at
  the unknowns and at the boundary vertices, and the band holds the complete stars of those
  vertices (their cotangent weights and masses are the whole mesh's); the band's other rows
  (the outer ring's, cut short) involve only fixed vertices and add a constant. --full solves
  on the whole mesh, as a check and for its time.
- The interior's positions are unknown, but the cotangent Laplacian needs a geometry for the
  hole's triangles. So the fill is two steps, both timed: the start, a membrane fill with the
  uniform (graph) Laplacian, L_uniform x = 0 at the unknowns with the boundary values fixed
  (scipy's sparse LU), which only needs the connectivity; then igl.harmonic(V, F, b, bc, 2)
  with V holding the start's interior positions. For reference the json also has the same
  k = 2 fill with the operator built on the true interior positions (which a real hole would not
  have): "oracle_*".

Figures (distances in the mesh's units, angles in radians):
- fill_median_s, fill_min_s: median and minimum over K runs (default 5) of the wall time of the
  igl.harmonic call; start_median_s the same for the membrane start; total = the two.
- truth_dev_max, truth_dev_rms: the distance | |x| - 1 | (the truth is the unit sphere) of the
  filled interior vertices, largest and root-mean-square.
- normal_jump_max, normal_jump_rms: at each vertex v of the hole's boundary loop, the angle
  atan2(|a x b|, a . b) between a = the sum over the fill's triangles at v of (p1 - p0) x
  (p2 - p0) (each triangle's normal times twice its area, so an area-weighted normal) and b =
  the same sum over the mesh's kept triangles at v; largest and RMS over the loop.
  normal_jump_reference_max/_rms: the same measure on the original sphere mesh (the removed
  triangles at their true positions), the jump the discretisation has by itself.
- flipped_faces: the fill's triangles whose normal (p1 - p0) x (p2 - p0) points towards the
  sphere's centre (makes an angle over 90 degrees with the outward normal at its centroid): a
  fold in the fill; 0 for a good one.
- boundary_dev: 0 by construction (the boundary vertices are fixed), so not printed.
"""
import json
import math
import statistics
import sys
import time

import igl
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def read_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                faces.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def face_normals(V, F):
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def flipped(V, F, center):
    """Triangles of F whose normal points into the sphere (towards its centre)."""
    nrm = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return int(np.sum(np.sum(nrm * (V[F].mean(axis=1) - center), axis=1) <= 0.0))


def normal_jump(V, F_fill, F_mesh, loop):
    """Angles between the area-weighted normals of the fill side and the mesh side at the
    boundary vertices `loop`."""
    a = np.zeros((len(V), 3))
    b = np.zeros((len(V), 3))
    nf = face_normals(V, F_fill)
    nm = face_normals(V, F_mesh)
    for k in range(3):
        np.add.at(a, F_fill[:, k], nf)
        np.add.at(b, F_mesh[:, k], nm)
    a, b = a[loop], b[loop]
    ang = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    return float(ang.max()), float(math.sqrt(np.mean(ang * ang)))


def membrane_start(Vb, Fb, unknown, fixed):
    """Interior positions from the uniform-Laplacian (graph) membrane fill."""
    n = len(Vb)
    i = np.concatenate([Fb[:, 0], Fb[:, 1], Fb[:, 2]])
    j = np.concatenate([Fb[:, 1], Fb[:, 2], Fb[:, 0]])
    A = sp.coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)).tocsr()
    A = ((A + A.T) > 0).astype(np.float64)
    L = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A
    Luu = L[unknown][:, unknown].tocsc()
    Luf = L[unknown][:, fixed]
    X = Vb.copy()
    X[unknown] = spla.splu(Luu).solve(-(Luf @ Vb[fixed]))
    return X


def main():
    args = sys.argv[1:]
    repeat, full = 5, False
    if "--full" in args:
        full = True
        args.remove("--full")
    try:
        if "--repeat" in args:
            i = args.index("--repeat")
            repeat = int(args[i + 1])
            del args[i:i + 2]
    except (IndexError, ValueError):
        repeat = 0
    if len(args) != 2 or repeat < 1:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    obj, meta_path = args
    V, F = read_obj(obj)
    with open(meta_path) as f:
        meta = json.load(f)
    R = np.array(meta["removed"]["vertices"], dtype=np.float64).reshape(-1, 3)
    FR = np.array(meta["removed"]["faces"], dtype=np.int64).reshape(-1, 3)
    loop = np.array(meta["boundary"], dtype=np.int64)
    n = len(V)
    Vall = np.vstack([V, R])
    truth = meta["truth"]
    center = np.asarray(truth["center"], dtype=np.float64)
    out = {"case": obj.rsplit("/", 1)[-1].rsplit(".", 1)[0], "peer": "libigl harmonic k=2",
           "setting": "full mesh" if full else "band", "boundary_vertices": len(loop),
           "unknowns": len(R)}

    # The band (or the whole mesh), renumbered.
    if full:
        Fsub_mesh = F
    else:
        on_loop = np.zeros(n, dtype=bool)
        on_loop[loop] = True
        Fsub_mesh = F[on_loop[F].any(axis=1)]
    Fsub = np.vstack([Fsub_mesh, FR])
    used = np.unique(Fsub.ravel())
    local = np.full(len(Vall), -1, dtype=np.int64)
    local[used] = np.arange(len(used))
    Fb = local[Fsub]
    Vtrue = Vall[used]
    unknown = np.nonzero(used >= n)[0].astype(np.int64)
    fixed = np.nonzero(used < n)[0].astype(np.int64)
    bc = Vtrue[fixed]
    out["band_vertices"] = len(used)
    out["band_faces"] = len(Fb)
    Vblank = Vtrue.copy()
    Vblank[unknown] = 0.0  # nothing of the true interior is used below

    try:
        start_t, fill_t = [], []
        W = None
        for _ in range(repeat):
            t0 = time.perf_counter()
            Vs = membrane_start(Vblank, Fb, unknown, fixed)
            t1 = time.perf_counter()
            W = igl.harmonic(Vs, Fb, fixed, bc, 2)
            t2 = time.perf_counter()
            start_t.append(t1 - t0)
            fill_t.append(t2 - t1)
        if not np.all(np.isfinite(W)):
            raise RuntimeError("non-finite positions in the fill")
        out["done"] = True
    except Exception as e:
        out["done"] = False
        out["error"] = f"{type(e).__name__}: {e}"
        print(json.dumps(out))
        sys.exit(1)
    out["fill_median_s"] = statistics.median(fill_t)
    out["fill_min_s"] = min(fill_t)
    out["start_median_s"] = statistics.median(start_t)
    out["total_median_s"] = statistics.median([a + b for a, b in zip(start_t, fill_t)])

    def deviation(X):
        d = np.abs(np.linalg.norm(X[unknown] - center, axis=1) - truth["radius"])
        return float(d.max()), float(math.sqrt(np.mean(d * d)))

    filled = Vall.copy()
    filled[used] = W
    out["truth_dev_max"], out["truth_dev_rms"] = deviation(W)
    out["normal_jump_max"], out["normal_jump_rms"] = normal_jump(filled, FR, F, loop)
    out["flipped_faces"] = flipped(filled, FR, center)
    out["normal_jump_reference_max"], out["normal_jump_reference_rms"] = normal_jump(Vall, FR, F, loop)
    Wo = igl.harmonic(Vtrue, Fb, fixed, bc, 2)
    out["oracle_truth_dev_max"], out["oracle_truth_dev_rms"] = deviation(Wo)
    filled[used] = Wo
    out["oracle_normal_jump_max"], _ = normal_jump(filled, FR, F, loop)
    out["start_truth_dev_max"], _ = deviation(Vs)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
