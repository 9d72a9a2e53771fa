//! `pdeshape::cad::import`: a CAD part read from STEP, its gap filled tangent to its faces.

use pdeshape::cad::import::{import_step, Fill};
use pdeshape::design::{solve_design, NurbsSurface};
use pdeshape::spec::parse_design;
use pdeshape::surface::{ClosestOptions, ClosestPointIndex, Surface};
use pdeshape_testkit::{example, example_path};

fn part() -> String {
    std::fs::read_to_string(example_path("cad/box_corner_gap.step")).unwrap()
}

#[test]
fn the_box_corner_gap_is_read_with_its_faces_edges_and_gap() {
    let imported = import_step(&part(), Fill::G1).unwrap();
    let kinds: Vec<&str> = imported.faces.iter().map(|f| f.kind.as_str()).collect();
    assert_eq!(
        kinds.iter().filter(|k| **k == "PLANE").count(),
        6,
        "{kinds:?}"
    );
    assert_eq!(
        kinds
            .iter()
            .filter(|k| **k == "CYLINDRICAL_SURFACE")
            .count(),
        3,
        "{kinds:?}"
    );
    assert!(imported.faces.iter().all(|f| f.imported));
    assert_eq!(imported.spec.curves.len(), 21);
    assert_eq!(imported.gaps.len(), 1);
    assert_eq!(imported.gaps[0].edges.len(), 3);
    assert_eq!(imported.gaps[0].patch.as_deref(), Some("fill1"));
    // The faces are reference surfaces: neighbours, not output.
    assert!(imported.spec.parametric.iter().all(|p| p.reference));
    // Every face's edges lie on its surface (the formulas are the file's own geometry).
    let d = solve_design(&imported.spec).unwrap();
    let names: Vec<&str> = d.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["fill1.0", "fill1.1", "fill1.2"]);
    for f in &imported.faces {
        let surface = d.surface_named(&f.name).unwrap().surface();
        let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
        for e in &f.edges {
            let curve = d.curves.iter().find(|c| &c.name == e).unwrap();
            let (a, b) = match curve.curve.domain() {
                pdeshape::curve::Domain::Interval(a, b) => (a, b),
                _ => panic!("{e}: an edge has ends"),
            };
            for k in 0..=8 {
                let p = curve.curve.point(a + (b - a) * k as f64 / 8.0);
                let c = index.closest(p).unwrap();
                let dist = (surface.point(c.u, c.v) - p).norm();
                assert!(dist < 1e-12, "{}: {e} at {k}/8 is {dist:e} off", f.name);
            }
        }
    }
}

