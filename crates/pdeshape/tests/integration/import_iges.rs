//! `pdeshape::cad::import::import_iges`: the STEP test parts written as IGES by OpenCascade
//! (`bench/peers/occ_box_corner_gap_iges.py`: as a B-rep, entities 186/514/510, and as
//! trimmed surfaces, entities 144) read as the STEP parts are, and their gap filled alike.

use super::import_step::{distance_between, match_occ_faces, occ_points};
use pdeshape::cad::import::{import_iges, import_step, Fill, Imported};
use pdeshape::design::{solve_design, NurbsSurface, SolvedDesign};
use pdeshape::surface::{ClosestOptions, ClosestPointIndex, Surface};
use pdeshape_testkit::example_path;

fn read(name: &str) -> String {
    std::fs::read_to_string(example_path(&format!("cad/{name}"))).unwrap()
}

/// The four IGES parts with the STEP part each was written from.
const PARTS: [(&str, &str); 4] = [
    ("box_corner_gap_brep.igs", "box_corner_gap.step"),
    ("box_corner_gap_trimmed.igs", "box_corner_gap.step"),
    ("box_corner_gap_nurbs_brep.igs", "box_corner_gap_nurbs.step"),
    (
        "box_corner_gap_nurbs_trimmed.igs",
        "box_corner_gap_nurbs.step",
    ),
];

/// The largest distance of points of a face's edges from the face (closest points).
fn edges_off_faces(imported: &Imported, d: &SolvedDesign) -> f64 {
    let mut worst: f64 = 0.0;
    for f in &imported.faces {
        let surface = d.surface_named(&f.name).unwrap().surface();
        let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
        for e in &f.edges {
            let curve = d.curves.iter().find(|c| &c.name == e).unwrap();
            let side = imported
                .spec
                .nsided
                .iter()
                .flat_map(|p| &p.sides)
                .find(|s| matches!(&s.curve, pdeshape::spec::CurveRef::Name(n) if n == e));
            let (a, b) = match (side.and_then(|s| s.range), curve.curve.domain()) {
                (Some([a, b]), _) => (a, b),
                (None, pdeshape::curve::Domain::Interval(a, b)) => (a, b),
                _ => panic!("{e}: an edge has ends"),
            };
            for k in 0..=16 {
                let p = curve.curve.point(a + (b - a) * k as f64 / 16.0);
                let c = index.closest(p).unwrap();
                worst = worst.max((surface.point(c.u, c.v) - p).norm());
            }
        }
    }
    worst
}

#[test]
fn iges_parts_are_read_with_the_faces_edges_and_gap_of_their_step_parts() {
    for (iges, step) in PARTS {
        let ours = import_iges(&read(iges), Fill::G1).unwrap();
        let theirs = import_step(&read(step), Fill::G1).unwrap();
        assert_eq!(ours.faces.len(), 9, "{iges}");
        assert!(
            ours.faces.iter().all(|f| f.imported),
            "{iges}: {:?}",
            ours.faces
        );
        assert_eq!(ours.spec.units, theirs.spec.units, "{iges}");
        // The same edges: 21, shared ones once (a trimmed-surface file gives them per face).
        assert_eq!(ours.spec.curves.len(), theirs.spec.curves.len(), "{iges}");
        assert_eq!(ours.spec.nurbs.len(), theirs.spec.nurbs.len(), "{iges}");
        assert_eq!(ours.gaps.len(), 1, "{iges}: {:?}", ours.gaps);
        assert_eq!(ours.gaps[0].edges.len(), 3, "{iges}");
        assert_eq!(ours.gaps[0].patch.as_deref(), Some("fill1"), "{iges}");
        // Every edge on its faces; the part's size is about 1.
        let d = solve_design(&ours.spec).unwrap();
        let off = edges_off_faces(&ours, &d);
        assert!(off <= 1e-9, "{iges}: an edge is {off:e} off its face");
    }
}

