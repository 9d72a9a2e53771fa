//! Spine edits (§5.3): control form, round trip, rigid motions, frames, edits with undo.

use super::spine::{spine_control_points, spine_hermite_of};
use super::{compile, CompiledDesign, Edit, SurfaceKind};
use crate::curve::{Bezier, Curve, Hermite};
use crate::elliptic::PdePatch;
use crate::spec::{parse_design, DesignSpec, SpineCarry, SpineMove, SpineSpec};
use crate::surface::{Spine, Surface};
use crate::{Vec3, TAU};

/// A biharmonic surface of revolution about z: circles of radius 1 at z = 0 and 0.6 at z = 2,
/// leaving and reaching them vertically with different speeds (so the spine is a straight line
/// along z with a non-uniform speed). Optionally with a `[[spine]]` table.
fn tube(spine: &str) -> DesignSpec {
    let text = format!(
        r#"
conditions = [
  {{ u = 0.0, curve = "c0" }},
  {{ u = 0.0, derivative = 1, curve = {{ type = "circle", center = [0, 0, 3], radius = 0.2 }} }},
  {{ u = 1.0, curve = "c1" }},
  {{ u = 1.0, derivative = 1, curve = {{ type = "circle", center = [0, 0, 1.5], radius = 0.1 }} }},
]
[operator]
kind = "polyharmonic"
order = 2
a = 1.3
[curves.c0]
type = "circle"
center = [0, 0, 0]
radius = 1.0
[curves.c1]
type = "circle"
center = [0, 0, 2]
radius = 0.6
{spine}
"#
    );
    parse_design(&text).unwrap()
}

fn pde(d: &CompiledDesign) -> &PdePatch {
    match &d.solved().surfaces[0].kind {
        SurfaceKind::Pde(p) => p,
        SurfaceKind::SpineEdited(e) => e.base(),
        _ => panic!("not a PDE patch"),
    }
}

fn control_toml(points: &[Vec3]) -> String {
    let pts: Vec<String> = points
        .iter()
        .map(|p| format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z))
        .collect();
    format!("control = [{}]", pts.join(", "))
}

fn spine_table(carry: &str, body: &str) -> String {
    format!("[[spine]]\ncarry = \"{carry}\"\n{body}\n")
}

const US: [f64; 9] = [0.0, 0.05, 0.2, 0.37, 0.5, 0.61, 0.8, 0.93, 1.0];
const SECTION: usize = 16;

fn section(s: &dyn Surface, u: f64) -> Vec<Vec3> {
    (0..SECTION)
        .map(|j| s.point(u, TAU * j as f64 / SECTION as f64))
        .collect()
}

/// The Bézier control form reproduces `A₀` (cubic from the Hermite form, other degrees by
/// collocation), and the corrected Eqs. 5.5–5.8 give `A₀`'s power form while the printed ones
/// do not.
#[test]
fn control_points_reproduce_the_solved_spine() {
    for order in 1..=5usize {
        // 2N conditions: positions and derivatives at u = 0, 1 and intermediate circles.
        let mut conds = vec![
            r#"{ u = 0.0, curve = { type = "circle", center = [0, 0, 0], radius = 1.0 } }"#
                .to_string(),
            r#"{ u = 1.0, curve = { type = "circle", center = [0.3, 0, 2], radius = 0.7 } }"#
                .to_string(),
        ];
        for k in 1..order {
            conds.push(format!(
                r#"{{ u = 0.0, derivative = {k}, curve = {{ type = "circle", center = [0.1, {k}, 1], radius = 0.2 }} }}"#
            ));
            conds.push(format!(
                r#"{{ u = 1.0, derivative = {k}, curve = {{ type = "circle", center = [-0.2, 0.4, {k}], radius = 0.3 }} }}"#
            ));
        }
        let text = format!(
            "conditions = [{}]\n[operator]\nkind = \"polyharmonic\"\norder = {order}\na = 1.0\n",
            conds.join(", ")
        );
        let d = compile(&parse_design(&text).unwrap()).unwrap();
        let p = pde(&d);
        let control = spine_control_points(p);
        assert_eq!(control.len(), 2 * order);
        let b = Bezier::new(control).unwrap();
        for k in 0..=20 {
            let u = k as f64 / 20.0;
            for der in 0..2 {
                let (want, got) = (p.spine(u, der), b.derivative(u, der));
                let tol = 1e-12 * (1.0 + want.norm()) * 4f64.powi(order as i32);
                assert!(
                    (want - got).norm() < tol,
                    "N = {order}, u = {u}, d = {der}: {want} vs {got}"
                );
            }
        }
    }
    // Eqs. 5.5–5.8: A₀ = a₀₀ + a₀₁u + a₀₂u² + a₀₃u³ with (corrected) a₀₂ = 3(p₁ − p₀) − 2v₀ − v₁,
    // a₀₃ = 2(p₀ − p₁) + v₀ + v₁; the printed a₀₁ = 3p₁ − v₁ − 3v₀ … is not the cubic.
    let d = compile(&tube("")).unwrap();
    let p = pde(&d);
    let [p0, p1, v0, v1] = spine_hermite_of(p);
    let h = Hermite::new(p0, p1, v0, v1);
    let printed = [p0, p1 * 3.0 - v1 - v0 * 3.0, v1 + v0 * 2.0 - p1 * 2.0, v0];
    let mut printed_err = 0.0f64;
    for k in 0..=10 {
        let u = k as f64 / 10.0;
        assert!((h.point(u) - p.spine(u, 0)).norm() < 1e-13);
        let pu = printed[0] + printed[1] * u + printed[2] * u * u + printed[3] * u * u * u;
        printed_err = printed_err.max((pu - p.spine(u, 0)).norm());
    }
    assert!(
        printed_err > 0.1,
        "the printed Eqs. 5.5–5.8 happen to fit: {printed_err}"
    );
}

