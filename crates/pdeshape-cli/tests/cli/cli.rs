//! End-to-end tests of the `pdeshape` binary: bad input gives exit status 2, one `error:` line
//! naming the place, and no output file; good input gives the files and reports.

use std::time::{Duration, Instant};

use crate::common::*;

#[test]
fn malformed_toml() {
    let text = edit(GOOD, "radius = 1.0\n", "radius = = 1.0\n");
    let line = bad_design(&text, &["d.toml:"]);
    // Points at the offending line.
    let n = text.lines().position(|l| l.contains("= =")).unwrap() + 1;
    assert!(line.contains(&format!("d.toml:{n}:")), "{line}");
}

#[test]
fn unknown_key() {
    let text = edit(GOOD, "radius = 1.0\n", "radiuss = 1.0\n");
    bad_design(&text, &["curves.base", "radiuss"]);
    bad_design(&format!("colour = 1\n{GOOD}"), &["colour"]);
    // A near miss gets the nearest key.
    bad_design(&text, &["curves.base", "radiuss", "did you mean `radius`?"]);
}

/// Misspelt subcommands, flags and values get clap's nearest name on the one error line; no
/// subcommand lists them all.
#[test]
fn typos_get_a_suggestion() {
    let design = example_path("cup.toml");
    let d = s(&design);
    for (args, needles) in [
        (
            vec!["surfce", d],
            vec![
                "unrecognized subcommand 'surfce'",
                "did you mean 'surface'?",
            ],
        ),
        (
            vec!["render", d, "-o", "x.png", "--colour", "mean"],
            vec!["'--colour'", "did you mean '--color'?"],
        ),
        (
            vec!["render", d, "-o", "x.png", "--color", "gaus"],
            vec!["'gaus'", "did you mean 'gauss'?"],
        ),
        (
            vec!["surface", d, "-o", "x.stpe"],
            vec!["'.stpe' (did you mean .step?)", ".stp, .igs or .iges"],
        ),
    ] {
        assert_bad(&pdeshape(&args), &needles);
    }
    let line = assert_bad(&pdeshape(&[]), &["a subcommand is required"]);
    for name in ["surface", "fit", "fill", "roundtrip", "schema", "serve"] {
        assert!(line.contains(name), "{line}");
    }
}

#[test]
fn nan_and_inf() {
    let text = edit(GOOD, "center = [0.0, 0.0, 2.0]", "center = [0.0, nan, 2.0]");
    bad_design(&text, &["curves.rim.center[1]: must be finite"]);
    let text = edit(GOOD, "a = 1.5", "a = inf");
    bad_design(&text, &["operator.a: must be finite"]);
    let text = edit(
        GOOD,
        "{ u = 1.0, curve = \"rim\" }",
        "{ u = -inf, curve = \"rim\" }",
    );
    bad_design(&text, &["conditions[2].u: must be finite"]);
}

const FORMULA_TOP: &str = "conditions = [ { u = 0.0, curve = \"f\" }, { u = 1.0, curve = \"c\" } ]\n\
    [operator]\nkind = \"polyharmonic\"\norder = 1\n\
    [curves.c]\ntype = \"circle\"\ncenter = [0, 0, 1]\nradius = 1\n[curves.f]\ntype = \"formula\"\n";

#[test]
fn formula_that_does_not_parse() {
    let text = format!("{FORMULA_TOP}x = \"cos(v\"\ny = \"sin(v)\"\nz = \"0\"\n");
    bad_design(&text, &["curves.f"]);
    let text = format!("{FORMULA_TOP}x = \"cos(w)\"\ny = \"sin(v)\"\nz = \"0\"\n");
    bad_design(&text, &["curves.f"]);
}

#[test]
fn formula_evaluating_to_nan() {
    let text = format!("{FORMULA_TOP}x = \"sqrt(cos(v))\"\ny = \"sin(v)\"\nz = \"0\"\n");
    bad_design(&text, &["curves.f"]);
}

#[test]
fn non_positive_smoothing_parameter() {
    bad_design(
        &edit(GOOD, "a = 1.5", "a = 0.0"),
        &["operator.a: must be positive (got 0)"],
    );
    bad_design(
        &edit(GOOD, "a = 1.5", "a = -2"),
        &["operator.a: must be positive (got -2)"],
    );
}

