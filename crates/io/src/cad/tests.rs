//! Tests of the CAD approximations, the STEP and IGES writers and the read-back.

use super::read::{read_iges, read_step};
use super::step::{to_step, LengthUnit, StepOptions};
use super::*;
use crate::design::solve_design;
use crate::spec::parse_design;
use certify::MAX_CELLS;

pub(super) fn solve(text: &str) -> SolvedDesign {
    solve_design(&parse_design(text).unwrap()).unwrap()
}

pub(super) fn example(name: &str) -> SolvedDesign {
    let text = match name {
        "laplace_blend" => include_str!("../../../../examples/laplace_blend.toml"),
        "cup" => include_str!("../../../../examples/cup.toml"),
        "wine_glass" => include_str!("../../../../examples/wine_glass.toml"),
        "vesicle" => include_str!("../../../../examples/vesicle.toml"),
        "blend_cylinders" => include_str!("../../../../examples/blend_cylinders.toml"),
        "yoghurt" => include_str!("../../../../examples/yoghurt.toml"),
        _ => unreachable!(),
    };
    solve(text)
}

/// The closed form of the Laplace blend of examples/laplace_blend.toml: `X_uu + X_vv = 0` with
/// `X(0, v) = (2 cos v, 2 sin v, 0)` and `X(1, v) = (cos v, sin v, 1)` is
/// `(r(u) cos v, r(u) sin v, u)` with `r'' = r`: `r = 2 cosh u + (1 − 2 cosh 1)/sinh 1 · sinh u`.
fn laplace_exact(u: f64, v: f64) -> Vec3 {
    let c = (1.0 - 2.0 * 1f64.cosh()) / 1f64.sinh();
    let r = 2.0 * u.cosh() + c * u.sinh();
    Vec3::new(r * v.cos(), r * v.sin(), u)
}

/// The true largest deviation of a net from `f`: a 9 × 9 lattice in every knot cell, then
/// local maximisation (coordinate-wise golden sections, shrinking steps) from the 8 largest.
pub(super) fn true_max_deviation(net: &BSplineSurface, f: &dyn Fn(f64, f64) -> Vec3) -> f64 {
    let [[u0, u1], [v0, v1]] = net.domain();
    let dev = |u: f64, v: f64| {
        let (u, v) = (u.clamp(u0, u1), v.clamp(v0, v1));
        (f(u, v) - net.derivative(u, v, 0, 0)).norm()
    };
    let mut ku = net.knots_u().to_vec();
    ku.dedup();
    let mut kv = net.knots_v().to_vec();
    kv.dedup();
    let mut samples = Vec::new();
    for cu in ku.windows(2) {
        for cv in kv.windows(2) {
            for a in 0..9 {
                for b in 0..9 {
                    let u = cu[0] + (cu[1] - cu[0]) * a as f64 / 8.0;
                    let v = cv[0] + (cv[1] - cv[0]) * b as f64 / 8.0;
                    samples.push((
                        dev(u, v),
                        u,
                        v,
                        (cu[1] - cu[0]) / 8.0,
                        (cv[1] - cv[0]) / 8.0,
                    ));
                }
            }
        }
    }
    samples.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut best = samples[0].0;
    for &(d0, mut u, mut v, mut hu, mut hv) in samples.iter().take(8) {
        let mut d = d0;
        for _ in 0..60 {
            let mut moved = false;
            for (du, dv) in [(hu, 0.0), (-hu, 0.0), (0.0, hv), (0.0, -hv)] {
                let e = dev(u + du, v + dv);
                if e > d {
                    (d, u, v, moved) = (e, u + du, v + dv, true);
                }
            }
            if !moved {
                hu *= 0.5;
                hv *= 0.5;
            }
        }
        best = best.max(d);
    }
    best
}

