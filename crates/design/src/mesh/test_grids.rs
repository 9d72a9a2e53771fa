//! Grids for the tests of every layer that meshes (the weld, its frames, the writers): a grid
//! from a position function, spheres, and the sets of grids that cover the weld's cases.
//! Compiled for this crate's tests and, with the feature `test-support`, for the tests of the
//! layers above (enabled only by their dev-dependencies).

use super::GridMesh;

/// A grid from a position function on `u ∈ [0, 1]` and `v` (periodic: `2πj/nv`, else
/// `[0, 2π]` with both ends), normals from finite differences of the function (any unit-ish
/// vector does: the weld only averages them).
pub fn grid(nu: usize, nv: usize, periodic: bool, f: impl Fn(f64, f64) -> [f64; 3]) -> GridMesh {
    let u: Vec<f64> = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    let v: Vec<f64> = if periodic {
        (0..nv).map(|j| crate::TAU * j as f64 / nv as f64).collect()
    } else {
        (0..nv)
            .map(|j| crate::TAU * j as f64 / (nv - 1).max(1) as f64)
            .collect()
    };
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for &a in &u {
        for &b in &v {
            let p = f(a, b);
            let (h, k) = (1e-5, 1e-5);
            let pu = f(a + h, b);
            let pv = f(a, b + k);
            let du = [pu[0] - p[0], pu[1] - p[1], pu[2] - p[2]];
            let dv = [pv[0] - p[0], pv[1] - p[1], pv[2] - p[2]];
            let n = [
                du[1] * dv[2] - du[2] * dv[1],
                du[2] * dv[0] - du[0] * dv[2],
                du[0] * dv[1] - du[1] * dv[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
            positions.push(p.map(|x| x as f32));
            normals.push(n.map(|x| (x / len) as f32));
        }
    }
    GridMesh {
        nu,
        nv,
        periodic_v: periodic,
        u,
        v,
        positions,
        normals,
    }
}

/// Sphere of radius r from pole to pole (`u ∈ [u0, u1]` of the half turn).
pub fn sphere(nu: usize, nv: usize, r: f64, u0: f64, u1: f64, periodic: bool) -> GridMesh {
    grid(nu, nv, periodic, move |u, v| {
        let t = std::f64::consts::PI * (u0 + (u1 - u0) * u);
        [r * t.sin() * v.cos(), r * t.sin() * v.sin(), r * t.cos()]
    })
}

/// Sets of grids covering the cases: poles (exact and within the tolerance), duplicated seam
/// columns, shared edges between patches (both directions), a collapsed row in the middle,
/// sheets, several groups, conflicting orientations, tiny and degenerate grids.
pub fn cases() -> Vec<(String, Vec<GridMesh>)> {
    use std::f64::consts::PI;
    let mut out: Vec<(String, Vec<GridMesh>)> = Vec::new();
    for (nu, nv) in [(2, 3), (3, 3), (3, 4), (4, 5), (9, 16), (17, 32)] {
        out.push((
            format!("sphere {nu}x{nv}"),
            vec![sphere(nu, nv, 2.0, 0.0, 1.0, true)],
        ));
        out.push((
            format!("hemispheres {nu}x{nv}"),
            vec![
                sphere(nu, nv, 2.0, 0.0, 0.5, true),
                sphere(nu, nv, 2.0, 1.0, 0.5, true),
            ],
        ));
        out.push((
            format!("seam column {nu}x{nv}"),
            vec![grid(nu, nv, false, |u, v| [v.cos(), v.sin(), u])],
        ));
        out.push((
            format!("sheet {nu}x{nv}"),
            vec![grid(nu, nv, false, |u, v| [u, v, 0.1 * (u * v).sin()])],
        ));
    }
    // A pole that is one point only within the tolerance (rounding noise below 1e-6 of the size).
    out.push((
        "noisy pole".into(),
        vec![grid(12, 20, true, |u, v| {
            let r = u + 1e-9 * (7.0 * v).sin();
            [r * v.cos(), r * v.sin(), 1.0 - u]
        })],
    ));
    // A row collapsed in the middle (a pinched tube) and poles at both ends.
    out.push((
        "pinched".into(),
        vec![grid(13, 10, true, |u, v| {
            let r = (PI * u).sin() * (2.0 * PI * u).sin().abs();
            [r * v.cos(), r * v.sin(), u]
        })],
    ));
    // A cylinder of 2 rows, a periodic grid of 3 columns, a strip 2 wide.
    out.push((
        "two rows".into(),
        vec![grid(2, 8, true, |u, v| [v.cos(), v.sin(), u])],
    ));
    out.push((
        "three columns".into(),
        vec![grid(6, 3, true, |u, v| [v.cos(), v.sin(), u])],
    ));
    out.push(("strip".into(), vec![grid(7, 2, false, |u, v| [u, v, 0.0])]));
    // A cup: bottom disc and wall sharing the rim circle, the wall's rows running up.
    let base = grid(9, 24, true, |u, v| [u * v.cos(), u * v.sin(), 0.0]);
    let wall = grid(11, 24, true, |u, v| [v.cos(), v.sin(), u]);
    out.push(("cup".into(), vec![base.clone(), wall.clone()]));
    // The wall's v reversed: the shared edge runs the same way in both patches.
    let wall_back = grid(11, 24, true, |u, v| [(-v).cos(), (-v).sin(), u]);
    out.push(("cup reversed wall".into(), vec![base.clone(), wall_back]));
    // Three patches on one edge (non-manifold), and two separate groups.
    let fin = grid(5, 24, true, |u, v| {
        [(1.0 + u) * v.cos(), (1.0 + u) * v.sin(), 0.0]
    });
    out.push((
        "three on an edge".into(),
        vec![base.clone(), wall.clone(), fin],
    ));
    let far = grid(7, 9, true, |u, v| [10.0 + v.cos(), v.sin(), u]);
    out.push(("two groups".into(), vec![base, wall, far]));
    // A Möbius-like band closing on itself with a flip: conflicting orientation.
    let half_a = grid(6, 9, false, |u, v| {
        let t = v / 2.0;
        let w = u - 0.5;
        [
            (1.0 + w * (t / 2.0).cos()) * t.cos(),
            (1.0 + w * (t / 2.0).cos()) * t.sin(),
            w * (t / 2.0).sin(),
        ]
    });
    let half_b = grid(6, 9, false, |u, v| {
        let t = PI + v / 2.0;
        let w = u - 0.5;
        [
            (1.0 + w * (t / 2.0).cos()) * t.cos(),
            (1.0 + w * (t / 2.0).cos()) * t.sin(),
            w * (t / 2.0).sin(),
        ]
    });
    out.push(("moebius".into(), vec![half_a, half_b]));
    out
}