#[test]
fn degenerate_curves() {
    bad_design(
        &edit(GOOD, "radius = 1.0\n", "radius = 0.0\n"),
        &["curves.base.radius: must be positive (got 0)"],
    );
    let ellipse = edit(
        GOOD,
        "rx = 1.5\nry = 1.0\n",
        "axis1 = [1, 0, 0]\naxis2 = [-2, 0, 0]\n",
    );
    bad_design(&ellipse, &["curves.rim.axis2", "parallel"]);
    let bspline = edit(
        GOOD,
        "type = \"ellipse\"\ncenter = [0.0, 0.0, 2.0]\nrx = 1.5\nry = 1.0\n",
        "type = \"bspline\"\ndegree = 3\ncontrol = [[1,0,2],[0,1,2],[-1,0,2],[0,-1,2]]\nknots = [0, 1, 1, 2, 3]\n",
    );
    bad_design(&bspline, &["curves.rim.knots[2]: must be increasing"]);
}

#[test]
fn wrong_condition_counts() {
    let few = edit(
        GOOD,
        "  { u = 1.0, derivative = 1, curve = \"rim_tangent\" },\n",
        "",
    );
    bad_design(
        &few,
        &["conditions: a polyharmonic operator of order 2 needs 4 conditions, got 3"],
    );
    let many = edit(
        GOOD,
        "  { u = 1.0, curve = \"rim\" },\n",
        "  { u = 1.0, curve = \"rim\" },\n  { u = 0.5, curve = \"base\" },\n",
    );
    bad_design(
        &many,
        &["conditions: a polyharmonic operator of order 2 needs 4 conditions, got 5"],
    );
}

#[test]
fn two_conditions_of_the_same_kind_at_the_same_u() {
    let dup = edit(
        GOOD,
        "{ u = 1.0, derivative = 1, curve = \"rim_tangent\" }",
        "{ u = 1.0, curve = \"base\" }",
    );
    bad_design(
        &dup,
        &["conditions[3]: prescribes the position at u = 1 like conditions[2]"],
    );
}

#[test]
fn u_outside_the_unit_interval() {
    let text = edit(
        GOOD,
        "{ u = 1.0, curve = \"rim\" }",
        "{ u = 1.25, curve = \"rim\" }",
    );
    bad_design(&text, &["conditions[2].u: must lie in [0, 1] (got 1.25)"]);
    let text = edit(
        GOOD,
        "{ u = 1.0, curve = \"rim\" }",
        "{ u = -0.5, curve = \"rim\" }",
    );
    bad_design(&text, &["conditions[2].u: must lie in [0, 1]"]);
}

#[test]
fn unknown_curve_name() {
    let text = edit(
        GOOD,
        "{ u = 1.0, curve = \"rim\" }",
        "{ u = 1.0, curve = \"rimm\" }",
    );
    bad_design(
        &text,
        &["conditions[2].curve: unknown curve 'rimm' (did you mean 'rim'? known: base, base_ahead"],
    );
}

#[test]
fn bad_grid_sizes_fail_fast() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let o = dir.path().join("out.obj");
    for (flag, value, needle) in [
        ("--nu", "0", "--nu: must be at least 2 (got 0)"),
        ("--nu", "1", "--nu: must be at least 2 (got 1)"),
        ("--nv", "0", "--nv: must be at least 3 (got 0)"),
        ("--nv", "1", "--nv: must be at least 3 (got 1)"),
        ("--nu", "1000000000", "refusing to allocate"),
        ("--nv", "1000000000", "refusing to allocate"),
    ] {
        let t = Instant::now();
        let out = pdeshape(&["surface", s(&d), "-o", s(&o), flag, value]);
        assert_bad(&out, &[needle]);
        assert!(
            t.elapsed() < Duration::from_secs(5),
            "{flag} {value} was slow"
        );
        assert!(!o.exists());
        let png = dir.path().join("out.png");
        let out = pdeshape(&["render", s(&d), "-o", s(&png), flag, value]);
        assert_bad(&out, &[needle]);
        assert!(!png.exists());
    }
    // Too large for usize: clap's own error, still one line and status 2.
    let out = pdeshape(&["surface", s(&d), "-o", s(&o), "--nu", "1e30"]);
    assert_bad(&out, &["--nu"]);
    // The same limits apply to [output].
    let text = edit(GOOD, "nu = 16", "nu = 1");
    let d2 = write(dir.path(), "d2.toml", &text);
    let out = pdeshape(&["surface", s(&d2), "-o", s(&o)]);
    assert_bad(&out, &["output.nu: must be at least 2 (got 1)", "d2.toml:"]);
    assert_eq!(files(dir.path()), vec!["d.toml", "d2.toml"]);
}

