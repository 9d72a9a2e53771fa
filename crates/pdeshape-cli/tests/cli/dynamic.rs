//! End-to-end tests of `pdeshape curve`: the §3.3 experiment and the §4 interpolation as design
//! files, checked numerically from the written files; every class of bad input gives exit
//! status 2, one `error:` line naming the place, and no output file.

use crate::common::*;

/// Runs `curve` with all three outputs on a bad design; checks the error and that nothing but the
/// design is left in the directory.
fn bad_curve(text: &str, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", text);
    let (o, f, p) = (
        dir.path().join("c.csv"),
        dir.path().join("f.csv"),
        dir.path().join("p.svg"),
    );
    let out = pdeshape(&[
        "curve",
        s(&d),
        "-o",
        s(&o),
        "--frames",
        s(&f),
        "--picture",
        s(&p),
    ]);
    let line = assert_bad(&out, needles);
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
    line
}

/// Rows of a CSV file of numbers (header skipped).
fn csv(path: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// §3.3 from the design file: the L² error at T = 15 recomputed from the CSV against the exact
/// solution is the one of the library's convergence test (1.166e-3, below h² + Δt² ≈ 0.0022), the
/// frames carry t = step·Δt every 45 levels, and the picture has the initial, four intermediate
/// and the final curve.
#[test]
fn section_33_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &example("dynamic_section33.toml"));
    let (o, f, p) = (
        dir.path().join("x.csv"),
        dir.path().join("frames.csv"),
        dir.path().join("x.svg"),
    );
    let out = pdeshape(&[
        "curve",
        s(&d),
        "-o",
        s(&o),
        "--frames",
        s(&f),
        "--picture",
        s(&p),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("exact x: L2 error 0.001166"), "{stdout}");
    assert!(
        stdout.contains("end conditions x at T: start 0, end 0"),
        "{stdout}"
    );
    let (header, rows) = csv(&o);
    assert_eq!(header, "u,x");
    assert_eq!(rows.len(), 31);
    let pi = std::f64::consts::PI;
    let exact = |u: f64, t: f64| (1.0 + (-t).exp()) * (pi * u).sin();
    let h = 1.0 / 30.0;
    let mut sum = 0.0;
    for (j, r) in rows.iter().enumerate() {
        assert_eq!(r[0], j as f64 / 30.0);
        sum += (r[1] - exact(r[0], 15.0)).powi(2) * h;
    }
    let l2 = sum.sqrt();
    assert!((l2 - 1.166e-3).abs() < 1e-6, "{l2}");
    let (header, rows) = csv(&f);
    assert_eq!(header, "step,t,u,x");
    assert_eq!(rows.len(), 11 * 31);
    for (k, chunk) in rows.chunks(31).enumerate() {
        let step = 45.0 * k as f64;
        for r in chunk {
            assert_eq!(r[0], step);
            assert!((r[1] - step / 30.0).abs() < 1e-12);
        }
    }
    // The first frame is the initial profile 2 sin(πu), exactly as evaluated.
    for r in &rows[..31] {
        assert!((r[3] - 2.0 * (pi * r[2]).sin()).abs() < 1e-15);
    }
    // The last frame is the final curve.
    let (_, last) = csv(&o);
    for (a, b) in rows[10 * 31..].iter().zip(&last) {
        assert_eq!(a[3], b[1]);
    }
    let svg = std::fs::read_to_string(&p).unwrap();
    assert!(svg.starts_with("<svg"));
    assert_eq!(svg.matches("<path").count(), 6);
}

