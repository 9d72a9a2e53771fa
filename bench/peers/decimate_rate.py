"""Quadric edge-collapse decimation (fast-simplification) against pdeshape's general fitting
mode, at equal bytes and at equal error (BENCHMARKS.md, "The general fitting mode").

Usage: python decimate_rate.py DIR — DIR holds NAME.obj (the mesh) and NAME.toml (pdeshape's
fit of it), written by `cargo bench -p pdeshape --bench fit_general_bench -- DIR`.

Sizes: pdeshape's design as TOML text, raw and gzipped (level 9); a decimated mesh as the
same binary layout the fit's report uses (12 bytes a vertex, 12 a triangle: f32 positions,
u32 indices), raw and gzipped. Errors: two-sided, relative to the original mesh's bounding-box
diagonal — the decimated mesh's vertices to the original surface and 20 000 points sampled on
the original to the decimated surface (trimesh's exact closest points); Hausdorff is the larger
maximum, RMS the root mean square of both directions' RMS. pdeshape's errors are its own
report's (measured by the fit on the solved patches), printed by the bench beside this.
"""

from __future__ import annotations

import gzip
import sys
from pathlib import Path

import fast_simplification
import numpy as np
import trimesh


def binary(v: np.ndarray, f: np.ndarray) -> bytes:
    return v.astype("<f4").tobytes() + f.astype("<u4").tobytes()


def distances(orig: trimesh.Trimesh, v: np.ndarray, f: np.ndarray) -> tuple[float, float]:
    dec = trimesh.Trimesh(v, f, process=False)
    diag = float(np.linalg.norm(orig.bounds[1] - orig.bounds[0]))
    _, d1, _ = trimesh.proximity.closest_point(orig, v)
    pts, _ = trimesh.sample.sample_surface(orig, 20000, seed=7)
    _, d2, _ = trimesh.proximity.closest_point(dec, pts)
    h = max(d1.max(), d2.max()) / diag
    rms = np.sqrt(0.5 * (np.mean(d1**2) + np.mean(d2**2))) / diag
    return float(h), float(rms)


def decimate(orig: trimesh.Trimesh, reduction: float):
    v, f = fast_simplification.simplify(
        orig.vertices.astype(np.float64), orig.faces.astype(np.int64), target_reduction=reduction
    )
    return v, f


def main() -> None:
    d = Path(sys.argv[1])
    print("| mesh | pdeshape TOML (gz) | decimated to equal gz bytes: triangles, Hausdorff, RMS | "
          "decimated to equal Hausdorff: triangles, bytes (gz) |")
    print("|---|---|---|---|")
    for toml in sorted(d.glob("*.toml")):
        name = toml.stem
        orig = trimesh.load(d / f"{name}.obj", process=False)
        text = toml.read_bytes()
        gz = len(gzip.compress(text, 9))
        # Equal bytes: the largest decimation whose gzipped binary is within pdeshape's gz.
        lo, hi = 0.0, 0.999
        best = None
        for _ in range(18):
            mid = 0.5 * (lo + hi)
            v, f = decimate(orig, mid)
            size = len(gzip.compress(binary(v, f), 9))
            if size <= gz:
                best = (v, f, size)
                hi = mid
            else:
                lo = mid
        if best is None:
            eq_bytes = "none that small"
        else:
            h, rms = distances(orig, best[0], best[1])
            eq_bytes = f"{len(best[1])}, {100 * h:.2f} %, {100 * rms:.3f} %"
        # Equal error: pdeshape's Hausdorff from the bench's row, given as NAME=H% arguments.
        target = None
        for a in sys.argv[2:]:
            if a.startswith(name + "="):
                target = float(a.split("=")[1]) / 100
        eq_err = ""
        if target is not None:
            lo, hi = 0.0, 0.999
            hit = None
            for _ in range(14):
                mid = 0.5 * (lo + hi)
                v, f = decimate(orig, mid)
                h, _ = distances(orig, v, f)
                if h <= target:
                    hit = (v, f)
                    lo = mid
                else:
                    hi = mid
            if hit is not None:
                b = binary(*hit)
                eq_err = f"{len(hit[1])}, {len(b)} ({len(gzip.compress(b, 9))})"
        print(f"| {name} | {len(text)} ({gz}) | {eq_bytes} | {eq_err} |")


if __name__ == "__main__":
    main()