/// The certified bound holds against the closed form of the Laplace blend, at every
/// tolerance, and is within a factor 10 of the true largest deviation.
#[test]
fn laplace_blend_bound_holds_and_is_tight() {
    let design = example("laplace_blend");
    let size = design_size(&design);
    for rel in [1e-2, 1e-3, 1e-4, 1e-6] {
        let model = approximate_design(&design, rel * size).unwrap();
        let s = &model.surfaces[0].approx;
        assert!(matches!(s.certificate, Certificate::Derivatives { .. }));
        assert!(s.deviation <= rel * size, "bound above the tolerance");
        let truth = true_max_deviation(&s.net, &laplace_exact);
        assert!(
            truth <= s.deviation,
            "tolerance {rel:e}: true deviation {truth:e} exceeds the bound {:e}",
            s.deviation
        );
        assert!(
            s.deviation <= 10.0 * truth,
            "tolerance {rel:e}: bound {:e} looser than 10 × the true deviation {truth:e}",
            s.deviation
        );
    }
}

/// The bound also holds for the multi-patch examples (against pdeshape's own evaluation), with
/// fourth-order convergence: halving the tolerance's fourth root halves the steps.
#[test]
fn bounds_hold_on_the_examples() {
    for name in ["cup", "wine_glass", "vesicle"] {
        let design = example(name);
        let size = design_size(&design);
        let model = approximate_design(&design, 1e-4 * size).unwrap();
        for (s, d) in model.surfaces.iter().zip(&design.surfaces) {
            let surface = d.kind.surface();
            let truth = true_max_deviation(&s.approx.net, &|u, v| surface.point(u, v));
            assert!(
                truth <= s.approx.deviation,
                "{name}/{}: {truth:e} > bound {:e}",
                s.name,
                s.approx.deviation
            );
            assert!(s.approx.deviation <= 1e-4 * size);
        }
    }
}

/// A tolerance that would need more than `MAX_CELLS` grid cells on a surface is refused, naming
/// the tolerance, both where the grid follows from a proven bound (the cup, whose grid grows as
/// tolerance^(−1/4) in each direction) and where it is refined by sampling (the yoghurt's bowl,
/// with an active spectral remainder): a spike of 2e6 in a design used to refine to 4096 × 4096
/// nodes, minutes of work and gigabytes.
#[test]
fn tolerances_needing_too_many_cells_are_refused() {
    for (name, relative) in [("cup", 3e-12), ("yoghurt", 1e-11)] {
        let design = example(name);
        let tolerance = relative * design_size(&design);
        let e = approximate_design(&design, tolerance)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("tolerance") && e.contains(&format!("{MAX_CELLS} grid cells")),
            "{name}: {e}"
        );
        // The default tolerance stays well inside the limit.
        let model = approximate_design(&design, 1e-4 * design_size(&design)).unwrap();
        for s in &model.surfaces {
            let [nu, nv] = s.approx.net.counts();
            assert!(nu * nv < 4 * MAX_CELLS, "{name}/{}: {nu} × {nv}", s.name);
        }
    }
}

/// Halving the steps divides the deviation by about 16 (the interpolant is fourth order).
#[test]
fn hermite_interpolant_is_fourth_order() {
    let design = example("laplace_blend");
    let SurfaceKind::Pde(p) = &design.surfaces[0].kind else {
        panic!("an analytic patch")
    };
    let errs: Vec<f64> = [8usize, 16, 32]
        .iter()
        .map(|&m| {
            let a = certify::approximate_pde(p, m, 4 * m).unwrap();
            true_max_deviation(&a.net, &laplace_exact)
        })
        .collect();
    for w in errs.windows(2) {
        let ratio = w[0] / w[1];
        assert!(
            (12.0..20.0).contains(&ratio),
            "ratio {ratio} (errors {errs:?})"
        );
    }
}

/// Piecewise bicubic surfaces are reproduced exactly: the BFS blend.
#[test]
fn blend_is_exact() {
    let design = example("blend_cylinders");
    let model = approximate_design(&design, 1e-3).unwrap();
    for (s, d) in model.surfaces.iter().zip(&design.surfaces) {
        assert_eq!(s.approx.certificate, Certificate::Exact);
        let dev = sampled_deviation(d.kind.surface(), &s.approx.net, 7);
        assert!(dev <= 1e-12 * 10.0, "{}: {dev:e}", s.name);
        assert!(dev <= s.approx.deviation);
    }
}