#[test]
fn the_filled_gap_is_the_vertex_blend_of_the_exact_fillets() {
    // OpenCascade's part and the hand-written exact example (`nsided_vertex_blend.toml`: the
    // same fillets as formulas) give the patch the same positions and tangent planes on the
    // same sides, and the PDE on the equilateral domain is invariant under its rotations and
    // reflections: the two fills are one surface, up to the rounding of the file's numbers.
    let imported = import_step(&part(), Fill::G1).unwrap();
    let ours = solve_design(&imported.spec).unwrap();
    let exact = solve_design(&parse_design(&example("nsided_vertex_blend.toml")).unwrap()).unwrap();
    let pieces: Vec<&dyn Surface> = exact
        .surfaces
        .iter()
        .filter(|s| s.name.starts_with("corner"))
        .map(|s| s.surface())
        .collect();
    let indices: Vec<ClosestPointIndex<_>> = pieces
        .iter()
        .map(|s| ClosestPointIndex::new(*s, &ClosestOptions::default()))
        .collect();
    let mut worst: f64 = 0.0;
    for s in &ours.surfaces {
        for i in 0..=12 {
            for j in 0..=12 {
                let p = s.surface().point(i as f64 / 12.0, j as f64 / 12.0);
                let d = pieces
                    .iter()
                    .zip(&indices)
                    .filter_map(|(q, idx)| idx.closest(p).map(|c| (q.point(c.u, c.v) - p).norm()))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
        }
    }
    assert!(worst < 1e-9, "{worst:e}");
    // Tangent to the three fillets (measured against the reference faces themselves) and on
    // its sides to rounding.
    let report = pdeshape::diagnostics::diagnose(&imported.spec, &ours);
    let ns = &report.nsided[0];
    assert!(ns.boundary < 1e-13, "{}", ns.boundary);
    for g in &ns.g1 {
        assert!(g.unwrap() < 1e-10, "{:?}", ns.g1);
    }
}

#[test]
fn bad_parts_are_refused_with_the_place() {
    let text = part();
    // A face bound pointing at a missing entity.
    let i = text.find("FACE_BOUND").unwrap();
    let at = text[i..].find('#').unwrap() + i + 1;
    let end = text[at..].find(|c: char| !c.is_ascii_digit()).unwrap() + at;
    let broken = format!("{}999999{}", &text[..at], &text[end..]);
    let e = import_step(&broken, Fill::G1).unwrap_err().to_string();
    assert!(e.contains("#999999"), "{e}");
    // Not STEP at all.
    let e = import_step("solid\nendsolid\n", Fill::None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("DATA"), "{e}");
    // A circle of negative radius.
    let i = text.find("CIRCLE(").unwrap();
    let close = text[i..].find(')').unwrap() + i;
    let comma = text[..close].rfind(',').unwrap();
    let broken = format!("{}-0.2{}", &text[..comma + 1], &text[close..]);
    let e = import_step(&broken, Fill::G1).unwrap_err().to_string();
    assert!(e.contains("line ") && e.contains("radii"), "{e}");
}

/// The part of `box_corner_gap.step` with every face a B-spline surface (OpenCascade's
/// `BRepBuilderAPI_NurbsConvert`; `bench/peers/occ_box_corner_gap_nurbs.py`).
fn nurbs_part() -> String {
    std::fs::read_to_string(example_path("cad/box_corner_gap_nurbs.step")).unwrap()
}

/// OpenCascade's evaluation of the faces of `box_corner_gap_nurbs.step` as it reads them back:
/// per face, rows of `u v X Xu Xv Xuu Xvv Xuv` in the surface's knot parameters.
/// OpenCascade's evaluation of a part's B-spline faces (`examples/cad/NAME`): per face, rows of
/// `u v` and the position and partials to second order.
pub(crate) fn occ_points(name: &str) -> Vec<Vec<[f64; 20]>> {
    let text = std::fs::read_to_string(example_path(&format!("cad/{name}"))).unwrap();
    let mut faces: Vec<Vec<[f64; 20]>> = Vec::new();
    for line in text.lines() {
        if line.starts_with("face") {
            faces.push(Vec::new());
            continue;
        }
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        faces.last_mut().unwrap().push(v.try_into().unwrap());
    }
    faces
}

/// Matches each of OpenCascade's faces (`truth`, [`occ_points`]) to exactly one of `ours`, by
/// positions and partials (rescaled from the knot parameter of `u` to the design's `u ∈ [0, 1]`)
/// agreeing to 1e-12 (relative); every one of ours is matched once. Returns the largest
/// difference of the matches.
pub(crate) fn match_occ_faces(ours: &[NurbsSurface], truth: &[Vec<[f64; 20]>], label: &str) -> f64 {
    let mut matched = vec![false; ours.len()];
    let mut worst: f64 = 0.0;
    for (k, rows) in truth.iter().enumerate() {
        let mut found = None;
        for (r, n) in ours.iter().enumerate() {
            let [[u0, u1], _] = n.knot_domain();
            let h = u1 - u0;
            let err = rows
                .iter()
                .map(|t| {
                    let p = n.partials((t[0] - u0) / h, t[1]);
                    let at = |i: usize| pdeshape::Vec3::new(t[i], t[i + 1], t[i + 2]);
                    [
                        (p.x, at(2)),
                        (p.xu, at(5) * h),
                        (p.xv, at(8)),
                        (p.xuu, at(11) * h * h),
                        (p.xvv, at(14)),
                        (p.xuv, at(17) * h),
                    ]
                    .iter()
                    .map(|(a, b)| (a - b).norm() / (1.0 + b.norm()))
                    .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max);
            if err < 1e-12 {
                assert!(
                    found.is_none(),
                    "{label}: OpenCascade's face {k} matches two of ours"
                );
                found = Some(r);
                worst = worst.max(err);
            }
        }
        let r = found.unwrap_or_else(|| panic!("{label}: OpenCascade's face {k} is none of ours"));
        assert!(!matched[r], "{label}: nurbs[{r}] matched twice");
        matched[r] = true;
    }
    assert!(
        matched.iter().all(|&m| m),
        "{label}: a face of ours matched none"
    );
    worst
}

/// The largest distance from points of `ours`, over their whole parameter domains, to the
/// surfaces of `theirs` (closest points).
pub(crate) fn distance_between(ours: &[&dyn Surface], theirs: &[&dyn Surface]) -> f64 {
    let indices: Vec<ClosestPointIndex<_>> = theirs
        .iter()
        .map(|s| ClosestPointIndex::new(*s, &ClosestOptions::default()))
        .collect();
    let mut worst: f64 = 0.0;
    for s in ours {
        let (v0, v1) = match s.v_domain() {
            pdeshape::surface::VDomain::Interval(a, b) => (a, b),
            pdeshape::surface::VDomain::Periodic => (0.0, std::f64::consts::TAU),
        };
        for i in 0..=12 {
            for j in 0..=12 {
                let p = s.point(
                    s.u_range().lerp(i as f64 / 12.0),
                    v0 + (v1 - v0) * j as f64 / 12.0,
                );
                let d = theirs
                    .iter()
                    .zip(&indices)
                    .filter_map(|(q, idx)| idx.closest(p).map(|c| (q.point(c.u, c.v) - p).norm()))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
        }
    }
    worst
}

#[test]
fn b_spline_faces_are_read_as_nurbs_surfaces_that_hold_their_edges() {
    let imported = import_step(&nurbs_part(), Fill::G1).unwrap();
    let kinds: Vec<&str> = imported.faces.iter().map(|f| f.kind.as_str()).collect();
    let count = |k: &str| kinds.iter().filter(|x| **x == k).count();
    // The planes are polynomial (bilinear) nets, the circular fillets rational quadratics.
    assert_eq!(count("B_SPLINE_SURFACE_WITH_KNOTS"), 6, "{kinds:?}");
    assert_eq!(count("RATIONAL_B_SPLINE_SURFACE"), 3, "{kinds:?}");
    assert!(imported.faces.iter().all(|f| f.imported));
    assert!(imported.spec.parametric.is_empty());
    assert_eq!(imported.spec.nurbs.len(), 9);
    assert_eq!(
        imported
            .spec
            .nurbs
            .iter()
            .filter(|n| n.weights.is_some())
            .count(),
        3
    );
    assert_eq!(imported.gaps.len(), 1);
    assert_eq!(imported.gaps[0].patch.as_deref(), Some("fill1"));
    let d = solve_design(&imported.spec).unwrap();
    // Reference surfaces: neighbours, not output.
    assert_eq!(d.names(), ["fill1.0", "fill1.1", "fill1.2"]);
    assert_eq!(d.references.len(), 9);
    let mut worst: f64 = 0.0;
    for f in &imported.faces {
        let surface = d.surface_named(&f.name).unwrap().surface();
        let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
        for e in &f.edges {
            let curve = d.curves.iter().find(|c| &c.name == e).unwrap();
            let (a, b) = match curve.curve.domain() {
                pdeshape::curve::Domain::Interval(a, b) => (a, b),
                _ => panic!("{e}: an edge has ends"),
            };
            for k in 0..=16 {
                let p = curve.curve.point(a + (b - a) * k as f64 / 16.0);
                let c = index.closest(p).unwrap();
                worst = worst.max((surface.point(c.u, c.v) - p).norm());
            }
        }
    }
    assert!(worst <= 1e-9, "an edge is {worst:e} off its face");
}

#[test]
fn nurbs_faces_evaluate_as_opencascade_evaluates_them() {
    let imported = import_step(&nurbs_part(), Fill::None).unwrap();
    let ours: Vec<NurbsSurface> = imported
        .spec
        .nurbs
        .iter()
        .map(|n| NurbsSurface::from_spec(n, "").unwrap())
        .collect();
    let truth = occ_points("box_corner_gap_nurbs.points");
    assert_eq!(truth.len(), 9);
    let worst = match_occ_faces(&ours, &truth, "box_corner_gap_nurbs.step");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The NURBS part's design with its rational (fillet) faces replaced by the exact cylinders
/// that `box_corner_gap.step` has at the same places (the `[[parametric]]` face holding the
/// rational face's middle point, under the rational face's name): the same sides, the
/// neighbours as formulas.
fn with_exact_fillets(nurbs: &pdeshape::DesignSpec) -> pdeshape::DesignSpec {
    let exact = import_step(&part(), Fill::G1).unwrap().spec;
    let solved = solve_design(&exact).unwrap();
    let mut out = nurbs.clone();
    out.nurbs.retain(|n| n.weights.is_none());
    for n in nurbs.nurbs.iter().filter(|n| n.weights.is_some()) {
        let p = NurbsSurface::from_spec(n, "").unwrap().point(0.5, 0.4);
        let mut twins = exact.parametric.iter().filter(|q| {
            let s = solved.surface_named(&q.name).unwrap().surface();
            let c = ClosestPointIndex::new(s, &ClosestOptions::default()).closest(p);
            c.is_some_and(|c| (s.point(c.u, c.v) - p).norm() < 1e-9)
        });
        let mut twin = twins
            .next()
            .expect("an exact face at the rational face")
            .clone();
        assert!(twins.next().is_none(), "{}: two exact faces", n.name);
        twin.name = n.name.clone();
        out.parametric.push(twin);
    }
    out
}

#[test]
fn the_gap_beside_nurbs_fillets_is_filled_as_beside_the_exact_cylinders() {
    // The file's fillets are rational quadratics whose middle weight is written with 12
    // digits (0.707106781187, cos 45° − 4.5e-13): they leave the exact cylinder of radius 0.2
    // by at most 2.2e-14 (radially, at mid-arc) and turn its normal by O(1e-13) rad. The fill
    // is linear in the neighbours' normals along its sides (sampled at 129 Chebyshev–Lobatto
    // points, a Lebesgue constant below 4), so the fills beside the NURBS faces and beside the
    // exact cylinders (the same sides) may differ by a small multiple of 1e-13 of the gap's
    // size (0.28): we allow 1e-11, a margin of about 100 over that estimate.
    for (fill, g2) in [(Fill::G1, false), (Fill::G2, true)] {
        let nurbs = import_step(&nurbs_part(), fill).unwrap().spec;
        let exact = with_exact_fillets(&nurbs);
        assert_eq!(exact.nurbs.len(), 6);
        assert_eq!(exact.parametric.len(), 3);
        let ours = solve_design(&nurbs).unwrap();
        let theirs = solve_design(&exact).unwrap();
        let a: Vec<&dyn Surface> = ours.surfaces.iter().map(|s| s.surface()).collect();
        let b: Vec<&dyn Surface> = theirs.surfaces.iter().map(|s| s.surface()).collect();
        let gap = distance_between(&a, &b).max(distance_between(&b, &a));
        assert!(gap < 1e-11, "{fill:?}: the fills differ by {gap:e}");
        // `check` against the NURBS faces themselves: the sides to rounding, G1 to the bound
        // the exact formulas meet (1e-10 rad: rounding and the closest-point solves; the
        // ribbon's interpolation error of the analytic normal field is far below it), G2 as
        // beside the exact cylinders (the residual is the patch's own rounding in its second
        // derivatives), and the corners' curvature conflict of the box's vertex blend the same.
        let report = pdeshape::diagnostics::diagnose(&nurbs, &ours);
        let twin = pdeshape::diagnostics::diagnose(&exact, &theirs);
        let (ns, ex) = (&report.nsided[0], &twin.nsided[0]);
        assert!(ns.boundary < 1e-13, "{}", ns.boundary);
        for g in &ns.g1 {
            assert!(g.unwrap() < 1e-10, "{:?}", ns.g1);
        }
        for (g, e) in ns.g2.iter().zip(&ex.g2) {
            assert_eq!(g.is_some(), g2);
            if let (Some(g), Some(e)) = (g, e) {
                assert!(
                    *g < 1e-9 && (g - e).abs() < 1e-10,
                    "{:?} vs {:?}",
                    ns.g2,
                    ex.g2
                );
            }
        }
        for (c, e) in ns.corner_curvature.iter().zip(&ex.corner_curvature) {
            assert_eq!(c.is_some(), g2);
            if let (Some(c), Some(e)) = (c, e) {
                assert!((c - e).abs() < 1e-9, "{c} vs {e}");
            }
        }
    }
}

#[test]
fn nurbs_faces_round_trip_and_bad_nets_are_refused_with_their_line() {
    let imported = import_step(&nurbs_part(), Fill::G2).unwrap();
    let text = pdeshape::spec::write_design(&imported.spec).unwrap();
    assert_eq!(parse_design(&text).unwrap(), imported.spec);
    let part = nurbs_part();
    // A rational surface with a negative weight.
    let i = part.find("RATIONAL_B_SPLINE_SURFACE((").unwrap();
    let at = part[i..].find("0.707106781187").unwrap() + i;
    let broken = format!("{}-{}", &part[..at], &part[at..]);
    let e = import_step(&broken, Fill::G1).unwrap_err().to_string();
    assert!(
        e.contains("line ") && e.contains("weights[1][0]") && e.contains("positive"),
        "{e}"
    );
    // Knot multiplicities that do not fit the net.
    let i = part.find("B_SPLINE_SURFACE_WITH_KNOTS('',").unwrap();
    let at = part[i..].find("(2,2),(2,2)").unwrap() + i;
    let broken = format!("{}(2,3),(2,2){}", &part[..at], &part[at + 11..]);
    let e = import_step(&broken, Fill::G1).unwrap_err().to_string();
    assert!(e.contains("line ") && e.contains("knots_u"), "{e}");
}
