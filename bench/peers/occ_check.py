"""OpenCascade checks of the STEP and IGES files pdeshape writes.

usage: occ_check.py PDESHAPE_BINARY EXAMPLES_DIR

For every example design with surfaces, writes part.step and part.igs with `pdeshape surface`
and checks with OpenCascade (cadquery-ocp): the file reads without failures or warnings; one
face per design surface; BRepCheck_Analyzer finds the shape valid; every face's surface,
evaluated by OpenCascade at the (u, v) of a dense `pdeshape surface -o x.csv` sample, lies
within the deviation pdeshape printed for that surface of pdeshape's own point; a closed design
gives one solid whose GProp volume matches `pdeshape analyze` within area × deviation.
Exits 1 on the first failed check (every check is a failure, none is skipped).
"""
import csv
import os
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
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
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
        r = run([binary, "surface", design, "-o", sample, "--nu", "41", "--nv", "83"])
        if r.returncode != 0 and "[[trims]]" in r.stderr:
            # Trimmed faces are not written yet: STEP output must refuse the design clearly.
            t = run([binary, "surface", design, "-o", os.path.join(tmp, name + ".step")])
            check(t.returncode == 2 and "trimmed surfaces is not available" in t.stderr,
                  f"{name}: a trimmed design's STEP output was not refused: {t.stderr.strip()}")
            continue
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
                dist = [0.0] * count
                for row in rows:
                    j = int(row.get("patch", "0"))
                    p = surf.Value(float(row["u"]), float(row["v"]))
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
            solids = shapes(shape, TopAbs_SOLID)
            line = f"{name}.{ext}: {len(faces)} faces, {'valid' if valid else 'INVALID'}, largest point deviation " + \
                ", ".join(f"{w:.2e} (bound {b:.2e})" for w, b in zip(worst, bounds))
            if ext == "step" and solids:
                a = run([binary, "analyze", design])
                total = [l for l in a.stdout.splitlines() if l.startswith("total")][0].split()
                area, volume = float(total[1]), float(total[2])
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
