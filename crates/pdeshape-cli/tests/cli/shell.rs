//! End-to-end tests of `pdeshape shell`. The error cases run without CalculiX (the solver is
//! named by `PDESHAPE_CCX`: a missing path, a program that fails, one that never finishes); the
//! `#[ignore]` tests need `ccx` and are run by `.ci/shell.sh` with `--ignored` (they fail when it
//! is missing).

use crate::common::*;

/// A clamped cylinder `R = 1 cm`, `H = 4 cm` with an axial line load on its free rim.
const CYLINDER: &str = r#"title = "cylinder"
units = "cm"
[[parametric]]
name = "wall"
x = "cos(v)"
y = "sin(v)"
z = "4*u"

[shell]
thickness = 0.0005
elements = [12, 24]
"#;

/// Runs `pdeshape shell` with `env` set and `TMPDIR` pointing at a fresh directory.
fn run(args: &[&str], env: &[(&str, &str)], tmp: &Path) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pdeshape"));
    c.arg("shell").args(args).env("TMPDIR", tmp);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("the pdeshape binary runs")
}

/// Runs `pdeshape COMMAND args` with `env` set and `TMPDIR` pointing at `tmp`.
fn run_command(command: &str, args: &[&str], env: &[(&str, &str)], tmp: &Path) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_pdeshape"));
    c.arg(command).args(args).env("TMPDIR", tmp);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("the pdeshape binary runs")
}

/// The strength optimisation of §7.5.1 as the example writes it.
fn yoghurt_optimize() -> String {
    let p = example_path("yoghurt_optimize.toml");
    std::fs::read_to_string(p).unwrap()
}

/// One `error: …` line with every needle, status `code`, nothing on stdout.
fn assert_fails(o: &Output, code: i32, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in {stderr}");
    }
    assert!(o.stdout.is_empty());
}

/// A fake solver: a shell script with `body`.
fn script(dir: &Path, body: &str) -> PathBuf {
    let p = dir.join("fake-ccx");
    std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    p
}

#[test]
fn solver_failures_are_one_line_errors_without_leftovers() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "c.toml", CYLINDER);
    let out = dir.path().join("field.vtu");
    // Missing solver: says how to install it.
    let o = run(
        &[s(&d), "-o", s(&out)],
        &[("PDESHAPE_CCX", "/nonexistent/ccx")],
        tmp.path(),
    );
    assert_fails(
        &o,
        1,
        &["not found", "apt-get install calculix-ccx", "PDESHAPE_CCX"],
    );
    // A run that fails (status 1, no result file).
    let failing = script(tmp.path(), "echo ' *ERROR reading the deck'; exit 3");
    let o = run(
        &[s(&d), "-o", s(&out)],
        &[("PDESHAPE_CCX", s(&failing))],
        tmp.path(),
    );
    assert_fails(&o, 1, &["failed", "*ERROR reading the deck"]);
    // A run that exceeds the time limit is killed.
    let slow = script(tmp.path(), "exec sleep 30");
    let timed = edit(
        CYLINDER,
        "elements = [12, 24]",
        "elements = [2, 4]\ntime_limit = 0.3",
    );
    let d2 = write(dir.path(), "slow.toml", &timed);
    let t = std::time::Instant::now();
    let o = run(
        &[s(&d2), "-o", s(&out)],
        &[("PDESHAPE_CCX", s(&slow))],
        tmp.path(),
    );
    assert_fails(&o, 1, &["did not finish within 0.3 s"]);
    assert!(t.elapsed().as_secs_f64() < 20.0);
    // No output file, no temporary file beside it, no solver directory left in TMPDIR.
    assert_eq!(files(dir.path()), vec!["c.toml", "slow.toml"]);
    assert_eq!(files(tmp.path()), vec!["fake-ccx"]);
}