/// Editing the spine to its own control points gives back the surface to rounding, in both
/// modes.
#[test]
fn spine_set_to_its_own_control_points_gives_the_same_surface() {
    let plain = compile(&tube("")).unwrap();
    let control = spine_control_points(pde(&plain));
    for carry in ["frame", "translate"] {
        let d = compile(&tube(&spine_table(carry, &control_toml(&control)))).unwrap();
        let s = d.solved().surfaces[0].surface();
        assert!(matches!(
            d.solved().surfaces[0].kind,
            SurfaceKind::SpineEdited(_)
        ));
        let base = plain.solved().surfaces[0].surface();
        let mut err = 0.0f64;
        for &u in &US {
            for j in 0..32 {
                let v = TAU * j as f64 / 32.0 + 0.01;
                let (a, b) = (base.partials(u, v), s.partials(u, v));
                err = err
                    .max((a.x - b.x).norm())
                    .max((a.xu - b.xu).norm())
                    .max((a.xv - b.xv).norm())
                    .max((a.xuu - b.xuu).norm());
            }
        }
        assert!(err < 1e-13, "{carry}: {err}");
    }
}

/// For a surface of revolution, a straight new spine moves every section rigidly: in
/// translate mode by a translation, in frame mode by one rotation (the frames of two straight
/// lines are constant) that also keeps each section across the new line.
#[test]
fn straight_spine_edit_moves_sections_rigidly() {
    let plain = compile(&tube("")).unwrap();
    let base = plain.solved().surfaces[0].surface();
    let old = spine_control_points(pde(&plain));
    // A straight line tilted by 35° in the xz plane, with the old spine's spacing along it.
    let dir = Vec3::new(35f64.to_radians().sin(), 0.0, 35f64.to_radians().cos());
    let new: Vec<Vec3> = old
        .iter()
        .map(|p| Vec3::new(0.5, -0.2, 0.1) + dir * p.z)
        .collect();
    for carry in ["frame", "translate"] {
        let d = compile(&tube(&spine_table(carry, &control_toml(&new)))).unwrap();
        let s = d.solved().surfaces[0].surface();
        let spine = s.as_spine().unwrap();
        for &u in &US {
            let (a, b) = (section(base, u), section(s, u));
            for i in 0..SECTION {
                for j in 0..SECTION {
                    let (da, db) = ((a[i] - a[j]).norm(), (b[i] - b[j]).norm());
                    assert!((da - db).abs() < 1e-12, "{carry} u = {u}: {da} vs {db}");
                }
            }
            let c = spine.spine(u, 0);
            for p in &b {
                let across = (p - c).dot(&dir);
                let vertical = (p - c).z;
                match carry {
                    "frame" => assert!(across.abs() < 1e-12, "u = {u}: {across}"),
                    _ => assert!(vertical.abs() < 1e-12, "u = {u}: {vertical}"),
                }
            }
        }
    }
}

