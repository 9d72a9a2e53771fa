//! `pdeshape fit`: a mesh in, a design out that `pdeshape surface` reads like any other; bad
//! meshes get one line and no output file.

mod common;

use common::*;

/// An ellipsoid of revolution (semi-axes 1, 1, 1.5) as an OBJ text: `rings` latitude rings of
/// `around` vertices, every other ring turned by half a step, and two poles.
fn ellipsoid_obj(rings: usize, around: usize) -> String {
    let mut out = String::from("# ellipsoid\nv 0 0 -1.5\n");
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..around {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / around as f64;
            out += &format!(
                "v {} {} {}\n",
                t.sin() * phi.cos(),
                t.sin() * phi.sin(),
                -1.5 * t.cos()
            );
        }
    }
    out += "v 0 0 1.5\n";
    let top = 1 + (rings - 1) * around + 1;
    let at = |i: usize, j: usize| 2 + (i - 1) * around + j % around;
    for j in 0..around {
        out += &format!("f 1 {} {}\n", at(1, j + 1), at(1, j));
        out += &format!("f {top} {} {}\n", at(rings - 1, j), at(rings - 1, j + 1));
    }
    for i in 1..rings - 1 {
        for j in 0..around {
            out += &format!("f {} {} {}\n", at(i, j), at(i, j + 1), at(i + 1, j + 1));
            out += &format!("f {} {} {}\n", at(i, j), at(i + 1, j + 1), at(i + 1, j));
        }
    }
    out
}

#[test]
fn fit_writes_a_design_that_surface_reads() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "egg.obj", &ellipsoid_obj(60, 80));
    let design = dir.path().join("egg.toml");
    let json = dir.path().join("egg.json");
    let pic = dir.path().join("egg.png");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--tolerance",
        "2e-3",
        "--json",
        s(&json),
        "--picture",
        s(&pic),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Hausdorff"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let m = &report["measures"];
    let h = m["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    assert!(m["ratio"].as_f64().unwrap() >= 20.0, "{report}");
    assert!(std::fs::read(&pic).unwrap().starts_with(b"\x89PNG"));
    // The design is an ordinary design file.
    let obj = dir.path().join("egg_fit.obj");
    let out = pdeshape(&[
        "surface",
        s(&design),
        "-o",
        s(&obj),
        "--nu",
        "16",
        "--nv",
        "32",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = pdeshape(&["check", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `fit` on a bad mesh file; checks the one-line error and that nothing was written.
fn bad_mesh(name: &str, bytes: &[u8], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join(name);
    std::fs::write(&mesh, bytes).unwrap();
    let design = dir.path().join("out.toml");
    let json = dir.path().join("out.json");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--json", s(&json)]);
    assert_bad(&out, needles);
    assert_eq!(files(dir.path()), vec![name.to_string()]);
}

#[test]
fn bad_meshes_get_one_line_and_no_output() {
    let good = ellipsoid_obj(12, 16);
    bad_mesh("empty.obj", b"", &["empty.obj", "no triangles"]);
    bad_mesh(
        "nan.obj",
        good.replacen("v 0 0 -1.5", "v nan 0 -1.5", 1).as_bytes(),
        &["nan.obj", "vertex 1 is not finite"],
    );
    // Open: the last face removed.
    let open: String = {
        let lines: Vec<&str> = good.lines().collect();
        lines[..lines.len() - 1].join("\n")
    };
    bad_mesh(
        "open.obj",
        open.as_bytes(),
        &["open.obj", "open (3 boundary edges)"],
    );
    // Two components: the ellipsoid twice, the second shifted.
    let n = 2 + 11 * 16;
    let mut two = good.clone();
    for l in good.lines() {
        if let Some(rest) = l.strip_prefix("v ") {
            let c: Vec<f64> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
            two += &format!("v {} {} {}\n", c[0] + 5.0, c[1], c[2]);
        }
    }
    for l in good.lines() {
        if let Some(rest) = l.strip_prefix("f ") {
            let c: Vec<usize> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
            two += &format!("f {} {} {}\n", c[0] + n, c[1] + n, c[2] + n);
        }
    }
    bad_mesh("two.obj", two.as_bytes(), &["2 separate components"]);
    // Non-manifold: a fin on an edge of the first ring.
    let fin = format!("{good}v 3 3 3\nf 2 3 {}\n", n + 1);
    bad_mesh("fin.obj", fin.as_bytes(), &["not manifold"]);
    // Binary STL announcing ten million triangles.
    let mut huge = vec![0u8; 84];
    huge[80..84].copy_from_slice(&10_000_000u32.to_le_bytes());
    bad_mesh("huge.stl", &huge, &["huge.stl", "10000000 triangles"]);
    // Truncated binary STL: two triangles announced, one and a half present.
    let mut cut = vec![0u8; 84 + 75];
    cut[80..84].copy_from_slice(&2u32.to_le_bytes());
    bad_mesh("cut.stl", &cut, &["cut.stl", "truncated"]);
    bad_mesh(
        "cut.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
        &["cut.ply", "PLY"],
    );
    // Bad flags.
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "m.obj", &good);
    let design = dir.path().join("out.toml");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--tolerance", "0"]);
    assert_bad(&out, &["--tolerance 0"]);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--template", "t.toml"]);
    assert_bad(&out, &["--template", "not available"]);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&dir.path().join("x.obj"))]);
    assert_bad(&out, &["-o", ".toml"]);
    assert_eq!(files(dir.path()), vec!["m.obj".to_string()]);
}