#[test]
fn bad_values_are_refused_before_the_solver_runs() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "c.toml", CYLINDER);
    let none = [("PDESHAPE_CCX", "/nonexistent/ccx")];
    let o = run(&[s(&d), "--thickness", "0"], &none, tmp.path());
    assert_bad(&o, &["--thickness", "positive"]);
    let o = run(&[s(&d), "--thickness=-0.001"], &none, tmp.path());
    assert_bad(&o, &["--thickness", "positive"]);
    let o = run(&[s(&d), "--elements", "300"], &none, tmp.path());
    assert_bad(&o, &["--elements", "between 1 and 250"]);
    let o = run(&[s(&d), "--elements", "0"], &none, tmp.path());
    assert_bad(&o, &["--elements"]);
    let o = run(&[s(&d), "-o", "x.vtk"], &none, tmp.path());
    assert_bad(&o, &["-o x.vtk", ".vtu or .csv"]);
    // In the design file: located at file:line:col.
    let bad = edit(CYLINDER, "thickness = 0.0005", "thickness = -0.0005");
    let b = write(dir.path(), "b.toml", &bad);
    let o = run(&[s(&b)], &none, tmp.path());
    assert_bad(&o, &["b.toml:10:1", "shell.thickness", "positive"]);
    let bad = edit(
        CYLINDER,
        "elements = [12, 24]",
        "elements = [12, 24]\nclamped = [{ patch = \"lid\", side = \"u0\" }]",
    );
    let b = write(dir.path(), "b.toml", &bad);
    let o = run(&[s(&b)], &none, tmp.path());
    assert_bad(&o, &["b.toml:12:", "shell.clamped[0].patch", "'lid'"]);
    // A mesh too large for the node limit or the memory budget.
    let big = edit(CYLINDER, "elements = [12, 24]", "elements = [400, 1000]");
    let b = write(dir.path(), "big.toml", &big);
    let o = run(&[s(&b)], &none, tmp.path());
    assert_bad(&o, &["big.toml:11:", "shell.elements", "limit of 200000"]);
    let o = run(
        &[s(&d), "--elements", "100"],
        &[
            ("PDESHAPE_CCX", "/nonexistent/ccx"),
            ("PDESHAPE_MAX_MEMORY", "1000000"),
        ],
        tmp.path(),
    );
    assert_bad(&o, &["--elements", "memory"]);
    assert_eq!(files(tmp.path()), Vec::<String>::new());
}

/// Reads the CSV of a run: `(patch, u, v, x, y, z, max_shear)` rows.
fn read_csv(text: &str) -> Vec<(String, [f64; 6])> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("patch,u,v,x,y,z,max_shear"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 7, "{l}");
            let mut v = [0.0; 6];
            for (k, x) in f[1..].iter().enumerate() {
                v[k] = x.parse().unwrap();
            }
            (f[0].to_string(), v)
        })
        .collect()
}

#[test]
#[ignore = "needs CalculiX (ccx); run by .ci/shell.sh"]
fn the_books_default_load_on_a_cylinder_gives_the_membrane_shear() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "c.toml", CYLINDER);
    let csv = dir.path().join("field.csv");
    let o = run(&[s(&d), "-o", s(&csv), "--json"], &[], tmp.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // 15 N/m on 0.5 mm: membrane stress q/t = 30 kPa, largest shear q/(2t) = 15 kPa away from
    // the clamped edge (where bending adds to it: the peak is at least that).
    let q_2t = 15.0 / (2.0 * 0.0005);
    let peak = v["max_shear"].as_f64().unwrap();
    assert!(peak >= 0.98 * q_2t, "{v}");
    // Mass: ρ t 2πRH = 1050 · 0.0005 · 2π · 0.01 · 0.04.
    let mass = 1050.0 * 0.0005 * 2.0 * std::f64::consts::PI * 0.01 * 0.04;
    assert!(
        (v["mass"].as_f64().unwrap() - mass).abs() < 1e-9 * mass,
        "{v}"
    );
    // Eight-node elements have no centre node: (2·12 + 1) × 2·24 grid points less 12 × 24.
    assert_eq!(v["nodes"].as_u64().unwrap(), 25 * 48 - 12 * 24);
    let rows = read_csv(&std::fs::read_to_string(&csv).unwrap());
    assert_eq!(rows.len(), 25 * 48 - 12 * 24);
    let mut band = 0;
    for (patch, r) in &rows {
        assert_eq!(patch, "wall");
        // Coordinates in metres.
        assert!((r[2].hypot(r[3]) - 0.01).abs() < 1e-12 && r[4] >= 0.0 && r[4] <= 0.04 + 1e-15);
        if (0.4..=0.9).contains(&r[0]) {
            assert!((r[5] - q_2t).abs() < 0.02 * q_2t, "{r:?}");
            band += 1;
        }
    }
    assert!(band > 100, "{band}");
    assert_eq!(files(tmp.path()), Vec::<String>::new());
}

