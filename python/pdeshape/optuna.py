"""Optuna studies over a design's parameters, serially or on a ``dask.distributed`` cluster.

:class:`Objective` turns a design's ``[optimize]`` problem (or parameter names with bounds and an
objective formula given here) into an Optuna objective: one ``trial.suggest_float`` per
parameter within its bounds, the value the library's own evaluation
(:meth:`pdeshape.Design.evaluate_problem`: one solve, the integrals at the problem's quadrature,
the objective formula plus the constraints' quadratic penalties, the number ``pdeshape optimize``
minimises). :func:`run_study` runs a study with Optuna's ask-and-tell interface: batches of
trials asked in this process (the study and its storage stay here), evaluated as tasks of
:func:`pdeshape.sweep.evaluate_problem` on the client's workers, told back::

    import optuna, pdeshape
    from dask.distributed import Client, LocalCluster
    from pdeshape.optuna import run_study

    design = pdeshape.Design.load("examples/optimize_curvature.toml")
    with Client(LocalCluster(n_workers=2, threads_per_worker=1)) as client:
        study = run_study(design, n_trials=200, client=client, seed=1)
    best = design.with_params(study.best_params)   # the best design, as a Design

Constraints: the value Optuna minimises carries them as penalties (the ``weight · violation²``
of the design's ``[optimize] constraints``), as annealing does. Each trial also records its
constraints as violations (``user_attrs["violations"]``, one per constraint, ``<= 0`` where it
holds as the library judges feasibility); :func:`constraints_func` returns them, so a sampler
built with ``constraints_func=constraints_func`` (TPE, NSGA-II, GP) prefers feasible designs.
:func:`run_study` builds its default sampler (TPE) that way when the problem has constraints.

A design that cannot be built at a trial's parameters is a failed trial (``TrialState.FAIL``,
its message in ``user_attrs["error"]``), never a crash of the study.
"""

from __future__ import annotations

import math
import tomllib
from typing import Any, Mapping, Sequence

import optuna

from . import sweep as _sweep
from ._pdeshape import EQUALITY_TOLERANCE, Design, DesignError
from .problem import problem_design

__all__ = ["Objective", "problem_design", "constraints_func", "violations", "run_study"]


def violations(result: Mapping[str, Any]) -> list[float]:
    """The constraints of an evaluation (:meth:`Design.evaluate_problem`'s dict) as Optuna's
    constraint values, one per constraint, ``<= 0`` where it holds: ``min − g`` or ``g − max``
    (the larger, for both), ``|g − target| − tol`` for an equality with the library's tolerance
    ``tol = EQUALITY_TOLERANCE · max(|target|, 1)``; ``inf`` where the formula is not a
    number."""
    out = []
    for c in result["constraints"]:
        g = c["value"]
        if not math.isfinite(g):
            out.append(math.inf)
        elif c["equal"] is not None:
            t = c["equal"]
            out.append(abs(g - t) - EQUALITY_TOLERANCE * max(abs(t), 1.0))
        else:
            parts = []
            if c["min"] is not None:
                parts.append(c["min"] - g)
            if c["max"] is not None:
                parts.append(g - c["max"])
            out.append(max(parts))
    return out


def constraints_func(trial: optuna.trial.FrozenTrial) -> list[float]:
    """The ``constraints_func`` of Optuna's samplers for studies of an :class:`Objective`: the
    trial's :func:`violations`."""
    return list(trial.user_attrs.get("violations", []))