#[test]
fn iges_nurbs_faces_evaluate_as_opencascade_evaluates_them() {
    for name in ["box_corner_gap_nurbs_brep", "box_corner_gap_nurbs_trimmed"] {
        let imported = import_iges(&read(&format!("{name}.igs")), Fill::None).unwrap();
        let ours: Vec<NurbsSurface> = imported
            .spec
            .nurbs
            .iter()
            .map(|n| NurbsSurface::from_spec(n, "").unwrap())
            .collect();
        let truth = occ_points(&format!("{name}.points"));
        assert_eq!(truth.len(), 9);
        match_occ_faces(&ours, &truth, name);
    }
}

#[test]
fn analytic_iges_faces_are_the_step_faces() {
    // The faces of an analytic IGES part are the STEP part's surfaces over the same boxes:
    // every face's points lie on the STEP part's faces and the other way round.
    let step = solve_design(
        &import_step(&read("box_corner_gap.step"), Fill::G1)
            .unwrap()
            .spec,
    )
    .unwrap();
    let theirs: Vec<&dyn Surface> = step.references.iter().map(|s| s.surface()).collect();
    for iges in ["box_corner_gap_brep.igs", "box_corner_gap_trimmed.igs"] {
        let spec = import_iges(&read(iges), Fill::G1).unwrap().spec;
        assert_eq!(spec.parametric.len(), 9, "{iges}");
        let d = solve_design(&spec).unwrap();
        let ours: Vec<&dyn Surface> = d.references.iter().map(|s| s.surface()).collect();
        let gap = distance_between(&ours, &theirs).max(distance_between(&theirs, &ours));
        // The two files write the same decimal numbers here (0.2, 0.8, 1: exact in the ten
        // digits of the IGES file), so the surfaces agree to rounding (measured 2.5e-14).
        assert!(gap < 1e-12, "{iges}: {gap:e}");
    }
}

#[test]
fn the_fill_from_iges_is_the_fill_from_step() {
    // OpenCascade writes IGES numbers with 10 significant digits (the fillets' middle weight
    // 0.707106781, the knots 6.283185307), the STEP files with 12 or more: each number of the
    // IGES part (coordinates up to 1, weights up to 1, knots up to 2π) may differ from the STEP
    // part's by half a unit in the tenth digit, at most 5e-10 × 2π ≈ 3.1e-9 for a knot and
    // 5e-10 for the rest. The sides and the neighbours' normals move by a small multiple of
    // that (a weight's change moves a rational quadratic arc by less than its radius, 0.2,
    // times the change), and the fill is linear in them with a Lebesgue constant below 4 (the
    // 129 Chebyshev–Lobatto samples of its sides), so the fills may differ by about 4 × 5e-10
    // = 2e-9 of the part's size (1). The analytic parts' numbers (0.2, 0.8, 1) are exact in ten
    // digits, so their fills agree to rounding; measured: 2e-14 and 8e-13 (B-rep and trimmed
    // surfaces, analytic), 9e-12 and 3e-11 (NURBS).
    for (iges, step) in PARTS {
        for fill in [Fill::G1, Fill::G2] {
            let ours = solve_design(&import_iges(&read(iges), fill).unwrap().spec).unwrap();
            let theirs = solve_design(&import_step(&read(step), fill).unwrap().spec).unwrap();
            let a: Vec<&dyn Surface> = ours.surfaces.iter().map(|s| s.surface()).collect();
            let b: Vec<&dyn Surface> = theirs.surfaces.iter().map(|s| s.surface()).collect();
            assert_eq!(a.len(), 3, "{iges}");
            let gap = distance_between(&a, &b).max(distance_between(&b, &a));
            assert!(gap < 2e-9, "{iges} {fill:?}: the fills differ by {gap:e}");
        }
    }
}

