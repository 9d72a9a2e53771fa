//! End-to-end tests of `pdeshape analyze` and of designs with `[[parametric]]` surfaces.

use crate::common::*;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A sphere of radius 2 written as a design surface.
const SPHERE: &str = r#"title = "ball"
[[parametric]]
name = "ball"
x = "2*sin(pi*u)*cos(v)"
y = "2*sin(pi*u)*sin(v)"
z = "2*cos(pi*u)"

[output]
nu = 12
nv = 16
"#;

#[test]
fn analyze_json_of_a_sphere_matches_closed_forms() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "ball.toml", SPHERE);
    let o = pdeshape(&["analyze", s(&f), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let pi = std::f64::consts::PI;
    let t = &v["total"];
    let get = |k: &str| t[k].as_f64().unwrap();
    assert!(rel(get("area"), 16.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("volume"), 32.0 / 3.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("willmore"), 16.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("bending_energy"), 8.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("gauss_integral"), 4.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("mean_integral"), -8.0 * pi) < 1e-12, "{t}");
    assert!(rel(get("reduced_volume"), 1.0) < 1e-12, "{t}");
    assert_eq!(v["closed"], true);
    assert_eq!(v["title"], "ball");
    let p = &v["patches"][0];
    assert_eq!(p["name"], "ball");
    assert!(rel(p["gauss_min"].as_f64().unwrap(), 0.25) < 1e-12);
    assert!(rel(p["mean_max"].as_f64().unwrap(), -0.5) < 1e-12);
    assert_eq!(p["converged"], true);
}

#[test]
fn analyze_table_of_the_cup() {
    let cup = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cup.toml");
    // Without `units`, no unit is printed.
    let o = pdeshape(&["analyze", cup]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.contains("\npatch") && !out.contains("area ("), "{out}");
    assert!(out.starts_with("total: area "), "{out}");
    // With `units = "cm"`, every dimensioned column says its unit.
    let dir = tempfile::tempdir().unwrap();
    let text = format!("units = \"cm\"\n{}", std::fs::read_to_string(cup).unwrap());
    let cm = write(dir.path(), "cup.toml", &text);
    let o = pdeshape(&["analyze", s(&cm)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    // The summary first: the total's area and volume in the design's units (cm), closed or
    // not, the quadrature's error.
    let first = out.lines().next().unwrap();
    assert!(first.starts_with("total: area "), "{out}");
    for want in [" cm², volume ", " cm³; closed by caps; quadrature error "] {
        assert!(first.contains(want), "missing '{want}' in\n{out}");
    }
    for want in [
        "design: Cup",
        "\nbase ",
        "\nbowl ",
        "\ntotal ",
        "area (cm²)",
        "K min (1/cm²)",
        "closed: no; volume closed by caps over 'bowl' u = 1",
        "reduced volume ν = ",
    ] {
        assert!(out.contains(want), "missing '{want}' in\n{out}");
    }
    // The base is a topological disc closed at a point with a flat bottom: ∫K dA there is
    // 2π minus the total geodesic curvature of its top edge, which is vertical (a parallel of
    // a surface of revolution where the profile is vertical): exactly 2π. The table shows it
    // with four significant digits; the JSON keeps full precision.
    let base = out.lines().find(|l| l.starts_with("base ")).unwrap();
    let cols: Vec<&str> = base.split_whitespace().skip(1).collect();
    assert_eq!(cols.len(), 6, "{base}");
    assert_eq!(cols[4], "6.283", "{base}");
    for c in &cols {
        let digits = c
            .trim_start_matches('-')
            .split('e')
            .next()
            .unwrap()
            .chars()
            .filter(char::is_ascii_digit)
            .collect::<String>();
        let significant = digits.trim_start_matches('0');
        assert_eq!(significant.len(), 4, "{c} in {base}");
    }
    let o = pdeshape(&["analyze", cup, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let base = v["patches"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "base")
        .unwrap();
    let k = base["gauss_integral"].as_f64().unwrap();
    assert!(rel(k, 2.0 * std::f64::consts::PI) < 1e-9, "{k}");
}

#[test]
fn analyze_errors_are_one_line_with_exit_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let bad = SPHERE.replace("2*cos(pi*u)", "2*cos(pi*w)");
    let f = write(dir.path(), "bad.toml", &bad);
    let o = pdeshape(&["analyze", s(&f)]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(
        e.starts_with(&format!(
            "error: {}:6:1: parametric[0].z: unknown variable 'w'",
            s(&f)
        )),
        "{e}"
    );
    assert!(o.stdout.is_empty());
    let good = write(dir.path(), "ball.toml", SPHERE);
    let o = pdeshape(&["analyze", s(&good), "--tolerance", "0"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "error: --tolerance: must be positive and below 1 (got 0)\n"
    );
}

#[test]
fn parametric_designs_write_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "ball.toml", SPHERE);
    let out = dir.path().join("ball.obj");
    let o = pdeshape(&["surface", s(&f), "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    // A 12 × 16 grid whose first and last rows are the poles, each welded into one vertex:
    // 10 × 16 + 2 vertices, all on the sphere of radius 2.
    let vs: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    assert_eq!(vs.len(), 10 * 16 + 2);
    for v in vs {
        let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((r - 2.0).abs() < 1e-6, "{v:?}");
    }
}

#[test]
fn render_colours_by_curvature() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "ball.toml", SPHERE);
    let png = dir.path().join("k.png");
    let o = pdeshape(&[
        "render",
        s(&f),
        "-o",
        s(&png),
        "--color",
        "gauss",
        "--size",
        "80x60",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    // K = 1/4 everywhere (to rounding): a constant, shown on the range 0.25 ± 1 %.
    assert!(
        out.contains("Gaussian curvature from 0.2475 (blue) to 0.2525 (red)"),
        "{out}"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 100);
    let o = pdeshape(&[
        "render",
        s(&f),
        "-o",
        s(&png),
        "--color",
        "mean",
        "--range",
        "-1,0",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8(o.stdout)
        .unwrap()
        .contains("mean curvature from -1.000 (blue) to 0 (red)"));
    // Bad ranges, and a range without a colouring, leave no picture behind.
    let none = dir.path().join("none.png");
    for (args, want) in [
        (
            vec!["--color", "mean", "--range", "1,1"],
            "error: --range: expected two numbers LO,HI with LO < HI (got '1,1')\n",
        ),
        (
            vec!["--range", "0,1"],
            "error: --range: needs --color gauss, mean or shear\n",
        ),
    ] {
        let mut all = vec!["render", s(&f), "-o", s(&none)];
        all.extend(args);
        let o = pdeshape(&all);
        assert_eq!(o.status.code(), Some(2));
        assert_eq!(stderr(&o), want);
        assert!(!none.exists());
    }
    let o = pdeshape(&["render", s(&f), "-o", s(&none), "--color", "area"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).starts_with("error: invalid value 'area' for '--color"),
        "{}",
        stderr(&o)
    );
}
