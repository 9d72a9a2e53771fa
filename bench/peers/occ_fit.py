"""OpenCascade's own B-spline approximation beside pdeshape's STEP export (BENCHMARKS.md,
"CAD export").

usage: occ_fit.py PDESHAPE_BINARY EXAMPLES_DIR [designs...]

For each design (default: cup, wine_glass) and relative tolerance (10⁻³, 10⁻⁶ of the design
size, the bounding-box diagonal pdeshape prints):
- pdeshape: `pdeshape surface DESIGN -o x.step --tolerance T`, whole process, median of 3 runs;
  file size; control points per patch (printed by pdeshape).
- OpenCascade: a dense sample of pdeshape's own surface (`pdeshape surface -o s.csv`, a grid
  about twice as fine as pdeshape's net in each direction, the periodic column closed) is
  approximated per patch by `GeomAPI_PointsToBSplineSurface` (degree 3, C2, Tol3D = T, chord
  length parametrisation); time of those calls (median of 3, in process); poles per patch; the
  size of a STEP file of the resulting faces (`STEPControl_Writer`).
- Error of both, measured the same way off the sample: the points of a 37 × 71 grid per patch
  (prime counts: almost none on the sample) projected onto each B-spline surface
  (`GeomAPI_ProjectPointOnSurf`); the largest distance.
Prints a markdown table.
"""
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRep import BRep_Builder
from OCP.TopoDS import TopoDS_Compound, TopoDS
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface, GeomAPI_ProjectPointOnSurf
from OCP.Approx import Approx_ParametrizationType
from OCP.GeomAbs import GeomAbs_Shape
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader, STEPControl_Writer, STEPControl_AsIs
from OCP.TColgp import TColgp_Array2OfPnt
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.gp import gp_Pnt


def run(args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)}: {r.stderr.strip()}")
    return r


def grid(path):
    """Rows of a pdeshape CSV grouped by patch: {patch: (us, vs, {(u, v): (x, y, z)})}."""
    out = {}
    for row in csv.DictReader(open(path)):
        j = int(row["patch"])
        us, vs, pts = out.setdefault(j, ([], [], {}))
        u, v = float(row["u"]), float(row["v"])
        if not us or us[-1] != u:
            us.append(u)
        if v not in vs:
            vs.append(v)
        pts[(u, v)] = gp_Pnt(float(row["x"]), float(row["y"]), float(row["z"]))
    return out


def occ_fit(patch, tol, closed_v):
    us, vs, pts = patch
    cols = vs + ([vs[0]] if closed_v else [])
    arr = TColgp_Array2OfPnt(1, len(us), 1, len(cols))
    for i, u in enumerate(us):
        for j, v in enumerate(cols):
            arr.SetValue(i + 1, j + 1, pts[(u, v)])
    api = GeomAPI_PointsToBSplineSurface()
    api.Init(arr, Approx_ParametrizationType.Approx_ChordLength, 3, 3, GeomAbs_Shape.GeomAbs_C2, tol)
    if not api.IsDone():
        sys.exit("GeomAPI_PointsToBSplineSurface failed")
    return api.Surface()


def max_distance(surface, points):
    # One projector per surface (its set-up samples the surface), then one Perform per point.
    proj = GeomAPI_ProjectPointOnSurf()
    u0, u1, v0, v1 = surface.Bounds()
    proj.Init(surface, u0, u1, v0, v1)
    worst = 0.0
    for p in points:
        proj.Perform(p)
        if proj.NbPoints() == 0:
            return float("inf")
        worst = max(worst, proj.LowerDistance())
    return worst


def faces_of(path):
    r = STEPControl_Reader()
    assert r.ReadFile(path) == IFSelect_RetDone
    r.TransferRoots()
    ex = TopExp_Explorer(r.OneShape(), TopAbs_FACE)
    out = []
    while ex.More():
        out.append(BRep_Tool.Surface_s(TopoDS.Face_s(ex.Current())))
        ex.Next()
    return out


