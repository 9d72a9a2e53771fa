//! Hole filling against independent truth: watertightness counted edge by edge, the unit
//! sphere's distance, planes filled flat, and the normal jump across the loop compared with
//! the mesh's own.

use pdeshape::fill::{self, Continuity, FillOptions, Filled, HoleSelection};
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
fn a_long_hole_is_filled_flat_by_another_ribbon_and_a_u_shaped_one_is_refused() {
    // An ellipse of axes 0.8 and 0.2: the conformal ribbon folds the fill, the harmonic one
    // (for a convex planar loop, close to the harmonic map, one-to-one) does not.
    let holed =
        hole_meshes::plane_hole_where(60, 3, |x, y| (x / 0.8).powi(2) + (y / 0.2).powi(2) < 1.0);
    let n0 = holed.mesh.positions.len();
    let options = FillOptions {
        holes: HoleSelection::MaxBoundary(200),
        ..FillOptions::default()
    };
    let filled = fill::fill_holes(&holed.mesh, &options).unwrap();
    let h = &filled.holes[0];
    assert_ne!(h.ribbon, "conformal", "{h:?}");
    let z = new_vertices(&filled, n0)
        .iter()
        .map(|p| p.z.abs())
        .fold(0.0, f64::max);
    assert!(z <= 1e-14, "{z:e}");
    assert!(new_vertices(&filled, n0)
        .iter()
        .all(|p| (p.x / 0.8).powi(2) + (p.y / 0.2).powi(2) < 1.1));
    // A U: no ribbon keeps the disk's map from folding over the tongue; refused, named.
    let holed = hole_meshes::plane_hole_where(60, 3, |x, y| {
        x.abs() < 0.5 && y.abs() < 0.5 && !(x.abs() < 0.2 && y > 0.0)
    });
    let e = fill::fill_holes(&holed.mesh, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("hole 2") && e.contains("too long or too winding"),
        "{e}"
    );
}
