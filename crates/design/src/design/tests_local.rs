//! Local edits of curves (§6.2) in designs: the cup with a lip, the edit with undo.

use super::{compile, Edit};
use crate::spec::{parse_design, write_design, DesignSpec};
use crate::TAU;

fn example(name: &str) -> DesignSpec {
    let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
    parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The lip of `examples/cup_lip.toml`: the bowl's X_u at the rim is the edited derivative
/// curve; outside the edited interval the bowl is the plain cup's, bit for bit on the rim.
#[test]
fn cup_lip_changes_the_bowl_only_near_the_lip() {
    let lip = compile(&example("cup_lip.toml")).unwrap();
    let plain = compile(&example("cup.toml")).unwrap();
    let bowl = |d: &super::CompiledDesign| {
        d.solved()
            .surfaces
            .iter()
            .position(|s| s.name == "bowl")
            .unwrap()
    };
    let (a, b) = (
        &lip.solved().surfaces[bowl(&lip)],
        &plain.solved().surfaces[bowl(&plain)],
    );
    let tangent = |d: &super::CompiledDesign| {
        d.solved()
            .curves
            .iter()
            .find(|c| c.name == "rim_tangent")
            .unwrap()
            .curve
            .clone()
    };
    let (ta, tb) = (tangent(&lip), tangent(&plain));
    let mut inside = 0.0f64;
    for k in 0..720 {
        let v = TAU * k as f64 / 720.0;
        let outside = (0.6..=5.7).contains(&v);
        let (ca, cb) = (ta.point(v), tb.point(v));
        if outside {
            assert_eq!(ca, cb, "v = {v}");
        } else {
            inside = inside.max((ca - cb).norm());
        }
        // The surface meets the edited condition.
        let xu = a.surface().partials(1.0, v).xu;
        assert!((xu - ca).norm() < 1e-9 * (1.0 + ca.norm()), "v = {v}");
    }
    assert!(inside > 1.0, "{inside}");
    // The rim itself did not move; the bowl heads outwards at the lip (v = 0 is along +x).
    let (pa, pb) = (a.surface().point(1.0, 0.0), b.surface().point(1.0, 0.0));
    assert!((pa - pb).norm() < 1e-12);
    let (xa, xb) = (
        a.surface().partials(1.0, 0.0).xu,
        b.surface().partials(1.0, 0.0).xu,
    );
    assert!(xa.x > xb.x + 1.0, "{xa} vs {xb}");
    assert!((a.surface().point(0.9, 0.0) - b.surface().point(0.9, 0.0)).norm() > 0.01);
}

/// `Edit::LocalEdit` wraps the named curve; its undo restores the design; the edited design
/// writes and reads back to the same spec and equals the example file's edit.
#[test]
fn local_edit_applies_and_undoes() {
    let spec = example("cup.toml");
    let mut d = compile(&spec).unwrap();
    let edit = Edit::LocalEdit {
        name: "rim_up".into(),
        from: 5.7,
        to: 0.6,
        at: Some(0.0),
        along: 0.0,
        across: 1.2,
        normal: -0.4,
    };
    let undo = d.apply(&edit).unwrap();
    let text = write_design(d.spec()).unwrap();
    assert_eq!(&parse_design(&text).unwrap(), d.spec());
    let p = d.solved().surfaces[1].surface().point(0.9, 0.0);
    let lip = compile(&example("cup_lip.toml")).unwrap();
    assert_eq!(p, lip.solved().surfaces[1].surface().point(0.9, 0.0));
    d.apply(&undo).unwrap();
    assert_eq!(d.spec(), &spec);
    // A handle outside the interval is refused with its place.
    let bad = Edit::LocalEdit {
        name: "rim_up".into(),
        from: 1.0,
        to: 2.0,
        at: Some(3.0),
        along: 0.0,
        across: 0.1,
        normal: 0.0,
    };
    let e = d.apply(&bad).unwrap_err();
    assert_eq!(e.place(), "curves.rim_up.at", "{e}");
    assert_eq!(d.spec(), &spec);
}
