//! Diagnostics of the examples: a crease along a shared edge, a smooth join, a bad condition.

use super::{check_report, diagnose, Verdict};
use crate::design::solve_design;
use crate::spec::{parse_design, DesignSpec};

fn example(name: &str) -> DesignSpec {
    let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
    parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `cup_closed.toml` without its declaration that the rim is a crease.
fn undeclared_cup() -> DesignSpec {
    let mut spec = example("cup_closed.toml");
    assert_eq!(spec.creases, ["rim"]);
    spec.creases.clear();
    spec
}

/// The lid of `cup_closed.toml` meets the bowl at an angle along 'rim': G0 holds, G1 fails
/// (about 1.47 rad), and the verdict asks for attention although there is no warning.
#[test]
fn a_crease_fails_g1_and_the_verdict() {
    let spec = undeclared_cup();
    let built = solve_design(&spec).unwrap();
    let d = diagnose(&spec, &built);
    let edges = d.edges.as_ref().unwrap();
    assert_eq!(edges.len(), 2);
    let rim = edges.iter().find(|e| e.curve == "rim").unwrap();
    assert!(rim.g0_met && !rim.g1_met, "{rim:?}");
    assert!((rim.g1 - 1.471).abs() < 1e-3, "{}", rim.g1);
    let belly = edges.iter().find(|e| e.curve == "belly").unwrap();
    assert!(belly.g0_met && belly.g1_met, "{belly:?}");
    assert_eq!(d.creases().count(), 1);
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    assert_eq!(d.verdict, Verdict::Attention);
    let json = d.to_json();
    assert_eq!(json["edges"].as_array().unwrap().len(), 2);
    assert_eq!(json["verdict"], "attention");
    // The crease is named above the verdict's label.
    let conclusion = d.conclusion();
    let lines: Vec<&str> = conclusion.lines().collect();
    assert_eq!(lines.len(), 2, "{conclusion}");
    assert!(
        lines[0]
            .starts_with("attention: shared edge 'bowl' u = 1 | 'lid' u = 0 along 'rim': G1 = ")
            && lines[0].ends_with(" rad (a crease)"),
        "{conclusion}"
    );
    assert_eq!(lines[1], "ATTENTION");
}

/// Without the lid the cup is G1 along its one shared edge: the verdict is OK, and the report
/// lists the edge and the condition errors of both patches.
#[test]
fn a_smooth_join_is_ok() {
    let spec = example("cup.toml");
    let built = solve_design(&spec).unwrap();
    let d = diagnose(&spec, &built);
    assert_eq!(d.verdict, Verdict::Ok, "{:?}", d.warnings);
    assert_eq!(d.conclusion(), "OK\n");
    assert_eq!(d.to_json()["verdict"], "ok");
    assert_eq!(d.creases().count(), 0);
    for s in &d.surfaces {
        assert!(!s.condition_errors.is_empty());
        assert!(s.condition_errors.iter().all(|e| e.relative < 1e-9));
    }
    let text = check_report("cup.toml", &spec, &built, &d);
    assert!(text.starts_with("design: cup.toml ("), "{text}");
    assert!(text.contains("along 'belly':  G0 = "), "{text}");
}

/// A single patch whose spectral remainder is off and whose curves are not finite Fourier series
/// misses its conditions: each such condition is a warning naming the patch, and the verdict
/// is not OK.
#[test]
fn an_unmet_condition_is_a_warning() {
    let text = r#"
[operator]
kind = "polyharmonic"
order = 2
a = 1.0

[solver]
modes = 2
remainder = false

[curves.c0]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.c1]
type = "formula"
x = "cos(v) + 0.3 * cos(5 * v)"
y = "sin(v)"
z = "1"

[curves.d]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[[conditions]]
u = 0.0
curve = "c0"
[[conditions]]
u = 0.0
derivative = 1
curve = "d"
[[conditions]]
u = 1.0
curve = "c1"
[[conditions]]
u = 1.0
derivative = 1
curve = "d"
"#;
    let spec = parse_design(text).unwrap();
    let built = solve_design(&spec).unwrap();
    let d = diagnose(&spec, &built);
    assert!(
        d.warnings
            .iter()
            .any(|w| w.contains("position condition at u = 1 is met only to")),
        "{:?}",
        d.warnings
    );
    assert_eq!(d.verdict, Verdict::Attention);
}

