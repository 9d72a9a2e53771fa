//! End-to-end tests of `pdeshape spline`: the control net as JSON (exact fractions), IGES, meshes,
//! the report on stdout, and bad input (exit 2, one located `error:` line, no output file).

use crate::common::*;

/// Seed 003 Example 1 with the printed boundary points, exact arithmetic.
const EXAMPLE1: &str = r#"title = "example 1"

[spline]
degree = [3, 3]
knots_u = [0, 1, 2, 3, 4, 5, 6, 7]
knots_v = [0, 1, 2, 3, 4, 5, 6, 7]
exact = true
operator = { kind = "second-order", a = 1, b = -2, c = 1 }
fixed = [
  { index = [0, 0], point = [1, 1, 1] },
  { index = [0, 1], point = [1, 2, -8] },
  { index = [0, 2], point = [1, 3, 8] },
  { index = [0, 3], point = [1, 4, 1] },
]
"#;

/// A harmonic Bézier patch of degree 3 from its first and last rows.
const HARMONIC: &str = r#"[spline]
degree = [3, 3]
operator = { kind = "laplace" }
fix = "first-last-rows"
net = [
  [[0, 0, 0], [0, 1, 1], [0, 2, 1], [0, 3, 0]],
  [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]],
  [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]],
  [[3, 0, 0], [3, 1, -1], [3, 2, 0.5], [3, 3, 0]],
]

[output]
nu = 5
nv = 6
"#;

/// Runs `spline` on a bad design: status 2, one `error:` line with every needle, no output file.
fn bad(text: &str, out_name: &str, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", text);
    let out_path = dir.path().join(out_name);
    let out = pdeshape(&["spline", s(&d), "-o", s(&out_path)]);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in: {stderr}");
    }
    assert!(out.stdout.is_empty());
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
    lines[0].to_string()
}

#[test]
fn example1_json_has_exact_fractions_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", EXAMPLE1);
    let o = dir.path().join("net.json");
    let out = pdeshape(&["spline", s(&d), "-o", s(&o)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("rank 9 (PDE alone: rank 9 in 16 control points)"),
        "{stdout}"
    );
    assert!(stdout.contains("solution set of dimension 3"), "{stdout}");
    assert!(stdout.contains("exact rational"), "{stdout}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&o).unwrap()).unwrap();
    assert_eq!(j["degree"], serde_json::json!([3, 3]));
    assert_eq!(j["report"]["rank"], 9);
    assert_eq!(j["report"]["freedom"], 3);
    // The functional ∫|x_u − x_v|² continues P_{0,j} along the diagonals: P_{1,3} = P_{0,4}
    // extrapolated, exactly.
    assert_eq!(j["control_exact"][0][3], serde_json::json!(["1", "4", "1"]));
    assert_eq!(j["control_exact"][1][2], j["control_exact"][0][3]);
    assert!(j["control_exact"][3][3][2].as_str().is_some());
}

#[test]
fn harmonic_patch_as_iges_and_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", HARMONIC);
    let igs = dir.path().join("h.igs");
    let out = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(["spline", s(&d), "-o", s(&igs)])
        .env("SOURCE_DATE_EPOCH", "0")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&igs).unwrap();
    assert!(text.lines().all(|l| l.len() == 80));
    assert!(text.contains("15H19700101.000000"));
    let t = text.lines().last().unwrap();
    assert!(t.starts_with("S      1G      "), "{t}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("determined: 8, free: 0"));
    for ext in ["obj", "stl", "ply", "glb", "csv", "json"] {
        let o = dir.path().join(format!("h.{ext}"));
        let out = pdeshape(&["spline", s(&d), "-o", s(&o)]);
        assert!(
            out.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(&o).unwrap().len() > 0);
    }
    // The OBJ has the [output] grid: 5 × 6 vertices; corners are corner control points.
    let obj = std::fs::read_to_string(dir.path().join("h.obj")).unwrap();
    let verts: Vec<&str> = obj.lines().filter(|l| l.starts_with("v ")).collect();
    assert_eq!(verts.len(), 30);
    let first: Vec<f64> = verts[0]
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(first, vec![0.0, 0.0, 0.0]);
    let last: Vec<f64> = verts[29]
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(last, vec![3.0, 3.0, 0.0]);
}

