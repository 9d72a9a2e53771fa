# The STEP part of examples/cad/box_corner_gap.step: the unit box with its three edges at
# (1, 1, 1) filleted (radius 0.2) by OpenCascade, and the vertex blend it made there (a sphere
# face) left out, so the shell has a three-sided gap between the three fillets.
# usage: python occ_box_corner_gap.py OUT.step   (cadquery-ocp, .ci/occ-requirements.txt)
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane, GeomAbs_Sphere
from OCP.STEPControl import STEPControl_Writer, STEPControl_AsIs
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.BRep import BRep_Builder
from OCP.TopoDS import TopoDS_Compound, TopoDS_Shell
box = BRepPrimAPI_MakeBox(1.0,1.0,1.0).Shape()
f = BRepFilletAPI_MakeFillet(box)
ex = TopExp_Explorer(box, TopAbs_EDGE)
n=0
while ex.More():
    e = TopoDS.Edge_s(ex.Current())
    c = BRepAdaptor_Curve(e)
    p0 = c.Value(c.FirstParameter()); p1 = c.Value(c.LastParameter())
    ends=[(round(p.X(),6),round(p.Y(),6),round(p.Z(),6)) for p in (p0,p1)]
    if (1.0,1.0,1.0) in ends:
        f.Add(0.2, e); n+=1
    ex.Next()
f.Build()
shape = f.Shape()
# keep every face except the vertex blend (a sphere) -> a shell with a three-sided gap
b = BRep_Builder(); shell = TopoDS_Shell(); b.MakeShell(shell)
ex = TopExp_Explorer(shape, TopAbs_FACE)
kinds=[]
while ex.More():
    fa = TopoDS.Face_s(ex.Current())
    t = BRepAdaptor_Surface(fa).GetType()
    kinds.append(int(t))
    if t != GeomAbs_Sphere:
        b.Add(shell, fa)
    ex.Next()
print("fillets", n, "face kinds", kinds)
import sys
w = STEPControl_Writer(); w.Transfer(shell, STEPControl_AsIs); w.Write(sys.argv[1] if len(sys.argv) > 1 else "box_corner_gap.step")