/// The rotation-minimising mode keeps every section across the bent spine's tangent; the
/// translate mode (sections stay horizontal) does not.
#[test]
fn frame_mode_keeps_sections_across_a_bent_spine() {
    let moves = "moves = [{ index = 1, by = [0.9, 0.3, 0.0] }, { index = 2, by = [1.6, -0.4, -0.3] }, { index = 3, by = [0.8, 0.0, -0.5] }]";
    let mut worst = [0.0f64; 2];
    for (m, carry) in ["frame", "translate"].into_iter().enumerate() {
        let d = compile(&tube(&spine_table(carry, moves))).unwrap();
        let SurfaceKind::SpineEdited(e) = &d.solved().surfaces[0].kind else {
            panic!("not edited")
        };
        for k in 0..=40 {
            let u = k as f64 / 40.0;
            let (c, t) = (e.spine(u, 0), e.tangent(u));
            assert!((t.norm() - 1.0).abs() < 1e-14);
            for p in section(&**e, u) {
                worst[m] = worst[m].max(((p - c).dot(&t)).abs());
            }
        }
    }
    assert!(worst[0] < 1e-12, "frame: {}", worst[0]);
    assert!(worst[1] > 0.1, "translate: {}", worst[1]);
}

/// The partials of an edited patch are its derivatives (central differences), and grid rows
/// equal pointwise evaluation.
#[test]
fn edited_partials_are_derivatives_and_rows_match() {
    let moves =
        "moves = [{ index = 1, by = [0.9, 0.3, 0.0] }, { index = 2, by = [1.6, -0.4, -0.3] }]";
    // The same with a travelling wave on top (§8.1.3.2), and a standing wave alone.
    let waved = format!(
        "{moves}\nwave = {{ amplitude = [0.1, 0.2, 0.3], alpha = 7.0, omega = 1.5, phase = 0.4, \
         time = 0.3, direction = [1, 1, 0] }}"
    );
    let standing = "wave = { kind = \"standing\", amplitude = [0.2, -0.1], alpha = 5.0, omega = \
                    1.0, time = 0.2, direction = [0, 1, 0] }";
    for (carry, body) in [
        ("frame", moves),
        ("translate", moves),
        ("frame", waved.as_str()),
        ("translate", waved.as_str()),
        ("frame", standing),
    ] {
        let d = compile(&tube(&spine_table(carry, body))).unwrap();
        let s = d.solved().surfaces[0].surface();
        let h = 1e-5;
        for &u in &[0.1, 0.37, 0.5, 0.9] {
            for &v in &[0.2, 1.9, 4.0] {
                let p = s.partials(u, v);
                let (pu0, pu1) = (s.partials(u - h, v), s.partials(u + h, v));
                let (pv0, pv1) = (s.partials(u, v - h), s.partials(u, v + h));
                let fd = |a: Vec3, b: Vec3| (b - a) / (2.0 * h);
                for (what, exact, approx) in [
                    ("xu", p.xu, fd(pu0.x, pu1.x)),
                    ("xv", p.xv, fd(pv0.x, pv1.x)),
                    ("xuu", p.xuu, fd(pu0.xu, pu1.xu)),
                    ("xuv", p.xuv, fd(pv0.xu, pv1.xu)),
                    ("xvv", p.xvv, fd(pv0.xv, pv1.xv)),
                ] {
                    assert!(
                        (exact - approx).norm() < 1e-7 * (1.0 + exact.norm()),
                        "{carry} {body} {what} at ({u}, {v}): {exact} vs {approx}"
                    );
                }
            }
        }
        let vs: Vec<f64> = (0..24).map(|j| TAU * j as f64 / 24.0).collect();
        let rows = s.row_evaluator(&vs);
        let mut row = crate::surface::RowBuf::new(vs.len());
        for &u in &US {
            rows.eval_row(u, &mut row);
            for (j, &v) in vs.iter().enumerate() {
                let p = s.partials(u, v);
                assert!((row.point(j) - p.x).norm() < 1e-13);
                assert!((row.normal(j) - p.normal()).norm() < 1e-12);
            }
        }
    }
}

