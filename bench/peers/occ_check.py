"""OpenCascade checks of the STEP and IGES files pdeshape writes.

usage: occ_check.py PDESHAPE_BINARY EXAMPLES_DIR

For every example design with surfaces, writes part.step and part.igs with `pdeshape surface`
and checks with OpenCascade (cadquery-ocp): the file reads without failures or warnings; one
face per design surface; BRepCheck_Analyzer finds the shape valid; every face's surface,
evaluated by OpenCascade at the (u, v) of a dense `pdeshape surface -o x.csv` sample, lies
within the deviation pdeshape printed for that surface of pdeshape's own point; a closed design
gives one solid whose GProp volume matches `pdeshape analyze` within area × deviation.
Trimmed designs ([[trims]]): each face has 1 + (its holes) wires, and its GProp area matches
`pdeshape analyze`'s trimmed area within analyze's own error estimate (its area change between
two grids) plus what the approximation allows to first order: 2·max|H|·area·ε for the surface
(the first variation of area under a normal displacement ε) and the face's edge length × ε for
its boundary, ε the largest deviation printed for the face and its holes. The points of a
trimmed surface are sampled from the same design without its [[trims]].
Exits 1 on the first failed check (every check is a failure, none is skipped).
"""
import csv
import math
import os
import json
import re
import subprocess
import sys
import tempfile

from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.IGESControl import IGESControl_Reader
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

FAILED = []


def check(ok, what):
    if not ok:
        FAILED.append(what)
        print("FAIL:", what)


def run(args):
    return subprocess.run(args, capture_output=True, text=True)


def shapes(shape, kind):
    ex = TopExp_Explorer(shape, kind)
    out = []
    while ex.More():
        out.append(ex.Current())
        ex.Next()
    return out


def read(path):
    reader = STEPControl_Reader() if path.endswith(".step") else IGESControl_Reader()
    status = reader.ReadFile(path)
    checks = reader.WS().ModelCheckList()
    clean = checks.IsEmpty(False)
    reader.TransferRoots()
    return status == IFSelect_RetDone, clean, reader.OneShape()


def untrimmed(design, tmp):
    """A copy of the design file without its [[trims]] tables and with `trim = false` on its
    on_patch curves (attachments then leave their hosts whole)."""
    out, skip = [], False
    for line in open(design).read().splitlines():
        if re.match(r"^\[\[?[A-Za-z0-9_.\" -]+\]\]?\s*(#.*)?$", line):
            skip = line.strip().startswith("[[trims]]")
        if skip:
            continue
        if line.strip() == 'type = "on_patch"':
            out.extend([line, "trim = false"])
        else:
            out.append(line.replace('type = "on_patch"', 'type = "on_patch", trim = false'))
    path = os.path.join(tmp, "untrimmed_" + os.path.basename(design))
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    return path


def analyze_tables(binary, design):
    """`pdeshape analyze --json` (full precision): per surface its area, its largest |H|, and
    for trimmed surfaces the trimmed area and its change between analyze's two grids."""
    data = json.loads(run([binary, "analyze", "--json", design]).stdout)
    area = {p["name"]: p["area"] for p in data["patches"]}
    h = {p["name"]: max(abs(p["mean_min"]), abs(p["mean_max"])) for p in data["patches"]}
    trimmed = {t["name"]: (t["area"], t["area_change"]) for t in data.get("trimmed", [])}
    return area, h, trimmed


