//! End-to-end tests of `pdeshape optimize`: the optimised design file (which `pdeshape surface`
//! re-runs), its mesh, picture and search log; bad input gives status 2, one located error line
//! and no files.

use crate::common::*;

/// A small biharmonic design with two parameters on the derivative curve d1 and `a`.
const DESIGN: &str = r#"title = "optimise me"
conditions = [
  { u = 0.0, curve = "p1" },
  { u = 0.0, derivative = 1, curve = "t1" },
  { u = 1.0, curve = "p2" },
  { u = 1.0, derivative = 1, curve = "t2" },
]

# The operator; the search writes its a back here.
[operator]
kind = "polyharmonic"
order = 2
a = 1.0

[solver]
modes = 2

[curves.p1]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0
[curves.d1]   # moved by the search
type = "circle"
center = [0.0, 0.0, 0.5]
radius = 1.5
[curves.t1]
type = "derivative"
position = "p1"
direction = "d1"
[curves.p2]
type = "circle"
center = [0.0, 0.0, 2.0]
radius = 0.7
[curves.d2]
type = "circle"
center = [0.0, 0.0, 2.5]
radius = 0.7
[curves.t2]
type = "derivative"
position = "p2"
direction = "d2"

[output]
nu = 12
nv = 16

[optimize]
objective = "bending"
evaluations = 120
chains = 2
polish = 30
parameters = [
  { name = "d1Dx", min = 0.2, max = 2.0 },
  { name = "d1Tz", min = -0.4, max = 0.4 },
  { name = "a", min = 0.3, max = 3.0 },
]
"#;

/// Status 2, one stderr line `error: …` with every needle, nothing on stdout, and no file but
/// the design left in the directory.
fn bad(text: &str, extra: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", text);
    let best = dir.path().join("best.toml");
    let mut args = vec!["optimize", s(&d), "-o", s(&best)];
    args.extend_from_slice(extra);
    let out = pdeshape(&args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line expected, got: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in: {stderr}");
    }
    assert!(out.stdout.is_empty());
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
}