/// §4 from the design file: the final curve passes within 1e-3 × 300 of the three points (at
/// their reported parameters, read back from the CSV), meets the end points exactly and the end
/// tangents through the scheme's one-sided differences to rounding.
#[test]
fn section_4_interpolation() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &example("dynamic_interpolate.toml"));
    let (o, p) = (dir.path().join("c.csv"), dir.path().join("c.svg"));
    let out = pdeshape(&["curve", s(&d), "-o", s(&o), "--picture", s(&p)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (header, rows) = csv(&o);
    assert_eq!(header, "u,x,y");
    assert_eq!(rows.len(), 201);
    let points = [(100.0, 60.0), (150.0, 70.0), (200.0, 60.0)];
    let mut reported = Vec::new();
    for line in stdout.lines().filter(|l| l.starts_with("point ")) {
        let u: f64 = line
            .split("u = ")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let d: f64 = line.split("distance ").nth(1).unwrap().parse().unwrap();
        reported.push((u, d));
    }
    assert_eq!(reported.len(), 3, "{stdout}");
    for ((u, d), (px, py)) in reported.iter().zip(points) {
        let r = &rows[(u * 200.0).round() as usize];
        let dist = ((r[1] - px).powi(2) + (r[2] - py).powi(2)).sqrt();
        assert!(dist < 0.3, "distance {dist}");
        assert!((dist - d).abs() < 1e-5 * (1.0 + d), "{dist} vs {d}");
    }
    assert_eq!((rows[0][1], rows[0][2]), (0.0, 0.0));
    assert_eq!((rows[200][1], rows[200][2]), (300.0, 0.0));
    let h = 1.0 / 200.0;
    for (c, want0, want1) in [(1, 28.0, 55.0), (2, 65.0, -37.0)] {
        let s0 = (-11.0 * rows[0][c] + 18.0 * rows[1][c] - 9.0 * rows[2][c] + 2.0 * rows[3][c])
            / (6.0 * h);
        let s1 = (11.0 * rows[200][c] - 18.0 * rows[199][c] + 9.0 * rows[198][c]
            - 2.0 * rows[197][c])
            / (6.0 * h);
        // Nodal values ~300 printed to shortest round-trip form; 1/(6h) ≈ 33 amplifies rounding.
        assert!(
            (s0 - want0).abs() < 1e-9 && (s1 - want1).abs() < 1e-9,
            "{s0} {s1}"
        );
    }
    assert!(stdout.contains("bending energy"));
    let svg = std::fs::read_to_string(&p).unwrap();
    // Three data points and the legend's mark for them.
    assert_eq!(svg.matches("<circle").count(), 4);
}

const RUN: &str = r#"[dynamic]
intervals = 10
steps = 20
t_end = 1.0

[dynamic.x]
a = 1.0
b = "x/2"
d = "1 + x^2"
f = "sin(u*t)"
start = 0.0
end = 1.0
start_slope = 1.0
end_slope = 1.0
position = "u"

[dynamic.y]
d = 1.0
start = 0.0
end = 0.0
start_slope = 0.0
end_slope = 0.0
position = 0.0
"#;

#[test]
fn a_small_planar_run_works() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", RUN);
    let o = dir.path().join("c.csv");
    let out = pdeshape(&["curve", s(&d), "-o", s(&o)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (header, rows) = csv(&o);
    assert_eq!(header, "u,x,y");
    // y has no force and zero data: it stays zero.
    assert!(rows.iter().all(|r| r[2] == 0.0));
    assert_eq!(
        files(dir.path()),
        vec!["c.csv".to_string(), "d.toml".to_string()]
    );
}

#[test]
fn formula_errors_name_the_key_and_line() {
    let line = bad_curve(
        &edit(RUN, "d = \"1 + x^2\"", "d = \"1 + x^\""),
        &["d.toml:9:", "dynamic.x.d", "cannot parse"],
    );
    assert!(line.contains("1 + x^"), "{line}");
    bad_curve(
        &edit(RUN, "start_slope = 0.0", "start_slope = \"u\""),
        &[
            "d.toml:21:",
            "dynamic.y.start_slope",
            "unknown variable 'u'",
            "may use t",
        ],
    );
    bad_curve(
        &edit(RUN, "position = \"u\"", "position = \"t\""),
        &["dynamic.x.position", "may use u"],
    );
}

#[test]
fn non_finite_values_during_the_run() {
    // f = 1/(u − 0.5) is infinite at the node u = 0.5.
    bad_curve(
        &edit(RUN, "f = \"sin(u*t)\"", "f = \"1/(u - 0.5)\""),
        &["d.toml:10:", "dynamic.x.f", "u = 0.5", "not finite"],
    );
}

#[test]
fn positivity_check() {
    let text = example("dynamic_section33.toml");
    bad_curve(
        &edit(
            &text,
            "frames_every = 45",
            "frames_every = 45\ncheck_positivity = true",
        ),
        &["dynamic.x.d", "d(u = 0, t = 0, x = 0) = 0", "d > 0"],
    );
    // Negative tension along the solution.
    bad_curve(
        &edit(RUN, "b = \"x/2\"", "b = \"x/2 - 0.3\"\n")
            .replace("t_end = 1.0", "t_end = 1.0\ncheck_positivity = true"),
        &["dynamic.x.b", "b(u = 0.05", "b >= 0"],
    );
}

#[test]
fn structural_errors() {
    bad_curve(
        &RUN.replace("t_end = 1.0\n", ""),
        &["dynamic", "missing key `t_end`"],
    );
    bad_curve(
        &edit(RUN, "intervals = 10", "intervals = 3"),
        &["d.toml:2:", "dynamic.intervals", "J = 3"],
    );
    bad_curve(
        &edit(RUN, "steps = 20", "steps = 20\npoints = [[1.0, 2.0]]"),
        &["dynamic.x", "belongs to a general run"],
    );
    bad_curve(
        &edit(RUN, "[dynamic.y]", "[dynamic.z]"),
        &["dynamic.z", "needs [dynamic.y]"],
    );
    bad_curve(
        &edit(RUN, "a = 1.0", "a = 1.0\nstiffnes = 2.0"),
        &["dynamic.x", "unknown field `stiffnes`"],
    );
    bad_curve("title = \"nothing\"\n", &["d.toml", "no [dynamic] section"]);
}

#[test]
fn interpolation_input_errors() {
    let text = example("dynamic_interpolate.toml");
    bad_curve(
        &edit(&text, "[200.0, 60.0]]", "[200.0, 60.0, 1.0]]"),
        &["dynamic.points[2]", "3 coordinates", "have 2"],
    );
    bad_curve(
        &edit(&text, "eps = 0.01", "eps = -0.01"),
        &["dynamic.eps", "> 0"],
    );
    bad_curve(
        &edit(&text, "params = \"fixed\"", "params = \"closest\""),
        &["dynamic.params", "unknown variant"],
    );
    bad_curve(
        &edit(&text, "k = 500.0", "k = 500.0\nsteps = 10"),
        &["dynamic.steps"],
    );
    // Too few steps to settle: an error naming the distances, and no output.
    bad_curve(
        &edit(&text, "dt = 0.01", "dt = 0.01\nmax_steps = 50"),
        &["dynamic", "not within 0.3 after 50 steps", "distances"],
    );
}

#[test]
fn wrong_command_for_the_design_and_wrong_extensions() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", RUN);
    let out = pdeshape(&["surface", s(&d), "-o", s(&dir.path().join("s.obj"))]);
    assert_bad(&out, &["dynamic", "pdeshape curve"]);
    let out = pdeshape(&["curve", s(&d), "-o", s(&dir.path().join("c.obj"))]);
    assert_bad(&out, &["-o", ".csv"]);
    let out = pdeshape(&[
        "curve",
        s(&d),
        "-o",
        s(&dir.path().join("c.csv")),
        "--picture",
        s(&dir.path().join("c.png")),
    ]);
    assert_bad(&out, &["--picture", ".svg"]);
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
}
