//! The JSON schema of `pdeshape schema` checked by an independent validator (the `jsonschema`
//! crate, draft 7): every example design is accepted, and each of a set of invalid designs is
//! rejected by the schema and by `pdeshape check` alike.

use crate::common::*;
use std::path::PathBuf;

fn validator() -> jsonschema::Validator {
    let out = pdeshape(&["schema"]);
    assert!(out.status.success());
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    jsonschema::draft7::new(&schema).expect("the schema is a valid draft-7 schema")
}

/// The design file as JSON, as an editor's TOML extension hands it to the schema.
fn as_json(text: &str) -> serde_json::Value {
    let v: toml::Value = toml::from_str(text).unwrap();
    serde_json::to_value(v).unwrap()
}

fn examples() -> Vec<PathBuf> {
    let root = examples_dir();
    let mut all = Vec::new();
    for dir in [root.clone(), root.join("spline"), root.join("anim")] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            // Morph files name two designs; they are not designs themselves.
            let morph = || std::fs::read_to_string(&p).unwrap().contains("\n[morph]");
            if p.extension().is_some_and(|x| x == "toml") && !morph() {
                all.push(p);
            }
        }
    }
    all.sort();
    all
}

#[test]
fn every_example_is_valid_under_the_schema() {
    let v = validator();
    let all = examples();
    assert!(all.len() >= 20, "{}", all.len());
    for p in &all {
        let json = as_json(&std::fs::read_to_string(p).unwrap());
        let errors: Vec<String> = v.iter_errors(&json).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{}: {errors:?}", p.display());
    }
}

