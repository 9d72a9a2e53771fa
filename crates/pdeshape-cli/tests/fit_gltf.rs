//! `pdeshape fit` on glTF meshes: a `.glb` is read in metres and turned from +Y up to the
//! design's +Z up, and the design carries `units = "m"`; the same mesh as an OBJ fits alike; a
//! `.gltf` reads its buffer beside it; the tool's own GLB and turned OBJ read back as designed;
//! a damaged file gets one line, exit status 2 and no output.

#[path = "cli/common.rs"]
#[allow(unused_imports)]
mod common;

use common::*;
use pdeshape::fit::{InputMesh, MeshFormat};

/// A sphere of radius 0.05 (metres) in the design's frame, `rings` × `around` vertices between
/// the poles, its triangles counter-clockwise seen from outside; coordinates in `f32`.
fn sphere(rings: usize, around: usize) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let r = 0.05f64;
    let mut p = vec![[0.0, 0.0, -r as f32]];
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..around {
            let f = std::f64::consts::TAU * j as f64 / around as f64;
            p.push([
                (r * t.sin() * f.cos()) as f32,
                (r * t.sin() * f.sin()) as f32,
                (-r * t.cos()) as f32,
            ]);
        }
    }
    p.push([0.0, 0.0, r as f32]);
    let at = |i: usize, j: usize| (1 + (i - 1) * around + j % around) as u32;
    let top = (p.len() - 1) as u32;
    let mut t = Vec::new();
    for j in 0..around {
        t.push([0, at(1, j + 1), at(1, j)]);
        t.push([top, at(rings - 1, j), at(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..around {
            t.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    (p, t)
}

/// The OBJ of a mesh, each coordinate written as the double that equals its `f32`.
fn obj_text(p: &[[f32; 3]], t: &[[u32; 3]]) -> String {
    let mut s = String::new();
    for v in p {
        s += &format!("v {} {} {}\n", v[0] as f64, v[1] as f64, v[2] as f64);
    }
    for f in t {
        s += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    s
}

/// The glTF JSON of a mesh given in the design's frame (turned to +Y up: `(x, y, z)` is
/// written `(x, z, −y)`) and its binary buffer; the buffer's `uri` is left to the caller.
fn gltf_parts(p: &[[f32; 3]], t: &[[u32; 3]]) -> (serde_json::Value, Vec<u8>) {
    let turned: Vec<[f32; 3]> = p.iter().map(|v| [v[0], v[2], -v[1]]).collect();
    let mut bin: Vec<u8> = turned
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let plen = bin.len();
    bin.extend(t.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let lo = [0, 1, 2].map(|c| turned.iter().map(|q| q[c]).fold(f32::INFINITY, f32::min));
    let hi = [0, 1, 2].map(|c| {
        turned
            .iter()
            .map(|q| q[c])
            .fold(f32::NEG_INFINITY, f32::max)
    });
    let doc = serde_json::json!({
        "asset": { "version": "2.0", "generator": "a test" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": p.len(), "type": "VEC3",
              "min": lo, "max": hi },
            { "bufferView": 1, "componentType": 5125, "count": 3 * t.len(), "type": "SCALAR" },
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": plen },
            { "buffer": 0, "byteOffset": plen, "byteLength": bin.len() - plen },
        ],
        "buffers": [{ "byteLength": bin.len() }],
    });
    (doc, bin)
}

fn glb(doc: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(doc).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((28 + j.len() + b.len()) as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(b);
    out
}

/// Fits `mesh` by the tube mode, whose design depends on the surface only (the general mode
/// breaks ties between equal collapses by vertex number, which the OBJ parser gives in the
/// order faces first use them and glTF in its accessor's order).
fn fit_ok(mesh: &Path, design: &Path) -> String {
    let out = pdeshape(&["fit", s(mesh), "-o", s(design), "--mode", "tube"]);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{stderr}");
    stderr
}

/// The design's text after its title line.
fn body(p: &Path) -> String {
    let t = std::fs::read_to_string(p).unwrap();
    t.split_once('\n').unwrap().1.to_string()
}

/// A GLB sphere in metres fits, its design in metres; the same sphere as an OBJ in the
/// design's frame gives the same design but for the units; the `.gltf` with its buffer beside
/// it too.
#[test]
fn a_glb_sphere_fits_in_metres_like_the_same_obj() {
    let dir = tempfile::tempdir().unwrap();
    let (p, t) = sphere(24, 32);
    let (doc, bin) = gltf_parts(&p, &t);
    let sphere_glb = dir.path().join("sphere.glb");
    std::fs::write(&sphere_glb, glb(&doc, &bin)).unwrap();
    let sphere_obj = write(dir.path(), "sphere.obj", &obj_text(&p, &t));
    let (a, b) = (dir.path().join("a.toml"), dir.path().join("b.toml"));
    let stderr = fit_ok(&sphere_glb, &a);
    assert!(
        stderr.contains("read as glTF: metres, +Y up, turned to +Z up"),
        "{stderr}"
    );
    fit_ok(&sphere_obj, &b);
    let (ga, ob) = (body(&a), body(&b));
    assert!(ga.contains("units = \"m\"\n"), "{ga}");
    assert!(!ob.contains("units ="), "{ob}");
    assert!(
        ga.replacen("units = \"m\"\n", "", 1) == ob,
        "the GLB's design differs from the OBJ's beyond its units"
    );
    // The design is in metres: a sphere of radius 0.05.
    let design = pdeshape::open::open(&a).unwrap().spec;
    assert_eq!(design.units, Some(pdeshape::spec::Units::Metre));
    // The reports say in which units their distances are: the GLB's in metres, the OBJ's in
    // the file's own (none stated), the same numbers (the two meshes are the same points).
    let report = |mesh: &Path, name: &str| {
        let (design, json) = (
            dir.path().join(name),
            dir.path().join(format!("{name}.json")),
        );
        let out = pdeshape(&["fit", s(mesh), "-o", s(&design), "--json", s(&json)]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&std::fs::read(&json).unwrap()).unwrap()
    };
    let (rg, ro) = (report(&sphere_glb, "g.toml"), report(&sphere_obj, "o.toml"));
    assert_eq!(
        (&rg["units"], &ro["units"]),
        (&serde_json::json!("m"), &serde_json::json!(null))
    );
    let diagonal = |r: &serde_json::Value| r["measures"]["diagonal"].as_f64().unwrap();
    // The polyhedron's box in metres: a cube of side 2 r (the poles, and the equator's points
    // at 0°, 90°, 180° and 270°), r the f32 nearest 0.05, so its diagonal is 2 r √3 to the
    // rounding of a norm (a few ε); in millimetres it would be 1000 times that.
    let cube = 2.0 * f64::from(0.05f32) * 3f64.sqrt();
    assert!(
        (diagonal(&rg) - cube).abs() <= 4.0 * f64::EPSILON * cube,
        "{rg}"
    );
    assert_eq!(diagonal(&rg), diagonal(&ro));
    assert!(
        rg["notes"][0]
            .as_str()
            .unwrap()
            .starts_with("read as glTF: metres"),
        "{rg}"
    );
    // A .gltf with its buffer in a file beside it (a name with a space, percent-encoded).
    let sub = dir.path().join("scan");
    std::fs::create_dir(&sub).unwrap();
    let mut doc = doc;
    doc["buffers"][0]["uri"] = serde_json::json!("sphere%20data.bin");
    let gltf = sub.join("sphere.gltf");
    std::fs::write(&gltf, serde_json::to_vec(&doc).unwrap()).unwrap();
    let c = dir.path().join("c.toml");
    let design = dir.path().join("missing.toml");
    let out = pdeshape(&["fit", s(&gltf), "-o", s(&design)]);
    assert_bad(
        &out,
        &["sphere.gltf: not a readable glTF file: buffers[0]: sphere%20data.bin: cannot read"],
    );
    assert!(!design.exists());
    std::fs::write(sub.join("sphere data.bin"), &bin).unwrap();
    fit_ok(&gltf, &c);
    assert_eq!(body(&c), ga);
}

/// A damaged GLB: exit status 2, one line naming the place, no output file.
#[test]
fn a_bad_glb_gets_one_line_and_no_output() {
    let (p, t) = sphere(6, 8);
    let (doc, bin) = gltf_parts(&p, &t);
    let good = glb(&doc, &bin);
    let mut index = bin.clone();
    let at = 12 * p.len() + 4 * 5;
    index[at..at + 4].copy_from_slice(&1000u32.to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "cut.glb",
            good[..good.len() - 9].to_vec(),
            "the GLB file is truncated",
        ),
        (
            "index.glb",
            glb(&doc, &index),
            "meshes[0].primitives[0]: index 1000 (accessors[1] element 5)",
        ),
        ("text.glb", b"solid x\n".to_vec(), "neither a GLB"),
    ];
    for (name, bytes, want) in cases {
        let dir = tempfile::tempdir().unwrap();
        let mesh = dir.path().join(name);
        std::fs::write(&mesh, bytes).unwrap();
        let design = dir.path().join("out.toml");
        let out = pdeshape(&["fit", s(&mesh), "-o", s(&design)]);
        assert_bad(&out, &[name, "not a readable glTF file", want]);
        assert_eq!(files(dir.path()), vec![name.to_string()]);
    }
}

/// The tool's own GLB of a design in cm and its OBJ written `--up y` read back as the design's
/// own OBJ: the OBJ exactly (the turn moves and negates numbers), the GLB within the f32
/// rounding of each coordinate scaled to metres (2⁻²⁴ of its size, against the design's f32
/// coordinate), in cm.
#[test]
fn the_tools_own_glb_and_turned_obj_read_back_in_the_designs_frame() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example_path("cup.toml")).unwrap();
    assert!(!text.contains("\nunits"), "the example states its units");
    let design = write(dir.path(), "cup.toml", &format!("units = \"cm\"\n{text}"));
    let mut read = Vec::new();
    for (file, up) in [("ref.obj", None), ("up.obj", Some("y")), ("cup.glb", None)] {
        let path = dir.path().join(file);
        let mut args = vec![
            "surface",
            s(&design),
            "-o",
            s(&path),
            "--nu",
            "12",
            "--nv",
            "20",
            "-q",
        ];
        if let Some(u) = up {
            args.extend(["--up", u]);
        }
        let out = pdeshape(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let format = MeshFormat::from_extension(file.rsplit('.').next().unwrap()).unwrap();
        let r = InputMesh::read_report(&std::fs::read(&path).unwrap(), format).unwrap();
        assert_eq!(r.units, Some(pdeshape::spec::Units::Centimetre), "{file}");
        read.push(r.mesh);
    }
    let (reference, up, glb) = (&read[0], &read[1], &read[2]);
    assert_eq!(up, reference);
    assert_eq!(glb.positions.len(), reference.positions.len());
    assert_eq!(glb.triangles.len(), reference.triangles.len());
    // The welds may number vertices apart: each GLB vertex has its design vertex within the
    // rounding.
    let mut worst = 0.0f64;
    for q in &glb.positions {
        // The OBJ's text of each f32, read in double precision, rounds back to that f32.
        let ok = reference.positions.iter().any(|p| {
            (0..3).all(|c| {
                let x = p[c] as f32 as f64;
                (q[c] - x).abs() <= x.abs() * 2f64.powi(-24) * 1.000001
            })
        });
        let d = reference
            .positions
            .iter()
            .map(|p| (q - p).norm())
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(d);
        assert!(ok, "{q:?}: nearest design vertex at {d}");
    }
    assert!(worst < 1e-5, "{worst}");
}