def step_size(surfaces, path):
    builder = BRep_Builder()
    comp = TopoDS_Compound()
    builder.MakeCompound(comp)
    for s in surfaces:
        builder.Add(comp, BRepBuilderAPI_MakeFace(s, 1e-7).Face())
    w = STEPControl_Writer()
    w.Transfer(comp, STEPControl_AsIs)
    w.Write(path)
    return os.path.getsize(path)


def main():
    binary, examples = sys.argv[1], sys.argv[2]
    names = sys.argv[3:] or ["cup", "wine_glass"]
    tmp = tempfile.mkdtemp()
    print("| design | T (rel., abs.) | pdeshape time | pdeshape size | pdeshape control points | pdeshape max error (certified bound) | OCC sample | OCC fit time | OCC STEP size | OCC poles | OCC max error |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        design = os.path.join(examples, name + ".toml")
        check_csv = os.path.join(tmp, name + "_check.csv")
        run([binary, "surface", design, "-o", check_csv, "--nu", "37", "--nv", "71"])
        check = grid(check_csv)
        for rel in [1e-3, 1e-6]:
            step = os.path.join(tmp, f"{name}_{rel}.step")
            # The design size: pdeshape prints it with the tolerance.
            r = run([binary, "surface", design, "-o", step])
            size = float(re.search(r"design size ([0-9.eE+-]+)", r.stdout).group(1))
            tol = rel * size
            times = []
            for _ in range(3):
                t0 = time.perf_counter()
                r = run([binary, "surface", design, "-o", step, "--tolerance", repr(tol)])
                times.append(time.perf_counter() - t0)
            counts = [(int(a), int(b)) for a, b in re.findall(r"(\d+) × (\d+) control points", r.stdout)]
            bounds = [float(x) for x in re.findall(r"deviation [≤≈] ([0-9.eE+-]+)", r.stdout)]
            ours = faces_of(step)
            # Dense sample: about twice pdeshape's net per direction (at least 41 × 80).
            nu = max(41, 2 * max(c[0] for c in counts) + 1)
            nv = max(80, 2 * max(c[1] for c in counts))
            sample_csv = os.path.join(tmp, f"{name}_{rel}_sample.csv")
            run([binary, "surface", design, "-o", sample_csv, "--nu", str(nu), "--nv", str(nv)])
            sample = grid(sample_csv)
            fit_times, fitted = [], None
            for k in range(3):
                t0 = time.perf_counter()
                fitted = [occ_fit(sample[j], tol, True) for j in sorted(sample)]
                fit_times.append(time.perf_counter() - t0)
                if fit_times[-1] > 20.0:
                    break  # one run when a run is long
            occ_step = os.path.join(tmp, f"{name}_{rel}_occ.step")
            occ_bytes = step_size(fitted, occ_step)
            poles = [(s.NbUPoles(), s.NbVPoles()) for s in fitted]
            err_occ, err_ours = [], []
            for j in sorted(check):
                pts = list(check[j][2].values())
                err_occ.append(max_distance(fitted[j], pts))
                # Our face of patch j: the one nearest to its first points (OpenCascade need
                # not keep the file's face order).
                best = min(ours, key=lambda s: max_distance(s, pts[::50]))
                err_ours.append(max_distance(best, pts))
            print(
                f"| {name} | {rel:.0e} ({tol:.2e}) | {1e3 * statistics.median(times):.0f} ms "
                f"| {os.path.getsize(step) / 1024:.0f} KiB | {', '.join(f'{a}×{b}' for a, b in counts)} "
                f"| {max(err_ours):.2e} (≤{max(bounds):.2e}) | {nu}×{nv} "
                f"| {1e3 * statistics.median(fit_times):.0f} ms{'' if len(fit_times) > 1 else ' (1 run)'} "
                f"| {occ_bytes / 1024:.0f} KiB | {', '.join(f'{a}×{b}' for a, b in poles)} "
                f"| {max(err_occ):.2e} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
