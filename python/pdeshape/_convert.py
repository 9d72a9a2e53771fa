"""Conversions of a design's mesh to trimesh and pyvista objects (optional packages).

Both carry the surface each triangle comes from (``patch``, an index into the metadata's
``patches``), the design's metadata (``title``, ``units``, ``file``, ``patches``, the parameter
values set by ``with_params``) and, for the unwelded mesh (``welded=False``: each surface's grid
as sampled, the vertices of :meth:`Design.tessellate`), the ``(u, v)`` of every vertex. The
welded mesh (the default: what the CLI writes) has no ``(u, v)``: a welded vertex has several.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _mesh(design: Any, nu: int | None, nv: int | None, separate_patches: bool, welded: bool) -> dict[str, Any]:
    """Vertices, faces, normals, per-face patch index, per-vertex uv (or None) and metadata."""
    if welded:
        m = design.mesh(nu, nv, separate_patches)
        names = [name for name, _, _ in m["parts"]]
        patch = np.zeros(len(m["faces"]), dtype=np.int64)
        for k, (_, start, end) in enumerate(m["parts"]):
            patch[start:end] = k
        uv = m["uv"].astype("float64") if len(m["uv"]) == len(m["vertices"]) and len(m["uv"]) else None
        out = {"vertices": m["vertices"].astype("float64"), "faces": m["faces"].astype("int64"),
               "normals": m["normals"].astype("float64"), "patch": patch, "uv": uv}
    else:
        t = design.tessellate(nu, nv)
        names = list(design.patches)
        faces = t["faces"].astype("int64")
        out = {"vertices": t["vertices"], "faces": faces, "normals": t["normals"],
               "patch": t["patch"].astype("int64")[faces[:, 0]] if len(faces) else np.zeros(0, dtype=np.int64),
               "uv": t["uv"]}
    out["metadata"] = {
        "title": design.title,
        "units": design.units,
        "file": design.file,
        "patches": names,
        "parameters": design.params(),
    }
    return out


def to_trimesh(design: Any, nu: int | None, nv: int | None, separate_patches: bool, welded: bool = True) -> Any:
    try:
        import trimesh
    except ImportError as e:
        raise ImportError("Design.to_trimesh needs the trimesh package (pip install trimesh)") from e
    m = _mesh(design, nu, nv, separate_patches, welded)
    tm = trimesh.Trimesh(
        vertices=m["vertices"],
        faces=m["faces"],
        vertex_normals=m["normals"],
        face_attributes={"patch": m["patch"]},
        metadata=dict(m["metadata"]),
        process=False,
    )
    if m["uv"] is not None:
        tm.vertex_attributes["uv"] = m["uv"]
        tm.visual = trimesh.visual.TextureVisuals(uv=m["uv"])
    return tm


def to_pyvista(design: Any, nu: int | None, nv: int | None, separate_patches: bool, welded: bool = True) -> Any:
    try:
        import pyvista
    except ImportError as e:
        raise ImportError("Design.to_pyvista needs the pyvista package (pip install pyvista)") from e
    m = _mesh(design, nu, nv, separate_patches, welded)
    faces = m["faces"]
    cells = np.hstack([np.full((len(faces), 1), 3, dtype="int64"), faces]).ravel()
    poly = pyvista.PolyData(m["vertices"], cells)
    poly.point_data["Normals"] = m["normals"]
    poly.cell_data["patch"] = m["patch"]
    if m["uv"] is not None:
        poly.point_data["uv"] = m["uv"]
        poly.point_data.active_texture_coordinates = m["uv"]
    meta = m["metadata"]

    # VTK's strings are ASCII: other characters (the title's "§") as backslash escapes.
    def ascii(text: str) -> str:
        return text.encode("ascii", "backslashreplace").decode("ascii")

    poly.field_data["patches"] = np.array([ascii(n) for n in meta["patches"]])
    for key in ("title", "units", "file"):
        if meta[key] is not None:
            poly.field_data[key] = np.array([ascii(meta[key])])
    return poly
