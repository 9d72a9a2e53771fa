//! End-to-end tests of `pdeshape blend`: the §6 example, every output kind, the report, and bad
//! input (exit status 2, one located `error:` line, no output file).

use crate::common::*;

/// Runs `blend` on a bad design: status 2, one `error:` line with every needle, no output.
fn bad(text: &str, out_name: &str, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("d.toml");
    std::fs::write(&d, text).unwrap();
    let out_path = dir.path().join(out_name);
    let out = pdeshape(&["blend", s(&d), "-o", s(&out_path)]);
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

/// `(G0, G1)` of a join line of the report: `  start (y = 0): G0 …, G1 … rad, C1 …`.
fn join_errors(stdout: &str, which: &str) -> (f64, f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with(which))
        .unwrap_or_else(|| panic!("no '{which}' line in {stdout}"));
    let num = |key: &str| -> f64 {
        let rest = &line[line.find(key).unwrap() + key.len()..];
        rest.split([',', ' '])
            .find(|w| !w.is_empty())
            .unwrap()
            .parse()
            .unwrap()
    };
    (num("G0 "), num("G1 "), num("C1 "))
}

#[test]
fn the_section_6_example_writes_every_format_and_reports_the_joins() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "stl", "ply", "glb", "csv", "json"] {
        let out_path = dir.path().join(format!("blend.{ext}"));
        let design = example_path("blend_cylinders.toml");
        let mut argv = vec!["blend", s(&design), "-o", s(&out_path)];
        // A .json control net has no grid: --nu/--nv are refused for it.
        if ext != "json" {
            argv.extend(["--nu", "33", "--nv", "9"]);
        }
        let out = pdeshape(&argv);
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{ext}: {stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out_path.metadata().unwrap().len() > 100, "{ext}");
        // Hermite edges of an 8-element circle: G0 ≤ h⁴/384 · √2 r (2π)⁴ = 2.8e-3 (r = 2),
        // G1 below 5.5e-3 rad, and the constant cross derivative interpolated exactly.
        let (g0, g1, c1) = join_errors(&stdout, "start");
        assert!(
            g0 > 1e-4 && g0 < 2.8e-3 && g1 < 5.5e-3 && c1 < 1e-12,
            "{stdout}"
        );
        let (g0, _, _) = join_errors(&stdout, "end");
        assert!(g0 < 1.4e-3, "{stdout}");
        assert_eq!(stdout.matches("  at [").count(), 9, "{stdout}");
        assert!(stdout.contains("wrote"), "{stdout}");
    }
    let obj = std::fs::read_to_string(dir.path().join("blend.obj")).unwrap();
    // A 33 × 9 grid closed around its first parameter: the repeated seam row is welded.
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 32 * 9);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("blend.json")).unwrap())
            .unwrap();
    assert_eq!(json["bezier"].as_array().unwrap().len(), 32);
    assert_eq!(json["bspline"]["control"].as_array().unwrap().len(), 18);
    assert_eq!(json["bspline"]["control"][0].as_array().unwrap().len(), 10);
    // The first B-spline control point is the blend's corner: f(0, 1) = (1, 2, 0).
    let p0: Vec<f64> = json["bspline"]["control"][0][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!((p0[0] - 1.0).abs() < 1e-12 && (p0[1] - 2.0).abs() < 1e-12 && p0[2].abs() < 1e-12);
    assert_eq!(files(dir.path()).len(), 6, "no temporary files left");
}

#[test]
fn smaller_epsilon_pulls_the_blend_to_the_points_and_check_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let max_distance = |text: &str| {
        let d = dir.path().join("d.toml");
        std::fs::write(&d, text).unwrap();
        let out = pdeshape(&["check", s(&d)]);
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        assert_eq!(out.status.code(), Some(0), "{stdout}");
        assert!(stdout.starts_with("OK\n") && stdout.contains("condition errors"));
        let line = stdout
            .lines()
            .find(|l| l.starts_with("  max "))
            .unwrap()
            .to_string();
        line.split_whitespace()
            .nth(1)
            .unwrap()
            .trim_end_matches(',')
            .parse::<f64>()
            .unwrap()
    };
    let text = example("blend_cylinders.toml");
    let d3 = max_distance(&text);
    let d5 = max_distance(&edit(
        &text,
        "epsilon = 1e-3\nenergy",
        "epsilon = 1e-5\nenergy",
    ));
    assert!(d5 < d3 / 10.0, "{d3} {d5}");
    // The paper's free edges: the report shows the seam.
    let open = edit(&text, "\nperiodic = true", "\nperiodic = false");
    let d = dir.path().join("open.toml");
    std::fs::write(&d, open).unwrap();
    let out = pdeshape(&["check", s(&d)]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("seam gap"));
}

#[test]
fn bad_blend_designs_are_located_and_leave_no_file() {
    let text = example("blend_cylinders.toml");
    let line = bad(
        &edit(
            &text,
            "axis = [2.0, 0.0, 0.0], radius = 2.0",
            "axis = [2.0, 0.0, 0.0], radius = -2.0",
        ),
        "o.obj",
        &["blend.start.surface.radius", "must be positive"],
    );
    assert!(line.contains("d.toml:"), "{line}");
    bad(
        &edit(&text, "epsilon = 1e-3\nenergy", "epsilon = 0.0\nenergy"),
        "o.obj",
        &["blend.epsilon"],
    );
    bad(
        &edit(&text, "elements = [8, 4]", "elements = [0, 4]"),
        "o.json",
        &["blend.elements[0]"],
    );
    bad(
        &edit(&text, "elements = [8, 4]", "elements = [4096, 4096]"),
        "o.obj",
        &["blend.elements", "refusing to allocate"],
    );
    bad(
        &edit(&text, "at = [0.0, 0.5]", "at = [0.0, 1.5]"),
        "o.obj",
        &["blend.points[0].at", "[0, 1]²"],
    );
    bad(
        &edit(
            &text,
            "energy = { kind = \"section6\", a = 10.0 }",
            "energy = { kind = \"general\", a = 1.0, c = 0.0, e = 100.0, mixed = 20.0 }",
        ),
        "o.obj",
        &["blend.energy", "not positive definite"],
    );
    bad(
        &edit(
            &text,
            "energy = { kind = \"section6\", a = 10.0 }",
            "energy = { kind = \"section6\", b = 10.0 }",
        ),
        "o.obj",
        &["blend.energy", "unknown field"],
    );
    bad(
        &edit(
            &text,
            "type = \"cylinder\", base = [1.0",
            "type = \"cone\", base = [1.0",
        ),
        "o.obj",
        &["blend.end.surface"],
    );
    // A periodic blend needs closed joins.
    bad(
        &edit(
            &text,
            "from = [0.0, 0.0]\nto = [1.0, 0.0]",
            "from = [0.0, 0.0]\nto = [0.5, 0.0]",
        ),
        "o.obj",
        &["blend.periodic", "closed"],
    );
    bad(
        &edit(
            &text,
            "cross = [0.0, 1.0]\n\n[blend.end]",
            "cross = [1.0, 1.0e-30]\n\n[blend.end]",
        ),
        "o.obj",
        &["blend.start.cross", "parallel"],
    );
    // An unknown output extension, and a design without [blend].
    bad(&text, "o.xyz", &["-o"]);
    bad("title = \"x\"\n", "o.obj", &["no [blend] section"]);
}
