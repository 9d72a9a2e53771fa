"""The NumPy-facing API: broadcasting of the point queries, their domain, the patch they need,
the version, the parameters a design declares, and what the mesh conversions carry."""

from __future__ import annotations

import numpy as np
import pytest

import pdeshape
from conftest import EXAMPLES
from pdeshape import Design, DesignError


@pytest.fixture(scope="module")
def cup():
    d = Design.load(EXAMPLES / "cup.toml")
    d.solve()
    return d


def test_parameters_broadcast_like_numpy(cup):
    # a scalar pair: one point, shape (3,)
    e = cup.evaluate(0.5, 1.0, patch="bowl")
    assert e["x"].shape == (3,) and e["xuv"].shape == (3,)
    flat = cup.evaluate(np.array([0.5]), np.array([1.0]), patch="bowl")
    assert np.array_equal(e["x"], flat["x"][0])
    # lists, and a scalar against a list
    lst = cup.evaluate([0.2, 0.5], 1.0, patch="bowl")
    assert lst["x"].shape == (2, 3)
    assert np.array_equal(lst["x"][1], e["x"])
    # a 2-D meshgrid: every output shaped like it, with a trailing 3 for vectors
    U, V = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 2 * np.pi, 5, endpoint=False))
    g = cup.evaluate(U, V, patch="bowl")
    assert g["x"].shape == (5, 4, 3)
    rows = cup.evaluate(U.ravel(), V.ravel(), patch="bowl")
    assert np.array_equal(g["x"].reshape(-1, 3), rows["x"])
    # broadcasting a column against a row
    b = cup.evaluate(np.linspace(0, 1, 4)[:, None], np.linspace(0, 1, 3)[None, :], patch="bowl")
    assert b["xu"].shape == (4, 3, 3)
    c = cup.curvature(U, V, patch="bowl")
    assert c["gauss"].shape == (5, 4) and c["normal"].shape == (5, 4, 3)
    flat_c = cup.curvature(U.ravel(), V.ravel(), patch="bowl")
    assert np.array_equal(c["mean"].ravel(), flat_c["mean"])
    assert cup.spine(0.5, "bowl").shape == (3,)
    assert cup.spine(np.zeros((2, 2)), "bowl").shape == (2, 2, 3)
    with pytest.raises(DesignError, match=r"^u: must be numbers"):
        cup.evaluate("half", 1.0, patch="bowl")


def test_out_of_domain_parameters_raise_or_clamp(cup):
    with pytest.raises(DesignError, match=r"^u: 1\.5 is outside the domain \[0, 1\] of 'bowl' \(pass clamp=True"):
        cup.evaluate(1.5, 0.0, patch="bowl")
    with pytest.raises(DesignError, match=r"^u: -0\.25 is outside"):
        cup.curvature([0.5, -0.25], 0.0, patch="bowl")
    with pytest.raises(DesignError, match=r"^u: 2 is outside"):
        cup.spine(2.0, "bowl")
    clamped = cup.evaluate([1.5, -0.5], 0.3, patch="bowl", clamp=True)["x"]
    assert np.array_equal(clamped[0], cup.evaluate(1.0, 0.3, patch="bowl")["x"])
    assert np.array_equal(clamped[1], cup.evaluate(0.0, 0.3, patch="bowl")["x"])
    # v is periodic: wrapped, not refused
    a = cup.evaluate(0.5, 0.3 + 2 * np.pi, patch="bowl")["x"]
    assert np.allclose(a, cup.evaluate(0.5, 0.3, patch="bowl")["x"], atol=1e-12)
    with pytest.raises(DesignError, match=r"^v: NaN is not a number"):
        cup.evaluate(0.5, float("nan"), patch="bowl")


def test_patch_is_required_when_the_design_has_several(cup):
    with pytest.raises(DesignError, match=r"^patch: the design has 2 surfaces \(base, bowl\); name one"):
        cup.evaluate(0.5, 1.0)
    with pytest.raises(DesignError, match=r"^patch: the design has 2 surfaces"):
        cup.curvature(0.5, 1.0)
    single = Design.load(EXAMPLES / "laplace_blend.toml")
    assert len(single.patches) == 1
    assert single.evaluate(0.5, 1.0)["x"].shape == (3,)


def test_version():
    assert pdeshape.__version__ == pdeshape.version()
    assert pdeshape.__version__.count(".") >= 2


def test_declared_parameters_are_listed_with_bounds_and_values():
    d = Design.load(EXAMPLES / "swirl_port_params.toml")
    ps = d.parameters()
    names = [p["name"] for p in ps]
    assert {"x1", "y1", "z1", "theta", "s"} <= set(names)
    theta = next(p for p in ps if p["name"] == "theta")
    assert theta["source"] == "parameters" and theta["kind"] == "angle"
    assert (theta["min"], theta["max"]) == (-1.2, 1.2)
    assert theta["min"] <= theta["value"] <= theta["max"]
    assert isinstance(theta["drives"], str) and theta["drives"]
    moved = d.with_params({"theta": 0.5})
    assert next(p for p in moved.parameters() if p["name"] == "theta")["value"] == 0.5
    every = d.parameter_names()
    assert every[: len(names)] == names and "a" in every
    # the cup declares none, but takes the book's names, each of which with_params reads
    cup = Design.load(EXAMPLES / "cup.toml")
    assert cup.parameters() == []
    book = cup.parameter_names()
    assert "a" in book and "bellyTz" in book and "bellyDx" in book
    for n in book:
        if n.endswith(("Tx", "Ty", "Tz", "Rx", "Ry", "Rz")):
            cup.with_params({n: 0.1})
        elif n.endswith(("Dx", "Dy", "Dz")):
            cup.with_params({n: 1.1})


def test_conversions_carry_patch_ids_uv_and_metadata(cup):
    import pyvista
    import trimesh

    m = cup.mesh(16, 32)
    tm = cup.to_trimesh(16, 32)
    patch = tm.face_attributes["patch"]
    assert patch.shape == (len(m["faces"]),)
    for k, (name, start, end) in enumerate(m["parts"]):
        assert np.all(patch[start:end] == k)
    assert tm.metadata["patches"] == ["base", "bowl"]
    assert tm.metadata["title"] == cup.title and tm.metadata["file"] == cup.file
    assert "units" in tm.metadata
    # unwelded: every vertex has its (u, v), the tessellation's
    t = cup.tessellate(16, 32)
    raw = cup.to_trimesh(16, 32, welded=False)
    assert np.array_equal(raw.vertex_attributes["uv"], t["uv"])
    assert np.array_equal(raw.face_attributes["patch"], t["patch"][t["faces"][:, 0]].astype(np.int64))
    assert isinstance(raw, trimesh.Trimesh)
    poly = cup.to_pyvista(16, 32)
    assert np.array_equal(poly.cell_data["patch"], patch)
    assert list(poly.field_data["patches"]) == ["base", "bowl"]
    raw = cup.to_pyvista(16, 32, welded=False)
    assert np.array_equal(raw.point_data["uv"], t["uv"])
    assert isinstance(raw, pyvista.PolyData)
