#!/usr/bin/env python3
"""OpenCascade's n-sided filling (BRepFill_Filling, a thin-plate surface approximated by a
B-spline) on the networks of network_cases.py, with the figures pdeshape's fill is compared on.

usage: occ_fill.py CASE.json [CASE.json ...] [--repeat K] [--setting default|tight|both]

Input: case files in the format of network_cases.py (its docstring). For each case and setting
prints one JSON object on a line (so `--setting both`, the default, gives two lines a case).
Exit status: 0 if every fill was done, 1 if any was not (its line says "done": false and the
exception or IsDone() = false; a failure is reported, never skipped), 2 on a usage error.

How the fill is set up:
- Each side becomes one edge: a cubic B-spline through the side's M points by
  GeomAPI_Interpolate, at parameters proportional to the point index times the polyline length
  (the points are uniform in the curve's natural parameter, so these are that parameter up to
  scale). Interpolation, not GeomAPI_PointsToBSpline: the latter approximates to a tolerance
  (1e-3 by default), which would add its own error to the boundary deviation, while
  interpolation passes through every given point and reproduces a smooth curve to O(h^4)
  between them. Consecutive edges share one TopoDS_Vertex at their common corner.
- A side with normals gets a G1 constraint, BRepFill_Filling::Add(edge, support, GeomAbs_G1),
  with the support face a ruled B-spline strip S(u, v) = C(u) + v (D(u) - C(u)), v in [0, 1],
  C the interpolated edge curve and D the interpolant, with the same parameters (so the same
  knots), of p_j + eps (n_j x t_j), t_j the unit tangent of C at p_j. Along v = 0 the strip's
  tangent plane is spanned by C'(u) and D(u) - C(u), i.e. by t and n x t at the points p_j
  (and by their interpolants between them): its normal is t x (n x t) = n, exactly the case's
  normal. The edge gets the pcurve v = 0 on the strip (BRepFill_Filling reads the constraint
  through the edge's pcurve on the support face). eps = 0.1 x the side's chord length: the
  constraint only uses the tangent plane along v = 0, so eps changes nothing in exact
  arithmetic; it is kept well away from 0 so that the strip is not a near-degenerate surface to
  OpenCascade's tolerances (1e-7), and well below the side's length so that the rulings of a
  curved side cannot cross (they would only if eps exceeded the radius of curvature of the side
  within the tangent plane; every case here has sides of zero geodesic curvature).
- A position-only side (normals null) is Add(edge, GeomAbs_C0).
- Settings: "default" = the constructor's documented defaults (Degree 3, NbPtsOnCur 15,
  NbIter 2, Anisotropie false, Tol2d 1e-5, Tol3d 1e-4, TolAng 0.01, TolCurv 0.1, MaxDeg 8,
  MaxSegments 9). "tight" = Tol2d 1e-7, Tol3d 1e-6, TolAng 1e-4 (SetConstrParam), NbPtsOnCur 40,
  NbIter 4 (SetResolParam), MaxDeg 10, MaxSegments 30 (SetApproxParam): tighter constraint
  tolerances mean little without more points on the constraints and more room in the final
  B-spline approximation, so all three are raised.

Figures (distances in the case's units, angles in radians):
- boundary_dev: the largest distance from the case's side points and from the midpoints, in
  parameter, of the interpolated edges between consecutive side points to the fill's surface
  (GeomAPI_ProjectPointOnSurf within the face's UV bounds). To the surface, not to the face:
  the face is bounded by the input edges themselves (within the edge tolerance), so a distance
  to the face (BRepExtrema) would be 0 whatever the plate does; the gap that matters is between
  the boundary curves and the surface the face carries. edge_tolerance_max is the largest
  tolerance OpenCascade put on the face's edges to cover that gap.
- g1_angle: over the side points of sides with normals, the largest angle between the fill's
  surface normal (GeomLProp_SLProps) at the point's projection onto the fill's surface and the
  case's normal, taken between lines: min(a, pi - a). null when no side has normals.
- truth_dev_max, truth_dev_rms, truth_samples: the distance to the case's truth surface of the
  points of a 50 x 50 grid over the face's UV bounds (BRepTools::UVBounds) that
  BRepClass_FaceClassifier puts inside the face; largest and root-mean-square. null without a
  truth.
- occ_g0_error, occ_g1_error: OpenCascade's own G0Error() and G1Error() of the fill.
- build_median_s, build_min_s: median and minimum over K runs (default 5) of the wall time of
  Build() alone; each run builds a fresh BRepFill_Filling with fresh edges and support faces,
  outside the timed call. The figures above are measured on the last run's face.
"""
import json
import math
import statistics
import sys
import time

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace,
                                BRepBuilderAPI_MakeVertex)
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepFill import BRepFill_Filling
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_BSplineSurface
from OCP.Geom2d import Geom2d_Line
from OCP.GeomAbs import GeomAbs_C0, GeomAbs_G1
from OCP.GeomAPI import GeomAPI_Interpolate, GeomAPI_ProjectPointOnSurf
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.TColgp import TColgp_Array2OfPnt, TColgp_HArray1OfPnt
from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_HArray1OfReal
from OCP.TopAbs import TopAbs_EDGE, TopAbs_IN
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Dir2d, gp_Pnt, gp_Pnt2d, gp_Vec

