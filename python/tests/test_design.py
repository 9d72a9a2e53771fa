"""The Design API: loading, listing, arrays (shapes, dtypes, order), evaluation against
independent truth, parameters, errors."""

from __future__ import annotations

import math
import threading
import time
import tomllib

import numpy as np
import pytest

from conftest import EXAMPLES
from pdeshape import Design, DesignError


def test_load_from_toml_and_from_dict_agree(cup_path):
    a = Design.load(cup_path)
    b = Design.from_toml(cup_path.read_text())
    c = Design.from_dict(tomllib.loads(cup_path.read_text()))
    assert a.title == "Cup (two biharmonic patches, §4.6)"
    assert a.curves == sorted(a.curves) and "belly" in a.curves and "rim" in a.curves
    assert a.patches == ["base", "bowl"] == b.patches == c.patches
    ta, tb, tc = a.tessellate(8, 16), b.tessellate(8, 16), c.tessellate(8, 16)
    assert np.array_equal(ta["vertices"], tb["vertices"])
    assert np.array_equal(ta["vertices"], tc["vertices"])


def test_tessellate_shapes_dtypes_and_order(cup_path):
    d = Design.load(cup_path)
    nu, nv = 5, 12
    t = d.tessellate(nu, nv)
    n = 2 * nu * nv
    assert t["vertices"].shape == (n, 3) and t["vertices"].dtype == np.float64
    assert t["normals"].shape == (n, 3) and t["normals"].dtype == np.float64
    assert t["uv"].shape == (n, 2) and t["uv"].dtype == np.float64
    assert t["patch"].shape == (n,) and t["patch"].dtype == np.uint32
    # periodic v: nv quads per row, two triangles each, per patch
    assert t["faces"].shape == (2 * (nu - 1) * nv * 2, 3) and t["faces"].dtype == np.uint32
    assert t["shape"].tolist() == [[nu, nv], [nu, nv]]
    # u-major order: row i, column j of patch k at k*nu*nv + i*nv + j, u_i = i/(nu-1), v_j = 2πj/nv
    uv = t["uv"].reshape(2, nu, nv, 2)
    assert np.allclose(uv[..., 0], np.linspace(0, 1, nu)[None, :, None], atol=0, rtol=0)
    assert np.allclose(uv[..., 1], (2 * np.pi * np.arange(nv) / nv)[None, None, :], rtol=1e-15)
    # the vertices are the surface at those parameters, evaluated point by point (the grid uses
    # row evaluators that sum the modes in another order: equal to rounding, the cup's size ~3)
    for k, name in enumerate(d.patches):
        sel = t["patch"] == k
        e = d.evaluate(t["uv"][sel, 0].copy(), t["uv"][sel, 1].copy(), name)
        assert np.max(np.abs(e["x"] - t["vertices"][sel])) < 1e-13
    assert np.allclose(np.linalg.norm(t["normals"], axis=1), 1.0, atol=1e-12)


def test_evaluate_partials_match_finite_differences(cup_path):
    d = Design.load(cup_path)
    rng = np.random.default_rng(1)
    u = rng.uniform(0.1, 0.9, 20)
    v = rng.uniform(0, 2 * np.pi, 20)
    h = 1e-5
    e = d.evaluate(u, v, "bowl")
    fu = (d.evaluate(u + h, v, "bowl")["x"] - d.evaluate(u - h, v, "bowl")["x"]) / (2 * h)
    fv = (d.evaluate(u, v + h, "bowl")["x"] - d.evaluate(u, v - h, "bowl")["x"]) / (2 * h)
    # central differences: error ~ h²|X'''|/6 plus rounding ~1e-16/h; both below 1e-8 here
    assert np.max(np.abs(fu - e["xu"])) < 1e-8
    assert np.max(np.abs(fv - e["xv"])) < 1e-8
    fuu = (d.evaluate(u + h, v, "bowl")["xu"] - d.evaluate(u - h, v, "bowl")["xu"]) / (2 * h)
    assert np.max(np.abs(fuu - e["xuu"])) < 1e-7


def test_boundary_conditions_and_spine(cup_path):
    d = Design.load(cup_path)
    v = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    # the bowl runs from the belly circle (radius 1.5, z = 0.9) to the rim (radius 1.35, z = 2.4)
    belly = d.evaluate(np.zeros_like(v), v, "bowl")["x"]
    rim = d.evaluate(np.ones_like(v), v, "bowl")["x"]
    assert np.allclose(np.hypot(belly[:, 0], belly[:, 1]), 1.5, atol=1e-12)
    assert np.allclose(belly[:, 2], 0.9, atol=1e-12)
    assert np.allclose(np.hypot(rim[:, 0], rim[:, 1]), 1.35, atol=1e-12)
    # the spine A0(u) is the mean of X over v (the v-mode 0 of the Fourier solution)
    u = np.linspace(0, 1, 7)
    s = d.spine(u, "bowl")
    for i, ui in enumerate(u):
        x = d.evaluate(np.full_like(v, ui), v, "bowl")["x"]
        assert np.allclose(x.mean(axis=0), s[i], atol=1e-12)
    assert s.shape == (7, 3) and s.dtype == np.float64