def main():
    binary, examples = sys.argv[1], sys.argv[2]
    designs = sorted(
        os.path.join(d, f)
        for d in [examples, os.path.join(examples, "spline")]
        if os.path.isdir(d)
        for f in os.listdir(d)
        if f.endswith(".toml")
    )
    tmp = tempfile.mkdtemp()
    checked = 0
    for design in designs:
        name = os.path.splitext(os.path.basename(design))[0]
        sample = os.path.join(tmp, name + ".csv")
        text = open(design).read()
        is_trimmed = (
            re.search(r"^\[\[trims\]\]", text, re.M) is not None
            or 'type = "on_patch"' in text
        )
        source = untrimmed(design, tmp) if is_trimmed else design
        r = run([binary, "surface", source, "-o", sample, "--nu", "41", "--nv", "83"])
        if r.returncode != 0:
            # Designs without a surface (a [dynamic] curve only) have nothing to export.
            check("has no surface" in r.stderr, f"{name}: csv sample failed: {r.stderr.strip()}")
            continue
        rows = list(csv.DictReader(open(sample)))
        for ext in ["step", "igs"]:
            out = os.path.join(tmp, f"{name}.{ext}")
            # In millimetres whatever the design's units, so that OpenCascade's lengths are the
            # design's numbers (the unit conversion itself is tested in the Rust suite).
            r = run([binary, "surface", design, "-o", out, "--units", "mm"])
            check(r.returncode == 0, f"{name}.{ext}: pdeshape failed: {r.stderr.strip()}")
            if r.returncode != 0:
                continue
            count = int(re.search(r"(\d+) B-spline surface", r.stdout).group(1))
            # A certified (or exact) deviation is a bound that must hold at every point. A
            # "sampled, not certified" one (printed with ≈) is only the largest deviation on pdeshape's own
            # sample lattice (surfaces with an active spectral remainder), so OpenCascade's points
            # off that lattice are held to the export's tolerance instead, which the fit promises.
            tolerance = float(re.search(r"tolerance ([0-9.eE+-]+)", r.stdout).group(1))
            found = re.findall(r"deviation ([≤≈]) ([0-9.eE+-]+) \(([^)]*)\)", r.stdout)
            bounds = [float(x) if rel == "≤" and "not certified" not in how
                      else max(float(x), tolerance) for rel, x, how in found]
            # Per surface: its name and the deviations of its holes ("    hole k: …").
            names, holes = [], []
            for l in r.stdout.splitlines():
                m = re.match(r"^  (.+?): \d+ × \d+ control points", l)
                if m:
                    names.append(m.group(1))
                    holes.append([])
                m = re.match(r"^    hole \d+: .*, ([0-9.eE+-]+) from the trim curve", l)
                if m:
                    holes[-1].append(float(m.group(1)))
            check(len(names) == count, f"{name}.{ext}: {len(names)} surface lines, expected {count}")
            done, clean, shape = read(out)
            check(done, f"{name}.{ext}: not read")
            check(clean, f"{name}.{ext}: read with failures or warnings")
            faces = shapes(shape, TopAbs_FACE)
            check(len(faces) == count, f"{name}.{ext}: {len(faces)} faces, expected {count}")
            valid = BRepCheck_Analyzer(shape).IsValid()
            check(valid, f"{name}.{ext}: BRepCheck_Analyzer: invalid")
            # OpenCascade need not list a shell's faces in the file's order: each face is
            # matched to the surface it lies closest to, and the matching must be one to one.
            worst = [0.0] * count
            matched = []
            for k, face in enumerate(faces[:count]):
                surf = BRep_Tool.Surface_s(TopoDS.Face_s(face))
                # A trimmed face's periodic v may start elsewhere (a hole across v = 0).
                v_lo, v_hi = surf.Bounds()[2:4]
                dist = [0.0] * count
                for row in rows:
                    j = int(row.get("patch", "0"))
                    v = float(row["v"])
                    if v < v_lo - 1e-12 and surf.IsVClosed():
                        v += (v_hi - v_lo) * math.ceil((v_lo - v) / (v_hi - v_lo))
                    p = surf.Value(float(row["u"]), v)
                    d = ((p.X() - float(row["x"])) ** 2 + (p.Y() - float(row["y"])) ** 2
                         + (p.Z() - float(row["z"])) ** 2) ** 0.5
                    dist[j] = max(dist[j], d)
                j = min(range(count), key=lambda i: dist[i])
                matched.append(j)
                worst[j] = dist[j]
                check(dist[j] <= bounds[j],
                      f"{name}.{ext}: face {k} (surface {j}): OpenCascade point {dist[j]:.3e} from pdeshape's, bound {bounds[j]:.3e}")
            check(sorted(matched) == list(range(min(count, len(faces)))),
                  f"{name}.{ext}: faces do not match the surfaces one to one: {matched}")
            if is_trimmed and len(names) == count:
                area, hmax, trimmed = analyze_tables(binary, design)
                for face, j in zip(faces, matched):
                    wires = len(shapes(face, TopAbs_WIRE))
                    check(wires == 1 + len(holes[j]),
                          f"{name}.{ext}: face of {names[j]}: {wires} wires, expected {1 + len(holes[j])}")
                    g = GProp_GProps()
                    BRepGProp.SurfaceProperties_s(face, g)
                    e = GProp_GProps()
                    BRepGProp.LinearProperties_s(face, e)
                    expected, change = trimmed.get(names[j], (area.get(names[j], float("nan")), 0.0))
                    eps = max([bounds[j]] + holes[j])
                    allowed = change + 2.0 * hmax.get(names[j], float("inf")) * g.Mass() * eps + e.Mass() * eps
                    check(abs(g.Mass() - expected) <= allowed,
                          f"{name}.{ext}: face of {names[j]}: area {g.Mass():.9e} vs analyze {expected:.9e} (allowed {allowed:.2e})")
                    line_area = f"{names[j]}: {wires} wires, area {g.Mass():.6f} vs analyze {expected:.6f} (|Δ| {abs(g.Mass() - expected):.1e}, allowed {allowed:.1e})"
                    print(f"{name}.{ext}: " + line_area)
            solids = shapes(shape, TopAbs_SOLID)
            line = f"{name}.{ext}: {len(faces)} faces, {'valid' if valid else 'INVALID'}, largest point deviation " + \
                ", ".join(f"{w:.2e} (bound {b:.2e})" for w, b in zip(worst, bounds))
            if ext == "step" and solids:
                total = json.loads(run([binary, "analyze", "--json", design]).stdout)["total"]
                area, volume = total["area"], total["volume"]
                g = GProp_GProps()
                BRepGProp.VolumeProperties_s(shape, g)
                allowed = 1.01 * area * max(bounds)
                check(abs(g.Mass() - volume) <= allowed,
                      f"{name}.step: volume {g.Mass():.9e} vs analyze {volume:.9e} (allowed {allowed:.2e})")
                line += f"; solid volume {g.Mass():.9f} vs analyze {volume:.9f} (allowed ±{allowed:.1e})"
            print(line)
            checked += 1
    check(checked >= 10, f"only {checked} files checked")
    if FAILED:
        print(f"{len(FAILED)} OpenCascade check(s) failed")
        sys.exit(1)
    print(f"OpenCascade: {checked} files checked, all valid")


if __name__ == "__main__":
    main()
