//! The examples of the design operations of chapters 5–6 (spine edits, trimmed patches,
//! attached patches, local edits of curves, design parameters) through `surface`, `render`,
//! `check` and `analyze`; `check` lists the trims, attachments, spine edits and parameters each
//! one uses, and reports G0/G1 along the attachments within the bounds of the design.

use crate::common::*;

/// Each example and lines its `check` report must contain.
const EXAMPLES: [(&str, &[&str]); 8] = [
    (
        "spine_bend.toml",
        &[
            "spine A0 (Bézier, degree 3)",
            "spine edit (sections turn with the spine's frame): ",
        ],
    ),
    (
        "trimmed_vase.toml",
        &[
            "trims:",
            "trims[0]: surface 'wall', 3 curve(s), method cdt",
            "circle enclosing",
            "bspline enclosing",
            ", 0 inverted",
        ],
    ),
    (
        "trim_book_methods.toml",
        &[
            "trims[0]: surface 'bilinear', 1 curve(s), method bilinear",
            "trims[1]: surface 'laplace', 1 curve(s), method laplace",
        ],
    ),
    (
        "teacup.toml",
        &[
            "attachments (G0/G1 by closest points on the host",
            "'handle_bottom' u = 0 on 'bowl' along 'bottom_root' (tangent field)",
            "'handle_top' u = 1 on 'bowl' along 'top_root' (tangent field)",
            "surface 'bowl', 2 curve(s), method cdt",
        ],
    ),
    (
        "aeroplane.toml",
        &[
            "'right_wing' u = 1 on 'fuselage' along 'right_root' (tangent field)",
            "'fin' u = 1 on 'fuselage' along 'fin_root' (tangent field)",
            "surface 'fuselage', 5 curve(s), method cdt",
        ],
    ),
    ("cup_lip.toml", &["rim_lip (local)"]),
    ("swirl_port.toml", &["curve 'outlet' (bspline)"]),
    (
        "swirl_port_params.toml",
        &["parameters:", "theta = 0.87 in [-1.2, 1.2] (neutral 0)"],
    ),
];

/// Attachments per example (the others have none).
fn attachments(name: &str) -> usize {
    match name {
        "teacup.toml" => 2,
        "aeroplane.toml" => 5,
        _ => 0,
    }
}

fn run_ok(args: &[&str]) -> Output {
    let out = pdeshape(args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn every_example_of_the_design_operations_runs_through_every_command() {
    let dir = tempfile::tempdir().unwrap();
    for (name, lines) in EXAMPLES {
        let ex = example_path(name);
        let stem = name.trim_end_matches(".toml");
        // surface: an OBJ mesh (trimmed designs are written in every mesh format but CSV).
        let obj = dir.path().join(format!("{stem}.obj"));
        run_ok(&["surface", s(&ex), "-o", s(&obj), "--nu", "17", "--nv", "32"]);
        let text = std::fs::read_to_string(&obj).unwrap();
        let vertices = text.lines().filter(|l| l.starts_with("v ")).count();
        let faces = text.lines().filter(|l| l.starts_with("f ")).count();
        assert!(
            vertices >= 17 * 32 / 2 && faces >= vertices,
            "{name}: {vertices} {faces}"
        );
        // render: a PNG of the asked size.
        let png = dir.path().join(format!("{stem}.png"));
        run_ok(&[
            "render",
            s(&ex),
            "-o",
            s(&png),
            "--size",
            "160x120",
            "--nu",
            "17",
            "--nv",
            "32",
        ]);
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
        assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 160);
        assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 120);
        // check: OK, no warning, and the operations it uses listed.
        let out = run_ok(&["check", s(&ex)]);
        let report = String::from_utf8_lossy(&out.stdout);
        assert!(report.starts_with("OK\n"), "{name}: {report}");
        assert!(!report.contains("warning:"), "{name}: {report}");
        for l in lines {
            assert!(report.contains(l), "{name}: no '{l}' in\n{report}");
        }
        // check --json: G0 ≤ 1e-10 and G1 ≤ 1e-8 rad along every attachment (by closest
        // points on the host), each meant to be tangent.
        let out = run_ok(&["check", s(&ex), "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let att = v["attachments"].as_array().unwrap();
        assert_eq!(att.len(), attachments(name), "{name}");
        for a in att {
            assert_eq!(a["tangent"], true, "{name}: {a}");
            let (g0, g1) = (a["g0"].as_f64().unwrap(), a["g1"].as_f64().unwrap());
            assert!(g0 <= 1e-10 && g1 <= 1e-8, "{name}: {a}");
        }
        // analyze: finite positive area; a trimmed design adds what remains, less than the
        // untrimmed surface and converged between its two grids, its volume share of the
        // same sign as the untrimmed one's.
        let out = run_ok(&["analyze", s(&ex), "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let area = v["total"]["area"].as_f64().unwrap();
        assert!(area.is_finite() && area > 0.1, "{name}: {area}");
        let trimmed = v["trimmed"].as_array().cloned().unwrap_or_default();
        let expect_trimmed = matches!(
            name,
            "trimmed_vase.toml" | "trim_book_methods.toml" | "teacup.toml" | "aeroplane.toml"
        );
        assert_eq!(!trimmed.is_empty(), expect_trimmed, "{name}");
        for t in &trimmed {
            let patch = v["patches"]
                .as_array()
                .unwrap()
                .iter()
                .find(|p| p["name"] == t["name"])
                .unwrap();
            let (a, a0) = (t["area"].as_f64().unwrap(), patch["area"].as_f64().unwrap());
            assert!(a > 0.5 * a0 && a < a0, "{name}: {t} vs {patch}");
            assert!(t["area_change"].as_f64().unwrap() < 1e-3 * a, "{name}: {t}");
            let (vol, vol0) = (
                t["volume"].as_f64().unwrap(),
                patch["volume"].as_f64().unwrap(),
            );
            assert!(vol * vol0 > 0.0, "{name}: {t} vs {patch}");
        }
    }
}
