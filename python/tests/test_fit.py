"""`pdeshape.fit` against `pdeshape fit MESH -o design.toml --json report.json`: the same design
text and report; located errors for meshes that cannot be fitted."""

from __future__ import annotations

import json
import math

import pytest

import pdeshape
from pdeshape import Design, DesignError
from meshes import ellipsoid_obj, torus_obj
from test_cli import cli_error


def test_fit_equals_the_cli(cli, tmp_path):
    mesh = tmp_path / "egg.obj"
    mesh.write_text(ellipsoid_obj(60, 80))
    cli("fit", str(mesh), "-o", str(tmp_path / "egg.toml"), "--json", str(tmp_path / "egg.json"))
    d, report = pdeshape.fit(mesh)
    assert isinstance(d, Design) and d.file == "<fit of egg.obj>"
    assert d.text == (tmp_path / "egg.toml").read_text()
    want = json.loads((tmp_path / "egg.json").read_text())
    del want["timings_ms"]
    assert report == want
    # from bytes, with a name: the same design
    d2, r2 = pdeshape.fit(mesh.read_bytes(), name="egg.obj")
    assert d2.text == d.text and r2 == {**report, "mesh": "egg.obj"}
    # the fit holds its tolerance, and the fitted solid has the ellipsoid's volume: the fitted
    # surface lies within the Hausdorff distance h of the mesh, so the volumes differ by at most
    # about area x h, plus the polyhedron's own shortfall (chord sag (pi/60)^2/8 of the radius,
    # ~3.4e-4, times 3 for a volume)
    h = report["measures"]["hausdorff"]
    assert report["measures"]["hausdorff_relative"] <= 2e-3
    total = d.analysis()["total"]
    exact = 4 / 3 * math.pi * 1.0 * 1.0 * 1.5
    assert abs(total["volume"] - exact) <= total["area"] * h + 3 * 3.4e-4 * exact


def test_fit_options_equal_the_cli(cli, tmp_path):
    mesh = tmp_path / "egg.obj"
    mesh.write_text(ellipsoid_obj(60, 80))
    cli("fit", str(mesh), "-o", str(tmp_path / "e.toml"), "--sections", "3", "--tolerance", "5e-3")
    d, report = pdeshape.fit(mesh, tolerance=5e-3, sections=3)
    assert d.text == (tmp_path / "e.toml").read_text() and report["patches"] == 3


def test_fit_errors_equal_the_cli(cli, tmp_path):
    good = ellipsoid_obj(12, 16)
    cases = {
        "empty.obj": "",
        "nan.obj": good.replace("v 0 0 -1.5", "v 0 0 nan", 1),
    }
    for name, text in cases.items():
        mesh = tmp_path / name
        mesh.write_text(text)
        r = cli("fit", str(mesh), "-o", str(tmp_path / "out.toml"), check=False)
        with pytest.raises(DesignError) as e:
            pdeshape.fit(mesh)
        assert str(e.value) == cli_error(r), name
    mesh = tmp_path / "egg.obj"
    mesh.write_text(good)
    r = cli("fit", str(mesh), "-o", str(tmp_path / "out.toml"), "--tolerance", "0", check=False)
    with pytest.raises(DesignError) as e:
        pdeshape.fit(mesh, tolerance=0.0)
    assert str(e.value) == cli_error(r).replace("--", "", 1)
    with pytest.raises(DesignError, match=r"^x\.3ds: unknown mesh format \(the extension must be obj, stl, ply, off, glb or gltf\)"):
        pdeshape.fit(b"3DS", name="x.3ds")
    # An OFF file's errors name its line.
    with pytest.raises(DesignError, match=r"^x\.off: not a readable OFF file: line 2: no count of faces"):
        pdeshape.fit(b"OFF\n3\n", name="x.off")
    with pytest.raises(DesignError, match=r"missing\.stl: cannot read: No such file"):
        pdeshape.fit(tmp_path / "missing.stl")
    with pytest.raises(DesignError, match=r"^name: "):
        pdeshape.fit(b"solid")
    assert not (tmp_path / "out.toml").exists()


def glb_of_obj(obj: str) -> bytes:
    """The OBJ's mesh as a GLB: +Y up (the design's (x, y, z) written (x, z, -y)), metres, f32
    positions and u32 indices, one node, no pdeshape extras."""
    import struct

    points = [tuple(float(w) for w in l.split()[1:4]) for l in obj.splitlines() if l.startswith("v ")]
    faces = [[int(w) - 1 for w in l.split()[1:4]] for l in obj.splitlines() if l.startswith("f ")]
    turned = [(x, z, -y) for x, y, z in points]
    pos = b"".join(struct.pack("<3f", *p) for p in turned)
    stored = [struct.unpack("<3f", pos[12 * k : 12 * k + 12]) for k in range(len(turned))]
    idx = b"".join(struct.pack("<3I", *f) for f in faces)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(turned), "type": "VEC3",
             "min": [min(p[c] for p in stored) for c in range(3)],
             "max": [max(p[c] for p in stored) for c in range(3)]},
            {"bufferView": 1, "componentType": 5125, "count": 3 * len(faces), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "buffers": [{"byteLength": len(pos) + len(idx)}],
    }
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    binary = pos + idx
    total = 12 + 8 + len(js) + 8 + len(binary)
    return (
        b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(js)) + b"JSON" + js
        + struct.pack("<I", len(binary)) + b"BIN\0" + binary
    )