/// Judged by a seam tolerance, the lid's crease (1.47 rad) fails: the verdict is FAIL, the
/// reason names the seam and the tolerance, and the smooth seam along 'belly' neither fails
/// nor is named. A tolerance above the crease leaves the verdict of `diagnose`.
#[test]
fn a_seam_above_the_tolerance_fails() {
    let spec = undeclared_cup();
    let built = solve_design(&spec).unwrap();
    let mut d = diagnose(&spec, &built);
    d.judge_seams(super::SEAM_G1_TOLERANCE);
    assert_eq!(d.verdict, Verdict::Fail);
    assert_eq!(d.verdict.label(), "FAIL");
    let failed: Vec<&str> = d.failed_seams().map(|e| e.curve.as_str()).collect();
    assert_eq!(failed, ["rim"]);
    let conclusion = d.conclusion();
    let lines: Vec<&str> = conclusion.lines().collect();
    assert_eq!(lines.len(), 2, "{conclusion}");
    assert!(
        lines[0].starts_with("fail: shared edge 'bowl' u = 1 | 'lid' u = 0 along 'rim': G1 = 1.47")
            && lines[0].ends_with("rad, above the tolerance 0.01745 rad (a crease)"),
        "{conclusion}"
    );
    assert_eq!(lines[1], "FAIL");
    let json = d.to_json();
    assert_eq!(json["verdict"], "fail");
    assert_eq!(json["g1_tolerance"], super::SEAM_G1_TOLERANCE);
    let edges = json["edges"].as_array().unwrap();
    let failed_json: Vec<bool> = edges.iter().map(|e| e["failed"] == true).collect();
    assert_eq!(failed_json.iter().filter(|f| **f).count(), 1);

    let mut lenient = diagnose(&spec, &built);
    lenient.judge_seams(1.5);
    assert_eq!(lenient.verdict, Verdict::Attention);
    assert_eq!(lenient.failed_seams().count(), 0);
    assert!(lenient.conclusion().starts_with("attention: "));

    let smooth_spec = example("cup.toml");
    let smooth = solve_design(&smooth_spec).unwrap();
    let mut ok = diagnose(&smooth_spec, &smooth);
    ok.judge_seams(super::SEAM_G1_TOLERANCE);
    assert_eq!(ok.verdict, Verdict::Ok);
}

/// The same crease declared by the design (`creases = ["rim"]`, as `cup_closed.toml` has it):
/// measured and marked in the report, but neither a failed seam nor a reason, and the verdict
/// is OK; the smooth seam along 'belly' is not marked.
#[test]
fn a_declared_crease_is_reported_but_not_judged() {
    let spec = example("cup_closed.toml");
    let built = solve_design(&spec).unwrap();
    let mut d = diagnose(&spec, &built);
    d.judge_seams(super::SEAM_G1_TOLERANCE);
    let rim = d.edges.iter().flatten().find(|e| e.curve == "rim").unwrap();
    assert!(
        rim.declared_crease && !rim.g1_met && !rim.g1_failed,
        "{rim:?}"
    );
    assert!((rim.g1 - 1.471).abs() < 1e-3, "{}", rim.g1);
    let belly = d
        .edges
        .iter()
        .flatten()
        .find(|e| e.curve == "belly")
        .unwrap();
    assert!(!belly.declared_crease);
    assert_eq!(d.verdict, Verdict::Ok);
    assert_eq!(d.conclusion(), "OK\n");
    assert!(d.to_json()["edges"][0]["declared_crease"].is_boolean());
    let report = check_report("cup_closed.toml", &spec, &built, &d);
    assert_eq!(
        report.matches("(a crease the design declares)").count(),
        1,
        "{report}"
    );
}

/// A surface of revolution about z with radius `1 + c (u − 1)² / 2` and height `u`: at `u = 1`
/// it meets the unit cylinder tangentially (G1), its profile curving by `c` there.
struct Bulge(f64);

