//! `pdeshape::cad::import`: a CAD part read from STEP, its gap filled tangent to its faces.

use pdeshape::cad::import::import_step;
use pdeshape::design::solve_design;
use pdeshape::spec::parse_design;
use pdeshape::surface::{ClosestOptions, ClosestPointIndex, Surface};
use pdeshape_testkit::{example, example_path};

fn part() -> String {
    std::fs::read_to_string(example_path("cad/box_corner_gap.step")).unwrap()
}

#[test]
fn the_box_corner_gap_is_read_with_its_faces_edges_and_gap() {
    let imported = import_step(&part(), true).unwrap();
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
    let imported = import_step(&part(), true).unwrap();
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
    let e = import_step(&broken, true).unwrap_err().to_string();
    assert!(e.contains("#999999"), "{e}");
    // Not STEP at all.
    let e = import_step("solid\nendsolid\n", false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("DATA"), "{e}");
    // A circle of negative radius.
    let i = text.find("CIRCLE(").unwrap();
    let close = text[i..].find(')').unwrap() + i;
    let comma = text[..close].rfind(',').unwrap();
    let broken = format!("{}-0.2{}", &text[..comma + 1], &text[close..]);
    let e = import_step(&broken, true).unwrap_err().to_string();
    assert!(e.contains("line ") && e.contains("radii"), "{e}");
}
