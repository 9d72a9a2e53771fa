"""Quadric decimation (fast-simplification) at the RMS distance of each of pdeshape's fits, packed
like the fit: the bytes each needs for the same error (BENCHMARKS.md, "Bytes at equal RMS").

Usage: python decimate_rms.py PDESHAPE MESH.obj SWEEP.csv [MAX_RMS_PERCENT]

SWEEP.csv is `pdeshape fit MESH.obj --sweep … -o SWEEP.csv`; its fit rows (tolerance, RMS,
packed bytes) are read, those with an RMS above MAX_RMS_PERCENT (default 0.1) skipped. For each
fit the mesh is decimated (fast-simplification: quadric costs, vertices moved to their
quadrics' optima) to the size whose RMS distance equals the fit's (both measured by trimesh,
below), found by bisection on the triangle count, and packed as pdeshape packs a fit (`fit/pack.rs`, `fit/rate.rs`): positions
quantised to the fit's own step (1/64 of its tolerance times the diagonal; the same treatment
for both), each axis in as many bits as its range needs, three indices of ceil(log2 V) bits a
triangle. Distances are measured after quantisation and two-sided as pdeshape measures a fit:
every vertex of the mesh to the decimated surface, and points spread over the decimated surface
(area-uniform, 40 000, seed 7) to the mesh, both by trimesh's exact closest points; RMS is the
root mean square of the two directions' RMS, Hausdorff the larger maximum.

Each fit is measured the same way, independently of pdeshape's own report: PDESHAPE (the built
command) fits the mesh again at the row's tolerance (`--mode general`), its packed design is
not written, so the design as written is tessellated (`pdeshape surface --nu 24 --nv 24`, 24 ×
24 points a piece) and measured like a decimated mesh; the table gives both RMS figures.
"""

from __future__ import annotations

import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import fast_simplification
import numpy as np
import trimesh


def measure(orig: trimesh.Trimesh, v: np.ndarray, f: np.ndarray, diag: float):
    dec = trimesh.Trimesh(v, f, process=False)
    _, d1, _ = trimesh.proximity.closest_point(dec, orig.vertices)
    pts, _ = trimesh.sample.sample_surface(dec, 40000, seed=7)
    _, d2, _ = trimesh.proximity.closest_point(orig, pts)
    rms = math.sqrt(0.5 * (np.mean(d1**2) + np.mean(d2**2))) / diag
    return rms, max(d1.max(), d2.max()) / diag


def packed_bytes(v: np.ndarray, f: np.ndarray, step: float) -> tuple[int, np.ndarray]:
    q = np.round(v / step).astype(np.int64)
    bits = 0
    for k in range(3):
        span = int(q[:, k].max() - q[:, k].min())
        bits += len(v) * max(span, 1).bit_length()
    index = max(len(v) - 1, 1).bit_length()
    bits += 3 * index * len(f)
    # Three axis minima (8 bytes) and widths (1 byte), two counts (4 bytes each).
    return 27 + 8 + (bits + 7) // 8, q * step


def decimated(orig: trimesh.Trimesh, triangles: int):
    reduction = 1.0 - triangles / len(orig.faces)
    return fast_simplification.simplify(
        orig.vertices.astype(np.float64),
        orig.faces.astype(np.int64),
        target_reduction=min(max(reduction, 0.0), 0.9995),
    )


def fit_measured(exe: str, mesh_path: str, tol: float, orig, diag: float):
    """The fit at `tol` tessellated and measured by trimesh: (RMS, Hausdorff)."""
    with tempfile.TemporaryDirectory() as tmp:
        design, tess = Path(tmp) / "fit.toml", Path(tmp) / "fit.obj"
        subprocess.run(
            [exe, "fit", mesh_path, "-o", str(design), "--mode", "general", "--tolerance",
             repr(tol), "-q"],
            check=True,
        )
        subprocess.run(
            [exe, "surface", str(design), "-o", str(tess), "--nu", "24", "--nv", "24", "-q"],
            check=True,
        )
        m = trimesh.load(str(tess), process=False, force="mesh")
        return measure(orig, m.vertices, m.faces, diag)


def main() -> None:
    exe, mesh_path, sweep_path = sys.argv[1], sys.argv[2], sys.argv[3]
    max_rms = float(sys.argv[4]) if len(sys.argv) > 4 else 0.1
    orig = trimesh.load(mesh_path, process=False)
    diag = float(np.linalg.norm(orig.bounds[1] - orig.bounds[0]))
    fits = [r for r in csv.DictReader(open(sweep_path)) if r["kind"] == "fit"]
    print(
        "| tolerance | fit: faces, RMS (own; trimesh), Hausdorff (own; trimesh), packed bytes "
        "| decimation at equal RMS: triangles, RMS, Hausdorff, packed bytes | fit ÷ decimation |"
    )
    print("|---|---|---|---|")
    for r in fits:
        rms = float(r["rms_percent"]) / 100.0
        if rms * 100.0 > max_rms:
            continue
        tol = float(r["tolerance_percent"]) / 100.0
        step = tol * diag / 64.0
        # Both measured alike: the decimation is held to the fit's RMS as trimesh measures it.
        t_rms, t_h = fit_measured(exe, mesh_path, tol, orig, diag)
        # Bisection on log(triangles) for the decimation whose quantised RMS equals the fit's.
        lo, hi = 64, len(orig.faces)
        best = None
        for _ in range(9):
            mid = int(round(math.sqrt(lo * hi)))
            v, f = decimated(orig, mid)
            size, vq = packed_bytes(v, f, step)
            d_rms, d_h = measure(orig, vq, f, diag)
            if d_rms <= t_rms:
                best = (len(f), d_rms, d_h, size)
                hi = mid
            else:
                lo = mid
            if hi / lo < 1.02:
                break
        if best is None:
            print(f"| {tol * 100:g} % | … | no decimation reaches the RMS | |")
            continue
        n, d_rms, d_h, size = best
        fit_bytes = int(r["packed_bytes"])
        print(
            f"| {tol * 100:g} % | {r['patches_or_triangles']}, {rms * 100:.4f} %; "
            f"{t_rms * 100:.4f} %, {float(r['hausdorff_percent']):.3f} %; {t_h * 100:.3f} %, "
            f"{fit_bytes} | {n}, {d_rms * 100:.4f} %, "
            f"{d_h * 100:.3f} %, {size} | {fit_bytes / size:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