#[test]
#[ignore = "needs CalculiX (ccx); run by .ci/shell.sh"]
fn the_yoghurt_container_writes_a_consistent_vtu() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let root = example_path("yoghurt.toml");
    let vtu = dir.path().join("y.vtu");
    let o = run(
        &[s(&root), "-o", s(&vtu), "--elements", "3"],
        &[],
        tmp.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = String::from_utf8_lossy(&o.stdout).to_string();
    for key in [
        "largest shear stress:",
        "ratio to yield:",
        "mass:",
        "mesh: ",
        "solver ",
    ] {
        assert!(report.contains(key), "{key}: {report}");
    }
    let text = std::fs::read_to_string(&vtu).unwrap();
    check_vtu(&text);
}

/// Parses the VTU's structure: the piece's counts against the data arrays' lengths, the
/// connectivity against the points, offsets against the cell types' node counts.
fn check_vtu(text: &str) {
    let attr = |tag: &str, name: &str| -> usize {
        let i = text.find(tag).unwrap();
        let rest = &text[i..];
        let j = rest.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        rest[j..j + rest[j..].find('"').unwrap()].parse().unwrap()
    };
    let points = attr("<Piece", "NumberOfPoints");
    let cells = attr("<Piece", "NumberOfCells");
    let array = |name: &str| -> Vec<f64> {
        let key = format!("Name=\"{name}\"");
        let i = text.find(&key).unwrap();
        let start = i + text[i..].find('>').unwrap() + 1;
        let end = start + text[start..].find("</DataArray>").unwrap();
        text[start..end]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect()
    };
    assert!(text.starts_with("<?xml") && text.trim_end().ends_with("</VTKFile>"));
    assert_eq!(array("Points").len(), 3 * points);
    assert_eq!(array("max_shear").len(), points);
    assert_eq!(array("displacement").len(), 3 * points);
    let types = array("types");
    let offsets = array("offsets");
    let conn = array("connectivity");
    assert_eq!(types.len(), cells);
    assert_eq!(offsets.len(), cells);
    let mut last = 0.0;
    for (t, o) in types.iter().zip(&offsets) {
        let n = match *t as u8 {
            22 => 6.0,
            23 => 8.0,
            t => panic!("cell type {t}"),
        };
        assert_eq!(*o - last, n);
        last = *o;
    }
    assert_eq!(last as usize, conn.len());
    assert!(conn.iter().all(|&c| c >= 0.0 && (c as usize) < points));
    assert!(array("max_shear")
        .iter()
        .all(|&x| x.is_finite() && x >= 0.0));
}

#[test]
fn a_strength_optimisation_without_the_solver_is_one_error_and_no_files() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "y.toml", &yoghurt_optimize());
    let best = dir.path().join("best.toml");
    let o = run_command(
        "optimize",
        &[s(&d), "-o", s(&best)],
        &[("PDESHAPE_CCX", "/nonexistent/ccx")],
        tmp.path(),
    );
    assert_fails(
        &o,
        1,
        &[
            "shell analysis of the starting design failed",
            "not found",
            "apt-get install calculix-ccx",
        ],
    );
    assert_eq!(files(dir.path()), vec!["y.toml"]);
    assert_eq!(files(tmp.path()), Vec::<String>::new());
    // Without `max_shear` in the formulas the solver is never run: the mass alone needs none.
    let mass_only = edit(
        &yoghurt_optimize(),
        r#"{ expr = "max_shear / yield", max = 0.3, weight = 10000.0 },"#,
        "",
    );
    let d = write(dir.path(), "m.toml", &mass_only);
    let o = run_command(
        "optimize",
        &[s(&d), "-o", s(&best), "--evaluations", "4", "--polish", "0"],
        &[("PDESHAPE_CCX", "/nonexistent/ccx")],
        tmp.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = String::from_utf8_lossy(&o.stdout);
    assert!(report.contains("0 failed shell analyses"), "{report}");
    assert!(report.contains(", mass = "), "{report}");
}

/// The gradient search differences the shell analysis: without the solver it stops at its
/// first design with the solver's one-line message, and writes nothing.
#[test]
fn a_gradient_strength_optimisation_without_the_solver_is_one_error_and_no_files() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "y.toml", &yoghurt_optimize());
    let best = dir.path().join("best.toml");
    for method in ["gradient", "hybrid"] {
        let o = run_command(
            "optimize",
            &[s(&d), "-o", s(&best), "--method", method],
            &[("PDESHAPE_CCX", "/nonexistent/ccx")],
            tmp.path(),
        );
        let code = o.status.code().unwrap_or(0);
        assert!(code == 1 || code == 2, "{method}: {code}");
        assert_fails(&o, code, &["not found", "apt-get install calculix-ccx"]);
        assert_eq!(files(dir.path()), vec!["y.toml"]);
        assert_eq!(files(tmp.path()), Vec::<String>::new());
    }
}

