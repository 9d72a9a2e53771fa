"""Checks `pdeshape animate` with independent readers; fails on any finding.

For the ventricle and the glass morph: the Khronos validator reports no error on the GLB;
trimesh loads it; every frame rebuilt from the GLB (base positions plus its morph target, read
from the binary chunk here) is a consistent open surface whose volume, closed over its one open
ring by a fan, matches the per-frame volume of `--csv` (the library's quadrature with a planar
cap) to the discretisation error of the 64 x 128 grid (chordal error about (2 pi/128)^2/6 = 4e-4
per direction; 3e-3 leaves room for the fan cap's polygon and nothing more). The ventricle's
volume curve has its maximum at t = 0 and its minimum at t = t_m/2.

For the face: both GLBs (the face and the scan re-targeted onto it) pass the validator and load
in trimesh; the re-targeted GLB has one frame per frame of the face, and its frames where every
expression weight is zero (t = 0, 2, 4) are the scan's vertices exactly (the OBJ's coordinates
as float32 in glTF's frame, metres); the others move it. The APNG is read back chunk by chunk
here: its size, frame count, endless loop and frame delay (1/12 s).
"""

import csv
import json
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[2]
VOLUME_TOL = 3e-3
failures = []


def fail(msg):
    print("FAIL", msg)
    failures.append(msg)


def run(cmd):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"{' '.join(map(str, cmd))}: exit {r.returncode}: {r.stderr.strip()}")
    return r


def read_glb(path):
    data = Path(path).read_bytes()
    magic, version, total = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and total == len(data)
    jlen, _ = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20 : 20 + jlen])
    blen, _ = struct.unpack_from("<II", data, 20 + jlen)
    binary = data[28 + jlen : 28 + jlen + blen]

    def accessor(i):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        comps = {"SCALAR": 1, "VEC3": 3}[a["type"]]
        dtype = {5126: np.float32, 5125: np.uint32}[a["componentType"]]
        arr = np.frombuffer(binary, dtype=dtype, count=a["count"] * comps, offset=v["byteOffset"])
        return arr.reshape(-1, comps) if comps > 1 else arr

    prim = doc["meshes"][0]["primitives"][0]
    base = accessor(prim["attributes"]["POSITION"]).astype(np.float64)
    faces = accessor(prim["indices"]).reshape(-1, 3)
    frames = [base] + [base + accessor(t["POSITION"]) for t in prim.get("targets", [])]
    return doc, frames, faces


def capped_volume(vertices, faces):
    """Volume of an open mesh closed by a fan over each boundary loop."""
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    edges = mesh.edges_sorted
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    boundary = set(map(tuple, uniq[counts == 1]))
    # Directed boundary edges as the faces run them.
    directed = [tuple(e) for e in mesh.edges if tuple(sorted(e)) in boundary]
    nxt = {a: b for a, b in directed}
    verts = list(vertices)
    extra = []
    seen = set()
    for start in list(nxt):
        if start in seen:
            continue
        loop = [start]
        seen.add(start)
        while nxt[loop[-1]] != start:
            loop.append(nxt[loop[-1]])
            seen.add(loop[-1])
        c = len(verts)
        verts.append(vertices[loop].mean(axis=0))
        for a in range(len(loop)):
            # The cap runs the loop the other way round (consistent orientation).
            extra.append([loop[(a + 1) % len(loop)], loop[a], c])
    all_faces = np.vstack([faces, extra]) if extra else np.asarray(faces)
    closed = trimesh.Trimesh(vertices=np.array(verts), faces=all_faces, process=False)
    if not closed.is_watertight or not closed.is_winding_consistent:
        return None
    return abs(closed.volume)


def check(bin_, out, validator, example, name, scale_m, ventricle):
    glb = out / f"{name}.glb"
    table = out / f"{name}.csv"
    run([bin_, "animate", ROOT / "examples" / example, "-o", glb, "--csv", table, "--quiet"])
    if not glb.exists():
        return
    r = subprocess.run(["node", validator, glb], capture_output=True, text=True)
    report = json.loads(r.stdout.strip().splitlines()[-1])
    print(f"validator {name}: {report['errors']} errors, {report['warnings']} warnings")
    if report["errors"] != 0:
        fail(f"{glb}: validator: {report['messages']}")
    loaded = trimesh.load(str(glb))
    if len(loaded.geometry) != 1:
        fail(f"{glb}: trimesh finds {len(loaded.geometry)} meshes")
    doc, frames, faces = read_glb(glb)
    rows = list(csv.DictReader(open(table)))
    if len(rows) != len(frames):
        fail(f"{name}: {len(frames)} frames in the GLB, {len(rows)} rows in the CSV")
    vol_key = [k for k in rows[0] if k.startswith("volume")][0]
    worst = 0.0
    for k, (f, row) in enumerate(zip(frames, rows)):
        v = capped_volume(f, faces)
        expected = float(row[vol_key]) * scale_m**3
        if v is None:
            fail(f"{name} frame {k}: not a consistent surface with capped rings")
            continue
        worst = max(worst, abs(v - expected) / expected)
    print(f"{name}: {len(frames)} frames, largest relative volume difference {worst:.2e}")
    if worst > VOLUME_TOL:
        fail(f"{name}: trimesh volume differs from the csv by {worst:.2e} > {VOLUME_TOL}")
    if ventricle:
        vols = [float(r[vol_key]) for r in rows]
        ts = [float(r["t"]) for r in rows]
        if ts[int(np.argmax(vols))] != 0.0 or abs(ts[int(np.argmin(vols))] - 0.4) > 1e-9:
            fail(f"{name}: volume extremes at t = {ts[int(np.argmax(vols))]}, {ts[int(np.argmin(vols))]}")
        edv, esv = max(vols), min(vols)
        print(f"ventricle: EDV {edv:.1f} ml, ESV {esv:.1f} ml, EF {100 * (edv - esv) / edv:.1f} %")
        if not doc["asset"]["extras"]["loop"]:
            fail("ventricle: not marked as a loop")


