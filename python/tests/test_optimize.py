"""Design.optimize: the annealing and gradient searches through the library call the CLI makes.

The gradient search's result is checked against what it claims: at least as good as the start,
inside the bounds, its reported first-order (KKT) conditions recomputed here from
Design.gradient at the result, and the same result as `pdeshape optimize --method gradient` on
the same design and seed (the same computation, so equal to the last bit).
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError

CURVATURE = EXAMPLES / "optimize_curvature.toml"
VESICLE = EXAMPLES / "vesicle.toml"

#: The search's stationarity tolerance: SLSQP stops when the objective changes by less than
#: 1e-10 of itself; with a quasi-Newton matrix of order one in the scaled variables a change
#: Δf ≈ ½‖g‖² leaves ‖g‖ ≈ 1.4e-5, and 1e-3 allows a conditioning of the matrix up to ~100² worse.
STATIONARITY = 1e-3


@pytest.fixture(scope="module")
def curvature_gradient():
    d = Design.load(CURVATURE)
    return d, d.optimize(method="gradient", seed=3)


def bounds(design: Design) -> dict[str, tuple[float, float]]:
    return {p["name"]: (p["min"], p["max"]) for p in design.parameters() if p["source"] == "optimize"}


def test_gradient_result_is_no_worse_than_its_start_and_inside_its_bounds(curvature_gradient):
    d, r = curvature_gradient
    assert r["method"] == "gradient"
    start = d.evaluate_problem()
    assert r["start_value"] == pytest.approx(start["value"], rel=1e-12)
    assert r["value"] <= r["start_value"]
    assert r["value"] < 0.99 * r["start_value"]  # it moves: the start is not stationary
    for name, (lo, hi) in bounds(d).items():
        assert lo <= r["x"][name] <= hi, name
    # The result re-evaluated from its parameters alone.
    again = d.evaluate_problem(r["x"])
    assert again["value"] == pytest.approx(r["value"], rel=1e-12)
    assert again["objective"] == pytest.approx(r["objective"], rel=1e-12)
    g = r["gradient"]
    assert g["evaluations"] == r["evaluations"] == g["starts"][0]["evaluations"]
    assert g["solves"] == r["solves"] >= r["evaluations"]
    # Each gradient: one batched tangent solve for the parameters the solve is affine in.
    assert r["tangent_solves"] == r["evaluations"]
    assert len(g["starts"]) == 1 and g["best_start"] == 0
    assert g["starts"][0]["x"] == pytest.approx(d.evaluate_problem()["x"])


def test_gradient_result_meets_the_kkt_conditions_it_reports(curvature_gradient):
    """Bounds only: the projected gradient, each derivative times its parameter's range over the
    objective at the start, recomputed from Design.gradient at the result."""
    d, r = curvature_gradient
    g = r["gradient"]
    assert g["converged"], g["starts"]
    kkt = g["kkt"]
    assert kkt["active_constraints"] == 0
    assert kkt["primal_infeasibility"] == 0.0 and kkt["dual_infeasibility"] == 0.0
    at = d.with_params(r["x"]).gradient()
    assert at["objective"] == pytest.approx(r["objective"], rel=1e-12)
    fscale = abs(d.evaluate_problem()["objective"])
    proj = []
    active = 0
    for k, name in enumerate(at["names"]):
        lo, hi = bounds(d)[name]
        s = at["d_objective"][k] * (hi - lo) / fscale
        x = r["x"][name]
        if x <= lo + 1e-9 * (hi - lo):
            proj.append(max(-s, 0.0))
            active += 1
        elif x >= hi - 1e-9 * (hi - lo):
            proj.append(max(s, 0.0))
            active += 1
        else:
            proj.append(abs(s))
    assert kkt["active_bounds"] == active
    assert kkt["stationarity"] == pytest.approx(max(proj), rel=1e-9, abs=1e-15)
    assert kkt["stationarity"] <= STATIONARITY


def test_gradient_result_equals_the_cli(curvature_gradient, cli, tmp_path):
    _, r = curvature_gradient
    out = tmp_path / "best.toml"
    p = cli(
        "optimize", str(CURVATURE), "-o", str(out), "--method", "gradient", "--seed", "3", "--timings",
    )
    with open(tmp_path / "best.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == r["evaluations"]
    # No constraint: every point is feasible and the result is the lowest value logged.
    best = min(rows, key=lambda row: float(row["value"]))
    assert float(best["value"]) == r["value"]
    assert {k: float(best[k]) for k in r["x"]} == r["x"]
    timings = next(line for line in p.stderr.splitlines() if line.startswith("{"))
    assert f'"solves":{r["solves"]}' in timings.replace(" ", "")
    assert f'"tangent_solves":{r["tangent_solves"]}' in timings.replace(" ", "")
    # The report's line of the first-order conditions is the same search's.
    line = next(line for line in p.stdout.splitlines() if line.startswith("gradient search:"))
    shown = float(line.split("stationarity ")[1].split(",")[0])
    assert shown == pytest.approx(r["gradient"]["kkt"]["stationarity"], rel=1e-3)


def test_constrained_gradient_result_is_feasible_and_first_order():
    """§7.5.2's ν = 0.8: the start is infeasible, the result feasible, one side of the ν band
    active with a multiplier of the right sign. The default budget: the start ends on the
    first-order test within it (status `first_order`), as the library's test of the same
    search."""
    d = Design.load(VESICLE)
    r = d.optimize(method="gradient")
    assert not d.evaluate_problem()["feasible"]
    assert r["feasible"]
    assert abs(r["measures"]["nu"] - 0.8) <= 1e-3
    assert r["value"] < r["start_value"]
    kkt = r["gradient"]["kkt"]
    assert r["gradient"]["converged"]
    assert r["gradient"]["starts"][0]["status"] == "first_order"
    assert r["gradient"]["evaluations"] < 100
    assert kkt["active_constraints"] == 1
    assert kkt["dual_infeasibility"] <= 1e-6
    assert kkt["stationarity"] <= STATIONARITY


def test_annealing_keeps_its_keys_and_reports_its_counts():
    d = Design.load(CURVATURE)
    r = d.optimize(seed=2, evaluations=40, chains=2, polish=10)
    assert r["method"] == "anneal" and r["gradient"] is None
    assert {"x", "value", "objective", "penalty"} <= r.keys()
    assert r["evaluations"] == r["solves"] <= 50
    assert r["tangent_solves"] == 0
    assert r["value"] <= r["start_value"]
    # The same call by keyword and positionally (the order before `method` is kept).
    assert d.optimize(2, 40, 2, 10)["x"] == r["x"]


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"method": "newton"}, "method: unknown method 'newton'"),
        ({"method": "gradient", "starts": 0}, "starts: must be between 1 and"),
        ({"method": "gradient", "starts": -1}, "starts: must be a non-negative integer"),
        ({"method": "gradient", "evaluations": 0}, "evaluations: must be between 1 and"),
        ({"method": "gradient", "chains": 2}, "chains: only with the anneal"),
        ({"method": "anneal", "starts": 2}, "starts: only with the gradient"),
        ({"evaluations": 1, "chains": 4}, "evaluations: must be at least the number of chains"),
        ({"seed": -1}, "seed: must be an integer"),
    ],
)
def test_bad_arguments_are_one_value_error(kwargs, needle):
    d = Design.load(CURVATURE)
    with pytest.raises(ValueError) as e:
        d.optimize(**kwargs)
    assert isinstance(e.value, DesignError)
    assert needle in str(e.value)
    assert "\n" not in str(e.value)


def test_gradient_search_of_shell_stress_needs_the_solver(monkeypatch):
    # max_shear is differenced by CalculiX's runs; without the solver the search stops at its
    # first design with the solver's message, at the [optimize] section's place.
    monkeypatch.setenv("PDESHAPE_CCX", "/nonexistent/ccx")
    d = Design.load(EXAMPLES / "yoghurt_optimize.toml")
    with pytest.raises(DesignError, match=r"yoghurt_optimize.toml.*optimize.*not found"):
        d.optimize(method="gradient")


def test_no_optimize_section():
    with pytest.raises(DesignError, match="optimize"):
        Design.load(EXAMPLES / "cup.toml").optimize(method="gradient")


def test_two_starts_are_never_worse_than_one():
    d = Design.load(VESICLE)
    one = d.optimize(method="gradient", evaluations=15)
    two = d.optimize(method="gradient", evaluations=15, starts=2)
    assert len(two["gradient"]["starts"]) == 2
    # The first start is the same search; the result is the better of the two: feasible
    # first, then the lower objective (feasible) or value (infeasible).
    assert two["gradient"]["starts"][0] == one["gradient"]["starts"][0]
    if one["feasible"]:
        assert two["feasible"] and two["objective"] <= one["objective"]
    elif not two["feasible"]:
        assert two["value"] <= one["value"]
    assert np.isfinite(two["value"])


def test_hybrid_is_never_worse_than_annealing_on_the_same_seed():
    """The hybrid contains annealing's run (the same seed and options) and keeps the better of
    annealing's result and the gradient search's from each chain's best point: feasible first,
    then the lower objective. On §7.5.2 (ν = 0.8) with a small annealing budget."""
    d = Design.load(VESICLE)
    opts = dict(seed=4, evaluations=90, chains=3, polish=10)
    a = d.optimize(**opts)
    h = d.optimize(method="hybrid", **opts)
    assert h["method"] == "hybrid"
    if a["feasible"]:
        assert h["feasible"] and h["objective"] <= a["objective"]
    elif not h["feasible"]:
        assert h["value"] <= a["value"]
    assert h["feasible"]  # the gradient stage meets the ν band
    g = h["gradient"]
    assert 1 <= len(g["starts"]) <= 3
    assert h["evaluations"] == a["evaluations"] + g["evaluations"]
    assert h["solves"] == a["solves"] + g["solves"]
    with pytest.raises(DesignError, match="starts: only with the gradient"):
        d.optimize(method="hybrid", starts=2)
