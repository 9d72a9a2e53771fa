"""Real meshes through `pdeshape fit MESH -o OUT` with the default options, measured by trimesh,
beside quadric decimation (fast-simplification) at the same Hausdorff distance
(BENCHMARKS.md, "Real meshes through `pdeshape fit` with the default options").

Usage: python fit_real.py PDESHAPE MESH… — PDESHAPE is the built command. For each mesh: the
fit's wall time (the whole process), its exit status, and, when it wrote a design, the design
tessellated by `pdeshape surface OUT.toml -o OUT.obj --nu 10 --nv 10` (`OUT.glb` for a glTF
mesh, in its +Y-up frame; 10 × 10 points a piece,
as the fit measures itself; a tube or sheet fit, whose patches span whole sections, by the
default tessellation) and measured
against the mesh by trimesh, both ways: the fit's tessellation's vertices to the mesh and
20 000 points sampled on the mesh to the tessellation (trimesh's exact closest points);
Hausdorff is the larger maximum, RMS the root mean square of both directions' RMS, both
relative to the mesh's bounding-box diagonal. Then the mesh decimated by fast-simplification
to the fewest triangles whose Hausdorff distance (measured the same way) is at most the
fit's, with its bytes as 12 a vertex and 12 a triangle (f32 positions, u32 indices).
Needs numpy, trimesh, rtree, fast-simplification 0.2.0.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fast_simplification
import numpy as np
import trimesh


def load(path: str) -> trimesh.Trimesh:
    m = trimesh.load(path, process=False, force="mesh")
    # Welded by position as `pdeshape fit` welds a multi-object OBJ; nothing else changed.
    return trimesh.Trimesh(m.vertices, m.faces, process=True, validate=False)


def distances(orig: trimesh.Trimesh, other: trimesh.Trimesh) -> tuple[float, float]:
    diag = float(np.linalg.norm(orig.bounds[1] - orig.bounds[0]))
    _, d1, _ = trimesh.proximity.closest_point(orig, other.vertices)
    pts, _ = trimesh.sample.sample_surface(orig, 20000, seed=7)
    _, d2, _ = trimesh.proximity.closest_point(other, pts)
    h = max(d1.max(), d2.max()) / diag
    rms = np.sqrt(0.5 * (np.mean(d1**2) + np.mean(d2**2))) / diag
    return float(h), float(rms)


def decimated_at(orig: trimesh.Trimesh, h: float) -> tuple[int, int, float]:
    """The fewest triangles (by bisection on the reduction) within Hausdorff `h`."""
    v, f = orig.vertices.astype(np.float64), orig.faces.astype(np.int64)
    lo, hi = 0.0, 0.999
    best = (len(f), 12 * len(v) + 12 * len(f), 0.0)
    for _ in range(8):
        mid = 0.5 * (lo + hi)
        dv, df = fast_simplification.simplify(v, f, target_reduction=mid)
        hd, _ = distances(orig, trimesh.Trimesh(dv, df, process=False))
        if hd <= h:
            best = (len(df), 12 * len(dv) + 12 * len(df), hd)
            lo = mid
        else:
            hi = mid
    return best


def main() -> None:
    exe = sys.argv[1]
    for path in sys.argv[2:]:
        name = Path(path).stem
        mesh = load(path)
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / f"{name}.toml"
            t = time.perf_counter()
            report_json = Path(tmp) / f"{name}.json"
            run = subprocess.run(
                [exe, "fit", path, "-o", str(out), "--json", str(report_json)],
                capture_output=True,
                text=True,
            )
            secs = time.perf_counter() - t
            if run.returncode != 0 or not out.exists():
                last = (run.stderr.strip().splitlines() or [""])[-1]
                print(f"{name}\t{len(mesh.faces)}\texit {run.returncode}\t{secs:.1f} s\t{last[:300]}")
                continue
            report = run.stdout.strip().splitlines()[-1]
            # A glTF file is +Y up: the fit turned it to the design's +Z up, and the GLB writer
            # turns the tessellation back, so it lies where trimesh reads the file (an OBJ of it
            # would lie turned, 15.9 % off `boolean.glb` where the fit is 1.38 %).
            glb = Path(path).suffix.lower() in (".glb", ".gltf")
            tess = Path(tmp) / f"{name}.{'glb' if glb else 'obj'}"
            # The general mode's pieces at 10 × 10 points, as the fit measures them; a tube's
            # or sheet's patch spans a whole section, so those take the default tessellation
            # (at 10 × 10 a tube patch is a coarse polygon: 3.7 % off where the fit is 0.16 %).
            mode = json.loads(report_json.read_text()).get("mode")
            grid = ["--nu", "10", "--nv", "10"] if mode == "general" else []
            subprocess.run(
                [exe, "surface", str(out), "-o", str(tess), *grid],
                check=True,
                capture_output=True,
            )
            fit = load(str(tess))
            h, rms = distances(mesh, fit)
            tri, dbytes, dh = decimated_at(mesh, h)
            print(
                f"{name}\t{len(mesh.faces)}\texit 0\t{secs:.1f} s\tHausdorff {100 * h:.3f} %\t"
                f"RMS {100 * rms:.4f} %\tTOML {out.stat().st_size} bytes\t"
                f"decimation at that Hausdorff: {tri} triangles, {dbytes} bytes ({100 * dh:.3f} %)\t"
                f"{report}"
            )


if __name__ == "__main__":
    main()
