"""Reads pdeshape's mesh files back with independent tools and fails on any finding.

Run by .ci/readers.sh (which installs the tools): for every example design, writes STL, OBJ, PLY
and GLB with the given pdeshape binary, then
  * trimesh: closed designs load watertight, winding-consistent, with positive volume equal to
    `pdeshape analyze`'s within the discretisation error; no mesh has a degenerate triangle;
  * ADMesh: closed designs' STL need no fix at all (no facet added, removed or reversed, no edge
    or normal fixed); open designs' STL need no normal, orientation or degeneracy fix;
  * the Khronos glTF validator: zero errors and zero warnings on every GLB.
Exits non-zero when a tool is missing or any check fails.
"""

import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import trimesh

ROOT = Path(__file__).resolve().parents[2]
# Closed designs: one connected, watertight surface. The chordal error of a 64 x 128 grid on
# these shapes is about (2*pi/128)^2/6 = 4e-4 of the volume along v plus a similar share along
# u; 2e-3 leaves room for both and nothing more.
CLOSED = ["vesicle.toml", "cup_closed.toml"]
# One-sided surfaces: no orientation exists, so only degeneracy and the validator apply.
NON_ORIENTABLE = ["klein_bottle.toml", "klein_bottle_patches.toml"]
VOLUME_TOL = 2e-3
UNITS_M = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}

failures = []


def fail(msg):
    print("FAIL", msg)
    failures.append(msg)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"{' '.join(map(str, cmd))}: exit {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def analyze_volume(bin_, design):
    out = json.loads(run([bin_, "analyze", str(design), "--json"]))
    return out["total"]["volume"]


def units_of(design):
    m = re.search(r'^units\s*=\s*"(\w+)"', design.read_text(), re.M)
    return m.group(1) if m else "mm"


def check_trimesh(path, closed, volume, scale=1.0, orientable=True):
    loaded = trimesh.load(str(path))
    if isinstance(loaded, trimesh.Scene):
        mesh = loaded.to_geometry()
    else:
        mesh = loaded
    mesh.merge_vertices()
    areas = mesh.area_faces
    if len(areas) == 0 or areas.min() <= 0.0:
        fail(f"{path}: trimesh finds degenerate triangles (min area {areas.min()})")
    if orientable and not mesh.is_winding_consistent:
        fail(f"{path}: trimesh: winding not consistent")
    if closed:
        if not mesh.is_watertight:
            fail(f"{path}: trimesh: not watertight")
        expected = volume * scale**3
        if not (mesh.volume > 0 and abs(mesh.volume - expected) <= VOLUME_TOL * expected):
            fail(f"{path}: trimesh volume {mesh.volume} vs analyze {expected}")
        print(f"ok trimesh {path.name}: watertight, volume {mesh.volume:.6g} (analyze {expected:.6g})")
    else:
        print(f"ok trimesh {path.name}: open, winding consistent, {len(areas)} triangles")


ADMESH_FIELDS = [
    "Degenerate facets",
    "Edges fixed",
    "Facets removed",
    "Facets added",
    "Facets reversed",
    "Backwards edges",
    "Normals fixed",
]


def check_admesh(path, closed):
    # Open surfaces: every check but hole filling (which would add facets by design).
    opts = [] if closed else ["--exact", "--normal-directions", "--normal-values"]
    out = run(["admesh", *opts, str(path)])
    for field in ADMESH_FIELDS:
        m = re.search(rf"{field}\s*:\s*(\d+)", out)
        if m is None:
            fail(f"{path}: admesh printed no '{field}'")
        elif int(m.group(1)) != 0:
            fail(f"{path}: admesh: {field} {m.group(1)}")
    print(f"ok admesh {path.name}")


def main():
    bin_ = sys.argv[1]
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    for tool in ["admesh", "node"]:
        if shutil.which(tool) is None:
            fail(f"{tool} is not installed")
    designs = sorted(p for p in (ROOT / "examples").glob("*.toml"))
    glbs = []
    for d in designs:
        text = d.read_text()
        if "[[patches]]" not in text and "conditions" not in text and "[blend]" not in text and "[[parametric]]" not in text:
            continue
        closed = d.name in CLOSED
        volume = analyze_volume(bin_, d) if closed else None
        for ext in ["stl", "obj", "ply", "glb"]:
            f = out / f"{d.stem}.{ext}"
            run([bin_, "surface", str(d), "-o", str(f)])
            if not f.exists():
                continue
            orientable = d.name not in NON_ORIENTABLE
            if ext == "glb":
                glbs.append(str(f))
                check_trimesh(f, closed, volume, UNITS_M[units_of(d)], orientable)
            else:
                check_trimesh(f, closed, volume, 1.0, orientable)
            if ext == "stl" and orientable:
                check_admesh(f, closed)
    r = subprocess.run(["node", str(Path(__file__).parent / "validate_gltf.mjs"), *glbs], capture_output=True, text=True)
    print(r.stdout.strip())
    if r.returncode != 0:
        fail(f"glTF validator: {r.stderr.strip() or 'errors or warnings'}")
    if failures:
        print(f"{len(failures)} reader check(s) failed")
        sys.exit(1)
    print("all reader checks passed")


if __name__ == "__main__":
    main()
