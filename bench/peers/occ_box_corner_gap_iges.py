# The IGES parts of examples/cad/box_corner_gap*.igs and their evaluation truth: OpenCascade reads
# the two STEP test parts (box_corner_gap.step, analytic faces; box_corner_gap_nurbs.step, every
# face a B-spline surface; made by occ_box_corner_gap.py and occ_box_corner_gap_nurbs.py) and
# writes each with IGESControl_Writer twice: as a B-rep (write.iges.brep.mode 1: entities
# 186/514/510/508/504/502) and as trimmed surfaces (mode 0: entities 144 with their 142
# boundaries), so the importer reads the same part from STEP, from an IGES B-rep and from IGES
# trimmed surfaces.
#
# For each NURBS IGES file, `<name>.points` is OpenCascade's own evaluation of the faces as it
# reads that file back (IGESControl_Reader): per face `face K` (the reader's face order), then on
# a 5 x 5 grid inside the surface's parameter box the lines `u v  X  Xu  Xv  Xuu  Xvv  Xuv`
# (20 numbers, OpenCascade's D2 order), as in box_corner_gap_nurbs.points.
# usage: python occ_box_corner_gap_iges.py EXAMPLES_CAD_DIR   (cadquery-ocp)
import os
import sys

from OCP.BRep import BRep_Tool
from OCP.gp import gp_Pnt, gp_Vec
from OCP.IFSelect import IFSelect_RetDone
from OCP.IGESControl import IGESControl_Reader, IGESControl_Writer
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS


def static(cls, name):
    # OCP before 8 names static methods with a `_s` suffix.
    return getattr(cls, name + "_s", None) or getattr(cls, name)


def faces(shape):
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    out = []
    while ex.More():
        out.append(static(TopoDS, "Face")(ex.Current()))
        ex.Next()
    return out


def read_step(path):
    r = STEPControl_Reader()
    assert r.ReadFile(path) == IFSelect_RetDone, path
    r.TransferRoots()
    return r.OneShape()


def read_iges(path):
    r = IGESControl_Reader()
    assert r.ReadFile(path) == IFSelect_RetDone, path
    r.TransferRoots()
    return r.OneShape()


def points(shape, out_path):
    lines = []
    for k, f in enumerate(faces(shape)):
        s = static(BRep_Tool, "Surface")(f)
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
    with open(out_path, "w") as out:
        out.write("\n".join(lines) + "\n")


root = sys.argv[1] if len(sys.argv) > 1 else "examples/cad"
for stem in ["box_corner_gap", "box_corner_gap_nurbs"]:
    shape = read_step(os.path.join(root, stem + ".step"))
    assert len(faces(shape)) == 9
    for mode, suffix in [(1, "_brep"), (0, "_trimmed")]:
        static(Interface_Static, "SetIVal")("write.iges.brep.mode", mode)
        w = IGESControl_Writer("MM", mode)
        assert w.AddShape(shape)
        w.ComputeModel()
        out = os.path.join(root, stem + suffix + ".igs")
        assert w.Write(out), out
        back = read_iges(out)
        n = len(faces(back))
        assert n == 9, (out, n)
        if stem.endswith("nurbs"):
            points(back, os.path.join(root, stem + suffix + ".points"))
        print("wrote", out, "(9 faces read back)")
