"""Geometric design with elliptic PDEs (the Bloor–Wilson method), from Python.

A :class:`Design` is read from a TOML design file (the format of ``docs/design-file.md``), a TOML
string or a dict; it solves with the Rust library (the GIL released), and returns NumPy arrays::

    import pdeshape
    cup = pdeshape.Design.load("examples/cup.toml")
    t = cup.tessellate(64, 128)          # t["vertices"]: (n, 3) float64, the CLI's CSV rows
    cup.analysis()["total"]["volume"]    # the numbers of `pdeshape analyze --json`
    wider = cup.with_params({"bellyDx": 1.2, "bellyDy": 1.2})
    wider.write("wider.obj")             # as `pdeshape surface wider.toml -o wider.obj`

Every error is a :class:`DesignError` (a ``ValueError``) with the CLI's located message
(``file:line:col: place: message``). :func:`fit` fits PDE patches to a triangle mesh.
:mod:`pdeshape.sweep` maps designs over parameter tables, lists of designs or lists of meshes on
a ``dask.distributed`` client.
"""

from __future__ import annotations

import os
from typing import Any

from ._pdeshape import Design, DesignError, fill_mesh, fit_mesh, version

__all__ = ["Design", "DesignError", "fill", "fit", "version", "__version__"]

#: The package's version (the library's: ``pdeshape.version()``).
__version__: str = version()

#: The mesh file extensions :func:`fit` reads.
MESH_EXTENSIONS = (".obj", ".stl", ".ply")


def fit(
    mesh: str | os.PathLike[str] | bytes,
    tolerance: float | None = None,
    sections: int | None = None,
    name: str | None = None,
    mode: str = "auto",
    best_effort: bool = False,
) -> tuple[Design, dict[str, Any]]:
    """Fits PDE patches to a triangle mesh, as ``pdeshape fit MESH -o design.toml --json
    report.json`` does (with ``--tolerance``, ``--sections``, ``--mode`` and ``--best-effort``).

    ``mesh``: the path of an OBJ, STL, PLY, OFF or glTF file (``.glb``, or ``.gltf`` with its
    buffers as data URIs), or its bytes with ``name`` a file name whose extension gives the
    format; the units a file states (glTF: metres) are the design's ``units``. ``tolerance``: the largest two-sided Hausdorff distance between
    the mesh and the fit, relative to the mesh's bounding-box diagonal (default 0.02; the tube
    and sheet modes then refine their sections to 0.002). ``sections``: a fixed number of
    patches instead of the adaptive choice. ``mode``: ``"auto"`` (tube for a closed body, sheet
    for an open one, the general mode — n-sided patches over a layout of the mesh, G1 across
    its edges — where those refuse the mesh or miss the tolerance), ``"tube"``, ``"sheet"`` or
    ``"general"``. ``best_effort``: return a fit that misses the tolerance instead of raising.

    Returns ``(design, report)``: the fitted :class:`Design` (its ``text`` is the file ``-o``
    writes) and the ``--json`` report as a dict (``mode``, ``patches``, ``measures`` with the
    two-sided distances, ``missed``, ``fallback``, …; without the timings). A mesh that cannot
    be read or fitted, or a fit that misses the tolerance, raises :class:`DesignError` naming
    the file (and the farthest point, for a miss).
    """
    data, name = _mesh_bytes(mesh, name)
    return fit_mesh(data, name, tolerance, sections, mode, best_effort)


def _mesh_bytes(mesh: Any, name: str | None) -> tuple[bytes, str]:
    """The bytes of a mesh given as a path or as bytes, and the file name its format comes
    from."""
    if isinstance(mesh, (bytes, bytearray, memoryview)):
        if name is None:
            raise DesignError("name: a file name (.obj, .stl or .ply) is needed with mesh bytes")
        return bytes(mesh), name
    try:
        with open(mesh, "rb") as f:
            data = f.read()
    except OSError as e:
        raise DesignError(f"{os.fspath(mesh)}: cannot read: {e.strerror or e}") from None
    return data, os.fspath(mesh) if name is None else name


def fill(
    mesh: str | os.PathLike[str] | bytes | tuple[Any, Any],
    continuity: str = "g1",
    largest: int | None = None,
    max_boundary: int | None = None,
    grading: float = 0.1,
    name: str | None = None,
) -> tuple[dict[str, Any], Design]:
    """Fills the holes of a triangle mesh with PDE patches, as ``pdeshape fill MESH -o OUT
    --design D.toml`` does.

    ``mesh``: the path of an OBJ, STL, PLY or OFF file, its bytes with ``name`` a file name whose
    extension gives the format, or a pair ``(positions, triangles)`` of arrays (n × 3 floats,
    m × 3 vertex indices from 0). ``continuity``: ``"g1"`` (tangent to the mesh), ``"g2"`` or
    ``"g0"``; ``largest``: only the K longest holes; ``max_boundary``: only the holes of at most
    N boundary vertices; ``grading``: how fast the fill's edges grow inwards (0 to 1).

    Returns ``(filled, design)``: ``filled`` a dict with ``vertices`` and ``faces`` (numpy
    arrays: the mesh's, then the fill's), ``mesh_faces``, ``open_edges`` (0: watertight),
    ``holes_found`` and ``holes`` (one dict per filled hole: ``boundary_vertices``,
    ``triangles_added``, ``g1_angle``, ``normal_jump``, ``pieces``, ``chord_g1_angle``, …);
    ``design`` the fill's patches as a :class:`Design` (one ``[[disk]]`` table each). A mesh
    that cannot be read or filled raises :class:`DesignError` naming it.
    """
    if isinstance(mesh, tuple):
        if len(mesh) != 2:
            raise DesignError("mesh: a pair (positions, triangles)")
        import numpy as np

        try:
            p = np.asarray(mesh[0], dtype=np.float64)
            t = np.asarray(mesh[1])
        except (TypeError, ValueError) as e:
            raise DesignError(f"mesh: not arrays of numbers: {e}") from None
        if p.ndim != 2 or p.shape[1] != 3 or t.ndim != 2 or t.shape[1] != 3:
            raise DesignError("mesh: positions and triangles must be n × 3 and m × 3 arrays")
        if t.size and not np.issubdtype(t.dtype, np.integer):
            raise DesignError("mesh: triangles must be integer vertex indices")
        out = fill_mesh(
            None,
            name or "<mesh>",
            p.tolist(),
            t.astype(np.int64).tolist(),
            continuity,
            largest,
            max_boundary,
            grading,
        )
        label = name or "<mesh>"
    else:
        data, name = _mesh_bytes(mesh, name)
        out = fill_mesh(data, name, None, None, continuity, largest, max_boundary, grading)
        label = name
    design = Design.from_toml(out.pop("design"), f"<fill of {label}>")
    return out, design
