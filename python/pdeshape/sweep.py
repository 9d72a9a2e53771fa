"""Design sweeps and annealing restarts, serially or on a ``dask.distributed`` cluster.

:func:`sweep` maps one design over a table of parameter values (or runs a list of designs, design
files, TOML texts or meshes, each mesh fitted first) and returns a table of measures, one row per
variant, in the input's order::

    from dask.distributed import Client, LocalCluster
    import numpy as np, pdeshape
    from pdeshape.sweep import sweep, grid

    cup = pdeshape.Design.load("examples/cup.toml")
    table = grid(bellyDx=np.linspace(0.8, 1.2, 100), rimTz=np.linspace(-0.3, 0.3, 100))
    with Client(LocalCluster(n_workers=2, threads_per_worker=1)) as client:
        df = sweep(cup, table, measures=["area", "volume"], client=client)

Rows are batched into chunks (one Dask task each), so ten thousand small solves cost a few hundred
tasks, not ten thousand. A variant that fails (a parameter value the design refuses, a surface
that is not finite) is a row with its error message in ``error`` and NaN measures; it is never
dropped. A worker that dies loses no rows: its tasks are run again elsewhere (``retries``, and
Dask's own rescheduling of the tasks of a lost worker). Without a client the same chunks run in
this process, so a serial run and a cluster run give identical tables.

:func:`anneal` runs independent annealing chains of a design's ``[optimize]`` problem (one task
per chain, seeds ``seed, seed + 1, …``) and keeps the best; :func:`evaluate_problem` evaluates
that problem at a list of points (what :mod:`pdeshape.optuna` sends to the cluster).
"""

from __future__ import annotations

import itertools
import math
import os
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ._pdeshape import Design, DesignError, fit_mesh
from . import MESH_EXTENSIONS

__all__ = [
    "sweep",
    "grid",
    "anneal",
    "evaluate_problem",
    "MEASURES",
    "FIT_COLUMNS",
    "run_chunk",
    "run_problem_chunk",
]

#: The measures a sweep can report: the totals of :meth:`Design.analysis` (the keys of
#: ``pdeshape analyze --json``'s ``total``).
MEASURES = (
    "area",
    "volume",
    "mean_integral",
    "mean_sq_integral",
    "gauss_integral",
    "bending_energy",
    "willmore",
    "reduced_volume",
    "equivalent_radius",
)


def grid(**axes: Iterable[float]) -> dict[str, np.ndarray]:
    """The full grid of the given axes as columns (the last axis varies fastest)::

    grid(a=[1, 2], b=[0, 1, 2])  # 6 rows
    """
    names = list(axes)
    values = [np.asarray(list(v), dtype=float) for v in axes.values()]
    mesh = np.meshgrid(*values, indexing="ij")
    return {n: m.ravel() for n, m in zip(names, mesh)}


def _columns(params: Any) -> tuple[list[str], np.ndarray]:
    """Parameter names and an ``(n, k)`` float64 array of values from a DataFrame, a dict of
    columns or a list of dicts."""
    if hasattr(params, "to_dict") and hasattr(params, "columns"):  # a pandas DataFrame
        names = [str(c) for c in params.columns]
        values = np.asarray(params.to_numpy(dtype=float), dtype=float).reshape(len(params), len(names))
        return names, values
    if isinstance(params, Mapping):
        names = [str(k) for k in params]
        cols = [np.asarray(params[k], dtype=float).ravel() for k in params]
        lengths = {len(c) for c in cols}
        if len(lengths) > 1:
            raise DesignError(f"params: the columns have different lengths {sorted(lengths)}")
        n = lengths.pop() if lengths else 0
        return names, (np.column_stack(cols) if cols else np.zeros((n, 0)))
    rows = list(params)
    names = []
    for r in rows:
        for k in r:
            if k not in names:
                names.append(str(k))
    values = np.full((len(rows), len(names)), np.nan)
    for i, r in enumerate(rows):
        for k, v in r.items():
            values[i, names.index(str(k))] = float(v)
    return names, values