/// The finite-difference surface is reproduced exactly.
#[test]
fn fd_surface_is_exact() {
    let text = include_str!("../../../../examples/cup.toml").replace(
        "[operator]",
        "solver = { method = \"fd\", grid = [16, 32] }\n\n[operator]",
    );
    let design = solve(&text);
    let model = approximate_design(&design, 1e-3).unwrap();
    for (s, d) in model.surfaces.iter().zip(&design.surfaces) {
        assert!(matches!(d.kind, SurfaceKind::Fd(_)));
        assert_eq!(s.approx.certificate, Certificate::Exact);
        let dev = sampled_deviation(d.kind.surface(), &s.approx.net, 7);
        assert!(dev <= s.approx.deviation, "{}: {dev:e}", s.name);
    }
}

/// Patches that share a curve get the same boundary row, closed directions no seam gap.
#[test]
fn shared_edges_are_identical_and_seams_closed() {
    let model = approximate_design(&example("cup"), 1e-4).unwrap();
    let (base, bowl) = (&model.surfaces[0].approx.net, &model.surfaces[1].approx.net);
    let [nu, nv] = base.counts();
    assert_eq!(base.knots_v(), bowl.knots_v());
    assert_eq!(&base.control()[(nu - 1) * nv..], &bowl.control()[..nv]);
    for net in [base, bowl] {
        let [nu, nv] = net.counts();
        for i in 0..nu {
            assert_eq!(net.control()[i * nv], net.control()[i * nv + nv - 1]);
        }
    }
}

fn opts() -> StepOptions {
    StepOptions {
        unit: LengthUnit::Millimetre,
        file_name: "x.step".into(),
        timestamp: "2026-01-01T00:00:00".into(),
    }
}

/// STEP: the nets read back bit for bit; the shell of the cup is open, the vesicle's closed; the
/// shared edge is one EDGE_CURVE.
#[test]
fn step_round_trip_and_topology() {
    for (name, closed) in [("cup", false), ("vesicle", true)] {
        let model = approximate_design(&example(name), 1e-4).unwrap();
        let text = to_step(&model, &opts()).unwrap();
        assert_eq!(text.contains("CLOSED_SHELL"), closed, "{name}");
        assert_eq!(text.contains("OPEN_SHELL"), !closed, "{name}");
        let read = read_step(&text).unwrap();
        assert_eq!(read.len(), model.surfaces.len());
        for (r, s) in read.iter().zip(&model.surfaces) {
            assert_eq!(r.name, s.name);
            assert_eq!(&r.net, &s.approx.net);
        }
        // Cup: 2 seams + bottom pole left out + belly shared + rim = 4 edges.
        if name == "cup" {
            assert_eq!(text.matches("EDGE_CURVE(").count(), 4);
        }
    }
}

#[test]
fn step_units() {
    let model = approximate_design(&example("laplace_blend"), 1e-3).unwrap();
    let mut o = opts();
    o.unit = LengthUnit::Inch;
    let text = to_step(&model, &o).unwrap();
    assert!(text.contains("CONVERSION_BASED_UNIT('INCH'"));
    o.unit = LengthUnit::Metre;
    assert!(to_step(&model, &o).unwrap().contains("SI_UNIT($,.METRE.)"));
    assert!(LengthUnit::parse("furlong").is_err());
}

/// IGES: one entity 128 per surface, read back bit for bit.
#[test]
fn iges_round_trip() {
    let model = approximate_design(&example("wine_glass"), 1e-3).unwrap();
    let text = to_iges(&model, LengthUnit::Millimetre, "w.igs", 0).unwrap();
    assert!(text.lines().all(|l| l.len() == 80));
    let read = read_iges(&text).unwrap();
    assert_eq!(read.len(), 3);
    for (r, s) in read.iter().zip(&model.surfaces) {
        assert_eq!(&r.net, &s.approx.net);
    }
}

/// Bad files give located errors, not panics.
#[test]
fn bad_files_are_refused_with_a_line() {
    let model = approximate_design(&example("laplace_blend"), 1e-3).unwrap();
    let text = to_step(&model, &opts()).unwrap();
    let broken = text.replacen("CARTESIAN_POINT('',(", "CARTESIAN_POINT('',(x", 1);
    let e = read_step(&broken).unwrap_err().to_string();
    assert!(e.contains("line "), "{e}");
    assert!(read_step("ISO-10303-21;").is_err());
    let truncated = &text[..text.len() / 2];
    assert!(read_step(truncated).is_err());
    assert!(approximate_design(&example("laplace_blend"), -1.0).is_err());
    assert!(approximate_design(&example("laplace_blend"), f64::NAN).is_err());
}