/// The objective (without penalties) of the report's `start:` line.
fn start_objective(report: &str) -> f64 {
    let line = report
        .lines()
        .find(|l| l.starts_with("start: objective "))
        .unwrap_or_else(|| panic!("no start line: {report}"));
    line["start: objective ".len()..]
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// A short strength optimisation with the search options `search`: a thin wall (0.15 mm: about
/// 25 % of the yield stress on this coarse mesh, near the 30 % limit) and a coarse mesh. The
/// result is feasible and lighter than the start, and `pdeshape shell` confirms its stress from
/// the file the search wrote.
fn short_strength_optimisation(search: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let text = edit(
        &edit(
            &yoghurt_optimize(),
            "thickness = 0.0005",
            "thickness = 0.00015",
        ),
        "elements = [4, 32]",
        "elements = [2, 16]",
    );
    let d = write(dir.path(), "y.toml", &text);
    let best = dir.path().join("best.toml");
    let o = run_command(
        "optimize",
        &[&[s(&d), "-o", s(&best)][..], search].concat(),
        &[],
        tmp.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(report.contains("the result is feasible"), "{report}");
    let start = start_objective(&report);
    let o = run_command("shell", &[s(&best), "--json"], &[], tmp.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let ratio = v["ratio_to_yield"].as_f64().unwrap();
    assert!(ratio <= 0.3, "largest shear / yield = {ratio}: {report}");
    let grams = 1000.0 * v["mass"].as_f64().unwrap();
    assert!(grams < start, "mass {grams} g, start {start} g: {report}");
    assert_eq!(files(tmp.path()), Vec::<String>::new());
}

#[test]
#[ignore = "needs CalculiX (ccx); run by .ci/shell.sh"]
fn a_short_strength_optimisation_lowers_the_mass_within_the_stress_limit() {
    short_strength_optimisation(&["--evaluations", "24", "--chains", "2", "--polish", "8"]);
}

/// The gradient search, `max_shear` differenced by the solver's runs.
#[test]
#[ignore = "needs CalculiX (ccx); run by .ci/shell.sh"]
fn a_short_gradient_strength_optimisation_lowers_the_mass_within_the_stress_limit() {
    short_strength_optimisation(&["--method", "gradient", "--evaluations", "8"]);
}

#[test]
#[ignore = "needs CalculiX (ccx); run by .ci/shell.sh"]
fn render_colours_the_container_by_its_shear_stress() {
    let dir = tempfile::tempdir().unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let root = example_path("yoghurt.toml");
    let png = dir.path().join("y.png");
    let o = run_command(
        "render",
        &[
            s(&root),
            "-o",
            s(&png),
            "--color",
            "shear",
            "--size",
            "400x300",
        ],
        &[],
        tmp.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = String::from_utf8_lossy(&o.stdout).to_string();
    // The colour map's top and the peak are the analysis's largest shear stress, in the
    // reports' four significant digits.
    let o = run_command("shell", &[s(&root), "--json"], &[], tmp.path());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let peak = pdeshape::number::sig(v["max_shear"].as_f64().unwrap() / 1e6, 4);
    assert!(
        line.contains(&format!("to {peak} MPa (red), peak {peak} MPa")),
        "{peak}: {line}"
    );
    // The picture has strongly red and strongly blue pixels (a stress field, not one colour).
    let decoder = png::Decoder::new(std::fs::File::open(&png).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let (mut red, mut blue) = (0, 0);
    for p in buf[..info.buffer_size()].chunks(channels) {
        let (r, g, b) = (p[0] as i32, p[1] as i32, p[2] as i32);
        if r > 2 * g && r > 2 * b {
            red += 1;
        }
        if b > 2 * r && b > g + 40 {
            blue += 1;
        }
    }
    assert!(red > 50 && blue > 50, "red {red}, blue {blue}");
    // A --range in MPa is the colour bar's.
    let o = run_command(
        "render",
        &[
            s(&root),
            "-o",
            s(&png),
            "--color",
            "shear",
            "--range",
            "0,2",
        ],
        &[],
        tmp.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("from 0 MPa (blue) to 2.000 MPa"));
    assert_eq!(files(tmp.path()), Vec::<String>::new());
}