def _measure_row(d: Design, measures: Sequence[str], tolerance: Any) -> tuple[list[float], str | None]:
    try:
        if isinstance(tolerance, tuple):
            total = d.analysis(quadrature=tolerance)["total"]
        else:
            total = d.analysis(tolerance)["total"]
        return [float(total[m]) for m in measures], None
    except DesignError as e:
        return [math.nan] * len(measures), str(e)


def run_chunk(
    text: str,
    file: str,
    base_params: Mapping[str, float],
    names: Sequence[str],
    values: np.ndarray,
    measures: Sequence[str],
    tolerance: float | None,
) -> tuple[np.ndarray, list[str | None]]:
    """Measures the design (TOML ``text`` with ``base_params`` set) at each row of ``values``:
    the work of one task. Returns the ``(rows, len(measures))`` measures and one error (or
    None) per row."""
    base = Design.from_toml(text, file)
    out = np.full((len(values), len(measures)), np.nan)
    errors: list[str | None] = []
    for i, row in enumerate(values):
        try:
            row_params = dict(base_params)
            row_params.update((n, float(x)) for n, x in zip(names, row) if not math.isnan(x))
            d = base.with_params(row_params)
        except DesignError as e:
            errors.append(str(e))
            continue
        out[i], err = _measure_row(d, measures, tolerance)
        errors.append(err)
    return out, errors


#: The columns a sweep over meshes adds: from each fit's report (``pdeshape fit --json``).
FIT_COLUMNS = ("fit_patches", "fit_hausdorff_relative", "fit_rms_relative")


def _fit_row(report: Mapping[str, Any]) -> list[float]:
    m = report["measures"]
    return [float(report["patches"]), float(m["hausdorff_relative"]), float(m["rms_relative"])]


def _run_designs(
    designs: Sequence[tuple],
    measures: Sequence[str],
    tolerance: Any,
    fit_options: tuple[float | None, int | None] = (None, None),
) -> tuple[np.ndarray, list[str | None], np.ndarray]:
    """The work of one task of a sweep over a list: each item is ``("design", text, file,
    params)``, ``("mesh", bytes, name)`` (fitted first) or ``("error", message)`` (a row that
    failed before it was sent). Returns the measures, the errors and the fit columns."""
    out = np.full((len(designs), len(measures)), np.nan)
    fits = np.full((len(designs), len(FIT_COLUMNS)), np.nan)
    errors: list[str | None] = []
    for i, item in enumerate(designs):
        kind = item[0]
        if kind == "error":
            errors.append(item[1])
            continue
        try:
            if kind == "mesh":
                d, report = fit_mesh(item[1], item[2], *fit_options, "auto", True)
                fits[i] = _fit_row(report)
            else:
                _, text, file, params = item
                d = Design.from_toml(text, file)
                if params:
                    d = d.with_params(params)
        except DesignError as e:
            errors.append(str(e))
            continue
        out[i], err = _measure_row(d, measures, tolerance)
        errors.append(err)
    return out, errors, fits


def _item(x: Any) -> tuple[tuple, str, bool]:
    """One input of a sweep over a list, as a task carries it (read here, so the workers need no
    shared file system): the item, its name, and whether it is a mesh."""
    if isinstance(x, Design):
        return ("design", x.text, x.file, dict(x.params())), x.file, False
    if isinstance(x, str) and "\n" in x:
        return ("design", x, "<string>", {}), "<string>", False
    if isinstance(x, (str, os.PathLike)):
        path = os.fspath(x)
        if path.lower().endswith(MESH_EXTENSIONS):
            try:
                with open(path, "rb") as f:
                    return ("mesh", f.read(), path), path, True
            except OSError as e:
                return ("error", f"{path}: cannot read: {e.strerror or e}"), path, True
        try:
            d = Design.load(path)
        except DesignError as e:
            return ("error", str(e)), path, False
        return ("design", d.text, d.file, {}), path, False
    raise DesignError(
        f"design: a list item must be a Design, a path (.toml, .obj, .stl, .ply) or TOML text "
        f"(got {type(x).__name__})"
    )