#[test]
fn bad_iges_files_are_refused_with_their_place() {
    let text = read("box_corner_gap_trimmed.igs");
    let lines: Vec<&str> = text.lines().collect();
    // Truncated: the Terminate section's counts no longer hold.
    let cut = lines[..lines.len() / 2].join("\n");
    let e = import_iges(&cut, Fill::G1).unwrap_err().to_string();
    assert!(e.contains("truncated"), "{e}");
    // A trimmed surface pointing at a directory entry that is not there.
    let (k, line) = lines
        .iter()
        .enumerate()
        .find(|(_, l)| l.starts_with("144,") && l.as_bytes()[72] == b'P')
        .unwrap();
    let fields: Vec<&str> = line[..64].split(',').collect();
    let broken_line = format!(
        "{:<64}{}",
        format!("144,99999,{}", fields[2..].join(",").trim_end()),
        &line[64..]
    );
    let mut broken: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    broken[k] = broken_line;
    let e = import_iges(&broken.join("\n"), Fill::G1)
        .unwrap_err()
        .to_string();
    let p = line[73..].trim().trim_start_matches('0');
    assert!(
        e.contains(&format!("P {p}")) && e.contains("entity 144") && e.contains("D 99999"),
        "{e}"
    );
    // A parameter that is not a number.
    let mut broken: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let (k, line) = lines
        .iter()
        .enumerate()
        .find(|(_, l)| l.starts_with("110,") && l.as_bytes()[72] == b'P')
        .unwrap();
    let data = format!("110,1.2.3{}", &line[4 + line[4..].find(',').unwrap()..64]);
    broken[k] = format!("{:<64}{}", &data[..data.len().min(64)], &line[64..]);
    let e = import_iges(&broken.join("\n"), Fill::G1)
        .unwrap_err()
        .to_string();
    let p = line[73..].trim().trim_start_matches('0');
    assert!(e.contains(&format!("P {p}")) && e.contains("1.2.3"), "{e}");
    // An entity the reader does not know where a curve belongs (a 110 made a 112).
    let broken: Vec<String> = lines
        .iter()
        .map(|l| {
            if l.starts_with("     110") && l.as_bytes()[72] == b'D' {
                l.replacen("     110", "     112", 1)
            } else if l.starts_with("110,") && l.as_bytes()[72] == b'P' {
                l.replacen("110,", "112,", 1)
            } else {
                l.to_string()
            }
        })
        .collect();
    let e = import_iges(&broken.join("\n"), Fill::G1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("entity 112") && e.contains("D "), "{e}");
    // Not IGES at all.
    let e = import_iges("solid\nendsolid\n", Fill::None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 1"), "{e}");
}

#[test]
fn damaged_iges_files_never_panic() {
    // Every file cut at many places and with bytes changed at many places: an error or a
    // design, never a panic.
    for (name, _) in PARTS {
        let text = read(name);
        let bytes = text.as_bytes();
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        for _ in 0..60 {
            let cut = next(bytes.len());
            let _ = import_iges(&String::from_utf8_lossy(&bytes[..cut]), Fill::G1);
            let mut changed = bytes.to_vec();
            for _ in 0..4 {
                let at = next(changed.len());
                changed[at] = b"0123456789,;.-+DHEP 7"[next(21)];
            }
            let _ = import_iges(&String::from_utf8_lossy(&changed), Fill::G1);
        }
    }
}

#[test]
fn the_global_sections_unit_and_model_scale_are_applied() {
    // Global parameters 13 (model space scale) and 14, 15 (units flag and name): a scale of 2
    // means two model units per inch, so every length read is halved.
    let text = read("box_corner_gap_nurbs_brep.igs");
    let edited = text.replacen(",1.,2,2HMM,", ",2.,1,2HIN,", 1);
    assert_ne!(edited, text);
    let mm = import_iges(&text, Fill::None).unwrap().spec;
    let inch = import_iges(&edited, Fill::None).unwrap().spec;
    assert_eq!(mm.units, Some(pdeshape::Units::Millimetre));
    assert_eq!(inch.units, Some(pdeshape::Units::Inch));
    for (a, b) in mm.nurbs.iter().zip(&inch.nurbs) {
        for (ra, rb) in a.control.iter().zip(&b.control) {
            for (pa, pb) in ra.iter().zip(rb) {
                assert_eq!(pa.map(|x| x / 2.0), *pb, "{}", a.name);
            }
        }
        assert_eq!(a.weights, b.weights);
    }
}