fn trimmed_example(name: &str) -> SolvedDesign {
    solve(match name {
        "vase" => include_str!("../../../../examples/trimmed_vase.toml"),
        "book" => include_str!("../../../../examples/trim_book_methods.toml"),
        _ => unreachable!(),
    })
}

/// Every hole's pcurve follows its trim curve within its stated deviation, its edge lies on
/// the face's net and on the design's image of the trim curve within the stated deviations,
/// at 4001 parameters per hole (not the ones the edge was built or measured on), and the
/// pcurve stays inside the face's parameter domain.
#[test]
fn hole_edges_lie_on_the_face_and_on_the_trim_image() {
    for (name, rel) in [("vase", 1e-4), ("vase", 1e-6), ("book", 1e-3)] {
        let design = trimmed_example(name);
        let tol = rel * design_size(&design);
        let model = approximate_design(&design, tol).unwrap();
        let mut holes = 0;
        for t in &design.trims {
            let s = &model.surfaces[t.surface];
            let surface = design.surfaces[t.surface].kind.surface();
            let net = &s.approx.net;
            let [[u0, u1], [v0, v1]] = net.domain();
            assert_eq!(s.holes.len(), t.curves.len());
            for h in &s.holes {
                holes += 1;
                let c = &t.curves[h.curve];
                let [a, b] = h.pcurve.domain();
                assert_eq!(h.edge.domain(), [a, b]);
                assert!((b - a - h.period).abs() < 1e-12);
                // Inside the domain: the control points bound the curve.
                for p in &h.pcurve.points {
                    assert!(
                        p.x > u0 && p.x < u1 && p.y > v0 && p.y < v1,
                        "{name}: {p:?}"
                    );
                }
                // A hole's deviation: the edge's sampled figure, the surface's and the pcurve's.
                assert!(
                    h.deviation <= s.approx.deviation + 0.3 * tol,
                    "{name}: {}",
                    h.deviation
                );
                let (mut on_face, mut on_image, mut on_curve) = (0.0f64, 0.0f64, 0.0f64);
                for k in 0..=4000 {
                    let s_ = a + (b - a) * (k as f64 + 0.37) / 4001.0;
                    let t_ = (s_ - a) / h.period;
                    let q = h.pcurve.point(s_);
                    let uv = c.point(t_);
                    let e = h.edge.point(s_);
                    on_curve = on_curve.max((q.x - uv[0]).hypot(q.y - h.v_shift - uv[1]));
                    on_face = on_face.max((e - net.derivative(q.x, q.y, 0, 0)).norm());
                    on_image = on_image.max((e - surface.point(uv[0], uv[1])).norm());
                }
                assert!(
                    on_curve <= h.pcurve_deviation,
                    "{name}: pcurve {on_curve:e} > {:e}",
                    h.pcurve_deviation
                );
                assert!(
                    on_face <= h.edge_deviation * (1.0 + 1e-9),
                    "{name}: edge {on_face:e} > {:e}",
                    h.edge_deviation
                );
                assert!(
                    on_image <= h.deviation,
                    "{name}: image {on_image:e} > {:e}",
                    h.deviation
                );
                // The edge closes on itself and meets its pcurve's image at the ends.
                assert_eq!(h.edge.points[0], *h.edge.points.last().unwrap());
            }
        }
        assert_eq!(holes, if name == "vase" { 3 } else { 2 });
    }
}