def read_obj_vertices(path):
    return np.array(
        [list(map(float, l.split()[1:4])) for l in open(path) if l.startswith("v ")],
        dtype=np.float64,
    )


def read_apng(path):
    """Width, height, frames, plays and the frame delays of an APNG, from its chunks."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, info, delays = 8, {}, []
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            info["size"] = struct.unpack_from(">II", body, 0)
        elif kind == b"acTL":
            info["frames"], info["plays"] = struct.unpack_from(">II", body, 0)
        elif kind == b"fcTL":
            num, den = struct.unpack_from(">HH", body, 20)
            delays.append((num, den))
        pos += 12 + length
    info["delays"] = delays
    return info


def check_face(bin_, out, validator):
    face = ROOT / "examples" / "anim" / "face.toml"
    scan = ROOT / "examples" / "anim" / "face_scan.obj"
    glb, sglb, apng, sheet = (out / n for n in ["face.glb", "scan.glb", "face.png", "sheet.png"])
    run([bin_, "animate", face, "-o", glb, "--retarget", scan, "--retarget-output", sglb,
         "--apng", apng, "--contact-sheet", sheet, "--picture-size", "160x120", "--quiet"])
    if not (glb.exists() and sglb.exists() and apng.exists() and sheet.exists()):
        fail("face: an output is missing")
        return
    for f in [glb, sglb]:
        r = subprocess.run(["node", validator, f], capture_output=True, text=True)
        report = json.loads(r.stdout.strip().splitlines()[-1])
        print(f"validator {f.name}: {report['errors']} errors, {report['warnings']} warnings")
        if report["errors"] != 0:
            fail(f"{f}: validator: {report['messages']}")
        if len(trimesh.load(str(f)).geometry) != 1:
            fail(f"{f}: trimesh does not find one mesh")
    _, face_frames, _ = read_glb(glb)
    _, frames, faces = read_glb(sglb)
    if len(frames) != len(face_frames) or len(frames) != 72:
        fail(f"face: {len(face_frames)} face frames, {len(frames)} re-targeted frames (72 expected)")
        return
    # The frames are float32 in design units, then scaled to metres in float64 and rounded to
    # float32 again; glTF is +Y up: (x, y, z) cm -> (x, z, -y) / 100.
    v = read_obj_vertices(scan).astype(np.float32).astype(np.float64)
    expected = np.stack([v[:, 0] * 0.01, v[:, 2] * 0.01, -v[:, 1] * 0.01], axis=1)
    base = frames[0].astype(np.float32)
    if not np.array_equal(base, expected.astype(np.float32)):
        worst = np.abs(base - expected.astype(np.float32)).max()
        fail(f"face: the first re-targeted frame is not the scan (largest difference {worst:.3g} m)")
    still = [k for k in range(72) if not np.any(frames[k] - frames[0])]
    print(f"face: re-targeted frames equal to the scan: {still}")
    if still[:3] != [0, 24, 48] or not all(k in (0, 24, 48) for k in still):
        fail(f"face: frames equal to the scan are {still}, expected [0, 24, 48]")
    moved = max(np.abs(f - frames[0]).max() for f in frames)
    print(f"face: largest re-targeted displacement {moved * 100:.3f} cm")
    if moved < 0.005:
        fail("face: the re-targeted scan does not move")
    info = read_apng(apng)
    print(f"face APNG: {info['size']}, {info['frames']} frames, plays {info['plays']}")
    if info["size"] != (160, 120) or info["frames"] != 72 or info["plays"] != 0:
        fail(f"face APNG: {info}")
    if len(info["delays"]) != 72 or set(info["delays"]) != {(1, 12)}:
        fail(f"face APNG: {len(info['delays'])} frame controls, delays {set(info['delays'])}")


def main():
    bin_, out, validator = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    check(bin_, out, validator, "anim/ventricle.toml", "ventricle", 0.01, True)
    check(bin_, out, validator, "anim/glass_morph.toml", "glass", 0.001, False)
    check(bin_, out, validator, "anim/fish.toml", "fish", 0.01, False)
    check(bin_, out, validator, "anim/snake.toml", "snake", 0.01, False)
    check(bin_, out, validator, "anim/arm.toml", "arm", 0.01, False)
    check_face(bin_, out, validator)
    if failures:
        print(f"{len(failures)} animation check(s) failed")
        sys.exit(1)
    print("all animation checks passed")


if __name__ == "__main__":
    main()
