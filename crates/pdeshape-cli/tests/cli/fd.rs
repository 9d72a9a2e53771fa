//! End-to-end tests of `pdeshape surface` with the finite-difference solver (`solver = "fd"`):
//! the surface agrees with the analytic solver's to the scheme's O(h²), and designs the scheme
//! cannot take give exit status 2 with one located `error:` line and no output file.

use crate::common::*;

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
