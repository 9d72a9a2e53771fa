"""pdeshape.sweep on a dask.distributed LocalCluster of 2 workers: equal to a serial run, no row
lost when a worker dies, failures reported as rows, annealing chains keep the best."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pandas as pd
import pytest
from dask.distributed import Client, LocalCluster

from conftest import EXAMPLES
from pdeshape import Design, DesignError
from pdeshape.sweep import anneal, grid, sweep

MEASURES = ["area", "volume", "bending_energy"]


def cup_grid(n):
    return grid(bellyDx=np.linspace(0.8, 1.2, n), rimDy=np.linspace(0.9, 1.1, n))


def equal_tables(a: pd.DataFrame, b: pd.DataFrame):
    assert list(a.columns) == list(b.columns)
    for c in a.columns:
        if c in ("error", "input"):
            assert list(a[c]) == list(b[c])
        else:
            assert np.array_equal(a[c].to_numpy().view(np.uint64), b[c].to_numpy().view(np.uint64)), c


def test_sweep_equals_serial_run(client, cup_path):
    cup = Design.load(cup_path)
    table = cup_grid(20)
    par = sweep(cup, table, measures=MEASURES, client=client, chunk_size=7)
    ser = sweep(cup, table, measures=MEASURES)
    assert isinstance(par, pd.DataFrame) and len(par) == 400
    equal_tables(par, ser)
    # each row is the design with that row's parameters, measured alone
    d = cup.with_params({"bellyDx": table["bellyDx"][123], "rimDy": table["rimDy"][123]})
    assert par["volume"][123] == d.analysis()["total"]["volume"]
    assert par["error"].isna().all()


def test_ten_thousand_cups_on_two_workers(client, cup_path):
    cup = Design.load(cup_path)
    table = cup_grid(100)
    t = time.perf_counter()
    par = sweep(cup, table, measures=["area", "volume"], client=client)
    elapsed = time.perf_counter() - t
    print(f"10 000 cups on 2 workers: {elapsed:.1f} s")
    assert len(par) == 10_000 and par["error"].isna().all()
    assert np.array_equal(par["bellyDx"].to_numpy(), table["bellyDx"])
    assert np.array_equal(par["rimDy"].to_numpy(), table["rimDy"])
    # the serial run of the same rows (a random tenth of them, for CI's time) is identical
    rows = np.sort(np.random.default_rng(7).choice(10_000, 1000, replace=False))
    sub = {k: v[rows] for k, v in table.items()}
    ser = sweep(cup, sub, measures=["area", "volume"])
    equal_tables(par.iloc[rows].reset_index(drop=True), ser)
    # the volume grows with the belly's width
    v = par["volume"].to_numpy().reshape(100, 100)
    assert np.all(np.diff(v, axis=0) > 0)


def test_failures_are_rows(client, cup_path):
    cup = Design.load(cup_path)
    table = {"bellyDx": [1.0, 0.0, 1.1], "a": [1.0, 1.0, -2.0]}
    df = sweep(cup, table, measures=["area"], client=client, chunk_size=1)
    assert len(df) == 3
    assert df["error"][0] is None and np.isfinite(df["area"][0])
    assert df["error"][1].startswith("params['bellyDx']: ") and np.isnan(df["area"][1])
    assert df["error"][2].startswith("params['a']: ") and np.isnan(df["area"][2])


def test_list_of_designs_and_dict_output(client, cup_path):
    cup = Design.load(cup_path)
    designs = [cup, cup.with_params({"rimTz": 0.2}), Design.load(EXAMPLES / "vesicle.toml")]
    got = sweep(designs, measures=["area"], client=client, as_pandas=False)
    assert isinstance(got, dict) and got["area"].dtype == np.float64
    want = [d.analysis()["total"]["area"] for d in designs]
    assert got["area"].tolist() == want and got["design"].tolist() == [0, 1, 2]


def test_fixed_quadrature_passes_through(cup_path):
    cup = Design.load(cup_path)
    df = sweep(cup, {"bellyDx": [1.1]}, measures=["area"], quadrature=(16, 32))
    assert df["area"][0] == cup.with_params({"bellyDx": 1.1}).analysis(quadrature=(16, 32))["total"]["area"]
    assert df["area"][0] != cup.with_params({"bellyDx": 1.1}).analysis()["total"]["area"]


def test_bad_arguments_raise():
    with pytest.raises(DesignError, match=r"^measures: unknown \['mass'\]"):
        sweep(Design.load(EXAMPLES / "cup.toml"), {"a": [1.0]}, measures=["mass"])
    with pytest.raises(DesignError, match=r"^params: the columns have different lengths"):
        sweep(Design.load(EXAMPLES / "cup.toml"), {"a": [1.0], "bellyDx": [1.0, 2.0]})


def test_killed_worker_loses_no_rows(cup_path):
    cup = Design.load(cup_path)
    table = cup_grid(30)  # 900 variants, a few seconds on two workers
    serial = sweep(cup, table, measures=["volume"])
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as c:
        pids = c.run(os.getpid)
        out = {}

        def run():
            out["df"] = sweep(cup, table, measures=["volume"], client=c, chunk_size=10)

        th = threading.Thread(target=run)
        th.start()
        # kill one worker once tasks are under way
        deadline = time.time() + 60
        while not any(c.processing().values()) and time.time() < deadline:
            time.sleep(0.05)
        time.sleep(0.3)
        assert th.is_alive(), "the sweep ended before a worker could be killed"
        os.kill(next(iter(pids.values())), signal.SIGKILL)
        th.join(timeout=300)
        assert not th.is_alive()
    equal_tables(out["df"], serial)


def test_annealing_chains_keep_the_best(client):
    d = Design.load(EXAMPLES / "optimize_curvature.toml")
    par = anneal(d, chains=3, seed=5, evaluations=60, polish=0, client=client)
    ser = anneal(d, chains=3, seed=5, evaluations=60, polish=0)
    assert par == ser
    assert [r["seed"] for r in par["chains"]] == [5, 6, 7]
    assert par["best"]["value"] == min(r["value"] for r in par["chains"])
    # the best point, applied as parameters, gives the value the chain reported
    assert set(par["best"]["x"]) == {p["name"] for p in d.parameters()}


def test_list_of_paths_texts_and_meshes_equals_a_serial_loop(client, tmp_path):
    import math

    import pdeshape
    from meshes import ellipsoid_obj
    from pdeshape.sweep import FIT_COLUMNS

    semi = [1.2, 1.5, 1.8]
    meshes = []
    for c in semi:
        p = tmp_path / f"egg{c}.obj"
        p.write_text(ellipsoid_obj(60, 80, c=c))
        meshes.append(p)
    broken = tmp_path / "broken.stl"
    broken.write_bytes(b"solid x\nendsolid x\n")
    cup_text = (EXAMPLES / "cup.toml").read_text()
    inputs = [
        meshes[0],
        EXAMPLES / "vesicle.toml",
        str(meshes[1]),
        cup_text,
        broken,
        Design.load(EXAMPLES / "cup.toml").with_params({"rimTz": 0.2}),
        tmp_path / "missing.toml",
        cup_text.replace("radius = 1.35", "radius = -1.35"),
        meshes[2],
    ]
    par = sweep(inputs, measures=["area", "volume"], client=client, chunk_size=2)
    ser = sweep(inputs, measures=["area", "volume"])
    equal_tables(par, ser)
    assert list(par.columns) == ["design", "input", *FIT_COLUMNS, "area", "volume", "error"]
    assert par["input"].tolist() == [
        str(meshes[0]), str(EXAMPLES / "vesicle.toml"), str(meshes[1]), "<string>", str(broken),
        str(EXAMPLES / "cup.toml"), str(tmp_path / "missing.toml"), "<string>", str(meshes[2]),
    ]
    # each row equals the same input measured alone, in a plain loop here
    for i in (0, 2, 8):
        d, report = pdeshape.fit(inputs[i])
        assert par["volume"][i] == d.analysis()["total"]["volume"]
        assert par["fit_patches"][i] == report["patches"]
        assert par["fit_hausdorff_relative"][i] == report["measures"]["hausdorff_relative"]
    assert par["area"][1] == Design.load(EXAMPLES / "vesicle.toml").analysis()["total"]["area"]
    assert par["area"][3] == Design.from_toml(cup_text).analysis()["total"]["area"]
    assert par["area"][5] == inputs[5].analysis()["total"]["area"]
    # the fitted eggs have the ellipsoids' volumes 4/3 pi a^2 c (to the fit's Hausdorff distance
    # times the area, plus the polyhedron's chord sag, as in test_fit.py)
    for i, c in zip((0, 2, 8), semi):
        exact = 4 / 3 * math.pi * c
        h = par["fit_hausdorff_relative"][i] * math.sqrt(8 + 4 * c * c)
        assert abs(par["volume"][i] - exact) <= par["area"][i] * h + 3 * 3.4e-4 * exact
    # failures are rows with the located message; designs have no fit columns
    errors = par["error"].tolist()
    assert [i for i, e in enumerate(errors) if e is not None] == [4, 6, 7]
    assert errors[4].startswith(f"{broken}: ")
    assert errors[6].startswith(f"{tmp_path / 'missing.toml'}: cannot read the design file")
    assert errors[7].startswith("<string>:") and "radius" in errors[7]
    assert np.isnan(par["fit_patches"][[1, 3, 5, 6, 7]]).all()
    assert np.isnan(par["volume"][[4, 6, 7]]).all()


def test_list_items_of_other_types_are_refused():
    with pytest.raises(DesignError, match=r"^design: a list item must be a Design, a path"):
        sweep([Design.load(EXAMPLES / "cup.toml"), 3.0], measures=["area"])
    with pytest.raises(DesignError, match=r"^design: a Design or a list"):
        sweep(str(EXAMPLES / "cup.toml"), measures=["area"])