/// `Edit::SetSpine` re-solves nothing (the patch is reused), its undo restores the design, and
/// the edited design equals a fresh compile bit for bit.
#[test]
fn spine_edits_apply_undo_and_match_fresh_compiles() {
    let spec = tube("");
    let mut d = compile(&spec).unwrap();
    let before = Vec3::from(d.solved().surfaces[0].surface().point(0.3, 1.0));
    let base_ptr = pde(&d) as *const PdePatch;
    let table = SpineSpec {
        patch: None,
        carry: SpineCarry::Frame,
        control: None,
        moves: vec![SpineMove {
            index: 2,
            by: [0.7, 0.0, 0.0],
        }],
        hermite: None,
        wave: None,
    };
    let undo = d
        .apply(&Edit::SetSpine {
            patch: None,
            spine: Some(table.clone()),
        })
        .unwrap();
    assert_eq!(
        pde(&d) as *const PdePatch,
        base_ptr,
        "the patch was re-solved"
    );
    let mut fresh_spec = spec.clone();
    fresh_spec.spine.push(table.clone());
    let fresh = compile(&fresh_spec).unwrap();
    let bits = |d: &CompiledDesign| {
        crate::mesh::sample(d.solved().surfaces[0].surface(), 9, 13)
            .unwrap()
            .positions
            .iter()
            .flatten()
            .map(|x| x.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&d), bits(&fresh));
    assert_eq!(
        d.meshes(9, 16).unwrap(),
        fresh.solved().meshes(9, 16).unwrap()
    );
    let moved = d.solved().surfaces[0].surface().point(0.3, 1.0);
    assert!((moved - before).norm() > 0.05);
    // Changing the carry replaces the table; undo twice gets back to the start.
    let undo2 = d
        .apply(&Edit::SetSpine {
            patch: None,
            spine: Some(SpineSpec {
                carry: SpineCarry::Translate,
                ..table
            }),
        })
        .unwrap();
    d.apply(&undo2).unwrap();
    assert_eq!(bits(&d), bits(&fresh));
    d.apply(&undo).unwrap();
    assert_eq!(d.spec(), &spec);
    assert_eq!(d.solved().surfaces[0].surface().point(0.3, 1.0), before);
    // Edits travel as JSON.
    let json = serde_json::to_string(&undo2).unwrap();
    assert_eq!(serde_json::from_str::<Edit>(&json).unwrap(), undo2);
}

/// Spine tables are written back out and read in to the same design.
#[test]
fn spine_tables_round_trip_through_the_file() {
    let spec = tube(&spine_table(
        "translate",
        "hermite = { p0 = [0, 0, 0], p1 = [1, 0, 2], d0 = [0, 0, 3], d1 = [1.5, 0, 0] }",
    ));
    let text = crate::spec::write_design(&spec).unwrap();
    assert!(text.contains("[[spine]]"), "{text}");
    assert_eq!(parse_design(&text).unwrap(), spec);
    // The Hermite form is the spine's end positions and speeds.
    let d = compile(&spec).unwrap();
    let s = d.solved().surfaces[0].surface().as_spine().unwrap();
    assert!((s.spine(1.0, 0) - Vec3::new(1.0, 0.0, 2.0)).norm() < 1e-15);
    assert!((s.spine(0.0, 1) - Vec3::new(0.0, 0.0, 3.0)).norm() < 1e-14);
    assert!((s.spine(1.0, 1) - Vec3::new(1.5, 0.0, 0.0)).norm() < 1e-14);
}

/// Bad spine tables are refused with their place.
#[test]
fn bad_spine_tables_are_refused_with_their_place() {
    let place = |spine: &str| {
        compile(&tube(spine))
            .err()
            .map(|e| (e.place().to_string(), e.to_string()))
            .unwrap()
    };
    let (p, m) = place("[[spine]]\ncontrol = [[0, 0, 0], [0, 0, 1]]\n");
    assert_eq!(p, "spine[0].control", "{m}");
    let (p, m) = place("[[spine]]\nmoves = [{ index = 7, by = [1, 0, 0] }]\n");
    assert_eq!(p, "spine[0].moves[0].index", "{m}");
    let (p, m) = place("[[spine]]\n");
    assert_eq!(p, "spine[0]", "{m}");
    let (p, m) = place("[[spine]]\npatch = \"nope\"\nmoves = [{ index = 1, by = [1, 0, 0] }]\n");
    assert_eq!(p, "spine[0].patch", "{m}");
    // A spine collapsed to a point has no tangent for the frames.
    let (p, m) = place("[[spine]]\ncontrol = [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]]\n");
    assert_eq!(p, "spine[0].carry", "{m}");
    assert!(m.contains("translate"), "{m}");
    // … which the translate mode accepts.
    compile(&tube(
        "[[spine]]\ncarry = \"translate\"\ncontrol = [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]]\n",
    ))
    .unwrap();
    let mut fd = tube("[[spine]]\nmoves = [{ index = 1, by = [1, 0, 0] }]\n");
    fd.solver.method = crate::spec::SolverMethod::Fd;
    fd.solver.grid = Some([16, 16]);
    let e = compile(&fd).unwrap_err();
    assert_eq!(e.place(), "spine[0]", "{e}");
}