/// The vase's ellipse crosses v = 0: its face's net starts its period elsewhere, and is the
/// same surface there (compared with the unmoved net at v and v − 2π).
#[test]
fn a_hole_across_the_seam_moves_the_net_exactly() {
    let design = trimmed_example("vase");
    let tol = 1e-4 * design_size(&design);
    let model = approximate_design(&design, tol).unwrap();
    let moved = &model.surfaces[0].approx.net;
    let plain = approximate(&design.surfaces[0].kind, tol, 1).unwrap().net;
    let [_, [v0, v1]] = moved.domain();
    assert!(v0 > 0.0 && (v1 - v0 - TAU).abs() < 1e-12, "{v0} {v1}");
    // The ellipse's pcurve was moved by a whole period.
    let hole = &model.surfaces[0].holes[1];
    assert_eq!(hole.v_shift, TAU);
    let mut worst = 0.0f64;
    for i in 0..=20 {
        for j in 0..=200 {
            let u = i as f64 / 20.0;
            let v = v0 + (v1 - v0) * j as f64 / 200.0;
            let w = if v > TAU { v - TAU } else { v };
            worst = worst.max((moved.derivative(u, v, 0, 0) - plain.derivative(u, w, 0, 0)).norm());
        }
    }
    assert!(worst < 1e-12, "{worst:e}");
    // First and last control columns are the same numbers (no seam gap).
    let [nu, nv] = moved.counts();
    for i in 0..nu {
        assert_eq!(moved.control()[i * nv], moved.control()[i * nv + nv - 1]);
    }
    // Moving back gives the first net's domain.
    let back = trimmed::rotate_v(moved, 0.0).unwrap();
    let [_, [b0, b1]] = back.domain();
    assert!(b0 == 0.0 && (b1 - TAU).abs() < 1e-12, "{b0} {b1}");
}

/// STEP and IGES of trimmed designs: one inner bound per hole, each with its pcurve; IGES
/// entities 144, 142 and 126; both read back within the surfaces' deviations.
#[test]
fn trimmed_faces_are_written_and_read_back() {
    for name in ["vase", "book"] {
        let design = trimmed_example(name);
        let tol = 1e-4 * design_size(&design);
        let model = approximate_design(&design, tol).unwrap();
        let holes: usize = model.surfaces.iter().map(|s| s.holes.len()).sum();
        let text = to_step(&model, &opts()).unwrap();
        assert_eq!(text.matches("FACE_BOUND('',").count(), holes, "{name}");
        assert_eq!(
            text.matches("FACE_OUTER_BOUND(").count(),
            model.surfaces.len()
        );
        assert_eq!(text.matches("PCURVE(").count(), holes);
        assert_eq!(text.matches("SURFACE_CURVE(").count(), holes);
        assert!(text.contains("OPEN_SHELL(") && !text.contains("CLOSED_SHELL("));
        let read = read_step(&text).unwrap();
        assert_eq!(read.len(), model.surfaces.len());
        for (r, (s, d)) in read.iter().zip(model.surfaces.iter().zip(&design.surfaces)) {
            assert_eq!(r.net, s.approx.net);
            let surface = d.kind.surface();
            assert!(read::same_domain(surface, &r.net));
            let dev = read::read_back_deviation(surface, &r.net, 9);
            assert!(
                dev <= s.approx.deviation,
                "{name}: {dev:e} > {:e}",
                s.approx.deviation
            );
        }
        let iges = to_iges(&model, LengthUnit::Millimetre, "x.igs", 0).unwrap();
        let types: Vec<&str> = iges
            .lines()
            .filter(|l| l.as_bytes().get(72) == Some(&b'D'))
            .step_by(2)
            .map(|l| l[..8].trim())
            .collect();
        let count = |t: &str| types.iter().filter(|&&x| x == t).count();
        let trimmed = model
            .surfaces
            .iter()
            .filter(|s| !s.holes.is_empty())
            .count();
        assert_eq!(count("144"), trimmed, "{name}");
        assert_eq!(count("142"), holes);
        assert_eq!(count("126"), 2 * holes);
        assert_eq!(count("128"), model.surfaces.len());
        let read = read_iges(&iges).unwrap();
        assert_eq!(read.len(), model.surfaces.len());
        for (r, s) in read.iter().zip(&model.surfaces) {
            assert!(certify::row_distance(r.net.control(), s.approx.net.control()) == 0.0);
        }
    }
}

/// The sphere of radius 2 and the torus R = 3, r = 1 of docs/design-file.md as formula
/// surfaces, with their closed forms (written out here, not through the formula machinery).
const BALL: &str = r#"
[[parametric]]
name = "ball"
x = "2*sin(pi*u)*cos(v)"
y = "2*sin(pi*u)*sin(v)"
z = "2*cos(pi*u)"
"#;

