//! Diagnostics of the examples: a crease along a shared edge, a smooth join, a bad condition.

use super::{check_report, diagnose, Verdict};
use crate::design::solve_design;
use crate::spec::{parse_design, DesignSpec};

fn example(name: &str) -> DesignSpec {
    let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
    parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The lid of `cup_closed.toml` meets the bowl at an angle along 'rim': G0 holds, G1 fails
/// (about 1.47 rad), and the verdict asks for attention although there is no warning.
#[test]
fn a_crease_fails_g1_and_the_verdict() {
    let spec = example("cup_closed.toml");
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