def test_curvature_of_a_known_surface(cup_path):
    d = Design.load(cup_path)
    u = np.array([0.3, 0.7])
    v = np.array([0.2, 1.9])
    c = d.curvature(u, v, 1)
    e = d.evaluate(u, v, 1)
    # K = (LN − M²)/(EG − F²) from the partials, computed here independently
    n = np.cross(e["xu"], e["xv"])
    n /= np.linalg.norm(n, axis=1)[:, None]
    E, F, G = (np.sum(a * b, axis=1) for a, b in [(e["xu"], e["xu"]), (e["xu"], e["xv"]), (e["xv"], e["xv"])])
    L, M, N = (np.sum(a * n, axis=1) for a in [e["xuu"], e["xuv"], e["xvv"]])
    K = (L * N - M * M) / (E * G - F * F)
    H = (E * N - 2 * F * M + G * L) / (2 * (E * G - F * F))
    assert np.allclose(c["gauss"], K, rtol=1e-10)
    assert np.allclose(c["mean"], H, rtol=1e-10)
    assert np.allclose(c["k1"] + c["k2"], 2 * c["mean"], rtol=1e-12)


def test_parameters_and_with_params(cup_path):
    d = Design.load(cup_path)
    assert d.parameters() == []
    base = d.analysis()["total"]
    # The derivative curves are scale·(direction − position) of the curves they name, so
    # translating every other curve along z moves the cup and keeps its area and volume.
    placed = [c for c in d.curves if not c.endswith("_tangent")]
    moved = d.with_params({f"{c}Tz": 0.5 for c in placed})
    m = moved.analysis()["total"]
    assert math.isclose(m["area"], base["area"], rel_tol=1e-10)
    assert math.isclose(m["volume"], base["volume"], rel_tol=1e-10)
    assert not math.isclose(d.with_params({"rim_tangentTz": 0.5}).analysis()["total"]["area"], base["area"], rel_tol=1e-6)
    # Dilating those curves (circles about the z axis and a point on it) by 2 in x and y scales
    # every condition's x, y by 2; the PDE is linear, so the cup's x, y scale by 2: volume × 4.
    wide = d.with_params({f"{c}D{a}": 2.0 for c in placed for a in "xy"}).analysis()["total"]
    assert math.isclose(wide["volume"], 4 * base["volume"], rel_tol=1e-9)
    assert moved.params() == {f"{c}Tz": 0.5 for c in placed}
    assert d.params() == {}


def test_optimize_parameters_listed_and_bounded():
    d = Design.load(pdeshape_example("optimize_curvature.toml"))
    ps = d.parameters()
    assert ps and all({"name", "min", "max", "initial"} <= p.keys() for p in ps)
    p = ps[0]
    with pytest.raises(DesignError, match=rf"params\['{p['name']}'\]: .* lies outside the bounds"):
        d.with_params({p["name"]: p["max"] + 1.0})


def pdeshape_example(name):
    return EXAMPLES / name


def test_errors_are_located(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (EXAMPLES / "cup.toml").read_text()
    line = text[: text.index("radius = 1.35")].count("\n") + 1
    bad.write_text(text.replace("radius = 1.35", "radius = -1.35"))
    with pytest.raises(DesignError) as e:
        Design.load(bad).solve()
    assert str(e.value).startswith(f"{bad}:{line}:1: curves.rim.radius: ")
    assert isinstance(e.value, ValueError)
    with pytest.raises(DesignError, match=r"^<string>:2:9: "):
        Design.from_toml('title = "x"\nbogus = = 1\n')
    with pytest.raises(DesignError, match="cannot read the design file"):
        Design.load(tmp_path / "missing.toml")
    with pytest.raises(DesignError, match="^<dict>"):
        Design.from_dict({"operator": {"kind": 3}})
    with pytest.raises(DesignError, match=r"^nu: "):
        Design.load(pdeshape_example("cup.toml")).tessellate(1, 16)
    with pytest.raises(DesignError, match=r"^patch: no surface is called 'lid'"):
        Design.load(pdeshape_example("cup.toml")).evaluate(np.zeros(1), np.zeros(1), "lid")
    with pytest.raises(DesignError, match=r"^u and v: shapes \[2\] and \[3\] do not broadcast"):
        Design.load(pdeshape_example("cup.toml")).evaluate(np.zeros(2), np.zeros(3), "bowl")


def test_write_refuses_bad_input_and_leaves_no_file(tmp_path, cup_path):
    d = Design.load(cup_path)
    with pytest.raises(DesignError, match=r"^path .*\.xyz: "):
        d.write(tmp_path / "cup.xyz")
    with pytest.raises(DesignError, match=r"^scale: "):
        d.write(tmp_path / "cup.obj", scale=-1)
    with pytest.raises(DesignError, match=r"^up z: glTF"):
        d.write(tmp_path / "cup.glb", up="z")
    with pytest.raises(DesignError, match=r"^path .*: "):
        d.write(tmp_path / "no" / "such" / "dir" / "cup.obj")
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_gil_released_during_solves(cup_path):
    # While one thread solves, another Python thread keeps running: it must get the
    # interpreter many times during the solves (with the GIL held throughout it would not).
    text = cup_path.read_text()
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0)

    t = threading.Thread(target=count)
    t.start()
    start = ticks
    for i in range(40):
        Design.from_toml(text).with_params({"bellyDx": 1 + 0.01 * i}).analysis()
    during = ticks - start
    done.set()
    t.join()
    assert during > 100