const RING: &str = r#"
[[parametric]]
name = "ring"
x = "(3 + cos(2*pi*u))*cos(v)"
y = "(3 + cos(2*pi*u))*sin(v)"
z = "sin(2*pi*u)"
"#;

fn ball(u: f64, v: f64) -> Vec3 {
    let t = std::f64::consts::PI * u;
    Vec3::new(
        2.0 * t.sin() * v.cos(),
        2.0 * t.sin() * v.sin(),
        2.0 * t.cos(),
    )
}

fn ring(u: f64, v: f64) -> Vec3 {
    let t = TAU * u;
    Vec3::new(
        (3.0 + t.cos()) * v.cos(),
        (3.0 + t.cos()) * v.sin(),
        t.sin(),
    )
}

/// The symbolic fourth-order partials and their enclosures against the closed forms: on tiny
/// boxes the bounds enclose `|∂u⁴X|`, `|∂v⁴X|`, `|∂u∂v⁴X|` and `|X|` of the closed form and
/// exceed them by at most 10⁻⁶ (relative).
#[test]
fn fourth_partials_of_formulas_match_the_closed_forms() {
    use std::f64::consts::PI;
    // (design, [|∂u⁴X|, |∂v⁴X|, |∂u∂v⁴X|, |X|] at (u, v)).
    type Norms = fn(f64, f64) -> [f64; 4];
    let cases: [(&str, Norms); 2] = [
        (BALL, |u, _| {
            let t = PI * u;
            [
                2.0 * PI.powi(4),
                2.0 * t.sin().abs(),
                2.0 * PI * t.cos().abs(),
                2.0,
            ]
        }),
        (RING, |u, _| {
            let t = TAU * u;
            let w = 3.0 + t.cos();
            [
                TAU.powi(4),
                w,
                TAU * t.sin().abs(),
                (w * w + t.sin().powi(2)).sqrt(),
            ]
        }),
    ];
    for (text, norms) in cases {
        let design = solve(text);
        let SurfaceKind::Parametric(p) = &design.surfaces[0].kind else {
            panic!("not a formula surface")
        };
        let fp = p.fourth_partials().unwrap();
        for k in 0..50 {
            let (u, v) = (0.013 + 0.0197 * k as f64, 0.31 + 0.117 * k as f64);
            let b = fp.bounds([u, u + 1e-10], [v, v + 1e-10]).unwrap();
            let want = norms(u, v);
            for (got, w) in b.iter().zip(want) {
                assert!(
                    *got >= w * (1.0 - 1e-9) - 1e-12 && *got <= w * (1.0 + 1e-6) + 1e-9,
                    "{text} at ({u}, {v}): bound {got} against {w}"
                );
            }
        }
    }
}

/// Formula surfaces are certified by interval bounds: on the sphere and the torus the true
/// largest deviation (dense sampling and local maximisation against the closed form) never
/// exceeds the certified figure, which is at most the tolerance and at most 6 × the truth
/// (see the argument in `certify/mod.rs`: the enclosures of the vector norms, the sum of the `u`
/// and `v` terms and the cell widths below the step the worst cell needs).
#[test]
fn formula_surfaces_are_certified_and_the_bound_is_tight() {
    for (text, exact) in [
        (BALL, ball as fn(f64, f64) -> Vec3),
        (RING, ring as fn(f64, f64) -> Vec3),
    ] {
        let design = solve(text);
        let size = design_size(&design);
        for rel in [1e-2, 1e-3, 1e-4, 1e-6] {
            let model = approximate_design(&design, rel * size).unwrap();
            let s = &model.surfaces[0].approx;
            assert!(
                matches!(s.certificate, Certificate::Intervals { .. }),
                "{:?} {:?}",
                s.certificate,
                s.note
            );
            assert!(s.deviation <= rel * size, "bound above the tolerance");
            let truth = true_max_deviation(&s.net, &exact);
            let [nu, nv] = s.net.counts();
            eprintln!(
                "formula {rel:e}: {nu} × {nv}, bound {:.3e}, true {truth:.3e}, ratio {:.2}",
                s.deviation,
                s.deviation / truth
            );
            assert!(
                truth <= s.deviation,
                "{text} tolerance {rel:e}: true deviation {truth:e} exceeds the bound {:e}",
                s.deviation
            );
            assert!(
                s.deviation <= 6.0 * truth,
                "{text} tolerance {rel:e}: bound {:e} looser than 6 × the true deviation {truth:e}",
                s.deviation
            );
        }
    }
}

