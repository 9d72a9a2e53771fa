//! End-to-end tests of `pdeshape surface` with the finite-difference solver (`solver = "fd"`):
//! the surface agrees with the analytic solver's to the scheme's O(h²), and designs the scheme
//! cannot take give exit status 2 with one located `error:` line and no output file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A biharmonic design that is valid; the bad cases below each break one thing in it.
const GOOD: &str = r#"title = "test design"
conditions = [
  { u = 0.0, curve = "base" },
  { u = 0.0, derivative = 1, curve = "base_tangent" },
  { u = 1.0, curve = "rim" },
  { u = 1.0, derivative = 1, curve = "rim_tangent" },
]

[operator]
kind = "polyharmonic"
order = 2
a = 1.5

[curves.base]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.base_ahead]
type = "circle"
center = [0.0, 0.0, 1.0]
radius = 1.2

[curves.base_tangent]
type = "derivative"
position = "base"
direction = "base_ahead"
scale = 1.0

[curves.rim]
type = "ellipse"
center = [0.0, 0.0, 2.0]
rx = 1.5
ry = 1.0

[curves.rim_ahead]
type = "circle"
center = [0.0, 0.0, 3.0]
radius = 1.5

[curves.rim_tangent]
type = "derivative"
position = "rim"
direction = "rim_ahead"
scale = 1.0

[output]
nu = 16
nv = 24
"#;

fn pdeshape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(args)
        .output()
        .expect("the pdeshape binary runs")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Replaces exactly one occurrence of `from` in `text`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "'{from}' must occur once");
    text.replace(from, to)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Status 2, exactly one stderr line `error: …` containing every `needle`, nothing on stdout.
fn assert_bad(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line expected on stderr, got: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in: {stderr}");
    }
    assert!(
        out.stdout.is_empty(),
        "stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    lines[0].to_string()
}

/// The files in `dir` (names), to check that nothing was left behind.
fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Runs `surface` on a design text that is bad; checks the error and that no output (and no
/// temporary file) exists afterwards.
fn bad_design(text: &str, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", text);
    let out_path = dir.path().join("out.obj");
    let out = pdeshape(&["surface", s(&d), "-o", s(&out_path)]);
    let line = assert_bad(&out, needles);
    assert!(!out_path.exists());
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
    // `check` reports the same error.
    let out = pdeshape(&["check", s(&d)]);
    assert_eq!(assert_bad(&out, needles), line);
    line
}

/// `u,v,x,y,z,…` rows of a CSV file.
fn csv_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect()
}

/// Largest distance between the FD and analytic surfaces on the output grid.
fn fd_against_analytic(dir: &Path, grid: [usize; 2]) -> f64 {
    let fd = edit(
        GOOD,
        "title = \"test design\"\n",
        &format!(
            "title = \"test design\"\nsolver = {{ method = \"fd\", grid = [{}, {}] }}\n",
            grid[0], grid[1]
        ),
    );
    let a = write(dir, "a.toml", GOOD);
    let f = write(dir, "f.toml", &fd);
    let (ao, fo) = (dir.join("a.csv"), dir.join("f.csv"));
    let out = pdeshape(&["surface", s(&a), "-o", s(&ao)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = pdeshape(&["surface", s(&f), "-o", s(&fo)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("finite differences on {} × {}", grid[0], grid[1])),
        "{stdout}"
    );
    let (ra, rf) = (csv_rows(&ao), csv_rows(&fo));
    assert_eq!(ra.len(), 16 * 24);
    assert_eq!(ra.len(), rf.len());
    let mut worst: f64 = 0.0;
    for (p, q) in ra.iter().zip(&rf) {
        assert_eq!(p[..2], q[..2], "same (u, v)");
        let d = ((p[2] - q[2]).powi(2) + (p[3] - q[3]).powi(2) + (p[4] - q[4]).powi(2)).sqrt();
        worst = worst.max(d);
    }
    worst
}

#[test]
fn fd_surface_converges_to_the_analytic_surface() {
    let dir = tempfile::tempdir().unwrap();
    let e1 = fd_against_analytic(dir.path(), [16, 32]);
    let e2 = fd_against_analytic(dir.path(), [32, 64]);
    // Second order: halving h divides the error by about 4 (the output grid is evaluated
    // through the bicubic interpolant, whose O(h⁴) error is smaller still).
    let order = (e1 / e2).log2();
    assert!(order >= 1.8, "errors {e1:e}, {e2:e}: order {order}");
    assert!(e2 < 1e-2, "{e2:e}");
}

#[test]
fn fd_surface_writes_every_format_and_a_picture() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(
        dir.path(),
        "d.toml",
        &edit(
            GOOD,
            "title = \"test design\"\n",
            "title = \"test design\"\nsolver = \"fd\"\n",
        ),
    );
    for ext in ["obj", "stl", "ply", "glb", "csv"] {
        let o = dir.path().join(format!("out.{ext}"));
        let pic = dir.path().join(format!("pic_{ext}.png"));
        let out = pdeshape(&[
            "surface",
            s(&d),
            "-o",
            s(&o),
            "--picture",
            s(&pic),
            "--timings",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(std::fs::metadata(&o).unwrap().len() > 100, "{ext}");
        let png = std::fs::read(&pic).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let timings = String::from_utf8_lossy(&out.stderr);
        assert!(timings.contains("solve_ms"), "{timings}");
    }
}

#[test]
fn fd_refuses_intermediate_conditions() {
    let t = edit(
        GOOD,
        "title = \"test design\"\n",
        "title = \"test design\"\nsolver = \"fd\"\n",
    );
    let t = edit(
        &t,
        "{ u = 1.0, derivative = 1, curve = \"rim_tangent\" }",
        "{ u = 0.5, curve = \"rim_tangent\" }",
    );
    let line = bad_design(&t, &["d.toml:7:", "conditions[3].u", "u = 0 and u = 1"]);
    assert!(line.contains("0.5"), "{line}");
}

#[test]
fn fd_refuses_small_grids_and_other_operators() {
    let fd = |s: &str| {
        edit(
            GOOD,
            "title = \"test design\"\n",
            &format!("title = \"test design\"\n{s}\n"),
        )
    };
    bad_design(
        &fd("solver = { method = \"fd\", grid = [2, 64] }"),
        &["d.toml:2:", "solver.grid[0]", "at least 4"],
    );
    bad_design(
        &fd("solver = { method = \"fd\", grid = [16, 3] }"),
        &["d.toml:2:", "solver.grid[1]", "at least 5"],
    );
    bad_design(
        &fd("solver = { grid = [16, 16] }"),
        &["d.toml:2:", "solver.grid", "method = \"fd\""],
    );
    bad_design(
        &fd("solver = \"spectral\""),
        &["d.toml:2:", "solver", "spectral"],
    );
    let general = edit(
        &fd("solver = \"fd\""),
        "kind = \"polyharmonic\"\norder = 2\na = 1.5",
        "kind = \"general\"\ncoefficients = [1.0, 2.0, 1.0]",
    );
    bad_design(&general, &["operator.kind", "polyharmonic"]);
    let zero_a = edit(&fd("solver = \"fd\""), "a = 1.5", "a = 0.0");
    bad_design(&zero_a, &["operator.a"]);
}
