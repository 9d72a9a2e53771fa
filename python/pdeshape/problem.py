"""A design with an ``[optimize]`` problem given from Python (what :mod:`pdeshape.optuna` and
:mod:`pdeshape.openmdao` take besides a design file's own ``[optimize]``)."""

from __future__ import annotations

import tomllib
from typing import Any, Mapping, Sequence

from ._pdeshape import Design, DesignError

__all__ = ["problem_design"]


def problem_design(
    design: Design,
    parameters: Mapping[str, Sequence[float] | None],
    objective: str,
    constraints: Sequence[Mapping[str, Any]] = (),
    **options: Any,
) -> Design:
    """A copy of ``design`` whose ``[optimize]`` section is the given problem.

    ``parameters``: ``{name: (min, max)}`` or ``{name: (min, max, initial)}``, names in the
    book's notation (``d1Tx``, ``a``, …) or of the design's ``[[parameters]]`` entries (whose
    bounds may be ``None``: the entry's own). ``objective``: a formula over the measures
    (``area``, ``volume``, ``bending``, ``willmore``, ``helfrich``, ``nu``, …; the variables of
    ``docs/optimize.md``). ``constraints``: tables as in ``[optimize] constraints`` (``expr`` and
    ``equal``, or ``min`` and/or ``max``; ``weight``). ``options``: other keys of
    ``[optimize]`` (``quadrature_u``, ``quadrature_v``, ``spontaneous_curvature``, …). The
    library checks the whole problem as it checks a design file's; a refused problem raises
    :class:`pdeshape.DesignError` naming the key.
    """
    table = tomllib.loads(design.text)
    entries = []
    for name, bounds in parameters.items():
        entry: dict[str, Any] = {"name": str(name)}
        if bounds is not None:
            b = [float(x) for x in bounds]
            if len(b) not in (2, 3):
                raise DesignError(f"parameters['{name}']: give (min, max) or (min, max, initial)")
            entry["min"], entry["max"] = b[0], b[1]
            if len(b) == 3:
                entry["initial"] = b[2]
        entries.append(entry)
    table["optimize"] = {
        **options,
        "objective": str(objective),
        "parameters": entries,
        "constraints": [dict(c) for c in constraints],
    }
    out = Design.from_dict(table, design.file)
    out.evaluate_problem()  # the problem checked here, not in the first trial
    return out