#[test]
fn optimise_writes_a_design_that_reruns_with_its_mesh_picture_and_log() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", DESIGN);
    let best = dir.path().join("best.toml");
    let run = |threads: &str| {
        let out = pdeshape(&["optimize", s(&d), "-o", s(&best), "--threads", threads]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (
            String::from_utf8_lossy(&out.stdout).to_string(),
            std::fs::read_to_string(&best).unwrap(),
            std::fs::read_to_string(dir.path().join("best.csv")).unwrap(),
        )
    };
    let (report, text, log) = run("1");
    assert_eq!(
        files(dir.path()),
        ["best.csv", "best.obj", "best.png", "best.toml", "d.toml"]
    );
    // The same with two threads: the search does not depend on the thread count.
    let (report2, text2, log2) = run("2");
    assert_eq!((&report, &text, &log), (&report2, &text2, &log2));

    // The report: start and best values, best below start.
    let first = report.lines().next().unwrap();
    let num = |key: &str| -> f64 {
        let rest = &first[first.find(key).unwrap() + key.len()..];
        rest.split([',', ' ']).next().unwrap().parse().unwrap()
    };
    let (start, best_value) = (num("start "), num("best "));
    assert!(best_value < start, "{first}");

    // The file keeps the user's layout and comments and carries the parameters.
    assert!(text.contains("# The operator; the search writes its a back here."));
    assert!(text.contains("[curves.d1]   # moved by the search"));
    assert!(text.contains("dilate = {"), "{text}");
    assert!(!text.contains("a = 1.0\n"), "a was not written: {text}");

    // `pdeshape surface` re-runs it.
    let obj = dir.path().join("again.obj");
    let out = pdeshape(&["surface", s(&best), "-o", s(&obj)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&obj).unwrap(),
        std::fs::read(dir.path().join("best.obj")).unwrap()
    );
    // The picture is a PNG.
    let png = std::fs::read(dir.path().join("best.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");

    // The log: a header with the parameter names, one row per evaluation, and its best column
    // ends at the reported best (annealing rows) or below (polish).
    let mut lines = log.lines();
    assert_eq!(
        lines.next().unwrap(),
        "phase,chain,level,temperature,value,accepted,best,d1Dx,d1Tz,a"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // 120 annealing evaluations and at most 30 of the polish (it stops early once converged).
    let annealing = rows.iter().filter(|r| r[0] == "anneal").count();
    assert_eq!(annealing, 120);
    assert!(rows.len() > 120 && rows.len() <= 150, "{}", rows.len());
    assert!(rows.iter().all(|r| r.len() == 10));
    let min_value = rows
        .iter()
        .map(|r| r[4].parse::<f64>().unwrap())
        .fold(f64::INFINITY, f64::min);
    assert!(
        (min_value - best_value).abs() <= 1e-6 * best_value.abs(),
        "{min_value} vs {best_value}"
    );
}

#[test]
fn bad_input_is_one_located_line_and_no_files() {
    bad(
        &edit(DESIGN, r#"name = "d1Tz""#, r#"name = "d9Tz""#),
        &[],
        &["d.toml:", "optimize.parameters[1].name", "'d9'"],
    );
    bad(
        &edit(
            DESIGN,
            r#"objective = "bending""#,
            r#"objective = "bending +""#,
        ),
        &[],
        &["d.toml:", "optimize.objective"],
    );
    bad(
        &edit(DESIGN, "polish = 30\n", "polish = 30\nbogus = 1\n"),
        &[],
        &["d.toml:", "optimize", "bogus"],
    );
    bad(
        &DESIGN.replace("[optimize]", "[unused]"),
        &[],
        &["unknown field"],
    );
    let without = &DESIGN[..DESIGN.find("[optimize]").unwrap()];
    bad(without, &[], &["optimize", "no [optimize] section"]);
    bad(DESIGN, &["--chains", "0"], &["--chains"]);
    bad(DESIGN, &["--threads", "0"], &["--threads"]);
    bad(DESIGN, &["--evaluations", "1"], &["--evaluations"]);
    // A design that no parameter value can build fails as a whole, not with a panic.
    bad(
        &edit(
            DESIGN,
            r#"objective = "bending""#,
            r#"objective = "bending + ln(0 - 1)""#,
        ),
        &[],
        &["every evaluation failed"],
    );
}

#[test]
fn output_must_be_toml() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", DESIGN);
    let out = pdeshape(&["optimize", s(&d), "-o", s(&dir.path().join("best.obj"))]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains(".toml"));
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
}

/// `--method gradient`: the same files, a result below the start reached in gradient
/// evaluations (the log's phase `gradient`), the same for any thread count, and `--timings`
/// prints the search's time, evaluations and solves as one JSON line.
#[test]
fn gradient_search_writes_the_same_files_and_improves_the_start() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", DESIGN);
    let best = dir.path().join("best.toml");
    let run = |threads: &str| {
        let out = pdeshape(&[
            "optimize",
            s(&d),
            "-o",
            s(&best),
            "--method",
            "gradient",
            "--threads",
            threads,
            "--timings",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{stderr}");
        (
            String::from_utf8_lossy(&out.stdout).to_string(),
            std::fs::read_to_string(&best).unwrap(),
            std::fs::read_to_string(dir.path().join("best.csv")).unwrap(),
            stderr,
        )
    };
    let (report, text, log, stderr) = run("1");
    assert_eq!(
        files(dir.path()),
        ["best.csv", "best.obj", "best.png", "best.toml", "d.toml"]
    );
    // One gradient evaluation is a search of its own (not refused as annealing's budget of
    // fewer evaluations than chains would be).
    let out = pdeshape(&[
        "optimize",
        s(&d),
        "-o",
        s(&best),
        "--method",
        "gradient",
        "--evaluations",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("after 1 gradient evaluations"));
    let (report2, text2, log2, _) = run("2");
    assert_eq!((&report, &text, &log), (&report2, &text2, &log2));
    let first = report.lines().next().unwrap();
    assert!(first.contains("gradient evaluations"), "{first}");
    let num = |key: &str| -> f64 {
        let rest = &first[first.find(key).unwrap() + key.len()..];
        rest.split([',', ' ']).next().unwrap().parse().unwrap()
    };
    let (start, best_value) = (num("start "), num("best "));
    assert!(best_value < start, "{first}");
    // Every logged evaluation is a gradient one, and the best is the lowest logged value.
    let rows: Vec<Vec<&str>> = log
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert!(!rows.is_empty());
    assert!(rows.iter().all(|r| r[0] == "gradient"), "{log}");
    let min_value = rows
        .iter()
        .map(|r| r[4].parse::<f64>().unwrap())
        .fold(f64::INFINITY, f64::min);
    assert!(
        (min_value - best_value).abs() <= 1e-6 * best_value.abs(),
        "{min_value} vs {best_value}"
    );
    let timings: serde_json::Value = serde_json::from_str(
        stderr
            .lines()
            .find(|l| l.starts_with('{'))
            .unwrap_or_else(|| panic!("no timings line in {stderr}")),
    )
    .unwrap();
    assert_eq!(timings["evaluations"].as_u64(), Some(rows.len() as u64));
    // d1Dx, d1Tz and `a` are exact (one batched tangent solve for the three): one solve and
    // one tangent solve per gradient.
    assert_eq!(timings["solves"].as_u64(), Some(rows.len() as u64));
    assert_eq!(timings["tangent_solves"].as_u64(), Some(rows.len() as u64));
    assert!(timings["search_ms"].as_f64().unwrap() > 0.0);
}

#[test]
fn gradient_search_bad_input() {
    let gradient = ["--method", "gradient"];
    bad(
        DESIGN,
        &[&gradient[..], &["--chains", "2"]].concat(),
        &["--chains", "anneal"],
    );
    bad(DESIGN, &["--starts", "2"], &["--starts", "gradient"]);
    bad(
        DESIGN,
        &[&gradient[..], &["--starts", "0"]].concat(),
        &["--starts"],
    );
    bad(
        DESIGN,
        &[&gradient[..], &["--evaluations", "0"]].concat(),
        &["--evaluations"],
    );
}

/// `--method hybrid`: annealing's evaluations in the log, then gradient ones from each chain's
/// best point; its result is never above annealing's at the same seed (a bounds-only problem,
/// so every design is feasible and the order is the value's); `--starts` is refused.
#[test]
fn hybrid_search_starts_from_the_chains_and_is_never_worse_than_annealing() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", DESIGN);
    let best = dir.path().join("best.toml");
    let run = |method: &str| {
        let out = pdeshape(&["optimize", s(&d), "-o", s(&best), "--method", method]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (
            String::from_utf8_lossy(&out.stdout).to_string(),
            std::fs::read_to_string(dir.path().join("best.csv")).unwrap(),
        )
    };
    let (anneal, anneal_log) = run("anneal");
    let (hybrid, log) = run("hybrid");
    let best_of = |report: &str| -> f64 {
        let first = report.lines().next().unwrap();
        let rest = &first[first.find("best ").unwrap() + 5..];
        rest.split(' ').next().unwrap().parse().unwrap()
    };
    assert!(best_of(&hybrid) <= best_of(&anneal), "{hybrid}\n{anneal}");
    assert!(hybrid.contains("gradient search: 2 start(s)"), "{hybrid}");
    // Annealing's rows first, as annealing alone logs them, then the gradient rows.
    let n = anneal_log.lines().count();
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(lines[..n], anneal_log.lines().collect::<Vec<_>>()[..]);
    assert!(lines[n..].iter().all(|l| l.starts_with("gradient,")));
    assert!(lines.len() > n);
    bad(
        DESIGN,
        &["--method", "hybrid", "--starts", "2"],
        &["--starts", "gradient"],
    );
}
