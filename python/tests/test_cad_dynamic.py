"""STEP/IGES from Python against `pdeshape surface -o x.step|x.igs` (byte for byte, the header's
date taken from the CLI's file), and `Design.dynamic()` against `pdeshape curve` (the CSV rows of
the curve and of its frames, bit for bit)."""

from __future__ import annotations

import calendar
import math
import re
import time

import numpy as np
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError

from test_cli import cli_error


def cli_seconds(path, fmt: str) -> int:
    """The Unix seconds of the date the CLI wrote into a file's header (its clock, UTC)."""
    text = path.read_text()
    if fmt == "step":
        stamp = re.search(r"FILE_NAME\('[^']*','(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d)'", text).group(1)
        return calendar.timegm(time.strptime(stamp, "%Y-%m-%dT%H:%M:%S"))
    stamps = set(re.findall(r"15H(\d{8}\.\d{6})", text))
    assert len(stamps) == 1, stamps  # the file's date and the model's, one clock reading
    return calendar.timegm(time.strptime(stamps.pop(), "%Y%m%d.%H%M%S"))


CASES = [
    ("cup.toml", "step", []),
    ("cup.toml", "igs", []),
    ("cup.toml", "stp", ["--tolerance", "1e-3", "--units", "cm"]),
    ("cup.toml", "iges", ["--tolerance", "1e-3", "--units", "in"]),
    ("vesicle.toml", "step", ["--units", "m"]),
    ("wine_glass.toml", "igs", []),
    ("blend_cylinders.toml", "step", []),
]


@pytest.mark.parametrize("name,ext,flags", CASES)
def test_cad_files_equal_the_cli(name, ext, flags, cli, tmp_path):
    path = EXAMPLES / name
    a, b = tmp_path / f"part.{ext}", tmp_path / "py" / f"part.{ext}"
    b.parent.mkdir()
    cli("surface", str(path), "-o", str(a), *flags)
    opts = dict(zip([f.lstrip("-") for f in flags[::2]], flags[1::2]))
    if "tolerance" in opts:
        opts["tolerance"] = float(opts["tolerance"])
    fmt = "step" if ext in ("step", "stp") else "igs"
    Design.load(path).write(b, timestamp=cli_seconds(a, fmt), **opts)
    assert b.read_bytes() == a.read_bytes()
    # The header's date is the only thing the clock changes: another date, other bytes.
    c = tmp_path / "later" / f"part.{ext}"
    c.parent.mkdir()
    Design.load(path).write(c, format=ext, timestamp=cli_seconds(a, fmt) + 86_400)
    if not flags:
        assert c.read_bytes() != a.read_bytes()
        assert len(c.read_bytes()) == len(a.read_bytes())


def test_cad_default_date_is_now(cup_path, tmp_path):
    before = int(time.time())
    Design.load(cup_path).write(tmp_path / "x.step")
    Design.load(cup_path).write(tmp_path / "x.igs")
    after = int(time.time())
    for fmt in ("step", "igs"):
        assert before <= cli_seconds(tmp_path / f"x.{fmt}", fmt) <= after


def test_cad_bad_options_name_the_argument_and_leave_no_file(cli, cup_path, tmp_path):
    d = Design.load(cup_path)
    out = tmp_path / "part.step"
    cases = [
        (dict(units="furlong"), ["--units", "furlong"]),
        (dict(tolerance=-1.0), ["--tolerance=-1"]),
        (dict(tolerance=1e-300), ["--tolerance", "1e-300"]),
    ]
    for kwargs, flags in cases:
        r = cli("surface", str(cup_path), "-o", str(out), *flags, check=False)
        with pytest.raises(DesignError) as e:
            d.write(out, **kwargs)
        # the CLI's message with the flag's name as the argument's
        assert str(e.value) == cli_error(r).replace("--", "", 1), kwargs
    for kwargs, word in [
        (dict(nu=10), "nu"),
        (dict(scale=2.0), "scale"),
        (dict(up="y"), "up"),
        (dict(separate_patches=True), "separate_patches"),
    ]:
        with pytest.raises(DesignError, match=rf"^{word}: does not apply to STEP or IGES output"):
            d.write(out, **kwargs)
    with pytest.raises(DesignError, match=r"^tolerance: does not apply to mesh and sample output"):
        d.write(tmp_path / "x.obj", tolerance=1e-3)
    with pytest.raises(DesignError, match=r"^timestamp: does not apply"):
        d.write(tmp_path / "x.stl", timestamp=0)
    assert list(tmp_path.iterdir()) == []


def test_cad_of_a_dynamic_design_is_refused_as_by_the_cli(cli, tmp_path):
    path = EXAMPLES / "dynamic_section33.toml"
    r = cli("surface", str(path), "-o", str(tmp_path / "x.step"), check=False)
    with pytest.raises(DesignError) as e:
        Design.load(path).write(tmp_path / "y.step")
    assert str(e.value) == cli_error(r)
    assert list(tmp_path.iterdir()) == []


