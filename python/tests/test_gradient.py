"""Design.gradient against central finite differences through with_params, on every example with
parameters: the measures' derivatives and, with [optimize], the objective's and the constraints'.

The finite-difference error is bounded from the differences themselves, before any comparison:
with D(h) the central difference of step h, D(h/2) has the truncation error
(D(h) − D(h/2)) / 3 + O(h⁴) (Richardson), bounded here by |D(h) − D(h/2)|, plus the rounding of
two values of size |f| divided by the step, bounded by ROUNDING · |f| / (h/2) with ROUNDING a
few hundred ulps (the values are sums over thousands of quadrature nodes). The gradient must lie
within that bound of D(h/2).
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError

EPS = np.finfo(float).eps
#: The relative rounding error of one measure, in units of eps.
ROUNDING = 512 * EPS
#: The measures compared (the shell measures need CalculiX: differenced in the Rust tests).
MEASURES = ("area", "volume", "mean", "mean_sq", "gauss", "bending", "willmore", "helfrich", "nu", "c0")


def interior(design: Design) -> dict[str, float]:
    """A point inside the parameters' bounds, off the start (so a parameter whose start is a
    bound can be stepped both ways): each value a fifth of the way from its start to the middle
    of its bounds."""
    out = {}
    for p in design.parameters():
        lo, hi, v = p["min"], p["max"], p["value"]
        out[p["name"]] = v + 0.2 * ((lo + hi) / 2 - v)
    return out


def step(design: Design, name: str) -> float:
    """The step of a parameter: 1e-3 of its range."""
    p = next(p for p in design.parameters() if p["name"] == name)
    return 1e-3 * (p["max"] - p["min"])


def central(f, x: dict[str, float], name: str, h: float) -> tuple[float, float]:
    """(D(h), max |f| of the two values)."""
    a = f({**x, name: x[name] + h})
    b = f({**x, name: x[name] - h})
    return (a - b) / (2 * h), max(abs(a), abs(b))


def check(f, x, name, h, exact):
    d1, _ = central(f, x, name, h)
    d2, size = central(f, x, name, h / 2)
    bound = abs(d1 - d2) + ROUNDING * size / (h / 2)
    assert abs(exact - d2) <= bound, (name, exact, d2, d1, bound)


@pytest.mark.parametrize("example", ["optimize_curvature.toml", "vesicle.toml"])
def test_problem_gradient_against_finite_differences(example):
    base = Design.load(EXAMPLES / example)
    x = interior(base)
    d = base.with_params(x)
    g = d.gradient()
    names = [p["name"] for p in base.parameters() if p["source"] == "optimize"]
    assert g["names"] == names
    ev = d.evaluate_problem()
    assert g["objective"] == pytest.approx(ev["objective"], rel=1e-12)
    for k, name in enumerate(names):
        h = step(base, name)
        for m in MEASURES:
            check(lambda v, m=m: base.evaluate_problem(v)["measures"][m], x, name, h, g["d_measures"][m][k])
        check(lambda v: base.evaluate_problem(v)["objective"], x, name, h, g["d_objective"][k])
        for i, c in enumerate(g["constraints"]):
            check(lambda v, i=i: base.evaluate_problem(v)["constraints"][i]["value"], x, name, h, c["gradient"][k])


def test_declared_parameters_gradient_against_finite_differences():
    # swirl_port_params.toml: position, angle, scale and v = 0 parameters ([[parameters]])
    base = Design.load(EXAMPLES / "swirl_port_params.toml")
    x = interior(base)
    d = base.with_params(x)
    q = (24, 48)
    g = d.gradient(quadrature=q)
    assert g["names"] == [p["name"] for p in base.parameters()]

    def measure(v, m):
        total = base.with_params(v).analysis(quadrature=q)["total"]
        return {"area": total["area"], "volume": total["volume"], "bending": total["bending_energy"]}[m]

    for k, name in enumerate(g["names"]):
        for m in ("area", "volume", "bending"):
            check(lambda v, m=m: measure(v, m), x, name, step(base, name), g["d_measures"][m][k])


def test_gradient_names_and_errors():
    d = Design.load(EXAMPLES / "optimize_curvature.toml")
    g = d.gradient(names=["a", "d1Tx"])
    assert g["names"] == ["a", "d1Tx"] and "d_objective" not in g
    assert g["d_measures"]["area"].shape == (2,)
    full = d.gradient()
    # Every parameter (`a` included: exact too) in one batched tangent solve.
    assert full["batch"] == sum(full["exact"]) == len(full["names"]) == 19
    assert full["tangent_solves"] == 1 and g["batch"] == 2
    k = full["names"].index("d1Tx")
    assert g["d_measures"]["area"][1] == pytest.approx(full["d_measures"]["area"][k], rel=1e-12)
    with pytest.raises(DesignError, match="nosuch"):
        d.gradient(names=["nosuchTx"])
    with pytest.raises(DesignError, match="quadrature"):
        d.gradient(quadrature=(0, 5))
    with pytest.raises(DesignError, match="names"):
        Design.load(EXAMPLES / "cup.toml").gradient()


def test_shell_problem_gradient_runs_the_solver_and_named_parameters_work(monkeypatch):
    # yoghurt_optimize.toml's constraint uses max_shear (CalculiX), differenced by the solver's
    # runs: without the solver the gradient is the solver's error; its geometric measures are
    # differentiated exactly, by names, on the design at a point inside the bounds.
    base = Design.load(EXAMPLES / "yoghurt_optimize.toml")
    with monkeypatch.context() as m:
        m.setenv("PDESHAPE_CCX", "/nonexistent/ccx")
        with pytest.raises(DesignError, match="not found"):
            base.gradient()
    x = interior(base)
    d = base.with_params(x)
    q = (24, 128)
    # a book name is differentiated from its neutral value on the design as it is: for a
    # translation, `a` and cT that is the derivative in the absolute value; for a dilation the
    # factor multiplies the current one (d/ds at 1 = s0 · d/ds at s0)
    names = ["d1Tz", "d2Tz", "a", "d1cT", "d1Dx"]
    g = d.gradient(names=names, quadrature=q)
    # `a` of a design of analytic PDE patches: exact (the operator's derivative, in the batch)
    assert g["names"] == names and g["methods"][2] == "exact" and g["exact"][2]
    assert g["x"]["d1Dx"] == 1.0 and g["x"]["a"] == pytest.approx(x["a"], rel=1e-15)

    def measure(v, m):
        return base.with_params(v).analysis(quadrature=q)["total"][m]

    for k, name in enumerate(names):
        scale = x[name] if name == "d1Dx" else 1.0
        for m in ("area", "volume"):
            check(lambda v, m=m: measure(v, m), x, name, step(base, name), g["d_measures"][m][k] / scale)