/// `(what, example, from, to)`: the example with `from` replaced by `to` once.
const INVALID: &[(&str, &str, &str, &str)] = &[
    ("order 0", "cup.toml", "order = 2", "order = 0"),
    ("order 21", "cup.toml", "order = 2", "order = 21"),
    ("a = 0", "cup.toml", "a = 1.0", "a = 0.0"),
    ("a above 10⁶", "cup.toml", "a = 1.0", "a = 2e6"),
    (
        "negative radius",
        "cup.toml",
        "radius = 1.0",
        "radius = -1.0",
    ),
    ("zero radius", "cup.toml", "radius = 1.35", "radius = 0.0"),
    (
        "u = 1.5",
        "cup.toml",
        "{ u = 1.0, curve = \"belly\" }",
        "{ u = 1.5, curve = \"belly\" }",
    ),
    (
        "u < 0",
        "cup.toml",
        "{ u = 0.0, curve = \"bottom\" }",
        "{ u = -0.5, curve = \"bottom\" }",
    ),
    (
        "modes = 0",
        "cup.toml",
        "[operator]",
        "solver = { modes = 0 }\n\n[operator]",
    ),
    (
        "modes = 257",
        "cup.toml",
        "[operator]",
        "solver = { modes = 257 }\n\n[operator]",
    ),
    (
        "unknown curve type",
        "cup.toml",
        "type = \"point\"",
        "type = \"spiral\"",
    ),
    (
        "unknown operator kind",
        "cup.toml",
        "kind = \"polyharmonic\"",
        "kind = \"harmonic\"",
    ),
    (
        "unknown top-level key",
        "cup.toml",
        "[operator]",
        "colour = 3\n\n[operator]",
    ),
    (
        "string for a number",
        "cup.toml",
        "scale = 2.5",
        "scale = \"2.5\"",
    ),
    (
        "unknown units",
        "cup.toml",
        "[operator]",
        "units = \"furlong\"\n\n[operator]",
    ),
    (
        "grid nu = 1",
        "cup.toml",
        "[operator]",
        "[output]\nnu = 1\n\n[operator]",
    ),
    (
        "grid nv = 2",
        "cup.toml",
        "[operator]",
        "[output]\nnv = 2\n\n[operator]",
    ),
    (
        "spline degree 0",
        "spline/example1.toml",
        "degree = [3, 3]",
        "degree = [0, 3]",
    ),
    (
        "spline degree 21",
        "spline/example1.toml",
        "degree = [3, 3]",
        "degree = [3, 21]",
    ),
    (
        "spline three degrees",
        "spline/example1.toml",
        "degree = [3, 3]",
        "degree = [3, 3, 3]",
    ),
    (
        "dynamic intervals 4",
        "dynamic_interpolate.toml",
        "intervals = 200",
        "intervals = 4",
    ),
    (
        "dynamic intervals too many",
        "dynamic_interpolate.toml",
        "intervals = 200",
        "intervals = 2000000",
    ),
    (
        "derivative scale 0",
        "cup.toml",
        "scale = 2.5",
        "scale = 0.0",
    ),
    (
        "transform factor 0",
        "swirl_port.toml",
        "factor = 0.8",
        "factor = 0.0",
    ),
    (
        "spline spans 0",
        "spline/coons_bspline.toml",
        "spans = [3, 3]",
        "spans = [3, 0]",
    ),
    (
        "spline spans 1001",
        "spline/coons_bspline.toml",
        "spans = [3, 3]",
        "spans = [1001, 3]",
    ),
    (
        "dynamic stiffness 0",
        "dynamic_interpolate.toml",
        "stiffness = 0.01",
        "stiffness = 0.0",
    ),
    (
        "dynamic frames_every 0",
        "dynamic_interpolate.toml",
        "frames_every = 2000",
        "frames_every = 0",
    ),
    (
        "blend elements 0",
        "blend_cylinders.toml",
        "elements = [8, 4]",
        "elements = [8, 0]",
    ),
    (
        "blend elements 4097",
        "blend_cylinders.toml",
        "elements = [8, 4]",
        "elements = [4097, 4]",
    ),
    (
        "blend epsilon 0",
        "blend_cylinders.toml",
        "\nepsilon = 1e-3",
        "\nepsilon = 0.0",
    ),
    (
        "blend energy a 0",
        "blend_cylinders.toml",
        "a = 10.0 }",
        "a = 0.0 }",
    ),
    (
        "blend point outside the unit square",
        "blend_cylinders.toml",
        "at = [0.0, 0.5]",
        "at = [0.0, 1.5]",
    ),
    (
        "time frames 0",
        "anim/ventricle.toml",
        "frames = 48",
        "frames = 0",
    ),
    (
        "time frames 10001",
        "anim/ventricle.toml",
        "frames = 48",
        "frames = 10001",
    ),
    (
        "time fps 0",
        "anim/ventricle.toml",
        "frames = 48",
        "fps = 0.0",
    ),
    (
        "trim ellipse with a zero semi-axis",
        "trimmed_vase.toml",
        "radii = [0.1, 0.45]",
        "radii = [0.0, 0.45]",
    ),
    (
        "no annealing evaluations",
        "optimize_curvature.toml",
        "evaluations = 2000",
        "evaluations = 0",
    ),
    (
        "shell thickness 0",
        "yoghurt.toml",
        "thickness = 0.0005",
        "thickness = 0.0",
    ),
    (
        "shell elements [0, 32]",
        "yoghurt.toml",
        "elements = [6, 32]",
        "elements = [0, 32]",
    ),
    (
        "shell time limit 0",
        "yoghurt.toml",
        "time_limit = 120.0",
        "time_limit = 0.0",
    ),
    (
        "too many Fourier terms",
        "cup.toml",
        "type = \"point\"\nat = [0.0, 0.0, 0.0]",
        "type = \"fourier\"\na0 = [0.0, 0.0, 0.0]\ncos = [FOURIER]",
    ),
];

#[test]
fn invalid_designs_are_refused_by_the_schema_and_by_check() {
    let v = validator();
    let root = examples_dir();
    let dir = tempfile::tempdir().unwrap();
    let fourier = vec!["[1.0, 0.0, 0.0]"; 1025].join(", ");
    for (what, example, from, to) in INVALID {
        let text = std::fs::read_to_string(root.join(example)).unwrap();
        assert!(text.contains(from), "{what}: '{from}' not in {example}");
        let bad = text.replacen(from, &to.replace("FOURIER", &fourier), 1);
        let path = write(dir.path(), "bad.toml", &bad);
        // The CLI refuses it: exit status 2, one `error:` line. A blend's numbers are checked
        // when it is solved (`pdeshape blend`), not by `check`.
        let out_obj = dir.path().join("out.obj");
        let out = if *example == "blend_cylinders.toml" {
            pdeshape(&["blend", s(&path), "-o", s(&out_obj)])
        } else {
            pdeshape(&["check", s(&path)])
        };
        assert_eq!(out.status.code(), Some(2), "{what}: check accepted it");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error: "), "{what}: {err}");
        // So does the schema (TOML that does not parse has nothing to validate: none here).
        let json = as_json(&bad);
        assert!(!v.is_valid(&json), "{what}: the schema accepts it");
    }
}

