//! End-to-end tests of STEP/IGES output (`pdeshape surface -o x.step|x.igs`) and `roundtrip`.

use crate::common::*;

#[test]
fn step_and_iges_are_written_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    for name in ["part.step", "part.igs"] {
        let out_path = dir.path().join(name);
        let out = pdeshape(&["surface", s(&d), "-o", s(&out_path), "--tolerance", "1e-4"]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("(certified)"), "{stdout}");
        // A proven figure is printed as a bound.
        assert!(stdout.contains("deviation ≤ "), "{stdout}");
        assert!(!stdout.contains('≈'), "{stdout}");
        let out = pdeshape(&["roundtrip", s(&d), s(&out_path), "--tolerance", "1e-4"]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{stdout}");
        assert!(stdout.contains(": ok"), "{stdout}");
        // A tolerance far below the file's deviation fails with status 1.
        let out = pdeshape(&["roundtrip", s(&d), s(&out_path), "--tolerance", "1e-12"]);
        assert_eq!(out.status.code(), Some(1));
    }
}

#[test]
fn bad_flags_name_the_flag_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", GOOD);
    let out_path = dir.path().join("part.step");
    let out = pdeshape(&["surface", s(&d), "-o", s(&out_path), "--units", "furlong"]);
    assert_bad(&out, &["--units", "furlong"]);
    let out = pdeshape(&["surface", s(&d), "-o", s(&out_path), "--tolerance=-1"]);
    assert_bad(&out, &["--tolerance"]);
    let out = pdeshape(&[
        "surface",
        s(&d),
        "-o",
        s(&out_path),
        "--tolerance",
        "1e-300",
    ]);
    assert_bad(&out, &["--tolerance"]);
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
    // A broken file read back: located error, status 2.
    let broken = write(
        dir.path(),
        "b.step",
        "ISO-10303-21;\nDATA;\n#1=CARTESIAN_POINT('',(1.,x));\nENDSEC;\nEND-ISO-10303-21;\n",
    );
    let out = pdeshape(&["roundtrip", s(&d), s(&broken)]);
    assert_bad(&out, &["b.step", "line 3"]);
    // A file that stops inside its DATA section: named, status 2.
    let cut = write(
        dir.path(),
        "c.step",
        "ISO-10303-21;\nDATA;\n#1=CARTESIAN_POINT('',(1.,2.,3.));\n",
    );
    let out = pdeshape(&["roundtrip", s(&d), s(&cut)]);
    assert_bad(&out, &["c.step", "ends inside the DATA section"]);
}