SETTINGS = {
    "default": {},
    "tight": {"constr": (1e-7, 1e-6, 1e-4, 0.1), "resol": (3, 40, 4, False), "approx": (10, 30)},
}

EPS_FRACTION = 0.1


def pnt(p):
    return gp_Pnt(float(p[0]), float(p[1]), float(p[2]))


def xyz(p):
    return np.array([p.X(), p.Y(), p.Z()])


def interpolate(points, params):
    arr = TColgp_HArray1OfPnt(1, len(points))
    par = TColStd_HArray1OfReal(1, len(points))
    for j, (p, t) in enumerate(zip(points, params)):
        arr.SetValue(j + 1, pnt(p))
        par.SetValue(j + 1, float(t))
    it = GeomAPI_Interpolate(arr, par, False, 1e-12)
    it.Perform()
    if not it.IsDone():
        raise RuntimeError("GeomAPI_Interpolate failed")
    return it.Curve()


def side_params(points):
    pts = np.asarray(points)
    length = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    return np.linspace(0.0, length, len(pts))


def strip(curve, points, normals, params):
    """The ruled support strip of the docstring, as a Geom_BSplineSurface of degree (3, 1)."""
    pts = np.asarray(points)
    eps = EPS_FRACTION * float(np.linalg.norm(pts[-1] - pts[0]))
    offs = []
    for p, n, t in zip(pts, np.asarray(normals), params):
        d1 = gp_Pnt()
        v = gp_Vec()
        curve.D1(float(t), d1, v)
        tg = np.array([v.X(), v.Y(), v.Z()])
        tg /= np.linalg.norm(tg)
        d = np.cross(n, tg)
        offs.append(p + eps * d / np.linalg.norm(d))
    other = interpolate(offs, params)
    nu = curve.NbPoles()
    if other.NbPoles() != nu or other.NbKnots() != curve.NbKnots():
        raise RuntimeError("the two interpolants of a strip differ in knots")
    poles = TColgp_Array2OfPnt(1, nu, 1, 2)
    for i in range(1, nu + 1):
        poles.SetValue(i, 1, curve.Pole(i))
        poles.SetValue(i, 2, other.Pole(i))
    uk = TColStd_Array1OfReal(1, curve.NbKnots())
    um = TColStd_Array1OfInteger(1, curve.NbKnots())
    for i in range(1, curve.NbKnots() + 1):
        uk.SetValue(i, curve.Knot(i))
        um.SetValue(i, curve.Multiplicity(i))
    vk = TColStd_Array1OfReal(1, 2)
    vk.SetValue(1, 0.0)
    vk.SetValue(2, 1.0)
    vm = TColStd_Array1OfInteger(1, 2)
    vm.SetValue(1, 2)
    vm.SetValue(2, 2)
    surf = Geom_BSplineSurface(poles, uk, vk, um, vm, curve.Degree(), 1)
    return BRepBuilderAPI_MakeFace(surf, 1e-7).Face()


def constraints(case):
    """Fresh edges (sharing corner vertices) and support faces: [(edge, face or None)]."""
    sides = case["sides"]
    corners = [BRepBuilderAPI_MakeVertex(pnt(s["points"][0])).Vertex() for s in sides]
    out = []
    builder = BRep_Builder()
    for i, s in enumerate(sides):
        params = side_params(s["points"])
        curve = interpolate(s["points"], params)
        edge = BRepBuilderAPI_MakeEdge(curve, corners[i], corners[(i + 1) % len(sides)]).Edge()
        face = None
        if s["normals"] is not None:
            face = strip(curve, s["points"], s["normals"], params)
            # The strip's u is the curve's parameter: the edge is the line v = 0 on it.
            line = Geom2d_Line(gp_Pnt2d(0.0, 0.0), gp_Dir2d(1.0, 0.0))
            builder.UpdateEdge(edge, line, face, 1e-7)
        out.append((edge, face, curve, params))
    return out


def make_filling(setting):
    f = BRepFill_Filling()
    s = SETTINGS[setting]
    if "constr" in s:
        f.SetConstrParam(*s["constr"])
    if "resol" in s:
        f.SetResolParam(*s["resol"])
    if "approx" in s:
        f.SetApproxParam(*s["approx"])
    return f


