//! `pdeshape fill`: a mesh with holes in, the mesh with its holes filled out (watertight when
//! holes were its only openings); bad meshes and options get one line and no output file.

use crate::common::*;
use pdeshape::fill::open_edges;
use pdeshape::fit::{InputMesh, MeshFormat};

/// A latitude–longitude sphere of radius 2 as an OBJ text (`rings` rings of `around` vertices
/// between the poles, counterclockwise seen from outside), with the triangles above latitude
/// `cut` (radians, none if `cut ≥ π/2`) left out: a round hole about the north pole.
fn sphere_obj(rings: usize, around: usize, cut: f64) -> String {
    let mut text = String::from("v 0 0 -2\n");
    let lat = |i: usize| {
        -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / (rings + 1) as f64
    };
    for i in 1..=rings {
        for j in 0..around {
            let (phi, t) = (
                lat(i),
                std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / around as f64,
            );
            text += &format!(
                "v {} {} {}\n",
                2.0 * phi.cos() * t.cos(),
                2.0 * phi.cos() * t.sin(),
                2.0 * phi.sin()
            );
        }
    }
    text += "v 0 0 2\n";
    let north = rings * around + 2;
    let id = |i: usize, j: usize| 2 + (i - 1) * around + j % around;
    let keep = |i: usize| lat(i) < cut;
    for j in 0..around {
        text += &format!("f 1 {} {}\n", id(1, j + 1), id(1, j));
    }
    for i in 1..rings {
        if !keep(i + 1) {
            break;
        }
        for j in 0..around {
            // Ring i is turned by half a step when i is odd.
            let a = if i % 2 == 1 { j + 1 } else { j };
            text += &format!("f {} {} {}\n", id(i, j), id(i, j + 1), id(i + 1, a));
            text += &format!(
                "f {} {} {}\n",
                id(i, j),
                id(i + 1, a),
                id(i + 1, a + around - 1)
            );
        }
    }
    if keep(rings) {
        for j in 0..around {
            text += &format!("f {} {} {north}\n", id(rings, j), id(rings, j + 1));
        }
    }
    text
}

fn read_ply(path: &std::path::Path) -> InputMesh {
    InputMesh::read(&std::fs::read(path).unwrap(), MeshFormat::Ply).unwrap()
}

#[test]
fn the_generator_is_closed_and_the_hole_is_one_loop() {
    let dir = tempfile::tempdir().unwrap();
    for (cut, open) in [(2.0, 0), (1.0, 40)] {
        let p = write(dir.path(), "s.obj", &sphere_obj(30, 40, cut));
        let m = InputMesh::read(&std::fs::read(&p).unwrap(), MeshFormat::Obj).unwrap();
        assert_eq!(open_edges(&m.triangles), open);
    }
}

#[test]
fn fill_makes_a_holed_sphere_watertight_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "holed.obj", &sphere_obj(30, 40, 1.0));
    for (continuity, ext) in [("g1", "ply"), ("g2", "obj"), ("g0", "stl"), ("g1", "glb")] {
        let outp = dir.path().join(format!("filled_{continuity}.{ext}"));
        let out = pdeshape(&["fill", s(&mesh), "-o", s(&outp), "--continuity", continuity]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{stdout} {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            stdout.contains("filled 1 of 1 holes") && stdout.contains("watertight"),
            "{stdout}"
        );
        assert!(std::fs::metadata(&outp).unwrap().len() > 0);
        if ext == "ply" {
            // Read back: closed, and the fill close to the sphere of radius 2. The hole's loop
            // is the ring at latitude −π/2 + 25π/31, a cap of angular radius α = 0.608; the
            // biharmonic fill of a cap lies within 2R⁴ of the unit sphere, R = tan(α/2) (see
            // the library's fill tests): 0.0385 at radius 2.
            let m = read_ply(&outp);
            assert_eq!(open_edges(&m.triangles), 0);
            let worst = m
                .positions
                .iter()
                .map(|p| (p.norm() - 2.0).abs())
                .fold(0.0, f64::max);
            assert!(worst < 0.0385, "{worst}");
        }
    }
}

