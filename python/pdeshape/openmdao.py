"""An OpenMDAO component over a design: its parameters in, its measures (and its ``[optimize]``
objective and constraints) out, with analytic partial derivatives from
:meth:`pdeshape.Design.gradient`.

:class:`DesignComponent` is an ``om.ExplicitComponent``: one scalar input per parameter (the
``[optimize]`` parameters of the design, or those given here with bounds), one scalar output per
requested measure (the variables of the objective formulas: ``area``, ``volume``, ``mean``,
``mean_sq``, ``gauss``, ``bending``, ``willmore``, ``helfrich``, ``nu``, ``c0``), plus
``objective`` (the objective formula, without penalties) and ``constraint_0``,
``constraint_1``, … (each constraint's formula), so a driver handles the constraints itself.
``compute`` is one evaluation of the library (one solve, the integrals at the problem's
quadrature), ``compute_partials`` the library's sensitivities of the same numbers.
:func:`build_problem` wires one into an ``om.Problem`` with the design's bounds as design
variables, its objective and its constraints::

    import openmdao.api as om, pdeshape
    from pdeshape.openmdao import build_problem

    prob = build_problem(pdeshape.Design.load("examples/optimize_curvature.toml"))
    prob.driver = om.ScipyOptimizeDriver(optimizer="SLSQP", maxiter=30)
    prob.setup()
    prob.run_driver()
    prob.get_val("design.objective")
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import openmdao.api as om

from ._pdeshape import Design, DesignError
from .problem import problem_design

__all__ = ["DesignComponent", "build_problem", "MEASURES"]

#: The measures a component can output (the geometric variables of the objective formulas).
MEASURES = ("area", "volume", "mean", "mean_sq", "gauss", "bending", "willmore", "helfrich", "nu", "c0")


class DesignComponent(om.ExplicitComponent):
    """A design's parameters in, its measures, objective and constraints out (see the module).

    Options: ``design`` (a :class:`pdeshape.Design`), ``parameters`` (``None``: the design's
    ``[optimize]`` parameters; else ``{name: (min, max)}`` as :func:`pdeshape.problem.problem_design`
    takes them, with ``objective`` a formula and ``constraints`` tables), ``measures`` (names of
    :data:`MEASURES` to output, default area, volume and bending).
    """

    def initialize(self) -> None:
        self.options.declare("design", types=Design, desc="the design")
        self.options.declare("parameters", default=None, allow_none=True, desc="{name: (min, max)}")
        self.options.declare("objective", default=None, allow_none=True, desc="objective formula")
        self.options.declare("constraints", default=(), desc="constraint tables")
        self.options.declare("measures", default=("area", "volume", "bending"), desc="measures to output")

    def _problem(self) -> Design:
        design = self.options["design"]
        if self.options["parameters"] is not None or self.options["objective"] is not None:
            if self.options["parameters"] is None or self.options["objective"] is None:
                raise DesignError("parameters, objective: give both (or neither, for the design's [optimize])")
            design = problem_design(
                design, self.options["parameters"], self.options["objective"], self.options["constraints"]
            )
        return design

    def setup(self) -> None:
        self._design = self._problem()
        start = self._design.evaluate_problem()
        #: ``(name, min, max, start value)`` of each input.
        self.inputs_ = [
            (p["name"], float(p["min"]), float(p["max"]), float(p["value"]))
            for p in self._design.parameters()
            if p["source"] == "optimize"
        ]
        if not self.inputs_:
            raise DesignError("optimize: the design has no [optimize] parameters")
        bad = [m for m in self.options["measures"] if m not in MEASURES]
        if bad:
            raise DesignError(f"measures: unknown {bad} (known: {', '.join(MEASURES)})")
        #: The constraints' tables (``expr``, ``equal``, ``min``, ``max``).
        self.constraints_ = start["constraints"]
        for name, _, _, value in self.inputs_:
            self.add_input(name, val=value)
        for m in self.options["measures"]:
            self.add_output(m, val=start["measures"][m])
        self.add_output("objective", val=start["objective"])
        for i, c in enumerate(self.constraints_):
            self.add_output(f"constraint_{i}", val=c["value"], desc=c["expr"])
        self.declare_partials("*", "*", method="exact")
        self._cache: dict[tuple[float, ...], dict[str, Any]] = {}

    def _point(self, inputs: Any) -> dict[str, float]:
        return {name: float(inputs[name][0]) for name, _, _, _ in self.inputs_}

    def compute(self, inputs: Any, outputs: Any) -> None:
        r = self._design.evaluate_problem(self._point(inputs))
        for m in self.options["measures"]:
            outputs[m] = r["measures"][m]
        outputs["objective"] = r["objective"]
        for i, c in enumerate(r["constraints"]):
            outputs[f"constraint_{i}"] = c["value"]

    def compute_partials(self, inputs: Any, partials: Any) -> None:
        g = self._design.with_params(self._point(inputs)).gradient()
        names = g["names"]
        for m in self.options["measures"]:
            for k, name in enumerate(names):
                partials[m, name] = g["d_measures"][m][k]
        for k, name in enumerate(names):
            partials["objective", name] = g["d_objective"][k]
            for i, c in enumerate(g["constraints"]):
                partials[f"constraint_{i}", name] = c["gradient"][k]


def build_problem(
    design: Design,
    parameters: Mapping[str, Sequence[float] | None] | None = None,
    objective: str | None = None,
    constraints: Sequence[Mapping[str, Any]] = (),
    measures: Sequence[str] = ("area", "volume", "bending"),
    name: str = "design",
) -> om.Problem:
    """An ``om.Problem`` whose model is one :class:`DesignComponent` (``name``), each input a
    design variable within the parameter's bounds, ``objective`` the objective and each
    constraint a constraint (``equals`` its target, or ``lower``/``upper``). Set a driver, then
    ``setup()`` and ``run_driver()``."""
    prob = om.Problem()
    comp = DesignComponent(
        design=design,
        parameters=parameters,
        objective=objective,
        constraints=tuple(constraints),
        measures=tuple(measures),
    )
    prob.model.add_subsystem(name, comp)
    # the inputs, bounds and constraints are known once the component has read the design
    problem = comp._problem()
    for p in problem.parameters():
        if p["source"] == "optimize":
            prob.model.add_design_var(f"{name}.{p['name']}", lower=float(p["min"]), upper=float(p["max"]))
    prob.model.add_objective(f"{name}.objective")
    for i, c in enumerate(problem.evaluate_problem()["constraints"]):
        if c["equal"] is not None:
            prob.model.add_constraint(f"{name}.constraint_{i}", equals=c["equal"])
        else:
            prob.model.add_constraint(f"{name}.constraint_{i}", lower=c["min"], upper=c["max"])
    return prob