def test_fit_of_a_glb_equals_the_cli(cli, tmp_path):
    mesh = tmp_path / "egg.glb"
    mesh.write_bytes(glb_of_obj(ellipsoid_obj(24, 32)))
    cli("fit", str(mesh), "-o", str(tmp_path / "egg.toml"), "--json", str(tmp_path / "egg.json"))
    d, report = pdeshape.fit(mesh)
    assert d.text == (tmp_path / "egg.toml").read_text()
    # the same report as the CLI's, which adds its timings
    cli_report = json.loads((tmp_path / "egg.json").read_text())
    del cli_report["timings_ms"]
    assert cli_report == report
    # glTF is in metres: the design and the report say so, and the notes say what was turned
    assert '\nunits = "m"\n' in d.text and report["units"] == "m"
    assert any("read as glTF: metres, +Y up, turned to +Z up" in n for n in report["notes"])
    # a damaged GLB: the CLI's one line
    bad = tmp_path / "cut.glb"
    bad.write_bytes(mesh.read_bytes()[:-10])
    r = cli("fit", str(bad), "-o", str(tmp_path / "out.toml"), check=False)
    with pytest.raises(DesignError) as e:
        pdeshape.fit(bad)
    assert str(e.value) == cli_error(r)
    assert "not a readable glTF file: the GLB file is truncated" in str(e.value)
    assert not (tmp_path / "out.toml").exists()


def sheet_obj(rows: int, across: int) -> str:
    """A sheet over [-1, 1] x [-1.5, 1.5] with heights 0.2 sin 2x cos y: rows of `across`
    vertices (every other row shifted by half a step inside), two triangles per cell."""
    out = ["# sheet"]
    for i in range(rows + 1):
        y = -1.5 + 3.0 * i / rows
        for j in range(across):
            shift = 0.5 if i % 2 == 1 and 0 < j < across - 1 else 0.0
            x = -1.0 + 2.0 * (j + shift) / (across - 1)
            out.append(f"v {x!r} {y!r} {0.2 * math.sin(2 * x) * math.cos(y)!r}")
    at = lambda i, j: 1 + i * across + j  # noqa: E731
    for i in range(rows):
        for j in range(across - 1):
            out.append(f"f {at(i, j)} {at(i, j + 1)} {at(i + 1, j + 1)}")
            out.append(f"f {at(i, j)} {at(i + 1, j + 1)} {at(i + 1, j)}")
    return "\n".join(out) + "\n"


def test_open_meshes_fit_as_sheets_as_the_cli_does(cli, tmp_path):
    mesh = tmp_path / "sheet.obj"
    mesh.write_text(sheet_obj(60, 41))
    cli("fit", str(mesh), "-o", str(tmp_path / "s.toml"), "--json", str(tmp_path / "s.json"))
    d, report = pdeshape.fit(mesh)
    assert d.text == (tmp_path / "s.toml").read_text()
    want = json.loads((tmp_path / "s.json").read_text())
    del want["timings_ms"]
    assert report == want
    assert report["mode"] == "sheet"
    assert 0 < report["measures"]["hausdorff_relative"] <= 2e-3


def test_a_torus_falls_back_to_the_general_mode_as_the_cli_does(cli, tmp_path):
    """Neither a tube nor a sheet: the automatic choice fits it by the general mode, in Python
    exactly as in the command (the same design text and report)."""
    mesh = tmp_path / "torus.obj"
    mesh.write_text(torus_obj(48, 16))
    cli("fit", str(mesh), "-o", str(tmp_path / "t.toml"), "--json", str(tmp_path / "t.json"))
    d, report = pdeshape.fit(mesh)
    assert d.text == (tmp_path / "t.toml").read_text()
    want = json.loads((tmp_path / "t.json").read_text())
    del want["timings_ms"]
    assert report == want
    assert report["mode"] == "general" and report["fallback"] and not report["missed"]
    assert report["measures"]["hausdorff_relative"] <= 0.02
    # the fit is one closed surface: its volume is the torus's, 2 pi^2 R r^2, within what the
    # Hausdorff distance h allows (area x h) plus the polyhedron's own shortfall (chord sag
    # (pi/16)^2/8 of the tube radius, times 3 for a volume)
    total = d.analysis()["total"]
    exact = 2 * math.pi**2 * 1.0 * 0.35**2
    h = report["measures"]["hausdorff"]
    assert abs(total["volume"] - exact) <= total["area"] * h + 3 * (math.pi / 16) ** 2 / 8 * exact


def test_a_miss_raises_with_its_point_unless_best_effort(cli, tmp_path):
    mesh = tmp_path / "torus.obj"
    mesh.write_text(torus_obj(24, 8))
    args = ("--mode", "general", "--sections", "8", "--tolerance", "1e-5")
    r = cli("fit", str(mesh), "-o", str(tmp_path / "t.toml"), *args, check=False)
    assert r.returncode == 1 and not (tmp_path / "t.toml").exists()
    with pytest.raises(DesignError, match=r"misses the tolerance [^ ]+% of the diagonal.* at \(") as e:
        pdeshape.fit(mesh, tolerance=1e-5, sections=8, mode="general")
    assert cli_error(r).split("; nothing written")[0] == str(e.value).split(" (a larger")[0]
    d, report = pdeshape.fit(mesh, tolerance=1e-5, sections=8, mode="general", best_effort=True)
    assert report["missed"] and report["mode"] == "general" and report["patches"] > 0
    with pytest.raises(DesignError, match=r"mode 'tubular': 'tubular' is not a mode"):
        pdeshape.fit(mesh, mode="tubular")