def truth_distance(truth, p):
    if truth["type"] == "sphere":
        return abs(float(np.linalg.norm(p - np.asarray(truth["center"]))) - truth["radius"])
    if truth["type"] == "plane":
        n = np.asarray(truth["normal"], dtype=float)
        return abs(float(np.dot(p - np.asarray(truth["point"]), n / np.linalg.norm(n))))
    if truth["type"] == "cylinder":
        a = np.asarray(truth["axis_dir"], dtype=float)
        a /= np.linalg.norm(a)
        q = p - np.asarray(truth["axis_point"])
        return abs(float(np.linalg.norm(q - np.dot(q, a) * a)) - truth["radius"])
    raise ValueError(f"unknown truth type {truth['type']}")


def measure(case, face):
    surf = BRep_Tool.Surface_s(face)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    bdev, g1 = 0.0, None
    for s, (_, _, curve, params) in zip(case["sides"], constraints(case)):
        pts = [np.asarray(p) for p in s["points"]]
        mids = [xyz(curve.Value(0.5 * (a + b))) for a, b in zip(params[:-1], params[1:])]
        for k, p in enumerate(pts + mids):
            proj = GeomAPI_ProjectPointOnSurf(pnt(p), surf, u0, u1, v0, v1)
            if not proj.NbPoints():
                raise RuntimeError("no projection of a boundary point onto the fill's surface")
            bdev = max(bdev, proj.LowerDistance())
            if k >= len(pts) or s["normals"] is None:
                continue
            u, v = proj.LowerDistanceParameters()
            props = GeomLProp_SLProps(surf, u, v, 1, 1e-12)
            if not props.IsNormalDefined():
                raise RuntimeError("fill normal undefined at a boundary point")
            nf = props.Normal()
            nf = np.array([nf.X(), nf.Y(), nf.Z()])
            nc = np.asarray(s["normals"][k])
            a = math.atan2(float(np.linalg.norm(np.cross(nf, nc))), float(np.dot(nf, nc)))
            g1 = max(g1 or 0.0, min(a, math.pi - a))
    tmax = trms = None
    count = 0
    if case["truth"] is not None:
        d = []
        for u in np.linspace(u0, u1, 50):
            for v in np.linspace(v0, v1, 50):
                cl = BRepClass_FaceClassifier(face, gp_Pnt2d(float(u), float(v)), 1e-9)
                if cl.State() != TopAbs_IN:
                    continue
                d.append(truth_distance(case["truth"], xyz(surf.Value(float(u), float(v)))))
        count = len(d)
        if d:
            tmax = max(d)
            trms = math.sqrt(sum(x * x for x in d) / len(d))
    tol = 0.0
    ex = TopExp_Explorer(face, TopAbs_EDGE)
    while ex.More():
        tol = max(tol, BRep_Tool.Tolerance_s(TopoDS.Edge_s(ex.Current())))
        ex.Next()
    return {"boundary_dev": bdev, "edge_tolerance_max": tol, "g1_angle": g1, "truth_dev_max": tmax, "truth_dev_rms": trms,
            "truth_samples": count}


def run(case, setting, repeat):
    out = {"case": case["name"], "peer": "occ BRepFill_Filling", "setting": setting,
           "sides": len(case["sides"]), "points_per_side": len(case["sides"][0]["points"]),
           "g1_sides": sum(s["normals"] is not None for s in case["sides"])}
    times, f = [], None
    try:
        for _ in range(repeat):
            f = make_filling(setting)
            for edge, face, _, _ in constraints(case):
                if face is None:
                    f.Add(edge, GeomAbs_C0, True)
                else:
                    f.Add(edge, face, GeomAbs_G1, True)
            t0 = time.perf_counter()
            f.Build()
            times.append(time.perf_counter() - t0)
            if not f.IsDone():
                break
        out["done"] = bool(f.IsDone())
    except Exception as e:  # OpenCascade's Standard_Failure arrives as a Python exception
        out["done"] = False
        out["error"] = f"{type(e).__name__}: {e}"
    if times:
        out["build_median_s"] = statistics.median(times)
        out["build_min_s"] = min(times)
    if out["done"]:
        try:
            out["occ_g0_error"] = f.G0Error()
            out["occ_g1_error"] = f.G1Error()
            out.update(measure(case, f.Face()))
        except Exception as e:
            out["measure_error"] = f"{type(e).__name__}: {e}"
    return out


def main():
    args = sys.argv[1:]
    repeat, setting = 5, "both"
    try:
        if "--repeat" in args:
            i = args.index("--repeat")
            repeat = int(args[i + 1])
            del args[i:i + 2]
        if "--setting" in args:
            i = args.index("--setting")
            setting = args[i + 1]
            del args[i:i + 2]
    except (IndexError, ValueError):
        repeat = 0
    if not args or repeat < 1 or setting not in ("default", "tight", "both"):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        sys.exit(2)
    settings = ["default", "tight"] if setting == "both" else [setting]
    ok = True
    for path in args:
        with open(path) as fh:
            case = json.load(fh)
        for s in settings:
            r = run(case, s, repeat)
            ok = ok and r["done"] and "measure_error" not in r
            print(json.dumps(r), flush=True)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