#[test]
fn bad_spline_designs_are_located_and_leave_nothing() {
    let line = bad(
        &EXAMPLE1.replace("point = [1, 4, 1] }", "point = [1, 4, 1] },\n  { index = [1, 0], point = [0, 0, 50] },\n  { index = [1, 1], point = [0, 0, -50] },\n  { index = [2, 0], point = [0, 9, 50] },\n  { index = [2, 1], point = [7, 0, -50] }"),
        "o.json",
        &["d.toml:", "spline.fixed:", "cannot hold", "the coefficient of s^"],
    );
    assert!(line.contains("d.toml:9:"), "{line}");
    bad(
        &EXAMPLE1.replace("index = [0, 3]", "index = [0, 4]"),
        "o.json",
        &[
            "d.toml:13:",
            "spline.fixed[3].index",
            "does not exist",
            "4 × 4",
        ],
    );
    bad(
        &EXAMPLE1.replace("index = [0, 3]", "index = [0, 2]"),
        "o.igs",
        &["spline.fixed[3].index", "already fixed by spline.fixed[2]"],
    );
    bad(
        &EXAMPLE1.replace(
            "knots_u = [0, 1, 2, 3, 4, 5, 6, 7]",
            "knots_u = [0, 1, 2, 3, 4, 3, 6, 7]",
        ),
        "o.json",
        &["d.toml:5:", "spline.knots_u", "must not decrease"],
    );
    bad(
        &EXAMPLE1.replace("exact = true", "exact = true\ncolour = 3"),
        "o.json",
        &["spline", "colour"],
    );
    bad(
        &EXAMPLE1.replace("kind = \"second-order\"", "kind = \"third-order\""),
        "o.json",
        &["spline.operator", "third-order"],
    );
    bad(
        &EXAMPLE1.replace("a = 1, b = -2, c = 1", "a = 0"),
        "o.json",
        &["spline.operator", "every coefficient is zero"],
    );
    bad(
        &EXAMPLE1.replace("degree = [3, 3]", "degree = [0, 3]"),
        "o.json",
        &["d.toml:4:", "spline.degree[0]"],
    );
    bad(
        HARMONIC
            .replace(
                "[0, 3, 0]],\n  [[0, 0, 0]",
                "[0, 3, 0]],\n  [[0, 0, 0], [0, 0, 0]",
            )
            .as_str(),
        "o.obj",
        &["spline.net[1]", "needs n_v = 4"],
    );
    bad(EXAMPLE1, "o.txt", &["-o", "unknown output extension"]);
    bad("title = \"x\"\n", "o.json", &["no [spline] section"]);
}

/// The CSV gives `u` and `v` in the same convention: the knot domains (`[3, 4]` for both knot
/// vectors of example 1), u outer and v inner.
#[test]
fn spline_csv_gives_u_and_v_in_the_knot_domain() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "e1.toml", EXAMPLE1);
    let o = dir.path().join("e1.csv");
    let out = pdeshape(&["spline", s(&d), "-o", s(&o), "--nu", "5", "--nv", "7"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&o).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("u,v,x,y,z,nx,ny,nz"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 35);
    let us: Vec<f64> = rows.iter().step_by(7).map(|r| r[0]).collect();
    let vs: Vec<f64> = rows[..7].iter().map(|r| r[1]).collect();
    assert_eq!(us, vec![3.0, 3.25, 3.5, 3.75, 4.0]);
    let expected_v: Vec<f64> = (0..7).map(|j| 3.0 + j as f64 / 6.0).collect();
    for (v, e) in vs.iter().zip(&expected_v) {
        assert!((v - e).abs() < 1e-15, "{vs:?}");
    }
    // Every row of one u holds that u; every column of one v holds that v.
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0], us[k / 7]);
        assert_eq!(r[1], vs[k % 7]);
    }
}

/// The IGES Global section declares the design's `units` (flag and name; mm when absent).
#[test]
fn spline_iges_declares_the_design_units() {
    let dir = tempfile::tempdir().unwrap();
    let global = |text: &str| -> String {
        text.lines()
            .filter(|l| l.as_bytes().get(72) == Some(&b'G'))
            .map(|l| &l[..72])
            .collect::<String>()
    };
    for (units, expected) in [
        (None, ",2,2HMM,"),
        (Some("in"), ",1,4HINCH,"),
        (Some("m"), ",6,1HM,"),
        (Some("cm"), ",10,2HCM,"),
    ] {
        let text = match units {
            None => EXAMPLE1.to_string(),
            Some(u) => EXAMPLE1.replace("[spline]", &format!("units = \"{u}\"\n\n[spline]")),
        };
        let d = write(dir.path(), "u.toml", &text);
        let o = dir.path().join("u.igs");
        let out = pdeshape(&["spline", s(&d), "-o", s(&o)]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let g = global(&std::fs::read_to_string(&o).unwrap());
        assert!(g.contains(expected), "{units:?}: {g}");
    }
}