def _chunk_size(n: int, client: Any, chunk_size: int | None) -> int:
    if chunk_size is not None:
        if chunk_size < 1:
            raise DesignError(f"chunk_size: must be at least 1 (got {chunk_size})")
        return chunk_size
    if client is None:
        return max(n, 1)
    # About eight tasks per worker thread: enough to balance load and to lose little when a
    # worker dies, few enough that the scheduler's ~1 ms per task does not matter.
    threads = sum(client.nthreads().values()) or 1
    return max(1, math.ceil(n / (8 * threads)))


def _table(columns: dict[str, Any], as_pandas: bool | None):
    if as_pandas is not False:
        try:
            import pandas as pd
        except ImportError:
            if as_pandas:
                raise
        else:
            # `error` holds None or a message (object dtype: pandas 3 would make None a NaN)
            errors = pd.Series(columns["error"], dtype=object)
            df = pd.DataFrame({k: v for k, v in columns.items() if k != "error"})
            df["error"] = errors
            return df
    return {k: np.asarray(v) if k != "error" else np.asarray(v, dtype=object) for k, v in columns.items()}


def sweep(
    design: Design | Sequence[Design],
    params: Any = None,
    measures: Sequence[str] = ("area", "volume", "bending_energy", "willmore"),
    client: Any = None,
    chunk_size: int | None = None,
    retries: int = 3,
    tolerance: float | None = None,
    as_pandas: bool | None = None,
    quadrature: tuple[int, int] | None = None,
    fit_tolerance: float | None = None,
    fit_sections: int | None = None,
):
    """Measures every variant of a design, or every design or mesh of a list.

    ``design``: a :class:`Design` with ``params`` a table of parameter values (a pandas
    DataFrame, a dict of equal-length columns, or a list of dicts; names in the book's notation
    as in :meth:`Design.with_params`), or a list (``params`` None) whose items are designs,
    design files (``.toml``), TOML texts (a ``str`` with a line break) or closed triangle meshes
    (``.obj``, ``.stl``, ``.ply``), each mesh fitted by :func:`pdeshape.fit` with
    ``fit_tolerance`` and ``fit_sections`` and the fitted design measured. Files are read here
    and their contents sent with the tasks (the workers need no shared file system).
    ``measures``: names from :data:`MEASURES`. ``client``: a ``dask.distributed.Client`` (None
    runs serially here). ``chunk_size``: rows per task (default: about eight tasks per worker
    thread). ``retries``: how often Dask re-runs a task whose worker failed. ``tolerance``: the
    adaptive quadrature's (default 1e-11), or ``quadrature=(qu, qv)`` for one fixed rule (see
    :meth:`Design.analysis`).

    Returns a pandas DataFrame (if pandas is installed and ``as_pandas`` is not False; else a
    dict of NumPy arrays) with the parameter columns, the measures and ``error`` (None, or the
    located message of the variant's failure), one row per variant in the input's order. A
    sweep over a list has the columns ``design`` (the position in the list) and ``input`` (the
    design's file, the path, or ``<string>``) instead of parameter columns, and, when the list
    holds a mesh, the :data:`FIT_COLUMNS` of each fit (NaN for designs).
    """
    measures = list(measures)
    if quadrature is not None:
        if tolerance is not None:
            raise DesignError("tolerance, quadrature: give one of them (adaptive or fixed quadrature)")
        tolerance = tuple(int(q) for q in quadrature)  # type: ignore[assignment]
    bad = [m for m in measures if m not in MEASURES]
    if bad:
        raise DesignError(f"measures: unknown {bad} (known: {', '.join(MEASURES)})")
    if isinstance(design, Design):
        if params is None:
            raise DesignError("params: a table of parameter values is needed with one design")
        names, values = _columns(params)
        n = len(values)
        size = _chunk_size(n, client, chunk_size)
        chunks = [values[i : i + size] for i in range(0, n, size)]
        base = dict(design.params())
        args = [(design.text, design.file, base, names, c, measures, tolerance) for c in chunks]
        results = _run(run_chunk, args, client, retries)
        columns: dict[str, Any] = {name: values[:, k] for k, name in enumerate(names)}
    else:
        if params is not None:
            raise DesignError("params: give either one design and a table, or a list of designs")
        if isinstance(design, (str, os.PathLike)):
            raise DesignError("design: a Design or a list (of designs, paths or TOML texts)")
        resolved = [_item(x) for x in design]
        items = [r[0] for r in resolved]
        n = len(items)
        size = _chunk_size(n, client, chunk_size)
        fit_options = (fit_tolerance, fit_sections)
        args = [(items[i : i + size], measures, tolerance, fit_options) for i in range(0, n, size)]
        results = _run(_run_designs, args, client, retries)
        columns = {"design": np.arange(n), "input": np.asarray([r[1] for r in resolved], dtype=object)}
        if any(r[2] for r in resolved):
            fits = np.concatenate([r[2] for r in results])
            for k, c in enumerate(FIT_COLUMNS):
                columns[c] = fits[:, k]
    out = np.concatenate([r[0] for r in results]) if results else np.zeros((0, len(measures)))
    errors = list(itertools.chain.from_iterable(r[1] for r in results))
    for k, m in enumerate(measures):
        columns[m] = out[:, k]
    columns["error"] = errors
    return _table(columns, as_pandas)


