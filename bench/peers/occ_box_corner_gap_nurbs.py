# The STEP part of examples/cad/box_corner_gap_nurbs.step and its evaluation truth
# examples/cad/box_corner_gap_nurbs.points: the part of occ_box_corner_gap.py (the unit box, its
# three edges at (1, 1, 1) filleted with radius 0.2, the vertex blend left out) with every face
# converted to a B-spline surface by BRepBuilderAPI_NurbsConvert: the planes become polynomial
# B-spline faces, the circular fillets rational ones (exact: a circle is a rational quadratic).
#
# The points file is OpenCascade's own evaluation of the faces as it reads them back from the
# written STEP file: per B-spline face a line `face K` (K in the file's face order), then on a
# 5 x 5 grid inside the surface's parameter box (its knot parameters) the lines
# `u v  X  Xu  Xv  Xuu  Xvv  Xuv` (20 numbers in OpenCascade's D2 order, the derivatives in
# those knot parameters).
# usage: python occ_box_corner_gap_nurbs.py OUT.step OUT.points   (cadquery-ocp)
import sys

from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.GeomAbs import GeomAbs_BSplineSurface, GeomAbs_Sphere
from OCP.gp import gp_Pnt, gp_Vec
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Reader, STEPControl_Writer
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shell


def faces(shape):
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    out = []
    while ex.More():
        out.append(TopoDS.Face_s(ex.Current()))
        ex.Next()
    return out


step_out = sys.argv[1] if len(sys.argv) > 1 else "box_corner_gap_nurbs.step"
points_out = sys.argv[2] if len(sys.argv) > 2 else "box_corner_gap_nurbs.points"

box = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape()
fillet = BRepFilletAPI_MakeFillet(box)
ex = TopExp_Explorer(box, TopAbs_EDGE)
while ex.More():
    e = TopoDS.Edge_s(ex.Current())
    c = BRepAdaptor_Curve(e)
    ends = [c.Value(c.FirstParameter()), c.Value(c.LastParameter())]
    if any(abs(p.X() - 1) + abs(p.Y() - 1) + abs(p.Z() - 1) < 1e-9 for p in ends):
        fillet.Add(0.2, e)
    ex.Next()
fillet.Build()
filleted = fillet.Shape()

# Every face as a B-spline surface (the topology, so the shared edges, is kept).
convert = BRepBuilderAPI_NurbsConvert(filleted, True)
converted = convert.Shape()
b = BRep_Builder()
shell = TopoDS_Shell()
b.MakeShell(shell)
kept = 0
for f in faces(filleted):
    blend = BRepAdaptor_Surface(f).GetType() == GeomAbs_Sphere
    g = TopoDS.Face_s(convert.ModifiedShape(f))
    assert BRepAdaptor_Surface(g).GetType() == GeomAbs_BSplineSurface
    if not blend:
        b.Add(shell, g)
        kept += 1
assert kept == 9, kept
w = STEPControl_Writer()
w.Transfer(shell, STEPControl_AsIs)
w.Write(step_out)

# The truth: the faces as OpenCascade reads the file back, evaluated on their own surfaces.
r = STEPControl_Reader()
assert r.ReadFile(step_out) == IFSelect_RetDone
r.TransferRoots()
back = faces(r.OneShape())
assert len(back) == 9, len(back)
lines = []
for k, f in enumerate(back):
    s = BRep_Tool.Surface_s(f)
    u0, u1, v0, v1 = s.Bounds()
    lines.append(f"face {k + 1}")
    for i in range(5):
        for j in range(5):
            u = u0 + (u1 - u0) * (0.05 + 0.9 * i / 4)
            v = v0 + (v1 - v0) * (0.05 + 0.9 * j / 4)
            p = gp_Pnt()
            d = [gp_Vec() for _ in range(5)]
            s.D2(u, v, p, *d)
            nums = [u, v, p.X(), p.Y(), p.Z()]
            for x in d:
                nums += [x.X(), x.Y(), x.Z()]
            lines.append(" ".join(repr(x) for x in nums))
with open(points_out, "w") as out:
    out.write("\n".join(lines) + "\n")
print("wrote", step_out, "and", points_out, "(9 B-spline faces)")