/// The vertex limit holds for the whole design, not per patch: 39 patches of 2^26 vertices
/// each would need tens of gigabytes.
#[test]
fn grid_limit_counts_every_patch() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("k.obj");
    let examples = example_path("klein_bottle_patches.toml");
    let t = Instant::now();
    let out = pdeshape(&[
        "surface",
        s(&examples),
        "-o",
        s(&o),
        "--nu",
        "8192",
        "--nv",
        "8192",
    ]);
    assert_bad(&out, &["39 patches", "refusing to allocate"]);
    assert!(t.elapsed() < Duration::from_secs(5));
    assert!(files(dir.path()).is_empty());
}

/// A message that quotes a multi-line string from the input still prints on one line.
#[test]
fn multi_line_input_strings_stay_on_one_line() {
    let text = GOOD.replacen("curve = \"", "curve = \"c1\\nsecond line", 1);
    let out = bad_design(&text, &["unknown curve"]);
    assert!(!out.trim_end().contains('\n'));
}

#[test]
fn unwritable_output_path() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let missing = dir.path().join("no-such-dir").join("x.obj");
    let out = pdeshape(&["surface", s(&d), "-o", s(&missing)]);
    assert_bad(&out, &["-o", "no-such-dir"]);
    assert!(!missing.exists());
    let out = pdeshape(&["surface", s(&d), "-o", "/proc/x.obj"]);
    assert_bad(&out, &["-o /proc/x.obj"]);
    let out = pdeshape(&["render", s(&d), "-o", "/proc/x.png"]);
    assert_bad(&out, &["-o /proc/x.png"]);
    // A directory as the output.
    let out = pdeshape(&["surface", s(&d), "-o", s(dir.path())]);
    assert_bad(&out, &["-o"]);
    assert_eq!(files(dir.path()), vec!["d.toml"]);
}

#[test]
fn unknown_output_extension() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    for name in ["out.xyz", "out"] {
        let o = dir.path().join(name);
        let out = pdeshape(&["surface", s(&d), "-o", s(&o)]);
        assert_bad(&out, &["-o", name]);
        assert!(!o.exists());
    }
    let out = pdeshape(&["render", s(&d), "-o", s(&dir.path().join("pic.jpg"))]);
    assert_bad(&out, &["-o", ".png"]);
    assert_eq!(files(dir.path()), vec!["d.toml"]);
}

#[test]
fn bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let png = dir.path().join("p.png");
    assert_bad(&pdeshape(&[]), &["subcommand"]);
    assert_bad(&pdeshape(&["frobnicate"]), &["frobnicate"]);
    assert_bad(&pdeshape(&["surface", s(&d)]), &["--output"]);
    assert_bad(
        &pdeshape(&["render", s(&d), "-o", s(&png), "--size", "800by600"]),
        &["--size"],
    );
    assert_bad(
        &pdeshape(&["render", s(&d), "-o", s(&png), "--size", "0x600"]),
        &["--size"],
    );
    assert_bad(
        &pdeshape(&["render", s(&d), "-o", s(&png), "--view", "1,2"]),
        &["--view"],
    );
    assert_bad(
        &pdeshape(&["render", s(&d), "-o", s(&png), "--view", "0,0,0"]),
        &["--view"],
    );
    let missing = dir.path().join("missing.toml");
    assert_bad(&pdeshape(&["check", s(&missing)]), &["missing.toml"]);
    assert_eq!(files(dir.path()), vec!["d.toml"]);
}

