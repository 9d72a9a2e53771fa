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
(``file:line:col: place: message``). :mod:`pdeshape.sweep` maps designs over parameter tables
on a ``dask.distributed`` client.
"""

from ._pdeshape import Design, DesignError, version

__all__ = ["Design", "DesignError", "version"]
