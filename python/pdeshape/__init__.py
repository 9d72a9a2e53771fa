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

from ._pdeshape import Design, DesignError, fit_mesh, version

__all__ = ["Design", "DesignError", "fit", "version", "__version__"]

#: The package's version (the library's: ``pdeshape.version()``).
__version__: str = version()

#: The mesh file extensions :func:`fit` reads.
MESH_EXTENSIONS = (".obj", ".stl", ".ply")


def fit(
    mesh: str | os.PathLike[str] | bytes,
    tolerance: float = 2e-3,
    sections: int | None = None,
    name: str | None = None,
) -> tuple[Design, dict[str, Any]]:
    """Fits PDE patches to a triangle mesh (closed: tube mode; open: sheet mode), as ``pdeshape fit MESH -o design.toml --json
    report.json`` does.

    ``mesh``: the path of an OBJ, STL or PLY file, or its bytes with ``name`` a file name whose
    extension gives the format. ``tolerance``: the largest distance between the mesh's sections
    and the fit, relative to the mesh's bounding-box diagonal. ``sections``: a fixed number of
    patches instead of the adaptive choice.

    Returns ``(design, report)``: the fitted :class:`Design` (its ``text`` is the file ``-o``
    writes) and the ``--json`` report as a dict (``patches``, ``modes``, ``measures`` with the
    two-sided distances, …; without the timings). A mesh that cannot be read or fitted raises
    :class:`DesignError` naming the file.
    """
    if isinstance(mesh, (bytes, bytearray, memoryview)):
        if name is None:
            raise DesignError("name: a file name (.obj, .stl or .ply) is needed with mesh bytes")
        data = bytes(mesh)
    else:
        name = os.fspath(mesh) if name is None else name
        try:
            with open(mesh, "rb") as f:
                data = f.read()
        except OSError as e:
            raise DesignError(f"{os.fspath(mesh)}: cannot read: {e.strerror or e}") from None
    return fit_mesh(data, name, tolerance, sections)