#[test]
fn schema_is_valid_json() {
    let out = pdeshape(&["schema"]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(v["title"], "DesignSpec");
    for key in [
        "operator",
        "solver",
        "curves",
        "conditions",
        "patches",
        "output",
    ] {
        assert!(v["properties"][key].is_object(), "{key}");
    }
    // A curve table: its keys listed once, and the type's own checks in an if/then/else chain.
    let curve = &v["definitions"]["CurveSpec"];
    assert!(curve["properties"]["radius"].is_object(), "{curve}");
    assert_eq!(
        curve["if"]["properties"]["type"]["const"], "circle",
        "{curve}"
    );
    assert!(curve["else"]["if"].is_object(), "{curve}");
}

// The tests below solve designs: they need the solver, the renderer and the writers.

fn good_surface(ext: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let o = dir.path().join(format!("out.{ext}"));
    let out = pdeshape(&["surface", s(&d), "-o", s(&o)]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stderr.is_empty());
    assert_eq!(
        files(dir.path()),
        vec!["d.toml".to_string(), format!("out.{ext}")]
    );
    std::fs::read(&o).unwrap()
}

#[test]
fn surface_writes_every_format() {
    for ext in ["obj", "stl", "ply", "glb"] {
        let bytes = good_surface(ext);
        assert!(!bytes.is_empty(), "{ext}");
    }
    assert_eq!(&good_surface("glb")[..4], b"glTF");
    // CSV: header and one row per vertex of the 16 × 24 grid from [output].
    let csv = String::from_utf8(good_surface("csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "u,v,x,y,z,nx,ny,nz");
    assert_eq!(lines.len(), 1 + 16 * 24);
    // The first row is u = 0, v = 0: the base circle's start point (1, 0, 0).
    let first: Vec<f64> = lines[1].split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(first.len(), 8);
    for (got, want) in first[..5].iter().zip([0.0, 0.0, 1.0, 0.0, 0.0]) {
        assert!((got - want).abs() < 1e-12, "{:?}", &first[..5]);
    }
}

#[test]
fn grid_flags_override_the_design() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let o = dir.path().join("out.csv");
    let out = pdeshape(&["surface", s(&d), "-o", s(&o), "--nu", "5", "--nv", "7"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&o).unwrap().lines().count(),
        1 + 5 * 7
    );
}

#[test]
fn timings_are_one_json_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let o = dir.path().join("out.stl");
    let out = pdeshape(&["surface", s(&d), "-o", s(&o), "--timings"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(lines[0]).unwrap();
    let obj = v.as_object().unwrap();
    assert_eq!(obj.len(), 7);
    let keys = [
        "solve_ms",
        "tessellate_ms",
        "write_ms",
        "weld_ms",
        "file_ms",
        "commit_ms",
        "total_ms",
    ];
    for key in keys {
        let t = obj[key].as_f64().unwrap();
        assert!(t >= 0.0 && t.is_finite(), "{key} = {t}");
    }
    let t = |key: &str| obj[key].as_f64().unwrap();
    // The write is its three stages; the total covers every stage.
    let parts = t("weld_ms") + t("file_ms") + t("commit_ms");
    assert!(
        (t("write_ms") - parts).abs() <= 1e-9 * t("write_ms").max(1.0),
        "{stderr}"
    );
    assert!(
        t("total_ms") >= t("solve_ms") + t("tessellate_ms") + t("write_ms"),
        "{stderr}"
    );
}

#[test]
fn render_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let o = dir.path().join("shape.png");
    let out = pdeshape(&[
        "render",
        s(&d),
        "-o",
        s(&o),
        "--size",
        "160x120",
        "--view",
        "1,-2,1",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&o).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, at bytes 16..24.
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 160);
    assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 120);
}

#[test]
fn check_passes_on_every_example() {
    let mut seen = 0;
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        // Curve designs (a [dynamic] section, no surface) are run by `pdeshape curve`
        // (the `dynamic` tests); `check` refuses them.
        let text = std::fs::read_to_string(&p).unwrap();
        let spec = pdeshape::spec::parse_design(&text).unwrap();
        if spec.dynamic.is_some() && spec.conditions.is_none() && spec.patches.is_none() {
            continue;
        }
        seen += 1;
        // Designs whose patches meet at an intended crease (a lid, a flange) declare it
        // (`creases`): they start with OK like every other example, and without the
        // declaration they fail the check at the default seam tolerance (one degree): FAIL
        // first, one `fail:` line per crease, exit status 1.
        let name = p.file_name().unwrap().to_str().unwrap();
        let out = pdeshape(&["check", s(&p)]);
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        if !spec.creases.is_empty() {
            let dir = tempfile::tempdir().unwrap();
            let bare = dir.path().join(name);
            std::fs::write(&bare, text.replace("creases = [\"rim\"]", "")).unwrap();
            let undeclared = pdeshape(&["check", s(&bare)]);
            let stdout = String::from_utf8_lossy(&undeclared.stdout).to_string();
            assert_eq!(undeclared.status.code(), Some(1), "{name}: {stdout}");
            assert_eq!(stdout.lines().next(), Some("FAIL"), "{name}: {stdout}");
            let fails: Vec<&str> = stdout.lines().filter(|l| l.starts_with("fail:")).collect();
            assert!(!fails.is_empty(), "{name}: {stdout}");
            for line in fails {
                assert!(
                    line.ends_with("rad, above the tolerance 0.01745 rad (a crease)"),
                    "{name}: {line}"
                );
            }
        }
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}{}",
            p.display(),
            stdout,
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(stdout.lines().next(), Some("OK"), "{name}: {stdout}");
        for line in stdout.lines().filter(|l| l.starts_with("attention:")) {
            assert!(line.ends_with("rad (a crease)"), "{name}: {line}");
        }
        if spec.conditions.is_some() || spec.patches.is_some() {
            assert!(stdout.contains("condition errors"), "{stdout}");
        }
        if !spec.nsided.is_empty() {
            assert!(stdout.contains("n-sided patch"), "{stdout}");
        }
        if !spec.network.is_empty() {
            assert!(stdout.contains("network '"), "{stdout}");
        }
        // Every condition is met to rounding and no patch oscillates (the Klein bottle's
        // sections sit at Chebyshev–Lobatto points of u; see its header).
        let warnings: Vec<&str> = stdout
            .lines()
            .filter(|l| l.starts_with("warning:"))
            .collect();
        assert!(warnings.is_empty(), "{}: {warnings:?}", p.display());
    }
    assert!(seen >= 7, "only {seen} examples found");
}