/// A surface without derivative bounds (a tube whose foot is an ellipse reparametrised by arc
/// length: that curve carries none) reports its sampled deviation as an estimate (`≈`), never
/// as a bound, with the condition that lacks bounds.
#[test]
fn sampled_deviations_are_printed_as_estimates() {
    let dir = tempfile::tempdir().unwrap();
    let design = dir.path().join("arc.toml");
    std::fs::write(
        &design,
        r#"title = "Tube on an arc-length ellipse"
conditions = [
  { u = 0.0, curve = "foot" },
  { u = 0.0, derivative = 1, curve = "up" },
  { u = 1.0, curve = "mouth" },
  { u = 1.0, derivative = 1, curve = "up" },
]
[operator]
kind = "polyharmonic"
order = 2
a = 1.0
[curves.foot]
type = "ellipse"
center = [0.0, 0.0, 0.0]
axis1 = [1.5, 0.0, 0.0]
axis2 = [0.0, 0.7, 0.0]
arc_length = true
[curves.up]
type = "point"
at = [0.0, 0.0, 3.0]
[curves.mouth]
type = "circle"
center = [0.0, 0.0, 4.0]
radius = 0.8
"#,
    )
    .unwrap();
    let out_path = dir.path().join("y.step");
    let out = pdeshape(&["surface", s(&design), "-o", s(&out_path)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let sampled: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("not certified"))
        .collect();
    assert!(!sampled.is_empty(), "{stdout}");
    for line in sampled {
        assert!(
            line.contains("deviation ≈ ") && !line.contains('≤'),
            "{line}"
        );
        assert!(
            line.contains("condition 0") && line.contains("ArcLength"),
            "{line}"
        );
    }
}

#[test]
fn trimmed_designs_are_written_with_their_holes_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "vase.toml", &example("trimmed_vase.toml"));
    for name in ["vase.step", "vase.igs"] {
        let out_path = dir.path().join(name);
        let out = pdeshape(&["surface", s(&d), "-o", s(&out_path)]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for k in 0..3 {
            assert!(
                stdout.contains(&format!("    hole {k}: edge of ")),
                "{stdout}"
            );
        }
        let text = std::fs::read_to_string(&out_path).unwrap();
        if name.ends_with(".step") {
            assert_eq!(text.matches("FACE_BOUND('',").count(), 3);
        } else {
            assert!(text.contains("\n     144"), "no entity 144");
        }
        let out = pdeshape(&["roundtrip", s(&d), s(&out_path)]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{stdout}");
        assert!(stdout.contains(": ok"), "{stdout}");
    }
}

/// A formula surface (the sphere of the benchmark designs) is written with a certified bound
/// (`≤`, interval arithmetic), and read back within it.
#[test]
fn formula_surfaces_are_certified() {
    let dir = tempfile::tempdir().unwrap();
    let design = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../bench/designs/formula_ball.toml");
    let out_path = dir.path().join("ball.step");
    let out = pdeshape(&["surface", s(&design), "-o", s(&out_path)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("deviation ≤ "), "{stdout}");
    assert!(stdout.contains("(certified)"), "{stdout}");
    let out = pdeshape(&["roundtrip", s(&design), s(&out_path)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains(": ok"), "{stdout}");
}

/// The holes of the four trimmed examples are written with certified deviations: the edge's
/// from its face and the whole from the trim curve's image (`≤`).
#[test]
fn hole_edges_of_the_trimmed_examples_are_certified() {
    let dir = tempfile::tempdir().unwrap();
    let examples = examples_dir();
    for (name, count) in [
        ("teacup", 2),
        ("aeroplane", 5),
        ("trimmed_vase", 3),
        ("trim_book_methods", 2),
    ] {
        let design = examples.join(format!("{name}.toml"));
        let out_path = dir.path().join(format!("{name}.step"));
        let out = pdeshape(&["surface", s(&design), "-o", s(&out_path)]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let holes: Vec<&str> = stdout.lines().filter(|l| l.contains("    hole ")).collect();
        assert_eq!(holes.len(), count, "{name}: {stdout}");
        for line in holes {
            assert!(
                line.contains("from the face (certified)")
                    && line.contains("from the trim curve's image (≤)")
                    && !line.contains("sampled")
                    && !line.contains('≈'),
                "{name}: {line}"
            );
        }
    }
}

/// The examples whose analytic patches carry a spectral remainder (B-spline, point-sample,
/// local-edit condition curves, and the tangent fields of attached patches) and the
/// spine-edited ones are written with a certified deviation on every surface.
#[test]
fn remainder_patches_are_certified() {
    let dir = tempfile::tempdir().unwrap();
    let root = examples_dir();
    for name in [
        "cup_lip.toml",
        "yoghurt.toml",
        "swirl_port.toml",
        "swirl_port_params.toml",
        "anim/water_glass.toml",
        "anim/face.toml",
        "teacup.toml",
        "aeroplane.toml",
        "spine_bend.toml",
        "anim/fish.toml",
        "anim/snake.toml",
    ] {
        let out_path = dir.path().join("x.step");
        let out = pdeshape(&["surface", s(&root.join(name)), "-o", s(&out_path)]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let faces: Vec<&str> = stdout.lines().filter(|l| l.contains("deviation")).collect();
        assert!(!faces.is_empty(), "{name}: {stdout}");
        for line in faces {
            assert!(
                line.contains("deviation ≤ ") && line.contains("(certified)"),
                "{name}: {line}"
            );
        }
    }
}

#[test]
fn import_reads_a_step_part_and_fills_its_gap() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("part.toml");
    let step = example_path("cad/box_corner_gap.step");
    let run = pdeshape(&["import", s(&step), "-o", s(&out), "--fill"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("# Imported from box_corner_gap.step"),
        "{text}"
    );
    assert!(text.contains("reference = true") && text.contains("[[nsided]]"));
    let check = pdeshape(&["check", s(&out)]);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(check.status.success(), "{stdout}");
    assert!(stdout.starts_with("OK"), "{stdout}");
    // Bad input: one line, status 2, nothing written.
    let bad = dir.path().join("bad.step");
    let text = std::fs::read_to_string(&step).unwrap();
    let broken = text.replacen(
        "CYLINDRICAL_SURFACE('',",
        "CYLINDRICAL_SURFACE('',#999999,",
        1,
    );
    std::fs::write(&bad, broken).unwrap();
    let none = dir.path().join("none.toml");
    assert_bad(
        &pdeshape(&["import", s(&bad), "-o", s(&none)]),
        &["bad.step", "line "],
    );
    assert!(!none.exists());
    assert_bad(
        &pdeshape(&["import", s(&out), "-o", s(&none)]),
        &["not a STEP or IGES file name"],
    );
    assert_bad(
        &pdeshape(&["import", s(&step), "-o", "x.obj"]),
        &["design file (.toml)"],
    );
    assert!(!none.exists());
}

#[test]
fn import_reads_nurbs_faces_and_fills_their_gap_g1_or_g2() {
    let dir = tempfile::tempdir().unwrap();
    let step = example_path("cad/box_corner_gap_nurbs.step");
    let g1 = dir.path().join("g1.toml");
    let run = pdeshape(&["import", s(&step), "-o", s(&g1), "--fill"]);
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(run.status.success(), "{said}");
    assert!(said.contains("9 of 9 faces"), "{said}");
    assert_eq!(
        said.matches("RATIONAL_B_SPLINE_SURFACE").count(),
        3,
        "{said}"
    );
    let text = std::fs::read_to_string(&g1).unwrap();
    assert_eq!(text.matches("[[nurbs]]").count(), 9);
    assert!(!text.contains("g2 = true"));
    let check = pdeshape(&["check", s(&g1)]);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        check.status.success() && stdout.starts_with("OK"),
        "{stdout}"
    );
    // G2: order 3 with curvature ribbons; `check` reports each side's G2 residual, and the
    // corners where the three fillets' curvatures cannot all be met.
    let g2 = dir.path().join("g2.toml");
    let run = pdeshape(&["import", s(&step), "-o", s(&g2), "--fill-g2"]);
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(run.status.success(), "{said}");
    assert!(said.contains("fill1 (G2)"), "{said}");
    let text = std::fs::read_to_string(&g2).unwrap();
    assert_eq!(text.matches("g2 = true").count(), 3, "{text}");
    assert!(text.contains("order = 3"), "{text}");
    let check = pdeshape(&["check", s(&g2)]);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(check.status.success(), "{stdout}");
    let sides: Vec<&str> = stdout.lines().filter(|l| l.contains(", G2 to ")).collect();
    assert_eq!(sides.len(), 3, "{stdout}");
    assert!(stdout.contains("curvature data disagree"), "{stdout}");
}

#[test]
fn import_reads_iges_parts_and_fills_their_gap() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "box_corner_gap_brep.igs",
        "box_corner_gap_nurbs_trimmed.igs",
    ] {
        let iges = example_path(&format!("cad/{name}"));
        let out = dir.path().join("part.toml");
        let run = pdeshape(&["import", s(&iges), "-o", s(&out), "--fill"]);
        let said = String::from_utf8_lossy(&run.stdout).to_string();
        assert!(
            run.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(
            said.contains("9 of 9 faces") && said.contains("(D "),
            "{said}"
        );
        assert!(said.contains("filled by [[nsided]] fill1"), "{said}");
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(
            text.starts_with(&format!("# Imported from {name}")),
            "{text}"
        );
        let check = pdeshape(&["check", s(&out)]);
        let stdout = String::from_utf8_lossy(&check.stdout);
        assert!(
            check.status.success() && stdout.starts_with("OK"),
            "{stdout}"
        );
    }
    // Bad input: one line naming the IGES place, status 2, nothing written.
    let text = std::fs::read_to_string(example_path("cad/box_corner_gap_brep.igs")).unwrap();
    let none = dir.path().join("none.toml");
    let bad = dir.path().join("bad.igs");
    let lines: Vec<&str> = text.lines().collect();
    // The last parameter lines lost, the Terminate line kept: its counts no longer hold.
    let cut = [&lines[..lines.len() - 10], &lines[lines.len() - 1..]].concat();
    std::fs::write(&bad, cut.join("\n")).unwrap();
    assert_bad(
        &pdeshape(&["import", s(&bad), "-o", s(&none)]),
        &["bad.igs", "T 1", "truncated"],
    );
    let broken: Vec<String> = lines
        .iter()
        .map(|l| {
            if l.starts_with("     100") && l.as_bytes().get(72) == Some(&b'D') {
                l.replacen("     100", "     125", 1)
            } else if l.starts_with("100,") && l.as_bytes().get(72) == Some(&b'P') {
                l.replacen("100,", "125,", 1)
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&bad, broken.join("\n")).unwrap();
    assert_bad(
        &pdeshape(&["import", s(&bad), "-o", s(&none)]),
        &["bad.igs", "D ", "entity 125"],
    );
    assert!(!none.exists());
}
