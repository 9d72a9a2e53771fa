//! Hole filling against independent truth: watertightness counted edge by edge, the unit
//! sphere's distance, planes filled flat, and the normal jump across the loop compared with
//! the mesh's own.

use pdeshape::fill::{self, Continuity, FillOptions, Filled, HoleSelection};
use pdeshape::surface::Surface;
use pdeshape::Vec3;
use pdeshape_testkit::hole_meshes::{self, cut_discs, graded_sphere};
use std::collections::HashMap;

/// Every undirected edge in exactly two triangles, once in each direction; returns the
/// Euler characteristic `V − E + F` over the vertices the triangles use.
fn closed_euler(triangles: &[[u32; 3]]) -> i64 {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for j in 0..3 {
            *directed.entry((t[j], t[(j + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &c) in &directed {
        assert_eq!(c, 1, "edge {a}–{b} runs {c} times in one direction");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}–{b} has no opposite"
        );
    }
    let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    used.len() as i64 - (directed.len() / 2) as i64 + triangles.len() as i64
}

/// How far a biharmonic fill of the sphere's geodesic disc of radius ρ = 0.5 may lie from the
/// sphere. The sphere's conformal chart from the disc, `X = (2Rz, 1 − R²|z|²)/(1 + R²|z|²)`
/// with `R = tan(ρ/2)`, has the fill's boundary and (conformal) ribbon; its terms up to
/// `R³|z|²z` are biharmonic, and the first that is not, `2R⁴|z|⁴` in the height, leaves the error
/// `e` with `Δ²e = −128 R⁴` and `e = ∂e/∂r = 0` on the circle: `e = −2R⁴(1 − r²)²`, at most
/// `2R⁴ = 8.5e-3` (the next terms, `O(R⁶)`, lower it).
const SPHERE_BOUND: f64 = 8.6e-3;

fn new_vertices(f: &Filled, before: usize) -> &[Vec3] {
    &f.positions[before..]
}

#[test]
fn a_square_hole_in_a_plane_is_filled_flat_and_watertight_inside() {
    for continuity in [Continuity::G1, Continuity::G0] {
        let holed = hole_meshes::plane_square_hole(20, 0.42);
        let n0 = holed.mesh.positions.len();
        let options = FillOptions {
            continuity,
            holes: HoleSelection::MaxBoundary(60),
            ..FillOptions::default()
        };
        let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
        assert_eq!((filled.holes_found, filled.holes.len()), (2, 1));
        let h = &filled.holes[0];
        assert_eq!(h.boundary_vertices, 32, "{h:?}");
        let z = new_vertices(&filled, n0)
            .iter()
            .map(|p| p.z.abs())
            .fold(0.0, f64::max);
        assert!(z <= 1e-14, "{continuity:?}: {z:e}");
        // Inside the square the fill stays inside it.
        assert!(new_vertices(&filled, n0)
            .iter()
            .all(|p| p.x.abs() < 0.4 + 1e-12 && p.y.abs() < 0.4 + 1e-12));
        // Only the outer square's 80 edges stay open.
        assert_eq!(filled.open_edges, 80);
        assert!(h.g1_angle <= 1e-12, "{h:?}");
    }
}

#[test]
fn a_sphere_with_a_round_hole_comes_out_watertight_and_round() {
    let holed = hole_meshes::sphere_ring_hole(0.02);
    let n0 = holed.mesh.positions.len();
    let filled = fill::fill_holes(&holed.mesh, &FillOptions::default()).unwrap();
    assert_eq!(filled.open_edges, 0);
    assert_eq!(closed_euler(&filled.triangles), 2);
    let h = &filled.holes[0];
    let added: usize = filled.holes.iter().map(|h| h.vertices_added).sum();
    assert_eq!(filled.positions.len(), n0 + added);
    let deviation = new_vertices(&filled, n0)
        .iter()
        .map(|p| (p.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("round hole: {h:?}, deviation from the sphere {deviation:.3e}");
    assert!(deviation < SPHERE_BOUND + 2e-4, "{deviation:e}");
}

#[test]
fn a_sphere_with_only_holes_comes_out_watertight() {
    let centres = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.2, 0.0).normalize(),
        Vec3::new(-0.5, -0.6, -0.6).normalize(),
    ];
    let (p, t) = graded_sphere(centres[0], 0.02, 0.25, 3);
    let holed = cut_discs(&p, &t, &centres, 0.4);
    let filled = fill::fill_holes(&holed.mesh, &FillOptions::default()).unwrap();
    assert_eq!(filled.holes_found, 3);
    assert_eq!(filled.holes.len(), 3);
    assert_eq!(filled.open_edges, 0);
    assert_eq!(closed_euler(&filled.triangles), 2);
    // The fill reuses the loop's vertices: only interior points are new.
    let added: usize = filled.holes.iter().map(|h| h.vertices_added).sum();
    assert_eq!(filled.positions.len(), holed.mesh.positions.len() + added);
}

#[test]
fn a_hole_in_a_sphere_is_filled_close_to_the_sphere_and_tangent_to_the_mesh() {
    let holed = hole_meshes::sphere_hole(565, 1);
    let n0 = holed.mesh.positions.len();
    let filled = fill::fill_holes(&holed.mesh, &FillOptions::default()).unwrap();
    assert_eq!(filled.open_edges, 0);
    assert_eq!(closed_euler(&filled.triangles), 2);
    let h = &filled.holes[0];
    let deviation = new_vertices(&filled, n0)
        .iter()
        .map(|p| (p.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    // The mesh's own jump: the removed triangles against the kept ones at the same vertices.
    let loops = fill::boundary_loops(&holed.mesh.positions, &holed.mesh.triangles).unwrap();
    let reference = fill::normal_jump(
        &holed.mesh.positions,
        &holed.removed,
        &holed.mesh.triangles,
        &loops[0].vertices,
    );
    eprintln!(
        "sphere 565: {} boundary vertices, {} triangles; deviation {deviation:.3e}, \
         G1 angle {:.3e}, jump max {:.3e} rms {:.3e}, the mesh's own max {:.3e} rms {:.3e}",
        h.boundary_vertices,
        h.triangles_added,
        h.g1_angle,
        h.normal_jump.0,
        h.normal_jump.1,
        reference.0,
        reference.1
    );
    // SPHERE_BOUND: the biharmonic cap against the sphere's conformal chart, plus the mesh's
    // own chordal error (h²/8 for edges h ≤ 0.04: 2e-4).
    assert!(deviation < SPHERE_BOUND + 2e-4, "{deviation:e}");
    assert!(
        h.normal_jump.1 < 2.0 * reference.1,
        "{h:?} vs {reference:?}"
    );
}

#[test]
fn a_hole_in_a_plane_is_filled_flat() {
    for continuity in [Continuity::G1, Continuity::G0] {
        let holed = hole_meshes::plane_hole(40, 0.55, 7);
        let n0 = holed.mesh.positions.len();
        // The outer square is a loop too (of 160 vertices): the hole alone.
        let options = FillOptions {
            continuity,
            holes: HoleSelection::MaxBoundary(150),
            ..FillOptions::default()
        };
        let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
        assert_eq!((filled.holes_found, filled.holes.len()), (2, 1));
        assert!(filled.holes[0].g1_angle <= 1e-12, "{:?}", filled.holes[0]);
        let z = new_vertices(&filled, n0)
            .iter()
            .map(|p| p.z.abs())
            .fold(0.0, f64::max);
        assert!(z <= 1e-14, "{continuity:?}: {z:e}");
        // Only the outer square's edges stay open.
        assert_eq!(filled.open_edges, 4 * 40);
    }
}

#[test]
fn a_g2_fill_of_a_sphere_hole_is_closer_to_the_sphere_than_the_g1_fill() {
    for (name, holed) in [
        ("round", hole_meshes::sphere_ring_hole(0.02)),
        ("jittered", hole_meshes::sphere_hole(565, 1)),
    ] {
        let n0 = holed.mesh.positions.len();
        let deviation = |continuity| {
            let options = FillOptions {
                continuity,
                ..FillOptions::default()
            };
            let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
            assert_eq!(filled.open_edges, 0);
            new_vertices(&filled, n0)
                .iter()
                .map(|p| (p.norm() - 1.0).abs())
                .fold(0.0, f64::max)
        };
        let (g1, g2) = (deviation(Continuity::G1), deviation(Continuity::G2));
        eprintln!("{name}: G1 {g1:.3e}, G2 {g2:.3e}");
        assert!(g2 < g1, "{name}: G1 {g1:e}, G2 {g2:e}");
    }
}

#[test]
fn a_long_and_a_u_shaped_hole_in_a_plane_are_split_and_filled_flat() {
    // An ellipse of axes 0.8 and 0.2 and a U: one disk patch would crowd or fold; the pieces
    // between chords stay in the plane and inside the hole, and the hole closes.
    let ellipse = |x: f64, y: f64| (x / 0.8).powi(2) + (y / 0.2).powi(2) < 1.0;
    let u = |x: f64, y: f64| x.abs() < 0.5 && y.abs() < 0.5 && !(x.abs() < 0.2 && y > 0.0);
    let options = FillOptions {
        holes: HoleSelection::MaxBoundary(200),
        ..FillOptions::default()
    };
    for (name, inside, grown) in [
        ("ellipse", &ellipse as &dyn Fn(f64, f64) -> bool, 1.1),
        ("U", &u, 1.0),
    ] {
        let holed = hole_meshes::plane_hole_where(60, 3, inside);
        let n0 = holed.mesh.positions.len();
        let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
        let h = &filled.holes[0];
        assert!(h.pieces >= 2, "{name}: {h:?}");
        let z = new_vertices(&filled, n0)
            .iter()
            .map(|p| p.z.abs())
            .fold(0.0, f64::max);
        assert!(z <= 1e-14, "{name}: {z:e}");
        assert!(h.chord_g1_angle <= 1e-12, "{name}: {h:?}");
        // The new points lie in the hole grown by half an edge (1/60).
        let half = 1.0 / 60.0;
        assert!(
            new_vertices(&filled, n0).iter().all(|p| {
                let near = |dx: f64, dy: f64| inside(p.x + dx, p.y + dy);
                near(0.0, 0.0)
                    || near(half, 0.0)
                    || near(-half, 0.0)
                    || near(0.0, half)
                    || near(0.0, -half)
                    || (name == "ellipse" && (p.x / 0.8).powi(2) + (p.y / 0.2).powi(2) < grown)
            }),
            "{name}"
        );
        // Only the outer square's edges stay open, and no fill triangle faces down.
        assert_eq!(filled.open_edges, 4 * 60, "{name}");
        assert_eq!(
            flipped(&filled, holed.mesh.triangles.len(), |_| Vec3::z()),
            0,
            "{name}"
        );
    }
}

/// The triangles of the fill (after the mesh's `t0`) whose normal points against `outward`
/// at their centroid.
fn flipped(f: &Filled, t0: usize, outward: impl Fn(Vec3) -> Vec3) -> usize {
    f.triangles[t0..]
        .iter()
        .filter(|t| {
            let p = t.map(|i| f.positions[i as usize]);
            let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
            n.dot(&outward((p[0] + p[1] + p[2]) / 3.0)) <= 0.0
        })
        .count()
}

/// A long, an L-shaped and a U-shaped hole in a sphere and in a cylinder, each split along
/// chords and filled: watertight, no triangle facing inwards, close to the true surface, and
/// the pieces tangent to each other along the chords.
#[test]
fn long_and_concave_holes_are_split_and_filled_close_to_the_surface() {
    type Case = (
        &'static str,
        hole_meshes::Holed,
        fn(Vec3) -> f64,
        fn(Vec3) -> Vec3,
    );
    let sphere_d: fn(Vec3) -> f64 = |p| p.norm() - 1.0;
    let sphere_n: fn(Vec3) -> Vec3 = |p| p;
    let cyl_d: fn(Vec3) -> f64 = |p| p.x.hypot(p.y) - 1.0;
    let cyl_n: fn(Vec3) -> Vec3 = |p| Vec3::new(p.x, p.y, 0.0);
    let cases: Vec<Case> = vec![
        (
            "sphere 8:1",
            hole_meshes::sphere_hole_where(0.02, 5, |x, y| x.abs() < 0.8 && y.abs() < 0.1),
            sphere_d,
            sphere_n,
        ),
        (
            "sphere L",
            hole_meshes::sphere_hole_where(0.02, 6, |x, y| {
                (x.abs() < 0.45 && (-0.45..-0.25).contains(&y))
                    || ((-0.45..-0.25).contains(&x) && y.abs() < 0.45)
            }),
            sphere_d,
            sphere_n,
        ),
        (
            "cylinder 8:1",
            hole_meshes::cylinder_hole_where(240, 1.0, 7, |a, z| a.abs() < 0.1 && z.abs() < 0.8),
            cyl_d,
            cyl_n,
        ),
        (
            "cylinder U",
            hole_meshes::cylinder_hole_where(240, 1.0, 8, |a, z| {
                a.abs() < 0.4 && z.abs() < 0.4 && !(a.abs() < 0.2 && z > -0.2)
            }),
            cyl_d,
            cyl_n,
        ),
    ];
    for (name, holed, distance, outward) in cases {
        let n0 = holed.mesh.positions.len();
        let t0 = holed.mesh.triangles.len();
        let loops = fill::boundary_loops(&holed.mesh.positions, &holed.mesh.triangles).unwrap();
        // The hole, not the cylinder's rims (240 vertices each).
        let hole = loops.iter().position(|l| l.vertices.len() < 240).unwrap();
        let options = FillOptions {
            holes: HoleSelection::MaxBoundary(239),
            ..FillOptions::default()
        };
        let filled =
            fill::fill_holes(&holed.mesh, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        let h = &filled.holes[0];
        let deviation = new_vertices(&filled, n0)
            .iter()
            .map(|&p| distance(p).abs())
            .fold(0.0, f64::max);
        let reference = fill::normal_jump(
            &holed.mesh.positions,
            &holed.removed,
            &holed.mesh.triangles,
            &loops[hole].vertices,
        );
        let open = filled.open_edges;
        let flips = flipped(&filled, t0, outward);
        eprintln!(
            "{name}: {} pieces, {} boundary vertices, {} triangles; deviation {deviation:.3e}; \
             G1 angle {:.3e}, chord G1 {:.3e}, chord jump {:.3e}/{:.3e}, jump {:.3e}/{:.3e} \
             (mesh's own {:.3e}/{:.3e}); flipped {flips}; open {open}; {:.1} ms",
            h.pieces,
            h.boundary_vertices,
            h.triangles_added,
            h.g1_angle,
            h.chord_g1_angle,
            h.chord_jump.0,
            h.chord_jump.1,
            h.normal_jump.0,
            h.normal_jump.1,
            reference.0,
            reference.1,
            h.seconds * 1e3,
        );
        assert!(h.pieces >= 2, "{name}: {h:?}");
        // Watertight (the cylinder's two rims stay open), one surface.
        if name.starts_with("sphere") {
            assert_eq!(open, 0, "{name}");
            assert_eq!(closed_euler(&filled.triangles), 2, "{name}");
        } else {
            assert_eq!(open, 2 * 240, "{name}");
        }
        assert_eq!(flips, 0, "{name}");
        // Every hole is 0.2 across (its arms, on the unit sphere or cylinder): a fill flat
        // across them would miss the surface by the sagitta 1 − cos 0.1; the fill does better.
        assert!(deviation < 1.0 - 0.1f64.cos(), "{name}: {deviation:e}");
        // The pieces' tangent planes along the chords agree better than the mesh's own
        // triangles do across the loop, and the fill meets the mesh as the mesh meets itself.
        assert!(h.chord_g1_angle < reference.1, "{name}: {h:?}");
        assert!(h.normal_jump.1 < 2.0 * reference.1, "{name}: {h:?}");
    }
}

#[test]
fn a_split_hole_is_filled_g2_too() {
    // The chord points' curvature is the ends' forms interpolated: the pieces still close the
    // hole, face outwards and stay nearer the sphere than a flat strip.
    let holed = hole_meshes::sphere_hole_where(0.02, 5, |x, y| x.abs() < 0.8 && y.abs() < 0.1);
    let n0 = holed.mesh.positions.len();
    let options = FillOptions {
        continuity: Continuity::G2,
        ..FillOptions::default()
    };
    let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
    let h = &filled.holes[0];
    assert!(h.pieces >= 2, "{h:?}");
    assert_eq!(filled.open_edges, 0);
    assert_eq!(closed_euler(&filled.triangles), 2);
    assert_eq!(flipped(&filled, holed.mesh.triangles.len(), |p| p), 0);
    let deviation = new_vertices(&filled, n0)
        .iter()
        .map(|p| (p.norm() - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!("G2: {h:?}, deviation {deviation:.3e}");
    assert!(deviation < 1.0 - 0.1f64.cos(), "{deviation:e}");
}

#[test]
fn a_hole_that_is_most_of_the_sphere_is_refused_naming_it() {
    // A cap of radius 0.5 kept about the peers' centre's antipode: the hole's loop goes round
    // the cap, and the hole is the rest of the sphere; no disk patch or chord spans it.
    let c = hole_meshes::peer_centre();
    let (p, t) = graded_sphere(c, 0.02, 0.25, 2);
    let holed = cut_discs(&p, &t, &[c], std::f64::consts::PI - 0.5);
    let e = fill::fill_holes(&holed.mesh, &FillOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("hole 1 (at vertex ") && e.contains("no chord inside it splits it"),
        "{e}"
    );
    assert!(!e.contains('\n'), "{e}");
}

#[test]
fn the_fill_patches_round_trip_through_a_design_file() {
    // A split hole (several patches) in G1 and G2, and a round hole in G0: written, read
    // back, solved again, each surface is the fill's patch to rounding.
    let strip = hole_meshes::sphere_hole_where(0.02, 5, |x, y| x.abs() < 0.8 && y.abs() < 0.1);
    let round = hole_meshes::sphere_ring_hole(0.04);
    for (holed, continuity) in [
        (&strip, Continuity::G1),
        (&strip, Continuity::G2),
        (&round, Continuity::G0),
    ] {
        let options = FillOptions {
            continuity,
            ..FillOptions::default()
        };
        let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
        let pieces: usize = filled.holes.iter().map(|h| h.pieces).sum();
        assert_eq!(filled.patches.len(), pieces);
        let spec = filled.design("round trip");
        let text = pdeshape::spec::write_design(&spec).unwrap();
        let back = pdeshape::parse_design(&text).unwrap();
        assert_eq!(back, spec, "{continuity:?}");
        let solved = pdeshape::design::solve_design(&back).unwrap();
        assert_eq!(solved.surfaces.len(), filled.patches.len());
        let mut worst = 0.0f64;
        for p in &filled.patches {
            let s = solved.surfaces.iter().find(|s| s.name == p.name).unwrap();
            for i in 0..=10 {
                for j in 0..16 {
                    let (u, v) = (i as f64 / 10.0, pdeshape::TAU * j as f64 / 16.0);
                    let (a, b) = (s.kind.surface().partials(u, v), p.patch.partials(u, v));
                    worst = worst
                        .max((a.x - b.x).norm())
                        .max((a.xu - b.xu).norm())
                        .max((a.xv - b.xv).norm());
                }
            }
        }
        // The same data solved the same way: equal to the last bit.
        assert_eq!(worst, 0.0, "{continuity:?}");
    }
}
