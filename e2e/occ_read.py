"""Reads a STEP file with OpenCascade and measures it against points of the design.

usage: occ_read.py FILE.step POINTS.json

POINTS.json: {"points": [[x, y, z], ...]} (points on the design's surfaces). Prints one JSON
object: the reader's status, the number of faces, BRepCheck's validity, and the largest
distance from a point to the nearest face (GeomAPI_ProjectPointOnSurf on every face).
"""
import json
import sys

from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt


def main():
    step, points = sys.argv[1], json.load(open(sys.argv[2]))["points"]
    reader = STEPControl_Reader()
    status = reader.ReadFile(step)
    out = {"read": status == IFSelect_RetDone}
    if not out["read"]:
        print(json.dumps(out))
        return
    reader.TransferRoots()
    shape = reader.OneShape()
    out["valid"] = BRepCheck_Analyzer(shape).IsValid()
    surfaces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        surfaces.append(BRep_Tool.Surface_s(TopoDS.Face_s(explorer.Current())))
        explorer.Next()
    out["faces"] = len(surfaces)
    worst = 0.0
    for p in points:
        best = float("inf")
        for s in surfaces:
            proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*p), s)
            if proj.NbPoints() > 0:
                best = min(best, proj.LowerDistance())
        worst = max(worst, best)
    out["worst"] = worst
    print(json.dumps(out))


main()