/// A formula with no fourth-derivative bound near an edge (`u^2.5` at `u = 0`: finite up to
/// second order, so the surface is accepted, but its third derivative is unbounded) is sampled,
/// with the reason and the cell named; an analytic one next to it stays certified.
#[test]
fn formulas_without_bounds_fall_back_to_sampling_with_the_reason() {
    let design = solve(
        r#"
[[parametric]]
name = "cusp"
x = "u^2.5"
y = "v"
z = "u*v"
domain = [0.0, 1.0]

[[parametric]]
name = "plane"
x = "u"
y = "v"
z = "u^2*v"
domain = [0.0, 1.0]
"#,
    );
    let model = approximate_design(&design, 1e-4).unwrap();
    let cusp = &model.surfaces[0].approx;
    assert_eq!(cusp.certificate, Certificate::Sampled);
    let note = cusp.note.as_deref().unwrap();
    assert!(
        note.starts_with("^ with a non-integer exponent on a base reaching 0 on the cell [0, "),
        "{note}"
    );
    let plane = &model.surfaces[1].approx;
    assert!(matches!(plane.certificate, Certificate::Intervals { .. }));
    // A quadratic in u and linear in v: all fourth partials vanish, the net is exact.
    assert!(plane.deviation <= 1e-11, "{}", plane.deviation);
}

/// A hole across the periodic seam moves its face's `v` window; the neighbour that shares an
/// edge with it (the cup's base, at the belly) moves with it, so the shared rows stay
/// identical, the STEP topology keeps one edge used by both faces, and the moved neighbour is
/// the same surface (within 10⁻¹² of its size).
#[test]
fn a_neighbour_of_a_seam_moved_face_keeps_the_shared_edge() {
    let text = format!(
        "{}\n[[trims]]\nsurface = \"bowl\"\ncurves = [{{ type = \"circle\", center = [0.5, 0.05], radius = 0.1 }}]\n",
        include_str!("../../../../examples/cup.toml")
    );
    let design = solve(&text);
    let plain = approximate_design(&example("cup"), 1e-3).unwrap();
    let model = approximate_design(&design, 1e-3).unwrap();
    let (base, bowl) = (&model.surfaces[0], &model.surfaces[1]);
    assert_eq!(bowl.holes.len(), 1);
    let start = bowl.approx.net.domain()[1][0];
    assert!(start != 0.0, "the bowl's window did not move");
    assert_eq!(base.approx.net.domain()[1][0], start);
    assert_eq!(base.approx.net.knots_v(), bowl.approx.net.knots_v());
    let [base_rows, bowl_rows] = [end_rows(&base.approx.net), end_rows(&bowl.approx.net)];
    assert!(
        base_rows.iter().any(|r| bowl_rows.iter().any(|o| o == r)),
        "no identical row"
    );
    let nets: Vec<&BSplineSurface> = model.surfaces.iter().map(|s| &s.approx.net).collect();
    let topo = step::Topology::build(&nets, 1e-9);
    assert!(topo.shared_edges() >= 1, "the belly edge is not shared");
    let plain_nets: Vec<&BSplineSurface> = plain.surfaces.iter().map(|s| &s.approx.net).collect();
    assert_eq!(
        step::Topology::build(&plain_nets, 1e-9).shared_edges(),
        topo.shared_edges()
    );
    // The moved base is the unmoved base re-expressed.
    let unmoved = &plain.surfaces[0].approx.net;
    for i in 0..=20 {
        for j in 0..=200 {
            let (u, v) = (i as f64 / 20.0, TAU * j as f64 / 200.0);
            let w = start + (v - start).rem_euclid(TAU);
            let d = (base.approx.net.derivative(u, w.min(start + TAU), 0, 0)
                - unmoved.derivative(u, v, 0, 0))
            .norm();
            assert!(d <= 1e-12 * 4.0, "{d:e} at ({u}, {v})");
        }
    }
}
