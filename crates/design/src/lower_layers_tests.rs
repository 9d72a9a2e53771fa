//! Tests of the geometry layer's surfaces that need this layer: a PDE patch solved from a design
//! file, meshes and integrals of a formula surface, the tessellation of a spline-PDE net.

use crate::design::solve_design;
use crate::spec::parse_design;
use crate::surface::{Interval, ParametricSurface, Partials, Surface, VDomain};
use crate::{Vec3, TAU};
use std::f64::consts::{FRAC_PI_2, PI};

/// The sphere of radius 2 about `(1, 0, 0)`, `u ∈ [−π/2, π/2]` (latitude).
fn sphere() -> ParametricSurface {
    ParametricSurface::with_u_range(
        "1 + 2*cos(u)*cos(v)",
        "2*cos(u)*sin(v)",
        "2*sin(u)",
        Interval::new(-FRAC_PI_2, FRAC_PI_2),
        VDomain::Periodic,
    )
    .unwrap()
}

/// The row path agrees with pointwise partials, with and without the spectral remainder.
#[test]
fn rows_of_partials_match_pointwise_partials() {
    let text = r#"
conditions = [
  { u = 0.0, curve = "a" },
  { u = 0.0, derivative = 1, curve = "da" },
  { u = 1.0, curve = "b" },
  { u = 1.0, derivative = 1, curve = "db" },
]
[curves.a]
type = "samples"
points = [[1, 0, 0], [0, 1.3, 0.1], [-1, 0, 0], [0, -0.8, -0.1], [0.7, -0.7, 0]]
[curves.b]
type = "circle"
center = [0, 0, 1.5]
radius = 0.6
[curves.da]
type = "derivative"
position = "a"
direction = { type = "circle", center = [0, 0, 1], radius = 1.2 }
[curves.db]
type = "derivative"
position = "b"
direction = { type = "circle", center = [0, 0, 2.5], radius = 0.9 }
[solver]
modes = 6
"#;
    for remainder in [true, false] {
        let t = text.replace("modes = 6", &format!("modes = 6\nremainder = {remainder}"));
        let d = solve_design(&parse_design(&t).unwrap()).unwrap();
        let p = d.surfaces[0].pde().unwrap();
        assert_eq!(p.has_remainder(), remainder);
        // Offset 0: the standard grid (the symmetric path for even nv); 0.3: the general one.
        for (nv, offset) in [
            (8, 0.0),
            (12, 0.0),
            (512, 0.0),
            (1usize, 0.0),
            (7, 0.0),
            (64, 0.0),
            (130, 0.0),
            (200, 0.3),
            (9, 0.3),
        ] {
            let vs: Vec<f64> = (0..nv)
                .map(|j| offset + TAU * j as f64 / nv as f64)
                .collect();
            let rows = p.partials_rows(&vs);
            let mut out = vec![Partials::default(); nv];
            for u in [0.0, 0.37, 1.0] {
                rows.eval_row(u, &mut out);
                for (j, &v) in vs.iter().enumerate() {
                    let e = p.partials(u, v);
                    let o = out[j];
                    for (a, b) in [
                        (o.x, e.x),
                        (o.xu, e.xu),
                        (o.xv, e.xv),
                        (o.xuu, e.xuu),
                        (o.xuv, e.xuv),
                        (o.xvv, e.xvv),
                    ] {
                        assert!(
                            (a - b).norm() <= 1e-13 * b.norm().max(1.0),
                            "remainder {remainder}, nv {nv}, u {u}, j {j}: {a} vs {b}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn meshes_of_a_formula_surface_cover_its_u_range() {
    let s = sphere();
    let grid = crate::mesh::sample(&s, 5, 8).unwrap();
    assert_eq!(grid.u[0], -FRAC_PI_2);
    assert_eq!(grid.u[4], FRAC_PI_2);
    let south = grid.positions[grid.index(0, 3)];
    let north = grid.positions[grid.index(4, 3)];
    assert!((Vec3::from(south) - Vec3::new(1.0, 0.0, -2.0)).norm() < 1e-12);
    assert!((Vec3::from(north) - Vec3::new(1.0, 0.0, 2.0)).norm() < 1e-12);
}

#[test]
fn integrals_of_a_formula_surface_cover_its_u_range() {
    use crate::analysis::{integrate_surface, Quadrature};
    let i = integrate_surface(&sphere(), &Quadrature::default()).unwrap();
    assert!((i.area - 16.0 * PI).abs() < 1e-9 * 16.0 * PI, "{i:?}");
    assert!((i.gauss - 4.0 * PI).abs() < 1e-9, "{i:?}");
}

/// The tessellation of a spline-PDE net (a biharmonic net fixed on two rings of a plane, which
/// solves it): `nu·nv` vertices, the first at the surface's corner.
#[test]
fn tessellation_of_a_spline_pde_net() {
    use crate::splinepde::{ring_indices, solve, Direction, Operator, SplineProblem};
    let cubic = || Direction::<f64> {
        degree: 3,
        knots: vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0],
    };
    let (u, v) = (cubic(), cubic());
    let n = [u.count(), v.count()];
    let plane = |i: usize, j: usize| {
        let (x, y) = (i as f64 / (n[0] - 1) as f64, j as f64 / (n[1] - 1) as f64);
        [x, y, 0.5 * x - 2.0 * y + 1.0]
    };
    let fixed = ring_indices([n[0] - 1, n[1] - 1], 2)
        .into_iter()
        .map(|[i, j]| ([i, j], plane(i, j)))
        .collect();
    let net = solve(&SplineProblem {
        u,
        v,
        operator: Operator::biharmonic(),
        fixed,
    })
    .unwrap();
    let VDomain::Interval(v0, _) = net.v_domain() else {
        panic!("a spline net has an interval in v")
    };
    let mesh = crate::mesh::tessellate(&net, 9, 7).unwrap();
    assert_eq!(mesh.len(), 63);
    let corner = Surface::point(&net, 0.0, v0);
    for d in 0..3 {
        // f32 positions: rounding of a coordinate of size ~2 is below 1e-6.
        assert!(
            (mesh.positions[0][d] as f64 - corner[d]).abs() < 1e-6,
            "{d}"
        );
    }
}
