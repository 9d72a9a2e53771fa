"""The package against the CLI on every bundled example: the same samples (bit for bit), the same
mesh files (byte for byte), the same analysis (to rounding), the same error messages."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError

ALL = sorted(p.name for p in EXAMPLES.glob("*.toml"))


def cli_error(r) -> str:
    assert r.returncode != 0
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("error: ")
    return line[len("error: "):]


@pytest.mark.parametrize("name", ALL)
def test_example_mesh_files_equal_the_cli(name, cli, tmp_path):
    path = EXAMPLES / name
    out_cli = tmp_path / "cli.obj"
    r = cli("surface", str(path), "-o", str(out_cli), "--nu", "24", "--nv", "40", check=False)
    out_py = tmp_path / "py.obj"
    if r.returncode != 0:
        with pytest.raises(DesignError) as e:
            Design.load(path).write(out_py, 24, 40)
        assert str(e.value) == cli_error(r)
        assert not out_py.exists()
        return
    Design.load(path).write(out_py, 24, 40)
    assert out_py.read_bytes() == out_cli.read_bytes()


@pytest.mark.parametrize("fmt", ["stl", "ply", "glb"])
def test_cup_formats_and_options_equal_the_cli(fmt, cli, cup_path, tmp_path):
    a, b = tmp_path / f"cli.{fmt}", tmp_path / f"py.{fmt}"
    flags = ["--scale", "2.5", "--separate-patches"] + (["--up", "y"] if fmt != "glb" else [])
    cli("surface", str(cup_path), "-o", str(a), *flags)
    Design.load(cup_path).write(b, scale=2.5, separate_patches=True, up=None if fmt == "glb" else "y")
    assert a.read_bytes() == b.read_bytes()


@pytest.mark.parametrize("name", ALL)
def test_example_samples_equal_the_cli_csv(name, cli, tmp_path):
    path = EXAMPLES / name
    out = tmp_path / "s.csv"
    r = cli("surface", str(path), "-o", str(out), "--nu", "9", "--nv", "17", check=False)
    if r.returncode != 0:
        with pytest.raises(DesignError) as e:
            d = Design.load(path)
            if d.patches == []:
                raise DesignError(cli_error(r))  # a [dynamic]-only design has nothing to sample
            d.tessellate(9, 17)
        assert str(e.value) == cli_error(r) or "[[trims]]" in str(e.value)
        return
    with out.open() as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], np.array([[float(x) for x in r] for r in rows[1:]])
    t = Design.load(path).tessellate(9, 17)
    assert header[:8] == ["u", "v", "x", "y", "z", "nx", "ny", "nz"]
    mine = np.hstack([t["uv"], t["vertices"], t["normals"]])
    # the CSV holds the shortest text that reads back to the same f64: equal bits
    assert mine.shape == rows[:, :8].shape
    assert np.array_equal(mine.view(np.uint64), rows[:, :8].view(np.uint64))
    if len(header) == 9:
        assert np.array_equal(t["patch"], rows[:, 8].astype(np.uint32))


def same(a, b, path=""):
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        if a is None or b is None:  # the CLI writes non-finite numbers as null
            assert (a is None or not math.isfinite(a)) and (b is None or not math.isfinite(b)), path
        else:
            # the same computation; JSON text of an f64 reads back exactly
            assert a == b, (path, a, b)
    else:
        assert a == b, path


@pytest.mark.parametrize("name", ALL)
def test_example_analysis_equals_the_cli(name, cli):
    path = EXAMPLES / name
    r = cli("analyze", "--json", str(path), check=False)
    if r.returncode != 0:
        with pytest.raises(DesignError) as e:
            Design.load(path).analysis()
        assert str(e.value) == cli_error(r)
        return
    want = json.loads(r.stdout)
    want.pop("trimmed", None)  # the trimmed integrals are the CLI's own addition
    got = Design.load(path).analysis()
    same(got, want)