/// The verdict's exit policy: `OK` and `ATTENTION` (a design that solved but deserves a look)
/// both exit with status 0, with the verdict as the first line and the reasons below it; `FAIL`
/// (a shared edge creased beyond `--g1-tolerance`, one degree by default) exits with status 1
/// and one `error:` line naming the seam; a refused design or tolerance exits with status 2
/// and prints no verdict. `--json` carries the same word.
#[test]
fn check_prints_the_verdict_and_exits_by_policy() {
    // The lid's crease without the design's declaration of it.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example_path("cup_closed.toml")).unwrap();
    assert!(text.contains("creases = [\"rim\"]"));
    let closed = write(
        dir.path(),
        "cup_closed.toml",
        &text.replace("creases = [\"rim\"]", ""),
    );
    let out = pdeshape(&["check", s(&closed)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.first(), Some(&"FAIL"), "{stdout}");
    assert!(
        lines[1].starts_with("fail: shared edge 'bowl' u = 1 | 'lid' u = 0 along 'rim': G1 = 1.47")
            && lines[1].ends_with("rad, above the tolerance 0.01745 rad (a crease)"),
        "{stdout}"
    );
    assert_eq!(lines[2], "", "{stdout}");
    assert!(lines[3].starts_with("design: "), "{stdout}");
    let err: Vec<&str> = stderr.lines().collect();
    assert_eq!(err.len(), 1, "{stderr}");
    assert!(
        err[0].starts_with("error: ")
            && err[0].contains("cup_closed.toml: a shared edge is creased beyond the G1 tolerance 0.01745 rad: 'bowl' | 'lid' along 'rim' (G1 = 1.47"),
        "{stderr}"
    );

    // A tolerance above the lid's crease: ATTENTION, status 0, the crease named.
    let out = pdeshape(&["check", "--g1-tolerance", "1.6", s(&closed)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.first(), Some(&"ATTENTION"), "{stdout}");
    assert!(
        !stdout.contains("\nOK\n") && !stdout.contains("fail:"),
        "{stdout}"
    );
    let reason = lines[1];
    // The details follow the reasons after a blank line.
    assert_eq!(lines[2], "", "{stdout}");
    assert!(lines[3].starts_with("design: "), "{stdout}");
    assert!(
        reason.starts_with(
            "attention: shared edge 'bowl' u = 1 | 'lid' u = 0 along 'rim': G1 = 1.47"
        ) && reason.ends_with("rad (a crease)"),
        "{reason}"
    );

    let out = pdeshape(&["check", s(&example_path("cup.toml"))]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert_eq!(stdout.lines().next(), Some("OK"), "{stdout}");
    assert!(!stdout.contains("attention:"), "{stdout}");

    for (name, tolerance, word, status) in [
        ("cup_closed.toml", None, "fail", 1),
        ("cup_closed.toml", Some("1.6"), "attention", 0),
        ("cup.toml", None, "ok", 0),
    ] {
        let path = if name == "cup_closed.toml" {
            closed.clone()
        } else {
            example_path(name)
        };
        let mut args = vec!["check", "--json", s(&path)];
        if let Some(t) = tolerance {
            args.extend(["--g1-tolerance", t]);
        }
        let out = pdeshape(&args);
        assert_eq!(out.status.code(), Some(status), "{name}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["verdict"], word, "{name}");
        assert_eq!(v["ok"], true, "{name}");
        let failed = v["edges"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["failed"] == true)
            .count();
        assert_eq!(failed, usize::from(word == "fail"), "{name}");
    }

    for bad in [
        "--g1-tolerance=-1",
        "--g1-tolerance=nan",
        "--g1-tolerance=inf",
    ] {
        let out = pdeshape(&["check", bad, s(&example_path("cup.toml"))]);
        assert_bad(
            &out,
            &["--g1-tolerance: expected an angle in radians, at least 0"],
        );
    }

    let dir = tempfile::tempdir().unwrap();
    let bad = write(dir.path(), "d.toml", &edit(GOOD, "a = 1.5", "a = 0.0"));
    let out = pdeshape(&["check", s(&bad)]);
    assert_bad(&out, &["operator.a: must be positive"]);
}

/// `--g2-tolerance` (not judged unless given): the cup's belly is G1 with a curvature jump
/// (its G2 figure from `--json`); a tolerance just below it fails (FAIL first, status 1, one
/// `error:` line naming the seam and its figure), just above it passes (OK, status 0); a bad
/// tolerance is refused with status 2.
#[test]
fn check_judges_the_g2_figure_by_the_curvature_tolerance() {
    let cup = example_path("cup.toml");
    let out = pdeshape(&["check", "--json", s(&cup)]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["g2_tolerance"], serde_json::Value::Null);
    let g2 = v["edges"][0]["g2"].as_f64().unwrap();
    assert!(g2 > 1e-3, "{g2}");

    let below = format!("{}", 0.99 * g2);
    let out = pdeshape(&["check", "--g2-tolerance", &below, s(&cup)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[0], "FAIL", "{stdout}");
    assert!(
        lines[1].starts_with("fail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly': G2 = ")
            && lines[1].ends_with("(a curvature jump)"),
        "{stdout}"
    );
    let err: Vec<&str> = stderr.lines().collect();
    assert_eq!(err.len(), 1, "{stderr}");
    assert!(
        err[0].contains(
            "cup.toml: a shared edge is curved unlike its neighbour beyond the G2 tolerance"
        ) && err[0].contains("'base' | 'bowl' along 'belly' (G2 = "),
        "{stderr}"
    );
    let out = pdeshape(&["check", "--json", "--g2-tolerance", &below, s(&cup)]);
    assert_eq!(out.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["verdict"], "fail");
    assert_eq!(v["edges"][0]["g2_failed"], true);
    assert_eq!(v["edges"][0]["g1_failed"], false);

    let above = format!("{}", 1.01 * g2);
    let out = pdeshape(&["check", "--g2-tolerance", &above, s(&cup)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert_eq!(stdout.lines().next(), Some("OK"), "{stdout}");

    for bad in [
        "--g2-tolerance=-1",
        "--g2-tolerance=nan",
        "--g2-tolerance=inf",
    ] {
        let out = pdeshape(&["check", bad, s(&cup)]);
        assert_bad(
            &out,
            &["--g2-tolerance: expected a curvature (1/length), at least 0"],
        );
    }
}

#[test]
fn check_reports_shared_edges_of_the_cup() {
    let out = pdeshape(&["check", s(&examples_dir().join("cup.toml"))]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let edge = stdout
        .lines()
        .find(|l| l.contains("along 'belly'"))
        .unwrap_or_else(|| panic!("no shared edge in\n{stdout}"));
    // Same position and derivative curve on both sides: G0 and G1 vanish to rounding.
    let g0: f64 = edge
        .split("G0 = ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let g1: f64 = edge
        .split("G1 = ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(g0 < 1e-9, "{edge}");
    assert!(g1 < 1e-6, "{edge}");
    // The two patches curve differently across the belly: G1 but not G2.
    let g2: f64 = edge.split("G2 = ").nth(1).unwrap().trim().parse().unwrap();
    assert!(g2 > 1e-3 && g2.is_finite(), "{edge}");
}

#[test]
fn the_klein_bottle_file_is_what_the_script_generates() {
    let script = examples_dir().join("klein_bottle.py");
    for (args, file) in [
        (&[][..], "klein_bottle.toml"),
        (&["--patches"][..], "klein_bottle_patches.toml"),
    ] {
        let Ok(out) = Command::new("python3").arg(&script).args(args).output() else {
            eprintln!("python3 not available; skipped");
            return;
        };
        assert!(out.status.success());
        let committed = std::fs::read_to_string(examples_dir().join(file)).unwrap();
        assert_eq!(String::from_utf8(out.stdout).unwrap(), committed, "{file}");
    }
}

/// Rows `[u, v, x, y, z, nx, ny, nz]` of a CSV written by `surface`.
fn csv_rows(design: &Path, nu: usize, nv: usize) -> Vec<Vec<f64>> {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("s.csv");
    let (nu_s, nv_s) = (nu.to_string(), nv.to_string());
    let out = pdeshape(&[
        "surface",
        s(design),
        "-o",
        s(&o),
        "--nu",
        &nu_s,
        "--nv",
        &nv_s,
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&o).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), nu * nv);
    rows
}

#[test]
fn laplace_example_matches_the_closed_form() {
    // §4.2: r(u) = b cosh u + (a_c − b cosh 1) sinh u / sinh 1, z = h u, with b = 2, a_c = 1,
    // h = 1 (the corrected Eq. 4.4).
    let rows = csv_rows(&examples_dir().join("laplace_blend.toml"), 11, 12);
    for row in rows {
        let (u, v) = (row[0], row[1]);
        let r = 2.0 * u.cosh() + (1.0 - 2.0 * 1f64.cosh()) * u.sinh() / 1f64.sinh();
        let want = [r * v.cos(), r * v.sin(), u];
        for k in 0..3 {
            assert!(
                (row[2 + k] - want[k]).abs() < 1e-12,
                "u = {u}, v = {v}: {:?} vs {want:?}",
                &row[2..5]
            );
        }
    }
}

#[test]
fn maple_example_meets_its_intermediate_positions() {
    // u = 0, 0.2, …, 1: rows at u = 0.2 and 0.8 lie on the intermediate circles; the spine is the
    // cubic through (0, 0), (0.2, 0.5), (0.8, 0.8), (1, 1) (mode 0 of the biharmonic equation).
    let rows = csv_rows(&examples_dir().join("maple_appendix.toml"), 6, 8);
    let nodes = [(0.0, 0.0), (0.2, 0.5), (0.8, 0.8), (1.0, 1.0)];
    let cubic = |u: f64| {
        nodes
            .iter()
            .enumerate()
            .map(|(i, &(ui, zi))| {
                let l: f64 = nodes
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, &(uj, _))| (u - uj) / (ui - uj))
                    .product();
                zi * l
            })
            .sum::<f64>()
    };
    let radius = |u: f64| match u {
        u if u < 0.1 => Some(0.5),
        u if (u - 0.2).abs() < 1e-12 => Some(0.5),
        u if (u - 0.8).abs() < 1e-12 => Some(2.0),
        u if u > 0.99 => Some(2.0),
        _ => None,
    };
    for row in rows {
        let (u, v) = (row[0], row[1]);
        // Circles: every point of a row has the same z, the spine's.
        assert!((row[4] - cubic(u)).abs() < 1e-12, "u = {u}: z = {}", row[4]);
        if let Some(r) = radius(u) {
            assert!((row[2] - r * v.cos()).abs() < 1e-12, "u = {u}, v = {v}");
            assert!((row[3] - r * v.sin()).abs() < 1e-12, "u = {u}, v = {v}");
        }
    }
}

#[test]
fn multi_patch_csv_has_a_patch_column() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("cup.csv");
    let cup = examples_dir().join("cup.toml");
    let out = pdeshape(&["surface", s(&cup), "-o", s(&o), "--nu", "4", "--nv", "5"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&o).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "u,v,x,y,z,nx,ny,nz,patch");
    assert_eq!(lines.len(), 1 + 2 * 4 * 5);
    assert!(lines[1].ends_with(",0") && lines[40].ends_with(",1"));
}

#[test]
fn conditions_that_do_not_determine_a_surface() {
    // Laplace with two derivative conditions: the constant of mode 0 is free.
    let text = "conditions = [ { u = 0.0, derivative = 1, curve = \"c\" }, \
                { u = 1.0, derivative = 1, curve = \"c\" } ]\n\
                [operator]\nkind = \"polyharmonic\"\norder = 1\n\
                [curves.c]\ntype = \"circle\"\ncenter = [0, 0, 1]\nradius = 1\n";
    bad_design(text, &["conditions", "unique"]);
}

/// `surface --picture` writes the mesh and the PNG, or neither.
#[test]
fn surface_with_a_picture() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let (o, png) = (dir.path().join("out.ply"), dir.path().join("shape.png"));
    let out = pdeshape(&["surface", s(&d), "-o", s(&o), "--picture", s(&png)]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert!(std::fs::metadata(&o).unwrap().len() > 0);
    std::fs::remove_file(&o).unwrap();
    std::fs::remove_file(&png).unwrap();
    let out = pdeshape(&[
        "surface",
        s(&d),
        "-o",
        s(&o),
        "--picture",
        s(&dir.path().join("shape.jpg")),
    ]);
    assert_bad(&out, &["shape.jpg", "png"]);
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
}

/// `--view` takes any non-zero direction, however large or small its numbers.
#[test]
fn view_directions_of_any_size() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    for view in ["1e308,1e308,0", "1e-320,0,0", "0,-1,0.5"] {
        let png = dir.path().join("v.png");
        let out = pdeshape(&[
            "render",
            s(&d),
            "-o",
            s(&png),
            "--size",
            "64x48",
            "--view",
            view,
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{view}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::remove_file(&png).unwrap();
    }
    let out = pdeshape(&[
        "render",
        s(&d),
        "-o",
        s(&dir.path().join("v.png")),
        "--view",
        "0,0,0",
    ]);
    assert_bad(&out, &["--view", "zero"]);
}

/// A formula that is NaN only between the points where it was checked: the error names the
/// curve and the parameter, not the output file.
#[test]
fn nan_between_checked_points_names_the_curve() {
    let text = GOOD.replace(
        "[curves.rim]\ntype = \"ellipse\"\ncenter = [0.0, 0.0, 2.0]\nrx = 1.5\nry = 1.0",
        "[curves.rim]\ntype = \"formula\"\nx = \"1.5*cos(v) + 0*sqrt((v-1)^2 - 0.000001)\"\ny = \"sin(v)\"\nz = \"2\"",
    );
    assert_ne!(text, GOOD);
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &text);
    let o = dir.path().join("out.obj");
    let out = pdeshape(&["surface", s(&d), "-o", s(&o), "--nv", "44"]);
    let line = assert_bad(
        &out,
        &[
            "d.toml:",
            "conditions[2].curve",
            "curve 'rim'",
            "not finite at v = ",
        ],
    );
    assert!(!line.contains("-o"), "{line}");
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
}

/// `creases` names curves of the design: a name that is not one is refused at its place, with
/// the nearest name suggested.
#[test]
fn declared_creases_name_curves() {
    let text = std::fs::read_to_string(example_path("cup_closed.toml")).unwrap();
    let line = bad_design(
        &text.replace("creases = [\"rim\"]", "creases = [\"rin\"]"),
        &["creases[0]", "unknown curve 'rin'", "did you mean 'rim'?"],
    );
    assert!(line.contains("d.toml:"), "{line}");
}
