//! Welding a design's grids into one mesh: poles, seams and shared edges joined, orientation
//! made consistent and outward, checked by counting edges and by volumes with closed forms.

use pdeshape::analysis::{integrate_design, Quadrature};
use pdeshape::design::solve_design;
use pdeshape::mesh::{report, tessellate, weld, GridMesh, WeldOptions};
use pdeshape::surface::{ParametricSurface, VDomain};
use std::f64::consts::PI;

fn grid(x: &str, y: &str, z: &str, domain: VDomain, nu: usize, nv: usize) -> GridMesh {
    let s = ParametricSurface::new(x, y, z, domain).unwrap();
    tessellate(&s, nu, nv).unwrap()
}

/// The sphere of radius r (u from the north pole to the south pole): X_u × X_v points inward.
fn sphere(nu: usize, nv: usize) -> GridMesh {
    grid(
        "2*sin(pi*u)*cos(v)",
        "2*sin(pi*u)*sin(v)",
        "2*cos(pi*u)",
        VDomain::Periodic,
        nu,
        nv,
    )
}

/// The inscribed polyhedron of the sphere of radius 2 on an nu × nv grid has volume
/// V (1 − O(h²)): its relative error is below (π/(nu−1))² + (2π/nv)² (each chord loses
/// about h²/6 of the radius-weighted volume, three directions at most).
fn sphere_tolerance(nu: usize, nv: usize) -> f64 {
    (PI / (nu - 1) as f64).powi(2) + (2.0 * PI / nv as f64).powi(2)
}

#[test]
fn a_sphere_is_closed_outward_with_one_vertex_per_pole() {
    let (nu, nv) = (33, 48);
    let m = weld(&[sphere(nu, nv)], &["ball"], WeldOptions::default());
    assert_eq!(m.positions.len(), (nu - 2) * nv + 2);
    // Two pole fans of nv triangles each, two triangles per other quad.
    assert_eq!(m.triangles.len(), 2 * nv + 2 * (nu - 3) * nv);
    let r = report(&m);
    assert!(r.is_closed_and_oriented(), "{r:?}");
    assert_eq!(r.degenerate_triangles, 0);
    let exact = 4.0 / 3.0 * PI * 8.0;
    assert!(r.signed_volume > 0.0, "wound inward: {r:?}");
    let rel = (exact - r.signed_volume) / exact;
    assert!(rel > 0.0 && rel < sphere_tolerance(nu, nv), "{rel}");
    // Vertex normals were turned with the triangles: outward.
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let dot: f32 = (0..3).map(|c| p[c] * n[c]).sum();
        assert!(dot > 0.0, "{p:?} {n:?}");
    }
    // Second order: the error falls about fourfold when the grid is refined twice.
    let fine = report(&weld(&[sphere(65, 96)], &[], WeldOptions::default()));
    let rel_fine = (exact - fine.signed_volume) / exact;
    assert!(rel_fine < rel / 3.0, "{rel} {rel_fine}");
}

/// Two hemispheres sharing the equator, the lower one wound against the upper.
fn hemispheres() -> Vec<GridMesh> {
    let top = grid(
        "2*sin(pi*u/2)*cos(v)",
        "2*sin(pi*u/2)*sin(v)",
        "2*cos(pi*u/2)",
        VDomain::Periodic,
        17,
        32,
    );
    // From the south pole up to the equator: the same winding rule makes it face outward, the
    // opposite of `top`.
    let bottom = grid(
        "2*sin(pi*u/2)*cos(v)",
        "2*sin(pi*u/2)*sin(v)",
        "-2*cos(pi*u/2)",
        VDomain::Periodic,
        17,
        32,
    );
    vec![top, bottom]
}

