"""Design.evaluate_problem and pdeshape.optuna: an Optuna study over §7.5's curvature design on a
dask.distributed LocalCluster improves on the start, and its numbers are the library's."""

from __future__ import annotations

import math

import optuna
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError
from pdeshape.optuna import Objective, constraints_func, problem_design, run_study

optuna.logging.set_verbosity(optuna.logging.WARNING)

CURVATURE = EXAMPLES / "optimize_curvature.toml"
#: The quadrature of optimize_curvature.toml's [optimize] (the defaults: 24 × 48).
QUADRATURE = (24, 48)


def test_evaluate_problem_is_the_design_measured():
    d = Design.load(CURVATURE)
    point = {"d1Tx": 0.3, "d2Rz": -0.2, "a": 1.7}
    r = d.evaluate_problem(point)
    assert set(r["x"]) == {p["name"] for p in d.parameters() if p["source"] == "optimize"}
    assert r["x"]["d1Tx"] == 0.3 and r["x"]["a"] == 1.7 and r["x"]["d1Dx"] == 1.0
    # no constraints: the value is the objective, the total bending of the design there
    assert r["penalty"] == 0.0 and r["feasible"] and r["constraints"] == []
    total = d.with_params(point).analysis(quadrature=QUADRATURE)["total"]
    assert r["objective"] == pytest.approx(total["bending_energy"], rel=1e-13)
    assert r["value"] == r["objective"]
    assert r["measures"]["area"] == pytest.approx(total["area"], rel=1e-13)
    assert r["measures"]["bending"] == r["objective"]
    assert math.isnan(r["measures"]["max_shear"])
    # values set by with_params are the default point
    assert d.with_params(point).evaluate_problem()["value"] == r["value"]
    # the start differs
    assert d.evaluate_problem()["value"] != r["value"]


def test_evaluate_problem_refuses_bad_points():
    d = Design.load(CURVATURE)
    with pytest.raises(DesignError, match=r"values\['d1Tx'\]: 5 lies outside the bounds \[-1.2, 1.2\]"):
        d.evaluate_problem({"d1Tx": 5.0})
    with pytest.raises(DesignError, match=r"values\['zzz'\]: not a parameter of \[optimize\]"):
        d.evaluate_problem({"zzz": 1.0})
    with pytest.raises(DesignError, match=r"values\['a'\]: must be a number"):
        d.evaluate_problem({"a": "x"})
    with pytest.raises(DesignError, match=r"optimize: the design has no \[optimize\] section"):
        Design.load(EXAMPLES / "cup.toml").evaluate_problem()


def test_constraint_values_and_violations():
    d = Design.load(CURVATURE)
    start = d.evaluate_problem()
    area, volume = start["measures"]["area"], start["measures"]["volume"]
    # an inequality that holds at the start, one that does not, and an equality that does not
    cons = [
        {"expr": "area", "max": area + 1.0},
        {"expr": "2 * volume", "min": 2 * volume + 0.5, "weight": 10.0},
        {"expr": "area / volume", "equal": 1.0},
    ]
    obj = Objective(d, {"d1Tx": (-1.2, 1.2), "a": (0.01, 9.0)}, "bending", cons)
    assert obj.constrained and [s[0] for s in obj.space] == ["d1Tx", "a"]
    r = obj.evaluate(obj.start)
    assert r["x"] == {"d1Tx": 0.0, "a": 0.5}
    values = [c["value"] for c in r["constraints"]]
    assert values[0] == pytest.approx(area, rel=1e-13)
    assert values[1] == pytest.approx(2 * volume, rel=1e-13)
    assert values[2] == pytest.approx(area / volume, rel=1e-13)
    # the penalty is the library's w · violation² over the violated ones
    expected = 10.0 * 0.5**2 + 1e4 * (area / volume - 1.0) ** 2
    assert r["penalty"] == pytest.approx(expected, rel=1e-9)
    assert not r["feasible"]
    study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=2))
    study.enqueue_trial(obj.start)
    study.optimize(obj, n_trials=3)
    t = study.trials[0]
    v = constraints_func(t)
    assert v[0] == pytest.approx(-1.0, abs=1e-9)
    assert v[1] == pytest.approx(0.5, abs=1e-9)
    assert v[2] == pytest.approx(abs(area / volume - 1.0) - 1e-3, rel=1e-9)
    assert t.value == pytest.approx(r["value"], rel=1e-13) and t.user_attrs["feasible"] is False
    for t in study.trials:
        assert t.state == optuna.trial.TrialState.COMPLETE
        assert -1.2 <= t.params["d1Tx"] <= 1.2 and 0.01 <= t.params["a"] <= 9.0


def test_problem_design_is_checked_by_the_library():
    d = Design.load(CURVATURE)
    with pytest.raises(DesignError, match=r"optimize.objective"):
        problem_design(d, {"a": (0.1, 2.0)}, "bending +")
    with pytest.raises(DesignError, match=r"optimize.parameters\[0\].name"):
        problem_design(d, {"nosuchTx": (0.0, 1.0)}, "bending")
    with pytest.raises(DesignError, match="parameters, objective: give both"):
        Objective(d, parameters={"a": (0.1, 2.0)})


def test_a_failed_design_is_a_failed_trial():
    # a point the library refuses (d1Dx = 0, enqueued by hand outside its bounds): the trial
    # fails with the library's message and the study goes on.
    d = Design.load(CURVATURE)
    obj = Objective(d)
    study = optuna.create_study()
    study.enqueue_trial({**obj.start, "d1Dx": 0.0})
    study.enqueue_trial(obj.start)
    run_study(obj, n_trials=2, study=study, start=False)
    assert [t.state for t in study.trials] == [optuna.trial.TrialState.FAIL, optuna.trial.TrialState.COMPLETE]
    assert "values['d1Dx']" in study.trials[0].user_attrs["error"]


def test_study_on_a_local_cluster_improves_on_the_start(client):
    d = Design.load(CURVATURE)
    start = d.evaluate_problem()["value"]
    study = run_study(d, n_trials=48, client=client, seed=7)
    assert len(study.trials) == 48
    first = study.trials[0]
    assert first.params == Objective(d).start and first.value == start
    assert all(t.state == optuna.trial.TrialState.COMPLETE for t in study.trials)
    assert study.best_value < start, (study.best_value, start)
    # the best trial's value is the library's, evaluating its parameters directly
    best = d.with_params(study.best_params)
    assert best.evaluate_problem()["value"] == study.best_value
    total = best.analysis(quadrature=QUADRATURE)["total"]
    assert total["bending_energy"] == pytest.approx(study.best_value, rel=1e-12)
    # the same study run serially in the same batches is the same study
    serial = run_study(d, n_trials=48, batch_size=2, seed=7)
    assert [t.params for t in serial.trials] == [t.params for t in study.trials]
    assert [t.value for t in serial.trials] == [t.value for t in study.trials]
