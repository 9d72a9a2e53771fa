"""Reads the stress field `pdeshape shell -o x.vtu` wrote with meshio (an independent VTU
reader) and checks it against the JSON report of the same run: node count, element count by
type (quadratic quadrilaterals and triangles), the max_shear field's maximum equal to the
report's largest shear stress, finite displacements, coordinates inside the design's extent.

usage: python shell_vtu_check.py RESULT.vtu REPORT.json
"""
import json
import sys

import meshio
import numpy as np


def main() -> int:
    vtu, report_path = sys.argv[1], sys.argv[2]
    with open(report_path, encoding="utf-8") as f:
        report = json.load(f)
    mesh = meshio.read(vtu)
    problems = []
    n = len(mesh.points)
    if n != report["nodes"]:
        problems.append(f"{n} points, the report says {report['nodes']} nodes")
    cells = {block.type: len(block.data) for block in mesh.cells}
    want_cells = {
        k: v
        for k, v in (("quad8", report["elements"]["S8R"]), ("triangle6", report["elements"]["S6"]))
        if v
    }
    if cells != want_cells:
        problems.append(f"cells {cells}, the report says {want_cells}")
    for block in mesh.cells:
        if block.data.min() < 0 or block.data.max() >= n:
            problems.append(f"{block.type} connectivity outside 0..{n - 1}")
    shear = np.asarray(mesh.point_data["max_shear"], dtype=float)
    peak = float(shear.max())
    want = float(report["max_shear"])
    # Both files write each number in its shortest round-trip form: exactly equal.
    if peak != want:
        problems.append(f"max_shear field maximum {peak!r}, the report's {want!r}")
    # The report's place of the maximum is a point of the VTU holding it (several points of an
    # axisymmetric design may hold the same value).
    where = report["at"]
    gap = np.abs(mesh.points - [where["x"], where["y"], where["z"]]).max(axis=1)
    k = int(gap.argmin())
    if gap[k] > 1e-12 or shear[k] != peak:
        problems.append(
            f"the report puts the maximum at {where}; the nearest point is {gap[k]:.3e} m away "
            f"with max_shear {shear[k]!r}"
        )
    disp = np.asarray(mesh.point_data["displacement"], dtype=float)
    if disp.shape != (n, 3) or not np.isfinite(disp).all():
        problems.append(f"displacement field of shape {disp.shape} or not finite")
    if not np.isfinite(mesh.points).all():
        problems.append("coordinates not finite")
    for p in problems:
        print(f"{vtu}: {p}", file=sys.stderr)
    if not problems:
        print(
            f"{vtu}: {n} points, cells {cells}, max_shear maximum {peak:.6e} Pa = the report's"
        )
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