#[test]
fn bad_meshes_and_options_get_one_line_and_no_output() {
    let holed = sphere_obj(12, 16, 1.0);
    let run = |name: &str, bytes: &[u8], extra: &[&str], out_name: &str, needles: &[&str]| {
        let sub = tempfile::tempdir().unwrap();
        let mesh = sub.path().join(name);
        std::fs::write(&mesh, bytes).unwrap();
        let outp = sub.path().join(out_name);
        let mut args = vec!["fill", s(&mesh), "-o", s(&outp)];
        args.extend_from_slice(extra);
        let out = pdeshape(&args);
        assert_bad(&out, needles);
        assert_eq!(files(sub.path()), vec![name.to_string()]);
    };
    run(
        "empty.obj",
        b"",
        &[],
        "o.obj",
        &["empty.obj", "no triangles"],
    );
    run(
        "closed.obj",
        sphere_obj(12, 16, 2.0).as_bytes(),
        &[],
        "o.obj",
        &["closed.obj", "no holes"],
    );
    // A third triangle on an edge of the mesh.
    let mut three = holed.clone();
    three += "v 5 5 5\nf 1 2 3000\n";
    let count = holed.lines().filter(|l| l.starts_with("v ")).count() + 1;
    let three = three.replace("f 1 2 3000", &format!("f 1 3 {count}"));
    run(
        "nonmanifold.obj",
        three.as_bytes(),
        &[],
        "o.obj",
        &["nonmanifold.obj", "not manifold"],
    );
    run(
        "holed.obj",
        holed.as_bytes(),
        &["--grading", "2"],
        "o.obj",
        &["--grading", "0 to 1"],
    );
    run(
        "holed.obj",
        holed.as_bytes(),
        &["--largest", "0"],
        "o.obj",
        &["--largest"],
    );
    run(
        "holed.obj",
        holed.as_bytes(),
        &["--max-boundary", "3"],
        "o.obj",
        &["--max-boundary", "no hole"],
    );
    // The hole is all of the sphere but a cap of two rings about the south pole.
    run(
        "cap.obj",
        sphere_obj(12, 16, -1.0).as_bytes(),
        &[],
        "o.obj",
        &[
            "cap.obj",
            "hole 1 (at vertex",
            "no chord inside it splits it",
        ],
    );
    run("holed.obj", holed.as_bytes(), &[], "o.csv", &["o.csv"]);
    // --design: the same file as -o, and a refused hole: neither file is written.
    let sub = tempfile::tempdir().unwrap();
    let cap = write(sub.path(), "cap.obj", &sphere_obj(12, 16, -1.0));
    let o = sub.path().join("o.obj");
    let d = sub.path().join("d.toml");
    let out = pdeshape(&["fill", s(&cap), "-o", s(&o), "--design", s(&o)]);
    assert_bad(&out, &["--design", "the same file as -o"]);
    let out = pdeshape(&["fill", s(&cap), "-o", s(&o), "--design", s(&d)]);
    assert_bad(&out, &["cap.obj", "no chord inside it splits it"]);
    assert_eq!(files(sub.path()), vec!["cap.obj".to_string()]);
    run(
        "holed.txt",
        holed.as_bytes(),
        &[],
        "o.obj",
        &[
            "holed.txt",
            "unknown mesh format (the extension must be obj, stl, ply, off, glb or gltf)",
        ],
    );
}

#[test]
fn fill_splits_a_long_hole_and_says_so() {
    // An 8:1 strip cut from a graded sphere: split along chords, watertight.
    let holed = pdeshape_testkit::hole_meshes::sphere_hole_where(0.02, 5, |x, y| {
        x.abs() < 0.8 && y.abs() < 0.1
    });
    let mut text = String::new();
    for p in &holed.mesh.positions {
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for t in &holed.mesh.triangles {
        text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "strip.obj", &text);
    let outp = dir.path().join("closed.ply");
    let design = dir.path().join("fill.toml");
    let out = pdeshape(&["fill", s(&mesh), "-o", s(&outp), "--design", s(&design)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains(" pieces along chords") && stdout.contains("watertight"),
        "{stdout}"
    );
    let m = read_ply(&outp);
    assert_eq!(open_edges(&m.triangles), 0);
    // The patches as a design file: one [[disk]] table per piece, which check, surface and
    // render read.
    let text = std::fs::read_to_string(&design).unwrap();
    let pieces: usize = stdout
        .split(" pieces along chords")
        .next()
        .and_then(|a| a.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert_eq!(text.matches("[[disk]]").count(), pieces, "{text}");
    let out = pdeshape(&["check", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let obj = dir.path().join("patches.obj");
    let out = pdeshape(&["surface", s(&design), "-o", s(&obj)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let back = InputMesh::read(&std::fs::read(&obj).unwrap(), MeshFormat::Obj).unwrap();
    // The patches lie near the unit sphere (the strip is 0.2 wide: within its sagitta).
    let worst = back
        .positions
        .iter()
        .map(|p| (p.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1.0 - 0.1f64.cos(), "{worst}");
    let png = dir.path().join("patches.png");
    let out = pdeshape(&["render", s(&design), "-o", s(&png), "--size", "200x150"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}