def _run(fn, args: list[tuple], client: Any, retries: int) -> list:
    if client is None:
        return [fn(*a) for a in args]
    futures = [client.submit(fn, *a, retries=retries, pure=False) for a in args]
    return client.gather(futures)


def _chain(text: str, file: str, seed: int, evaluations: int | None, polish: int | None) -> dict:
    d = Design.from_toml(text, file)
    r = d.optimize(seed=seed, evaluations=evaluations, chains=1, polish=polish)
    r["seed"] = seed
    return r


def anneal(
    design: Design,
    chains: int = 4,
    seed: int = 1,
    evaluations: int | None = None,
    polish: int | None = None,
    client: Any = None,
    retries: int = 3,
) -> dict:
    """Runs ``chains`` independent annealing chains of the design's ``[optimize]`` problem (seeds
    ``seed … seed + chains − 1``, ``evaluations`` each; default the file's), one task each on
    ``client`` (or here, serially), and keeps the best.

    Returns a dict: ``best`` (the best chain's ``x``, ``value``, ``objective``, ``penalty``,
    ``seed``) and ``chains`` (every chain's result, in seed order).
    """
    if chains < 1:
        raise DesignError(f"chains: must be at least 1 (got {chains})")
    args = [(design.text, design.file, seed + k, evaluations, polish) for k in range(chains)]
    results = _run(_chain, args, client, retries)
    best = min(results, key=lambda r: (r["value"], r["seed"]))
    return {"best": best, "chains": results}


def run_problem_chunk(
    text: str, file: str, base_params: Mapping[str, float], points: Sequence[Mapping[str, float]]
) -> list[dict]:
    """Evaluates the ``[optimize]`` problem of the design (TOML ``text`` with ``base_params``
    set) at each point: the work of one task. Returns one dict per point,
    :meth:`Design.evaluate_problem`'s, or ``{"error": message}`` where it fails."""
    try:
        base = Design.from_toml(text, file)
        if base_params:
            base = base.with_params(dict(base_params))
    except DesignError as e:
        return [{"error": str(e)} for _ in points]
    out: list[dict] = []
    for point in points:
        try:
            out.append(base.evaluate_problem(dict(point)))
        except DesignError as e:
            out.append({"error": str(e)})
    return out


def evaluate_problem(
    design: Design,
    points: Sequence[Mapping[str, float]],
    client: Any = None,
    chunk_size: int | None = None,
    retries: int = 3,
) -> list[dict]:
    """The design's ``[optimize]`` problem evaluated at each point (``{name: value}`` of its
    parameters; the others at the values ``with_params`` set, else their initial ones), in
    chunks of ``chunk_size`` points per task on ``client`` (or here, serially).

    Returns one dict per point in the input's order: :meth:`Design.evaluate_problem`'s (``x``,
    ``value``, ``objective``, ``penalty``, ``feasible``, ``measures``, ``constraints``), or
    ``{"error": message}`` for a point the design refuses or cannot be solved at.
    """
    rows = [dict(p) for p in points]
    size = _chunk_size(len(rows), client, chunk_size)
    base = dict(design.params())
    args = [(design.text, design.file, base, rows[i : i + size]) for i in range(0, len(rows), size)]
    return list(itertools.chain.from_iterable(_run(run_problem_chunk, args, client, retries)))