fn validator_of(kind: &str) -> jsonschema::Validator {
    let out = pdeshape(&["schema", "--kind", kind]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    jsonschema::draft7::new(&schema).expect("a valid draft-7 schema")
}

/// Morph files and fit templates have schemas of their own (`schema --kind morph|template`):
/// the bundled morph file and the template of the fitting docs are valid under theirs, and a
/// design is not a morph file.
#[test]
fn morph_files_and_templates_have_schemas() {
    let morph = validator_of("morph");
    let text = std::fs::read_to_string(examples_dir().join("anim/glass_morph.toml")).unwrap();
    let errors: Vec<String> = morph
        .iter_errors(&as_json(&text))
        .map(|e| e.to_string())
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(
        !validator().is_valid(&as_json(&text)),
        "a morph file is no design"
    );
    let cup = std::fs::read_to_string(examples_dir().join("cup.toml")).unwrap();
    assert!(!morph.is_valid(&as_json(&cup)));
    assert!(!morph.is_valid(&as_json(&text.replace("ease = 1.5", "ease = 0.0"))));

    let template = validator_of("template");
    let good = "a = 0.5\n[[parts]]\nname = \"left\"\nmode = \"tube\"\naxis = [0, 0, 1]\n\
                origin = [-1, 0, 0]\npositions = [0.0, 2.0]\nstart = \"pole\"\nsections = 32\n\
                [[parts]]\nname = \"bend\"\nplanes = [\n  { point = [-1, 0, 2], normal = [0, 0, 1] },\n\
                { point = [0, 0, 3], normal = [1, 0, 0] },\n]\n";
    assert!(pdeshape::fit::parse_template(good).is_ok());
    let errors: Vec<String> = template
        .iter_errors(&as_json(good))
        .map(|e| e.to_string())
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    for (from, to) in [
        ("mode = \"tube\"", "mode = \"cube\""),
        ("sections = 32", "sections = 2"),
        ("name = \"left\"", "name = \"left arm\""),
        ("a = 0.5", "a = 0.5\ncolour = 1"),
    ] {
        let bad = edit(good, from, to);
        assert!(pdeshape::fit::parse_template(&bad).is_err(), "{to}");
        assert!(!template.is_valid(&as_json(&bad)), "{to}");
    }
}

/// A curve table is checked against its own `type`: a key another type takes is refused by
/// name, and the table's property list (what editors complete) names every key once.
#[test]
fn curve_tables_are_checked_against_their_type() {
    let v = validator();
    let cup = std::fs::read_to_string(examples_dir().join("cup.toml")).unwrap();
    let bad = edit(&cup, "radius = 1.35", "radius = 1.35\nrx = 2.0");
    let errors: Vec<String> = v
        .iter_errors(&as_json(&bad))
        .map(|e| e.to_string())
        .collect();
    assert!(
        errors.iter().any(|e| e.contains("'rx' was unexpected")),
        "{errors:?}"
    );
    let out = pdeshape(&["schema"]);
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let curve = &schema["definitions"]["CurveSpec"];
    assert!(curve.get("oneOf").is_none());
    let keys = curve["properties"].as_object().unwrap();
    assert!(keys.len() < 60, "{}", keys.len());
    for k in [
        "type",
        "center",
        "radius",
        "rx",
        "control",
        "transform",
        "v_origin",
    ] {
        assert!(keys.contains_key(k), "{k}");
    }
    assert!(keys["rx"]["description"]
        .as_str()
        .unwrap()
        .contains("(type ellipse)"));
}
