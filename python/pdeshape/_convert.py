"""Conversions of a design's mesh to trimesh and pyvista objects (optional packages)."""

from __future__ import annotations

from typing import Any


def to_trimesh(design: Any, nu: int | None, nv: int | None, separate_patches: bool) -> Any:
    try:
        import trimesh
    except ImportError as e:
        raise ImportError("Design.to_trimesh needs the trimesh package (pip install trimesh)") from e
    m = design.mesh(nu, nv, separate_patches)
    return trimesh.Trimesh(
        vertices=m["vertices"].astype("float64"),
        faces=m["faces"].astype("int64"),
        vertex_normals=m["normals"].astype("float64"),
        process=False,
    )


def to_pyvista(design: Any, nu: int | None, nv: int | None, separate_patches: bool) -> Any:
    try:
        import numpy as np
        import pyvista
    except ImportError as e:
        raise ImportError("Design.to_pyvista needs the pyvista package (pip install pyvista)") from e
    m = design.mesh(nu, nv, separate_patches)
    faces = m["faces"].astype("int64")
    cells = np.hstack([np.full((len(faces), 1), 3, dtype="int64"), faces]).ravel()
    poly = pyvista.PolyData(m["vertices"].astype("float64"), cells)
    poly.point_data["Normals"] = m["normals"]
    return poly
