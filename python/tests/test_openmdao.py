"""pdeshape.openmdao: the component's analytic partials pass OpenMDAO's check_partials, and an
SLSQP run on §7.5's curvature design lowers its objective."""

from __future__ import annotations

import numpy as np
import openmdao.api as om
import pytest
from openmdao.utils.assert_utils import assert_check_partials

from conftest import EXAMPLES
from pdeshape import Design, DesignError
from pdeshape.openmdao import DesignComponent, build_problem

CURVATURE = EXAMPLES / "optimize_curvature.toml"


@pytest.fixture(autouse=True)
def openmdao_outputs(tmp_path, monkeypatch):
    """OpenMDAO's output folders (one per problem) under a temporary directory, no reports."""
    monkeypatch.setenv("OPENMDAO_WORKDIR", str(tmp_path))
    monkeypatch.setenv("OPENMDAO_REPORTS", "0")


def interior(design: Design) -> dict[str, float]:
    """A point a fifth of the way from the start to the middle of the bounds (the start has
    parameters on their bounds, where a finite-difference step would leave them)."""
    return {
        p["name"]: p["value"] + 0.2 * ((p["min"] + p["max"]) / 2 - p["value"])
        for p in design.parameters()
        if p["source"] == "optimize"
    }


@pytest.mark.parametrize("example", ["optimize_curvature.toml", "vesicle.toml"])
def test_check_partials(example):
    base = Design.load(EXAMPLES / example)
    prob = om.Problem()
    comp = DesignComponent(design=base.with_params(interior(base)), measures=("area", "volume", "bending", "nu"))
    prob.model.add_subsystem("design", comp)
    prob.setup()
    prob.run_model()
    names = [p["name"] for p in base.parameters() if p["source"] == "optimize"]
    # the outputs are the library's numbers at the inputs
    r = base.evaluate_problem(interior(base))
    assert prob.get_val("design.objective")[0] == r["objective"]
    assert prob.get_val("design.nu")[0] == r["measures"]["nu"]
    for i, c in enumerate(r["constraints"]):
        assert prob.get_val(f"design.constraint_{i}")[0] == c["value"]
    data = prob.check_partials(method="fd", form="central", out_stream=None)
    pairs = data["design"]
    outputs = 5 + len(r["constraints"])
    assert len(pairs) == outputs * len(names)
    assert_check_partials(data)


def test_slsqp_lowers_the_objective():
    d = Design.load(CURVATURE)
    start = d.evaluate_problem()["objective"]
    prob = build_problem(d)
    prob.driver = om.ScipyOptimizeDriver(optimizer="SLSQP", maxiter=15, tol=1e-9, disp=False)
    prob.setup()
    prob.run_driver()
    best = prob.get_val("design.objective")[0]
    assert best < 0.9 * start, (best, start)
    x = {p["name"]: float(prob.get_val(f"design.{p['name']}")[0]) for p in d.parameters()}
    for p in d.parameters():
        assert p["min"] <= x[p["name"]] <= p["max"]
    # the driver's objective is the library's at the driver's point
    assert d.evaluate_problem(x)["objective"] == pytest.approx(best, rel=1e-12)


def test_constraints_are_outputs_and_driver_constraints():
    d = Design.load(EXAMPLES / "vesicle.toml")
    prob = build_problem(d, measures=("nu",))
    prob.setup()
    prob.run_model()
    cons = prob.model.get_constraints()
    assert list(cons) == ["design.constraint_0"]
    assert cons["design.constraint_0"]["equals"] == 0.8
    assert prob.get_val("design.constraint_0")[0] == pytest.approx(prob.get_val("design.nu")[0], rel=1e-15)


def test_explicit_problem_and_errors():
    d = Design.load(CURVATURE)
    prob = om.Problem()
    prob.model.add_subsystem(
        "design",
        DesignComponent(design=d, parameters={"a": (0.1, 4.0), "d1Tx": (-1, 1)}, objective="area", measures=("volume",)),
    )
    prob.setup()
    prob.run_model()
    assert prob.get_val("design.objective")[0] == pytest.approx(d.analysis(quadrature=(24, 48))["total"]["area"], rel=1e-12)
    assert_check_partials(prob.check_partials(method="fd", form="central", out_stream=None))
    bad = om.Problem()
    bad.model.add_subsystem("design", DesignComponent(design=d, measures=("nosuch",)))
    with pytest.raises(DesignError, match="measures: unknown"):
        bad.setup()
    assert np.isfinite(prob.get_val("design.volume")[0])
