"""OpenCascade's mesher (BRepMesh) on the trimmed face pdeshape writes, beside pdeshape's own
trimmed tessellation: a peer for the trimmed-mesh benchmark.

usage: occ_trim_mesh.py PDESHAPE_BINARY DESIGN.toml [REPEATS]

Writes DESIGN as STEP with `pdeshape surface` (one trimmed B-spline face per trimmed patch) and
as a 256 × 512 OBJ, estimates the OBJ's deflection (the largest distance between a triangle's
centroid and the STEP surface, over every 37th triangle, by OpenCascade's projection: a sample,
so a lower estimate), then times `BRepMesh_IncrementalMesh` (sequential, then parallel) on the
STEP face at that deflection and at 2 and 4 times it. Medians of REPEATS runs (default 7);
every run starts from a cleaned shape.
"""
import statistics
import subprocess
import sys
import tempfile
import time

from OCP.BRep import BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS


def faces(shape):
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    out = []
    while ex.More():
        out.append(TopoDS.Face_s(ex.Current()))
        ex.Next()
    return out


def triangles(shape):
    n = 0
    for f in faces(shape):
        t = BRep_Tool.Triangulation_s(f, TopLoc_Location())
        if t is None:
            raise SystemExit("OpenCascade left a face without triangulation")
        n += t.NbTriangles()
    return n


def mesh(shape, deflection, parallel):
    BRepTools.Clean_s(shape)
    t0 = time.perf_counter()
    BRepMesh_IncrementalMesh(shape, deflection, False, 0.5, parallel)
    return time.perf_counter() - t0


def main():
    binary, design = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    with tempfile.TemporaryDirectory() as tmp:
        step, obj = f"{tmp}/part.step", f"{tmp}/part.obj"
        for out, extra in [(step, []), (obj, ["--nu", "256", "--nv", "512"])]:
            r = subprocess.run([binary, "surface", design, "-o", out, *extra],
                               capture_output=True, text=True)
            if r.returncode != 0:
                raise SystemExit(f"pdeshape surface failed: {r.stderr.strip()}")
        reader = STEPControl_Reader()
        if reader.ReadFile(step) != IFSelect_RetDone:
            raise SystemExit("OpenCascade could not read the STEP file")
        reader.TransferRoots()
        shape = reader.OneShape()
        surfaces = [BRep_Tool.Surface_s(f) for f in faces(shape)]
        verts, tris = [], 0
        with open(obj) as fh:
            for line in fh:
                if line.startswith("v "):
                    verts.append([float(x) for x in line.split()[1:4]])
                elif line.startswith("f "):
                    tris += 1
        # pdeshape's deflection: centroid-to-surface distance over the faces' triangles.
        defl = 0.0
        with open(obj) as fh:
            faces_seen = 0
            for line in fh:
                if not line.startswith("f "):
                    continue
                faces_seen += 1
                if faces_seen % 37:
                    continue
                idx = [int(w.split("/")[0]) - 1 for w in line.split()[1:4]]
                c = [sum(verts[i][k] for i in idx) / 3 for k in range(3)]
                best = min(
                    GeomAPI_ProjectPointOnSurf(gp_Pnt(*c), s).LowerDistance() for s in surfaces
                )
                defl = max(defl, best)
        print(f"pdeshape 256x512 trimmed mesh: {tris} triangles, deflection {defl:.3e}")
        for d in [4 * defl, 2 * defl, defl]:
            for parallel in (False, True):
                times = [mesh(shape, d, parallel) for _ in range(repeats)]
                print(
                    f"BRepMesh deflection {d:.3e}: {triangles(shape)} triangles, "
                    f"{'parallel' if parallel else 'sequential'}: median "
                    f"{1e3 * statistics.median(times):.2f} ms of {repeats}"
                )


if __name__ == "__main__":
    main()