impl crate::surface::Surface for Bulge {
    fn v_domain(&self) -> crate::surface::VDomain {
        crate::surface::VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> crate::surface::Partials {
        let (s, c) = v.sin_cos();
        let d = u - 1.0;
        let (r, r1, r2) = (1.0 + self.0 * d * d / 2.0, self.0 * d, self.0);
        crate::surface::Partials {
            x: crate::Vec3::new(r * c, r * s, u),
            xu: crate::Vec3::new(r1 * c, r1 * s, 1.0),
            xv: crate::Vec3::new(-r * s, r * c, 0.0),
            xuu: crate::Vec3::new(r2 * c, r2 * s, 0.0),
            xuv: crate::Vec3::new(-r1 * s, r1 * c, 0.0),
            xvv: crate::Vec3::new(-r * c, -r * s, 0.0),
        }
    }
}

/// The G2 figure of a seam is the jump of the normal curvature across it: zero between a
/// surface and itself and between two cylinders, `|c|` where a profile of curvature `c` meets a
/// straight one tangentially, whichever way the two run in `u`.
#[test]
fn the_g2_figure_is_the_jump_of_the_normal_curvature() {
    use super::seam_g2;
    let cylinder = Bulge(0.0);
    let bulge = Bulge(0.4);
    assert_eq!(seam_g2(&bulge, 1.0, &bulge, 1.0, 64), 0.0);
    assert!(seam_g2(&cylinder, 1.0, &cylinder, 1.0, 64) < 1e-15);
    let g2 = seam_g2(&cylinder, 1.0, &bulge, 1.0, 64);
    assert!((g2 - 0.4).abs() < 1e-12, "{g2}");
    let g2 = seam_g2(&bulge, 1.0, &cylinder, 1.0, 64);
    assert!((g2 - 0.4).abs() < 1e-12, "{g2}");
    // The cup's seam along 'belly' is G1 but not G2: its two patches curve differently there.
    let spec = example("cup.toml");
    let built = solve_design(&spec).unwrap();
    let d = diagnose(&spec, &built);
    let belly = &d.edges.as_ref().unwrap()[0];
    assert!(
        belly.g1 < 1e-12 && belly.g2 > 1e-3 && belly.g2.is_finite(),
        "{belly:?}"
    );
}

/// Judged by a curvature tolerance, a seam whose G2 figure exceeds it fails (FAIL, a `fail:`
/// line naming the seam, its figure and the tolerance; `g2_failed` in the JSON), one within it
/// does not; a declared crease is not judged. The cup's belly is G1 but jumps in curvature.
#[test]
fn a_seam_above_the_curvature_tolerance_fails() {
    let spec = example("cup.toml");
    let built = solve_design(&spec).unwrap();
    let g2 = diagnose(&spec, &built).edges.unwrap()[0].g2;
    assert!(g2 > 1e-3 && g2.is_finite(), "{g2}");

    let mut strict = diagnose(&spec, &built);
    strict.judge_seams(super::SEAM_G1_TOLERANCE);
    assert_eq!(strict.verdict, Verdict::Ok);
    strict.judge_curvature(0.99 * g2);
    assert_eq!(strict.verdict, Verdict::Fail);
    let belly = &strict.edges.as_ref().unwrap()[0];
    assert!(belly.g2_failed && !belly.g1_failed, "{belly:?}");
    assert_eq!(strict.failed_seams().count(), 1);
    let conclusion = strict.conclusion();
    let lines: Vec<&str> = conclusion.lines().collect();
    assert_eq!(lines.len(), 2, "{conclusion}");
    assert!(
        lines[0].starts_with("fail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly': G2 = ")
            && lines[0].ends_with("(a curvature jump)"),
        "{conclusion}"
    );
    assert_eq!(lines[1], "FAIL");
    let json = strict.to_json();
    assert_eq!(json["edges"][0]["g2_failed"], true);
    assert_eq!(json["edges"][0]["g1_failed"], false);
    assert_eq!(json["edges"][0]["failed"], true);
    assert_eq!(json["g2_tolerance"], 0.99 * g2);

    let mut lenient = diagnose(&spec, &built);
    lenient.judge_curvature(1.01 * g2);
    assert_eq!(lenient.verdict, Verdict::Ok);
    assert_eq!(lenient.failed_seams().count(), 0);

    // The lid's rim is a declared crease: neither its angle nor its curvature is judged.
    let closed = example("cup_closed.toml");
    let built = solve_design(&closed).unwrap();
    let mut d = diagnose(&closed, &built);
    d.judge_curvature(0.0);
    let rim = d.edges.iter().flatten().find(|e| e.curve == "rim").unwrap();
    assert!(rim.declared_crease && !rim.g2_failed, "{rim:?}");
    let belly = d
        .edges
        .iter()
        .flatten()
        .find(|e| e.curve == "belly")
        .unwrap();
    assert!(belly.g2_failed);
}