#[test]
fn patches_sharing_an_edge_become_one_consistently_wound_mesh() {
    let g = hemispheres();
    let m = weld(&g, &["top", "bottom"], WeldOptions::default());
    let r = report(&m);
    assert!(r.is_closed_and_oriented(), "{r:?}");
    assert!(r.signed_volume > 0.0);
    // The equator's 32 vertices are shared; each pole is one vertex.
    assert_eq!(m.positions.len(), 2 * (15 * 32 + 1) + 32);
    assert_eq!(m.parts.len(), 2);
    assert_eq!(
        (m.parts[0].name.as_str(), m.parts[1].name.as_str()),
        ("top", "bottom")
    );
    m.check().unwrap();

    // Kept apart: two open hemispheres, each outward... by its own first-patch rule or its
    // capped volume, and no vertex shared.
    let apart = weld(
        &g,
        &["top", "bottom"],
        WeldOptions {
            join_patches: false,
        },
    );
    let r = report(&apart);
    assert_eq!(r.boundary_edges, 2 * 32);
    assert_eq!(r.misoriented_edges, 0);
    assert_eq!(apart.positions.len(), 2 * (16 * 32 + 1));
}

#[test]
fn a_duplicated_seam_column_is_welded() {
    // v over [0, 2π] with both ends: the first and last columns coincide (as the periodic blend
    // writes them).
    let g = grid(
        "cos(v)",
        "sin(v)",
        "u",
        VDomain::Interval(0.0, 2.0 * PI),
        5,
        17,
    );
    let m = weld(&[g], &[], WeldOptions::default());
    assert_eq!(m.positions.len(), 5 * 16);
    let r = report(&m);
    // Only the two end circles are boundary.
    assert_eq!(r.boundary_edges, 2 * 16);
    assert_eq!(
        r.misoriented_edges + r.nonmanifold_edges + r.degenerate_triangles,
        0
    );
}

#[test]
fn open_surfaces_face_out_of_what_they_hold_and_sheets_keep_their_side() {
    // A cup (bottom pole, open top) wound inward: turned so its capped volume is positive.
    let cup = grid(
        "sin(pi*u/2)*cos(v)",
        "sin(pi*u/2)*sin(v)",
        "u",
        VDomain::Periodic,
        9,
        16,
    );
    let m = weld(&[cup], &[], WeldOptions::default());
    let bottom = m
        .positions
        .iter()
        .position(|p| p == &[0.0, 0.0, 0.0])
        .unwrap();
    assert!(m.normals[bottom][2] < -0.99, "{:?}", m.normals[bottom]);
    // A plane z = 0 with normal +z stays +z, whichever way is "out".
    let sheet = grid("u", "v", "0", VDomain::Interval(0.0, 1.0), 4, 4);
    let m = weld(&[sheet], &[], WeldOptions::default());
    assert!(m.normals.iter().all(|n| n == &[0.0, 0.0, 1.0]));
}

#[test]
fn the_vesicle_example_is_watertight_with_analyzes_volume() {
    let spec = pdeshape_testkit::example_spec("vesicle.toml");
    let solved = solve_design(&spec).unwrap();
    let exact = integrate_design(
        &solved,
        &Quadrature {
            tolerance: 1e-9,
            ..Default::default()
        },
    )
    .unwrap()
    .total
    .volume;
    let mut errors = Vec::new();
    for (nu, nv) in [(32, 64), (64, 128)] {
        let grids = solved.meshes(nu, nv).unwrap();
        let m = solved.weld(&grids, &Default::default());
        let r = report(&m);
        assert!(r.is_closed_and_oriented(), "{r:?}");
        assert_eq!(r.degenerate_triangles, 0);
        assert!(r.signed_volume > 0.0);
        errors.push((r.signed_volume - exact).abs() / exact);
    }
    // The chordal error is second order: a few 1e-4 at 64 × 128, about a quarter of 32 × 64's.
    assert!(errors[1] < 1e-3, "{errors:?}");
    assert!(errors[1] < errors[0] / 3.0, "{errors:?}");
}