/// A spine wave (§8.1.3.2): its derivatives are those of `w(u)` (differences), the edited spine
/// is the Bézier spine plus `w(u) d`, and bad wave tables are refused with their place.
#[test]
fn spine_waves_add_their_displacement_and_derivatives() {
    use super::spine::Wave;
    use crate::spec::{SpineWave, WaveKind};
    let spec = SpineWave {
        kind: WaveKind::Travelling,
        amplitude: vec![0.1, -0.3, 0.5, 0.2],
        alpha: 6.5,
        omega: 1.3,
        phase: 0.7,
        time: 0.45,
        direction: [0.0, 3.0, 4.0],
    };
    for kind in [WaveKind::Travelling, WaveKind::Standing] {
        let w = Wave::new(&SpineWave {
            kind,
            ..spec.clone()
        })
        .unwrap();
        let omega = |u: f64| 0.1 - 0.3 * u + 0.5 * u * u + 0.2 * u * u * u;
        let th = TAU * 1.3 * 0.45;
        for &u in &US {
            let want = match kind {
                WaveKind::Travelling => omega(u) * (6.5 * u - th + 0.7).sin(),
                WaveKind::Standing => omega(u) * (6.5 * u + 0.7).cos() * th.sin(),
            };
            assert!((w.displacement(u) - want).abs() < 1e-15, "{kind:?} at {u}");
            let h = 1e-5;
            for k in 1..=5 {
                let fd = (w.derivative(u + h, k - 1) - w.derivative(u - h, k - 1)) / (2.0 * h);
                let exact = w.derivative(u, k);
                assert!(
                    // Central differences err by h²/6 |w⁽ᵏ⁺²⁾| ≲ 10⁻¹¹ · 6.5ᵏ⁺².
                    (exact - fd).abs() < 2e-8 * 6.5f64.powi(k as i32 + 2),
                    "{kind:?} order {k} at {u}: {exact} vs {fd}"
                );
            }
        }
        assert!((w.direction() - Vec3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
    }
    // The edited surface's spine is the solved one plus the wave.
    let table =
        "[[spine]]\nwave = { amplitude = [0.2, 0.3], alpha = 9.0, omega = 2.0, time = 0.1, \
                 direction = [1, 0, 0] }\n";
    let d = compile(&tube(table)).unwrap();
    let base = pde(&d);
    let s = d.solved().surfaces[0].surface();
    let sp = s.as_spine().unwrap();
    for &u in &US {
        let want =
            base.spine(u, 0) + Vec3::x() * ((0.2 + 0.3 * u) * (9.0 * u - TAU * 2.0 * 0.1).sin());
        assert!((sp.spine(u, 0) - want).norm() < 1e-13, "{u}");
    }
    let place = |spine: &str| {
        compile(&tube(spine))
            .err()
            .map(|e| (e.place().to_string(), e.to_string()))
            .unwrap()
    };
    let (p, m) = place(
        "[[spine]]\nwave = { amplitude = [], alpha = 1, omega = 1, direction = [1, 0, 0] }\n",
    );
    assert_eq!(p, "spine[0].wave.amplitude", "{m}");
    let (p, m) = place(
        "[[spine]]\nwave = { amplitude = [1], alpha = 1, omega = 1, direction = [0, 0, 0] }\n",
    );
    assert_eq!(p, "spine[0].wave.direction", "{m}");
    let (p, m) = place(
        "[[spine]]\nwave = { amplitude = [1], alpha = 1, omega = 1e308, time = 1e10, direction = [1, 0, 0] }\n",
    );
    assert_eq!(p, "spine[0].wave.omega", "{m}");
}

/// A drag: successive edits of one patch's spine share the solved spine's frames and the solved
/// patch's rows (kept from the second edit on); every step's mesh equals, bit for bit, the mesh of
/// a fresh compile of the same table, in both ways of carrying the sections.
#[test]
fn a_drag_of_the_spine_gives_the_meshes_of_fresh_compiles() {
    let spec = tube("");
    for carry in [SpineCarry::Frame, SpineCarry::Translate] {
        let mut d = compile(&spec).unwrap();
        for (step, x) in [0.3, 0.35, 0.4, 0.45, 0.5].into_iter().enumerate() {
            let table = SpineSpec {
                patch: None,
                carry,
                control: None,
                moves: vec![SpineMove {
                    index: 1 + step % 2,
                    by: [x, 0.1 * x, 0.0],
                }],
                hermite: None,
                wave: None,
            };
            d.apply(&Edit::SetSpine {
                patch: None,
                spine: Some(table.clone()),
            })
            .unwrap();
            let mut fresh_spec = spec.clone();
            fresh_spec.spine.push(table);
            let fresh = compile(&fresh_spec).unwrap();
            assert_eq!(
                d.meshes(17, 32).unwrap(),
                fresh.solved().meshes(17, 32).unwrap(),
                "{carry:?}, step {step}"
            );
            // A second grid size on the same edit (the kept rows are for the other grid).
            assert_eq!(
                d.meshes(9, 16).unwrap(),
                fresh.solved().meshes(9, 16).unwrap(),
                "{carry:?}, step {step}, coarse grid"
            );
        }
        let SurfaceKind::SpineEdited(e) = &d.solved().surfaces[0].kind else {
            panic!("the patch is not spine-edited");
        };
        assert!(
            e.kept_rows() > 0,
            "{carry:?}: the drag kept none of the solved patch's rows"
        );
    }
}

/// A picture of an edited patch draws its sections at the conditions' `u`, where the edit
/// carried the position curves, not the curves themselves, which the edited patch no longer
/// meets. In translate mode the mouth is the solved mouth circle moved by the last control
/// point's move; in frame mode a circle of the same radius about the new spine's end, across its
/// tangent. The foot (first two control points kept) stays the foot circle. Tolerance: the
/// conditions are met to ≈ 1e-15 and the frames err by ≈ 1e-13 of the design's size (≈ 5).
#[test]
fn overlays_of_an_edited_patch_are_its_sections() {
    let moves =
        "moves = [{ index = 2, by = [2.5, 0.0, 0.0] }, { index = 3, by = [3.0, 0.0, -1.5] }]";
    let tol = 1e-11;
    for carry in ["frame", "translate"] {
        let d = compile(&tube(&spine_table(carry, moves))).unwrap();
        let SurfaceKind::SpineEdited(e) = &d.solved().surfaces[0].kind else {
            panic!("not edited")
        };
        let curves: Vec<_> = d
            .solved()
            .overlays()
            .into_iter()
            .filter(|l| l.closed)
            .collect();
        assert_eq!(curves.len(), 2, "{carry}");
        let end = e.spine(1.0, 0);
        assert!((end - Vec3::new(3.0, 0.0, 0.5)).norm() < 1e-12, "{end}");
        let t = e.tangent(1.0);
        let n = curves[0].points.len();
        for k in 0..n {
            let v = TAU * k as f64 / n as f64;
            // The foot: the circle of radius 1 about the origin in z = 0.
            let foot = Vec3::new(v.cos(), v.sin(), 0.0);
            assert!((curves[0].points[k] - foot).norm() < tol, "{carry} foot");
            let p = curves[1].points[k];
            match carry {
                "translate" => {
                    let want = Vec3::new(0.6 * v.cos() + 3.0, 0.6 * v.sin(), 2.0 - 1.5);
                    assert!((p - want).norm() < tol, "{carry}: {p} vs {want}");
                }
                _ => {
                    assert!(((p - end).norm() - 0.6).abs() < tol, "{carry}");
                    assert!((p - end).dot(&t).abs() < tol, "{carry}");
                }
            }
            // Far from the mouth circle the design file gives (the old overlay).
            let old = Vec3::new(0.6 * v.cos(), 0.6 * v.sin(), 2.0);
            assert!((p - old).norm() > 1.0);
        }
    }
}