def test_trimesh_conversion(cup_path):
    import trimesh

    d = Design.load(cup_path)
    m = d.mesh(64, 128)
    tm = d.to_trimesh(64, 128)
    assert isinstance(tm, trimesh.Trimesh)
    assert tm.vertices.shape == m["vertices"].shape and tm.faces.shape == m["faces"].shape
    assert m["vertices"].dtype == np.float32 and m["faces"].dtype == np.uint32
    # the welded cup is one consistently oriented surface (the CLI welds the pole and the
    # shared belly edge), and its area is the analysis's up to the chords' O(h²) error
    assert tm.is_winding_consistent
    area = d.analysis()["total"]["area"]
    assert abs(tm.area - area) / area < 2e-3


def test_pyvista_conversion(cup_path):
    import pyvista

    d = Design.load(cup_path)
    for separate in (False, True):
        m = d.mesh(32, 48, separate_patches=separate)
        poly = d.to_pyvista(32, 48, separate_patches=separate)
        assert isinstance(poly, pyvista.PolyData)
        # the mesh's points (f32 widened to f64, exactly) and its triangles, in order
        assert poly.n_points == len(m["vertices"]) and poly.n_cells == len(m["faces"])
        assert np.array_equal(poly.points, m["vertices"].astype(np.float64))
        assert poly.is_all_triangles
        cells = poly.faces.reshape(-1, 4)
        assert np.all(cells[:, 0] == 3)
        assert np.array_equal(cells[:, 1:], m["faces"].astype(np.int64))
        assert np.array_equal(poly.point_data["Normals"], m["normals"])
    # VTK's own area of the triangles equals the analysis's up to the chords' O(h²) error
    poly = d.to_pyvista(64, 128)
    area = d.analysis()["total"]["area"]
    assert abs(poly.area - area) / area < 2e-3


def test_type_stubs_name_every_public_method():
    import ast
    import pathlib

    import pdeshape
    from pdeshape import _pdeshape

    stub = ast.parse((pathlib.Path(_pdeshape.__file__).parent / "_pdeshape.pyi").read_text())
    cls = next(n for n in stub.body if isinstance(n, ast.ClassDef) and n.name == "Design")
    stubbed = {n.name for n in cls.body if isinstance(n, ast.FunctionDef)}
    public = {n for n in dir(Design) if not n.startswith("_")}
    assert stubbed == public
    functions = {n.name for n in stub.body if isinstance(n, ast.FunctionDef)}
    assert functions == {n for n in dir(_pdeshape) if callable(getattr(_pdeshape, n))
                         and not n.startswith("_") and n not in ("Design", "DesignError")}
    # and the stubbed signatures' parameter names are the runtime's
    for name in sorted(stubbed):
        fn = next(n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == name)
        doc = getattr(Design, name).__doc__ or ""
        sig = getattr(getattr(Design, name), "__text_signature__", None)
        if sig:
            want = [a.arg for a in fn.args.args if a.arg not in ("self",)]
            got = [p.strip().split("=")[0].lstrip("$*") for p in sig.strip("()").split(",")]
            got = [g for g in got if g and g not in ("self", "/", "cls", "type")]
            assert want == got, (name, want, got, doc[:40])
    assert callable(pdeshape.fit)


def test_check_reports_creases_and_the_verdict():
    # The lid's crease along the rim, declared by the design: reported, not judged.
    declared = Design.load(EXAMPLES / "cup_closed.toml").check()
    assert declared["verdict"] == "ok"
    rim = next(e for e in declared["edges"] if e["curve"] == "rim")
    assert rim["declared_crease"] and rim["g1"] > 1.4
    text = (EXAMPLES / "cup_closed.toml").read_text().replace('creases = ["rim"]', "")
    closed = Design.from_toml(text, "cup_closed.toml").check()
    assert closed["ok"] and closed["verdict"] == "attention"
    assert {e["curve"] for e in closed["edges"]} == {"belly", "rim"}
    assert closed["report"].startswith("design: ")
    assert closed["warnings"] == []
    assert Design.load(EXAMPLES / "cup.toml").check()["verdict"] == "ok"


def test_parameter_entries_keep_their_own_bounds():
    d = Design.load(EXAMPLES / "swirl_port_params.toml")
    with pytest.raises(DesignError, match=r"params\['theta'\]: .*'theta' lies outside \[min, max\]"):
        d.with_params({"theta": 1.5})
    assert d.with_params({"theta": 0.5}).params() == {"theta": 0.5}