class Objective:
    """An Optuna objective over a design's ``[optimize]`` problem.

    ``Objective(design)`` takes the parameters, bounds, objective and constraints of the
    design's ``[optimize]`` section; ``Objective(design, parameters, objective, constraints)``
    replaces them (see :func:`problem_design`). Calling it with a trial suggests every
    parameter (``trial.suggest_float(name, min, max)``), evaluates the design there and returns
    ``objective + penalty`` (or NaN, a failed trial, where the design fails), recording
    ``objective``, ``penalty``, ``feasible``, ``violations`` and the ``measures`` as the
    trial's user attributes.
    """

    def __init__(
        self,
        design: Design,
        parameters: Mapping[str, Sequence[float] | None] | None = None,
        objective: str | None = None,
        constraints: Sequence[Mapping[str, Any]] | None = None,
        **options: Any,
    ) -> None:
        if parameters is not None or objective is not None or constraints is not None or options:
            if parameters is None or objective is None:
                raise DesignError(
                    "parameters, objective: give both (or neither, for the design's [optimize])"
                )
            design = problem_design(design, parameters, objective, constraints or (), **options)
        self.design = design
        #: ``(name, min, max)`` of each parameter, in ``[optimize]``'s order.
        self.space: list[tuple[str, float, float]] = []
        #: The starting point: the values ``with_params`` set, else the initial values.
        self.start: dict[str, float] = {}
        for p in design.parameters():
            if p["source"] == "optimize":
                self.space.append((p["name"], float(p["min"]), float(p["max"])))
                self.start[p["name"]] = float(p["value"])
        if not self.space:
            raise DesignError(
                "optimize: the design has no [optimize] section (give parameters and an objective)"
            )
        #: Whether the problem has constraints.
        self.constrained = bool(tomllib.loads(design.text).get("optimize", {}).get("constraints"))

    def suggest(self, trial: optuna.trial.BaseTrial) -> dict[str, float]:
        """The trial's point: one ``suggest_float`` per parameter within its bounds."""
        return {name: trial.suggest_float(name, lo, hi) for name, lo, hi in self.space}

    def record(self, trial: optuna.trial.BaseTrial, result: Mapping[str, Any]) -> float:
        """Stores an evaluation on the trial (user attributes) and returns the value Optuna
        minimises: ``objective + penalty``, NaN for a design that failed."""
        if "error" in result:
            trial.set_user_attr("error", result["error"])
            return math.nan
        trial.set_user_attr("objective", result["objective"])
        trial.set_user_attr("penalty", result["penalty"])
        trial.set_user_attr("feasible", bool(result["feasible"]))
        trial.set_user_attr("violations", violations(result))
        trial.set_user_attr("measures", {k: v for k, v in result["measures"].items() if math.isfinite(v)})
        value = float(result["value"])
        return value if not math.isnan(value) else math.inf

    def evaluate(self, point: Mapping[str, float]) -> dict[str, Any]:
        """The design's problem at ``point`` (or ``{"error": message}``)."""
        try:
            return self.design.evaluate_problem(dict(point))
        except DesignError as e:
            return {"error": str(e)}

    def __call__(self, trial: optuna.trial.Trial) -> float:
        return self.record(trial, self.evaluate(self.suggest(trial)))


def run_study(
    design: Design | Objective,
    n_trials: int,
    client: Any = None,
    batch_size: int | None = None,
    study: optuna.Study | None = None,
    seed: int | None = None,
    start: bool = True,
    retries: int = 3,
) -> optuna.Study:
    """Runs ``n_trials`` trials of a study over the design's problem, ``batch_size`` at a time
    (default: one per worker thread of ``client``, else 1): each batch is asked of the study
    here (``study.ask()``), evaluated as tasks of :func:`pdeshape.sweep.evaluate_problem` (one
    trial per task) on ``client`` (or here, serially), and told back (``study.tell``) in the
    order asked.

    ``design``: a :class:`pdeshape.Design` with ``[optimize]`` or an :class:`Objective`.
    ``study``: a study to continue (its direction must be "minimize"); by default a new one in
    memory with a TPE sampler seeded by ``seed`` (with :func:`constraints_func` when the problem
    has constraints). ``start``: evaluate the starting point first (an enqueued trial), so the
    study's best is never worse than the start. Returns the study.
    """
    objective = design if isinstance(design, Objective) else Objective(design)
    if n_trials < 0:
        raise DesignError(f"n_trials: must not be negative (got {n_trials})")
    if study is None:
        sampler = optuna.samplers.TPESampler(
            seed=seed, constraints_func=constraints_func if objective.constrained else None
        )
        study = optuna.create_study(direction="minimize", sampler=sampler)
    elif study.direction != optuna.study.StudyDirection.MINIMIZE:
        raise DesignError("study: must minimise (direction='minimize')")
    if batch_size is None:
        batch_size = max(1, sum(client.nthreads().values())) if client is not None else 1
    if batch_size < 1:
        raise DesignError(f"batch_size: must be at least 1 (got {batch_size})")
    if start and n_trials > 0:
        study.enqueue_trial(objective.start)
    done = 0
    while done < n_trials:
        trials = [study.ask() for _ in range(min(batch_size, n_trials - done))]
        points = [objective.suggest(t) for t in trials]
        results = _sweep.evaluate_problem(objective.design, points, client=client, chunk_size=1, retries=retries)
        for trial, result in zip(trials, results):
            value = objective.record(trial, result)
            if math.isnan(value):
                study.tell(trial, state=optuna.trial.TrialState.FAIL)
            else:
                study.tell(trial, value)
        done += len(trials)
    return study
