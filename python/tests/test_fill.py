"""`pdeshape.fill` against `pdeshape fill MESH -o OUT --design D.toml` and against the unit
sphere: the same design text, a watertight mesh near the sphere, long holes split, and errors
that name their place."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pdeshape
from pdeshape import DesignError
from meshes import ellipsoid_obj


def sphere(cut) -> tuple[np.ndarray, np.ndarray]:
    """The unit sphere's latitude-longitude mesh without the triangles whose centroid `cut`
    selects."""
    v, f = [], []
    for line in ellipsoid_obj(60, 120, 1.0, 1.0).splitlines():
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:]])
        elif line.startswith("f "):
            f.append([int(x) - 1 for x in line.split()[1:]])
    v, f = np.array(v), np.array(f)
    keep = np.array([not cut(v[t].mean(axis=0)) for t in f])
    return v, f[keep]


def cap(c) -> bool:
    return c[2] > math.cos(0.5)


def strip(c) -> bool:
    return c[0] > 0 and abs(math.atan2(c[1], c[0])) < 0.8 and abs(c[2]) < 0.1


def obj_text(v, f) -> str:
    return "".join(f"v {float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n" for p in v) + "".join(
        f"f {t[0] + 1} {t[1] + 1} {t[2] + 1}\n" for t in f
    )


def test_fill_equals_the_cli(cli, tmp_path):
    v, f = sphere(cap)
    mesh = tmp_path / "holed.obj"
    mesh.write_text(obj_text(v, f))
    cli("fill", str(mesh), "-o", str(tmp_path / "out.obj"), "--design", str(tmp_path / "d.toml"))
    filled, design = pdeshape.fill(str(mesh), name="holed.obj")
    assert design.text == (tmp_path / "d.toml").read_text()
    assert filled["open_edges"] == 0
    assert len(filled["holes"]) == 1


def test_a_cap_hole_is_filled_watertight_near_the_sphere():
    v, f = sphere(cap)
    filled, design = pdeshape.fill((v, f))
    assert filled["open_edges"] == 0
    assert filled["holes_found"] == 1 and len(filled["holes"]) == 1
    assert filled["mesh_faces"] == len(f)
    new = filled["vertices"][len(v):]
    assert len(new) == filled["holes"][0]["vertices_added"] > 0
    # A flat fill of the cap of angular radius 0.5 would miss the sphere by its sagitta.
    assert np.abs(np.linalg.norm(new, axis=1) - 1).max() < 1 - math.cos(0.5)
    # The design holds the patch: its surface lies near the sphere too.
    m = design.mesh()
    assert np.abs(np.linalg.norm(m["vertices"], axis=1) - 1).max() < 1 - math.cos(0.5)


def test_a_long_hole_is_split_into_pieces():
    v, f = sphere(strip)
    filled, design = pdeshape.fill((v, f))
    h = filled["holes"][0]
    assert filled["open_edges"] == 0
    assert h["pieces"] >= 2
    assert design.text.count("[[disk]]") == h["pieces"]
    assert h["chord_g1_angle"] < 1e-2
    new = filled["vertices"][len(v):]
    assert np.abs(np.linalg.norm(new, axis=1) - 1).max() < 1 - math.cos(0.1)


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"continuity": "g4"}, "continuity 'g4'"),
        ({"largest": 1, "max_boundary": 5}, "not both"),
        ({"largest": 0}, "largest"),
        ({"grading": 3.0}, "grading"),
    ],
)
def test_bad_options_raise_naming_them(kwargs, needle):
    v, f = sphere(cap)
    with pytest.raises(DesignError, match=needle):
        pdeshape.fill((v, f), **kwargs)


def test_bad_meshes_raise_naming_the_place():
    v, f = sphere(lambda c: False)
    with pytest.raises(DesignError, match="no holes"):
        pdeshape.fill((v, f), name="closed.obj")
    with pytest.raises(DesignError, match=r"triangles\[0\]"):
        pdeshape.fill((v, np.array([[0, 1, len(v)]])))
    with pytest.raises(DesignError, match="n × 3"):
        pdeshape.fill((v[:, :2], f))
    with pytest.raises(DesignError, match="needed with mesh bytes"):
        pdeshape.fill(b"v 0 0 0\n")