def test_cad_of_a_trimmed_design_has_its_holes_as_by_the_cli(cli, tmp_path):
    path = EXAMPLES / "trimmed_vase.toml"
    cli("surface", str(path), "-o", str(tmp_path / "x.step"))
    Design.load(path).write(tmp_path / "y.step")
    x, y = (tmp_path / "x.step").read_text(), (tmp_path / "y.step").read_text()
    assert x.count("FACE_BOUND('',") == y.count("FACE_BOUND('',") == 3
    strip = lambda t: [l for l in t.splitlines() if not l.startswith("FILE_NAME(")]
    assert strip(x) == strip(y)


def read_csv(path) -> tuple[list[str], np.ndarray]:
    lines = path.read_text().splitlines()
    rows = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    return lines[0].split(","), rows


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize("name", ["dynamic_section33.toml", "dynamic_interpolate.toml"])
def test_dynamic_curve_equals_the_cli(name, cli, tmp_path):
    path = EXAMPLES / name
    c, f = tmp_path / "c.csv", tmp_path / "f.csv"
    cli("curve", str(path), "-o", str(c), "--frames", str(f))
    d = Design.load(path)
    assert d.has_dynamic
    got = d.dynamic()
    head, rows = read_csv(c)
    dim = got["dim"]
    assert head == ["u", *"xyz"[:dim]]
    assert got["u"].dtype == np.float64 and got["u"].shape == (len(rows),)
    assert got["nodes"].shape == (len(rows), dim)
    assert same_bits(got["u"], rows[:, 0]) and same_bits(got["nodes"], rows[:, 1:])
    head, rows = read_csv(f)
    assert head == ["step", "t", "u", *"xyz"[:dim]]
    fr = got["frames"]
    nf, nj = fr["nodes"].shape[:2]
    assert fr["nodes"].shape == (nf, nj, dim) and len(rows) == nf * nj
    assert fr["step"].dtype == np.uint64 and fr["t"].dtype == np.float64
    assert np.array_equal(np.repeat(fr["step"], nj), rows[:, 0].astype(np.uint64))
    assert same_bits(np.repeat(fr["t"], nj), rows[:, 1])
    assert same_bits(np.tile(got["u"], nf), rows[:, 2])
    assert same_bits(fr["nodes"].reshape(-1, dim), rows[:, 3:])
    # the last frame is the final curve
    assert same_bits(fr["nodes"][-1], got["nodes"])
    # without frames: the same curve, no frames
    bare = d.dynamic(frames=False)
    assert same_bits(bare["nodes"], got["nodes"]) and bare["frames"]["nodes"].shape == (0, nj, dim)


def test_dynamic_run_meets_its_end_conditions_and_exact_solution():
    got = Design.load(EXAMPLES / "dynamic_section33.toml").dynamic()
    assert got["kind"] == "run" and got["t_end"] == 15.0 and got["steps"] == 450
    x = got["nodes"][:, 0]
    u = got["u"]
    # x(0) = x(1) = 0 are imposed exactly by the scheme (Dirichlet rows)
    assert x[0] == 0.0 and x[-1] == 0.0
    # the exact solution (1 + e^{-t}) sin(pi u) at T = 15: the scheme is second order in
    # h = 1/30, so the error is O(h^2) ~ 1e-3 times the solution's fourth derivative scale
    exact = (1 + math.exp(-15.0)) * np.sin(np.pi * u)
    err = np.abs(x - exact).max()
    assert err < 10 * (1 / 30) ** 2, err
    # the frames run from t = 0 to T every 45 levels
    assert got["frames"]["step"].tolist() == list(range(0, 451, 45))
    assert got["frames"]["t"][-1] == pytest.approx(15.0, abs=1e-12)


def test_dynamic_interpolation_meets_its_tolerance():
    got = Design.load(EXAMPLES / "dynamic_interpolate.toml").dynamic(frames=False)
    assert got["kind"] == "interpolate" and got["dim"] == 2
    assert got["points"].tolist() == [[100.0, 60.0], [150.0, 70.0], [200.0, 60.0]]
    # the run stops once every point lies within tolerance x data size (1e-3 x 300) of the curve
    assert np.all(got["distances"] <= 1e-3 * 300.0)
    # params are nodes' parameters, increasing along the curve
    assert np.all(np.diff(got["params"]) > 0)
    # the distances are those of the points to the nodes at their parameters
    j = np.rint(got["params"] * (len(got["u"]) - 1)).astype(int)
    dist = np.linalg.norm(got["nodes"][j] - got["points"], axis=1)
    assert np.allclose(dist, got["distances"], rtol=1e-12, atol=0)


def test_dynamic_errors(cup_path):
    with pytest.raises(DesignError, match=r"cup\.toml: the design has no \[dynamic\] section"):
        Design.load(cup_path).dynamic()
    assert not Design.load(cup_path).has_dynamic
    bad = (EXAMPLES / "dynamic_section33.toml").read_text().replace("intervals = 30", "intervals = 1")
    with pytest.raises(DesignError, match=r"^<string>:\d+:\d+: dynamic"):
        Design.from_toml(bad).dynamic()
