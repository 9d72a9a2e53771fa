//! Design parameters (`[[parameters]]`) on the command line: the swirl port example through
//! `surface`, `render`, `check` and `analyze`; `--set NAME=VALUE`; bad parameters and flags.

use crate::common::*;

fn check_json(extra: &[&str]) -> serde_json::Value {
    let ex = example_path("swirl_port_params.toml");
    let mut args = vec!["check", s(&ex), "--json"];
    args.extend_from_slice(extra);
    let out = pdeshape(&args);
    assert!(out.status.success(), "{out:?}");
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn swirl_port_example_runs_through_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let ex = example_path("swirl_port_params.toml");
    let obj = dir.path().join("port.obj");
    let out = pdeshape(&["surface", s(&ex), "-o", s(&obj)]);
    assert!(out.status.success(), "{out:?}");
    assert!(std::fs::metadata(&obj).unwrap().len() > 1000);
    let png = dir.path().join("port.png");
    let out = pdeshape(&["render", s(&ex), "-o", s(&png), "--size", "320x240"]);
    assert!(out.status.success(), "{out:?}");
    let out = pdeshape(&["analyze", s(&ex), "--json"]);
    assert!(out.status.success(), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["total"]["area"].as_f64().unwrap() > 1.0);

    // check lists every parameter with value, bounds, neutral value and what it drives.
    let out = pdeshape(&["check", s(&ex)]);
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("parameters:"), "{text}");
    assert!(
        text.contains("theta = 0.87 in [-1.2, 1.2] (neutral 0)"),
        "{text}"
    );
    assert!(
        text.contains("twist = 0.6 in [-3.2, 3.2] (neutral 0): v = 0 point"),
        "{text}"
    );
    assert!(text.contains("(with outlet_ahead)"), "{text}");
    let v = check_json(&[]);
    let params = v["parameters"].as_array().unwrap();
    let names: Vec<&str> = params.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["x1", "y1", "z1", "theta", "s", "twist"]);
    assert_eq!(params[4]["kind"], "scale");
    assert_eq!(params[4]["value"], 2.1);
    assert_eq!(params[4]["curve"], "outlet");
    // The neutral scale is the outlet's own width |X1X2| between v = 0 and π (about 2.6).
    let neutral = params[4]["neutral"].as_f64().unwrap();
    assert!((2.4..2.8).contains(&neutral), "{neutral}");
}

#[test]
fn set_overrides_a_value_on_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let ex = example_path("swirl_port_params.toml");
    let csv = |name: &str, set: &[&str]| {
        let p = dir.path().join(name);
        let mut args = vec!["surface", s(&ex), "-o", s(&p), "--nu", "9", "--nv", "16"];
        for a in set {
            args.push("--set");
            args.push(a);
        }
        let out = pdeshape(&args);
        assert!(out.status.success(), "{out:?}");
        std::fs::read(&p).unwrap()
    };
    let file = csv("file.csv", &[]);
    // The file's own value set again: the same bytes; another value: another surface.
    assert_eq!(csv("same.csv", &["theta=0.87"]), file);
    assert_ne!(csv("other.csv", &["theta=0.2"]), file);
    assert_ne!(csv("twist.csv", &["twist=0"]), file);
    let v = check_json(&["--set", "theta=0.2", "--set", "s=3"]);
    assert_eq!(v["parameters"][3]["value"], 0.2);
    assert_eq!(v["parameters"][4]["value"], 3.0);
    let out = pdeshape(&["analyze", s(&ex), "--set", "s=3", "--json"]);
    assert!(out.status.success(), "{out:?}");
    let png = dir.path().join("p.png");
    let out = pdeshape(&[
        "render",
        s(&ex),
        "-o",
        s(&png),
        "--size",
        "64x48",
        "--set",
        "x1=1",
    ]);
    assert!(out.status.success(), "{out:?}");
}

#[test]
fn bad_set_flags_are_refused_naming_the_flag_and_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let ex = example_path("swirl_port_params.toml");
    let obj = dir.path().join("out.obj");
    let cases: [(&str, &[&str]); 5] = [
        (
            "theta=5",
            &[
                "--set theta=5",
                "'theta'",
                "outside [min, max] = [-1.2, 1.2]",
            ],
        ),
        (
            "phi=0",
            &["--set phi=0", "no parameter named 'phi'", "theta"],
        ),
        ("theta", &["--set theta", "NAME=VALUE"]),
        ("theta=abc", &["--set theta=abc", "not a finite number"]),
        ("s=inf", &["--set s=inf", "not a finite number"]),
    ];
    for (flag, needles) in cases {
        let out = pdeshape(&["surface", s(&ex), "-o", s(&obj), "--set", flag]);
        assert_bad(&out, needles);
        assert!(!obj.exists());
        let out = pdeshape(&["check", s(&ex), "--set", flag]);
        assert_bad(&out, needles);
    }
    assert!(files(dir.path()).is_empty());
}

#[test]
fn bad_parameters_are_refused_with_their_place() {
    let text = example("swirl_port_params.toml");
    bad_design(
        &edit(&text, "name = \"y1\"", "name = \"x1\""),
        &["parameters[1].name", "given twice"],
    );
    bad_design(
        &edit(&text, "value = 0.87", "value = 1.5"),
        &["parameters[3].value", "outside"],
    );
    bad_design(
        &edit(&text, "v2 = 3.141592653589793", "v2 = 0.0"),
        &["parameters[4].v2", "differ"],
    );
    bad_design(
        &edit(&text, "v2 = 3.141592653589793", "v2 = 6.283185307179586"),
        &["parameters[4].v2", "coincide"],
    );
    let line = bad_design(
        &edit(
            &text,
            "curve = \"outlet\"\nwith = [\"outlet_ahead\"]\nv1 = 0.0\nplane",
            "curve = \"outlet2\"\nwith = [\"outlet_ahead\"]\nv1 = 0.0\nplane",
        ),
        &["parameters[3].curve", "'outlet2'"],
    );
    // The place is located in the file (line:col of the key).
    assert!(line.contains("d.toml:"), "{line}");
}
