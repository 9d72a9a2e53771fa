use super::*;
use crate::analysis::{integrate_surface, integrate_trimmed, Quadrature};
use crate::surface::{closest_point, ClosestOptions, ParametricSurface, VDomain};
use crate::Vec3;
use std::collections::HashMap;

/// A periodic surface with a non-constant area element (a flared, wavy tube).
fn tube() -> ParametricSurface {
    ParametricSurface::new(
        "(1 + 0.3*u)*cos(v)",
        "(1 + 0.3*u)*sin(v)",
        "u + 0.2*sin(2*v)",
        VDomain::Periodic,
    )
    .unwrap()
}

fn sheet() -> ParametricSurface {
    ParametricSurface::new("u", "v", "0.3*u*u - 0.2*v*v", VDomain::Interval(0.0, 1.0)).unwrap()
}

fn curves() -> Vec<TrimCurve> {
    vec![
        TrimCurve::circle([0.5, 1.0], 0.2),
        TrimCurve::Ellipse {
            center: [0.45, 3.2],
            radii: [0.15, 0.5],
            angle: 0.3,
        },
        // A concave (boomerang) closed B-spline.
        TrimCurve::BSpline {
            degree: 3,
            points: vec![
                [0.3, 4.6],
                [0.5, 4.3],
                [0.7, 4.6],
                [0.75, 5.2],
                [0.5, 4.8],
                [0.25, 5.2],
            ],
        },
    ]
}

/// The area and the volume share `(1/3)∫X·(X_u × X_v) dA` of the hole of a circle or ellipse
/// on `s`, by Gauss–Legendre in the radius and the trapezoid rule in the angle over the hole in
/// `(u, v)` with the area element (independent of the trimmed mesh).
fn hole_integrals(s: &dyn Surface, center: [f64; 2], radii: [f64; 2], angle: f64) -> [f64; 2] {
    let rule = crate::analysis::gauss_legendre(40);
    let g = rule.nodes.iter().copied().zip(rule.weights.iter().copied());
    let nt = 400;
    let (sa, ca) = angle.sin_cos();
    let mut sum = [0.0; 2];
    for (x, w) in g {
        let r = 0.5 * (x + 1.0);
        for k in 0..nt {
            let th = TAU * k as f64 / nt as f64;
            let (px, py) = (radii[0] * r * th.cos(), radii[1] * r * th.sin());
            let (u, v) = (center[0] + ca * px - sa * py, center[1] + sa * px + ca * py);
            let p = s.partials(u, v.rem_euclid(TAU));
            let n = p.xu.cross(&p.xv);
            // Jacobian of (r, θ) ↦ (u, v): a b r.
            let dw = 0.5 * w * (TAU / nt as f64) * radii[0] * radii[1] * r;
            sum[0] += dw * n.norm();
            sum[1] += dw * p.x.dot(&n) / 3.0;
        }
    }
    sum
}

fn hole_area(s: &dyn Surface, center: [f64; 2], radii: [f64; 2], angle: f64) -> f64 {
    hole_integrals(s, center, radii, angle)[0]
}

/// Sum of the flat triangles' areas, vertices evaluated in full precision.
fn mesh_area(s: &dyn Surface, pm: &ParamMesh) -> f64 {
    let x: Vec<Vec3> = pm.uv.iter().map(|p| s.point(p[0], p[1])).collect();
    pm.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| x[i as usize]);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum()
}

fn edge_counts(pm: &ParamMesh) -> HashMap<(u32, u32), usize> {
    let mut e = HashMap::new();
    for t in &pm.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *e.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    e
}

/// Every edge has one or two triangles; the edges of one triangle are exactly the domain's
/// boundary: the two `u` ends (`nv` edges each, periodic) and the chords of every hole.
fn assert_watertight(pm: &ParamMesh, nv: usize) {
    let e = edge_counts(pm);
    assert!(
        e.values().all(|&c| c == 1 || c == 2),
        "an edge with > 2 triangles"
    );
    let open = e.values().filter(|&&c| c == 1).count();
    assert_eq!(open, 2 * nv + pm.on_trim.len());
}

#[test]
fn trim_vertices_lie_on_the_trim_curves_and_their_images_on_the_surface() {
    let s = tube();
    let all = curves();
    for (method, cs) in [
        (TrimMethod::Cdt, &all[..]),
        (TrimMethod::Bilinear, &all[..2]),
        (TrimMethod::Laplace, &all[..2]),
    ] {
        let (m, pm) = trimmed_mesh(&s, 33, 64, cs, method, "tube").unwrap();
        m.check().unwrap();
        assert!(pm.on_trim.len() > 60);
        // Every curve has vertices, and each vertex is listed once.
        for k in 0..cs.len() {
            assert!(pm.on_trim.iter().filter(|o| o.curve == k).count() >= 8);
        }
        let mut seen: Vec<u32> = pm.on_trim.iter().map(|o| o.vertex).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), pm.on_trim.len());
        for o in &pm.on_trim {
            let uv = pm.uv[o.vertex as usize];
            let c = cs[o.curve].point(o.t);
            assert!(
                (uv[0] - c[0]).abs() <= 1e-12 && (uv[1] - c[1]).abs() <= 1e-12,
                "{method:?}"
            );
            // Independently of the sampling: the circle's vertices are at the radius (its
            // points carry a few roundings of values below 2: ≤ 1e-15).
            if o.curve == 0 {
                let r = (uv[0] - 0.5).hypot(uv[1] - 1.0);
                assert!((r - 0.2).abs() < 1e-12, "{method:?}: {r}");
            }
        }
        // The 3D images, in the mesh: the f32 rounding of X(u, v) (half an f32 ulp of each
        // coordinate; X by another evaluation path differs by a few f64 ulps of the largest
        // coordinate), and on the surface: the closest point of the stored f32 point lies within
        // that rounding (√3 f32 ulps of the largest coordinate) of it.
        let opts = ClosestOptions::default();
        let eps32 = f64::from(f32::EPSILON);
        for o in pm.on_trim.iter().step_by(5) {
            let [u, v] = pm.uv[o.vertex as usize];
            let x = s.point(u, v.rem_euclid(TAU));
            let p = m.positions[o.vertex as usize];
            for k in 0..3 {
                let bound = 0.5 * eps32 * x[k].abs() + 8.0 * f64::EPSILON * x.amax();
                assert!((f64::from(p[k]) - x[k]).abs() <= bound, "{method:?}");
            }
            let q = Vec3::new(p[0].into(), p[1].into(), p[2].into());
            let c = closest_point(&s, q, &opts).unwrap();
            let bound = 3f64.sqrt() * eps32 * q.amax();
            assert!(c.distance <= bound, "{method:?}: {} > {bound}", c.distance);
        }
    }
}

/// The same on the vase of `examples/trimmed_vase.toml` (a PDE patch, the three holes of the
/// design file), through the design's own trimmed mesh: every vertex of a hole's boundary lies
/// on its curve to 1e-12 in `(u, v)`, and its stored point on the patch (closest point within
/// the f32 rounding).
#[test]
fn the_vase_trim_vertices_lie_on_the_patch() {
    let path = format!(
        "{}/../../examples/trimmed_vase.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let spec = crate::spec::parse_design(&std::fs::read_to_string(path).unwrap()).unwrap();
    let d = crate::design::compile(&spec).unwrap();
    let solved = d.solved();
    let s = solved.surfaces[0].surface();
    let trim = solved.trim_of(0).unwrap();
    let (m, pm) = trimmed_mesh(s, 65, 128, &trim.curves, trim.method, "wall").unwrap();
    assert_eq!(trim.curves.len(), 3);
    let opts = ClosestOptions::default();
    for o in &pm.on_trim {
        let uv = pm.uv[o.vertex as usize];
        let c = trim.curves[o.curve].point(o.t);
        assert!((uv[0] - c[0]).abs() <= 1e-12 && (uv[1] - c[1]).abs() <= 1e-12);
        let p = m.positions[o.vertex as usize];
        let q = Vec3::new(p[0].into(), p[1].into(), p[2].into());
        let cp = closest_point(s, q, &opts).unwrap();
        let bound = 3f64.sqrt() * f64::from(f32::EPSILON) * q.amax();
        assert!(cp.distance <= bound, "{} > {bound}", cp.distance);
    }
}

/// The volume share of what remains of a trimmed design surface is given with the design's
/// outward normal, as the untrimmed patch's is, and converges at second order to the untrimmed
/// share minus the holes' shares (computed independently by quadrature over each hole).
#[test]
fn trimmed_volume_share_has_the_design_orientation_and_converges() {
    use crate::analysis::{integrate_design, integrate_trimmed_design};
    let path = format!(
        "{}/../../examples/trimmed_vase.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut spec = crate::spec::parse_design(&std::fs::read_to_string(path).unwrap()).unwrap();
    // The circle and the ellipse across the seam (holes the polar quadrature covers).
    spec.trims[0].curves.truncate(2);
    let d = crate::design::compile(&spec).unwrap();
    let solved = d.solved();
    let s = solved.surfaces[0].surface();
    let di = integrate_design(solved, &Quadrature::default()).unwrap();
    // The vase's X_u × X_v points inwards: the design turns it.
    assert_eq!(di.orientation, [-1.0]);
    let sign = di.orientation[0];
    let [mut hole_a, mut hole_v] = [0.0; 2];
    for c in &solved.trim_of(0).unwrap().curves {
        let TrimCurve::Ellipse {
            center,
            radii,
            angle,
        } = c
        else {
            panic!("not an ellipse: {c:?}");
        };
        let [a, v] = hole_integrals(s, *center, *radii, *angle);
        hole_a += a;
        hole_v += v;
    }
    let exact_area = di.patches[0].area - hole_a;
    let exact_volume = di.patches[0].volume - sign * hole_v;
    assert!(exact_volume > 0.0 && di.patches[0].volume > 0.0);
    let mut errs = Vec::new();
    for (nu, nv) in [(33, 64), (65, 128), (129, 256)] {
        let t = integrate_trimmed_design(solved, nu, nv, &di.orientation).unwrap();
        assert_eq!(t.len(), 1);
        // Same sign as the untrimmed share, smaller by about the holes' share.
        assert!(t[0].volume > 0.0, "{t:?}");
        errs.push([
            (t[0].area - exact_area).abs(),
            (t[0].volume - exact_volume).abs(),
        ]);
    }
    // Chords and flat parameter triangles err by O(h²): each halving of h divides the error by
    // about 4; ask for more than 3 (order > 1.58).
    for w in errs.windows(2) {
        for (coarse, fine) in w[0].iter().zip(&w[1]) {
            assert!(*fine < coarse / 3.0, "errors {errs:?}");
        }
    }
}

#[test]
fn trimmed_area_converges_at_second_order_to_the_area_minus_the_holes() {
    let s = tube();
    let cs: Vec<TrimCurve> = curves().into_iter().take(2).collect();
    let full = integrate_surface(&s, &Quadrature::default()).unwrap().area;
    let holes: f64 = cs
        .iter()
        .map(|c| match c {
            TrimCurve::Ellipse {
                center,
                radii,
                angle,
            } => hole_area(&s, *center, *radii, *angle),
            _ => unreachable!(),
        })
        .sum();
    let exact = full - holes;
    for method in [TrimMethod::Cdt, TrimMethod::Bilinear, TrimMethod::Laplace] {
        let mut errs = Vec::new();
        let mut quad_errs = Vec::new();
        for k in 0..4 {
            let (nu, nv) = (16 * (1 << k) + 1, 32 * (1 << k));
            let pm = trim_domain(s.parameter_domain(), nu, nv, &cs, method).unwrap();
            errs.push((mesh_area(&s, &pm) - exact).abs());
            quad_errs.push((integrate_trimmed(&s, &pm).area - exact).abs());
        }
        for e in [&errs, &quad_errs] {
            let orders: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            if method == TrimMethod::Cdt {
                assert!(
                    orders[1..].iter().all(|&o| o > 1.8),
                    "{method:?}: errors {e:?}, orders {orders:?}"
                );
            } else {
                // The book's rings change shape with the grid (rectangle snapped to grid lines,
                // layer counts rounded), so the signed chord and flat-triangle errors cancel
                // irregularly: assert the O(h²) bound instead, error·4^k never above twice
                // its largest value on the two coarsest grids.
                let scaled: Vec<f64> = e
                    .iter()
                    .enumerate()
                    .map(|(k, x)| x * 4f64.powi(k as i32))
                    .collect();
                let bound = 2.0 * scaled[0].max(scaled[1]);
                assert!(
                    scaled.iter().all(|&s| s <= bound),
                    "{method:?}: errors {e:?}, scaled {scaled:?}"
                );
            }
        }
    }
}

#[test]
fn no_inverted_triangle_and_a_watertight_mesh_for_every_method() {
    let s = tube();
    let all = curves();
    for (method, cs) in [
        (TrimMethod::Cdt, all.clone()),
        (TrimMethod::Bilinear, all[..2].to_vec()),
        (TrimMethod::Laplace, all[..2].to_vec()),
    ] {
        for (nu, nv) in [(17, 32), (65, 128)] {
            let pm = trim_domain(s.parameter_domain(), nu, nv, &cs, method).unwrap();
            let pts: Vec<[f64; 3]> = (0..pm.triangles.len())
                .flat_map(|k| pm.triangle_uv(k, true))
                .map(|p| [p[0], p[1], 0.0])
                .collect();
            let tris: Vec<[u32; 3]> = (0..pm.triangles.len() as u32)
                .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                .collect();
            let q = quality(&pts, &tris, None);
            assert_eq!(q.inverted, 0, "{method:?} {nu}×{nv}");
            assert_watertight(&pm, nv);
            let (m, _) = trimmed_mesh(&s, nu, nv, &cs, method, "t").unwrap();
            let x: Vec<[f64; 3]> = m.positions.iter().map(|p| p.map(f64::from)).collect();
            let n: Vec<[f64; 3]> = m.normals.iter().map(|p| p.map(f64::from)).collect();
            assert_eq!(quality(&x, &m.triangles, Some(&n)).inverted, 0);
        }
    }
}

#[test]
fn the_general_method_keeps_the_smallest_angle_bounded() {
    let s = tube();
    for (nu, nv) in [(17, 32), (33, 64), (65, 128), (129, 256), (257, 512)] {
        let pm = trim_domain(s.parameter_domain(), nu, nv, &curves(), TrimMethod::Cdt).unwrap();
        // In grid cells (the triangulation's own metric), over the re-meshed triangles.
        let du = 1.0 / (nu - 1) as f64;
        let dv = TAU / nv as f64;
        let mut pts = Vec::new();
        for k in pm.grid_triangles..pm.triangles.len() {
            for p in pm.triangle_uv(k, true) {
                pts.push([p[0] / du, p[1] / dv, 0.0]);
            }
        }
        let tris: Vec<[u32; 3]> = (0..(pts.len() / 3) as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        let q = quality(&pts, &tris, None);
        assert!(q.min_angle_deg > 14.0, "{nu}×{nv}: {q:?}");
        assert!(q.max_aspect < 6.0, "{nu}×{nv}: {q:?}");
    }
}

#[test]
fn a_hole_across_the_periodic_seam_is_cut_like_one_away_from_it() {
    let s = tube();
    // The same circle at v = 0 (across the seam) and at v = π on a surface symmetric under
    // v ↦ v + π (z has sin 2v): equal areas.
    let at = |v: f64| {
        let pm = trim_domain(
            s.parameter_domain(),
            65,
            128,
            &[TrimCurve::circle([0.5, v], 0.3)],
            TrimMethod::Cdt,
        )
        .unwrap();
        assert_watertight(&pm, 128);
        integrate_trimmed(&s, &pm).area
    };
    let (a, b) = (at(0.0), at(std::f64::consts::PI));
    assert!((a - b).abs() < 1e-9 * a, "{a} {b}");
    // Written below 0 or above 2π: the same hole.
    let c = at(TAU);
    assert!((a - c).abs() < 1e-9 * a);
}

#[test]
fn an_interval_domain_is_trimmed_too() {
    let s = sheet();
    let cs = [TrimCurve::Polyline(vec![
        [0.3, 0.3],
        [0.7, 0.3],
        [0.7, 0.7],
        [0.5, 0.5],
        [0.3, 0.7],
    ])];
    let pm = trim_domain(s.parameter_domain(), 41, 41, &cs, TrimMethod::Cdt).unwrap();
    // Every corner of the polygon is a vertex.
    for c in [[0.3, 0.3], [0.7, 0.3], [0.7, 0.7], [0.5, 0.5], [0.3, 0.7]] {
        assert!(pm.uv.contains(&c), "{c:?}");
    }
    // The plane z = quadratic: the flat-triangle area misses only O(h²); the polygon's area in
    // (u, v) is exact for the quadrature of a polygonal hole, so compare with the unit square's
    // area element integrated minus the hole's.
    let a = integrate_trimmed(&s, &pm).area;
    let full = integrate_surface(&s, &Quadrature::default()).unwrap().area;
    assert!(a < full && a > full - 0.2, "{a} {full}");
    let e = edge_counts(&pm);
    assert_eq!(
        e.values().filter(|&&c| c == 1).count(),
        4 * 40 + pm.on_trim.len()
    );
}

#[test]
fn bad_trims_are_refused_with_their_place() {
    let s = tube();
    let d = s.parameter_domain();
    let err = |cs: &[TrimCurve], m| trim_domain(d, 33, 64, cs, m).unwrap_err();
    let e = err(&[TrimCurve::circle([0.95, 1.0], 0.2)], TrimMethod::Cdt);
    assert_eq!(e.place(), "curves[0]");
    assert!(e.to_string().contains("inside the patch"), "{e}");
    let e = err(
        &[
            TrimCurve::circle([0.5, 1.0], 0.2),
            TrimCurve::circle([0.5, 1.2], 0.2),
        ],
        TrimMethod::Cdt,
    );
    assert!(e.to_string().contains("cross"), "{e}");
    let e = err(
        &[
            TrimCurve::circle([0.5, 1.0], 0.3),
            TrimCurve::circle([0.5, 1.0], 0.1),
        ],
        TrimMethod::Cdt,
    );
    assert!(e.to_string().contains("inside"), "{e}");
    let u_shape = TrimCurve::Polyline(vec![
        [0.3, 1.0],
        [0.7, 1.0],
        [0.7, 2.0],
        [0.6, 2.0],
        [0.6, 1.2],
        [0.4, 1.2],
        [0.4, 2.0],
        [0.3, 2.0],
    ]);
    let e = err(&[u_shape], TrimMethod::Bilinear);
    assert!(e.to_string().contains("star-shaped"), "{e}");
    assert_eq!(e.place(), "curves[0]");
    let e = err(
        &[TrimCurve::Ellipse {
            center: [0.5, 1.0],
            radii: [0.1, 3.1],
            angle: 0.0,
        }],
        TrimMethod::Cdt,
    );
    assert!(e.to_string().contains("all around"), "{e}");
    let e = err(&[TrimCurve::circle([0.5, 1.0], 0.0)], TrimMethod::Cdt);
    assert_eq!(e.place(), "curves[0].radius");
}

/// Bits of every number of a triangle mesh, for comparisons that tell −0 from +0.
fn mesh_bits(m: &TriMesh) -> (Vec<u32>, Vec<[u32; 3]>, Vec<Part>) {
    let floats = m
        .positions
        .iter()
        .chain(&m.normals)
        .flatten()
        .chain(m.uv.iter().flatten())
        .map(|x| x.to_bits())
        .collect();
    (floats, m.triangles.clone(), m.parts.clone())
}

fn param_bits(pm: &ParamMesh) -> Vec<u64> {
    pm.uv
        .iter()
        .flatten()
        .map(|x| x.to_bits())
        .chain(pm.on_trim.iter().map(|o| o.t.to_bits()))
        .collect()
}

/// The mesh built in place equals the grid's tessellation with the trim vertices evaluated
/// exactly (`to_trimesh`), and a re-mesh into the buffers of an earlier mesh (another grid,
/// other curves, another method) equals a fresh one, bit for bit.
#[test]
fn a_re_mesh_into_reused_buffers_equals_a_fresh_mesh_bit_for_bit() {
    let s = tube();
    let cs = curves();
    let mut moved = cs.clone();
    if let TrimCurve::Ellipse { center, .. } = &mut moved[0] {
        center[1] += 0.05;
    }
    let mut out = TrimmedMesh::default();
    let steps: [(usize, usize, &[TrimCurve], TrimMethod); 5] = [
        (65, 128, &cs, TrimMethod::Cdt),
        (65, 128, &moved, TrimMethod::Cdt),
        (33, 64, &cs, TrimMethod::Cdt),
        (65, 128, &cs[..2], TrimMethod::Laplace),
        (129, 256, &moved, TrimMethod::Cdt),
    ];
    for (nu, nv, c, method) in steps {
        trimmed_mesh_into(&s, nu, nv, c, method, "tube", &mut out).unwrap();
        let (fresh, pm) = trimmed_mesh(&s, nu, nv, c, method, "tube").unwrap();
        assert_eq!(
            mesh_bits(&out.mesh),
            mesh_bits(&fresh),
            "{nu}×{nv} {method:?}"
        );
        assert_eq!(out.param, pm);
        assert_eq!(param_bits(&out.param), param_bits(&pm));
        // The path through the whole grid's tessellation.
        let grid = crate::mesh::tessellate(&s, nu, nv).unwrap();
        let via_grid = to_trimesh(&s, &grid, &pm, "tube");
        assert_eq!(
            mesh_bits(&fresh),
            mesh_bits(&via_grid),
            "{nu}×{nv} {method:?}"
        );
        assert_eq!(
            pm,
            trim_domain(s.parameter_domain(), nu, nv, c, method).unwrap()
        );
    }
    // A refused trim leaves the buffers empty, and the next mesh is whole again.
    let bad = [TrimCurve::circle([0.95, 1.0], 0.2)];
    assert!(trimmed_mesh_into(&s, 65, 128, &bad, TrimMethod::Cdt, "tube", &mut out).is_err());
    assert!(out.mesh.positions.is_empty() && out.mesh.triangles.is_empty());
    assert!(out.param.uv.is_empty() && out.param.triangles.is_empty());
    trimmed_mesh_into(&s, 65, 128, &cs, TrimMethod::Cdt, "tube", &mut out).unwrap();
    let (fresh, _) = trimmed_mesh(&s, 65, 128, &cs, TrimMethod::Cdt, "tube").unwrap();
    assert_eq!(mesh_bits(&out.mesh), mesh_bits(&fresh));
}

/// The coordinate bounds of the three kinds hold against the exact first and second
/// derivatives (`jet`) on a dense sample of each piece, and a B-spline's third derivative
/// (constant on a piece of a cubic) is attained.
#[test]
fn coordinate_bounds_hold_on_every_piece() {
    let curves = [
        TrimCurve::Ellipse {
            center: [0.5, -0.2],
            radii: [0.3, 0.1],
            angle: 0.7,
        },
        TrimCurve::Polyline(vec![[0.0, 0.0], [1.0, 0.2], [0.5, 0.9]]),
        TrimCurve::BSpline {
            degree: 3,
            points: vec![[0.0, 0.0], [1.0, 0.1], [1.2, 0.8], [0.4, 1.1], [-0.1, 0.5]],
        },
    ];
    for c in &curves {
        let mut cuts = c.breaks();
        if cuts.is_empty() {
            cuts = vec![0.0, 0.25, 0.5, 0.75];
        }
        cuts.push(1.0);
        for w in cuts.windows(2) {
            let b = c.coordinate_bounds(w[0], w[1]);
            let mut seen = [[0.0f64; 3]; 2];
            for j in 1..200 {
                let t = w[0] + (w[1] - w[0]) * j as f64 / 200.0;
                let jet = c.jet(t);
                for (o, d) in jet.iter().enumerate() {
                    for k in 0..2 {
                        seen[k][o] = seen[k][o].max(d[k].abs());
                    }
                }
            }
            for k in 0..2 {
                for o in 0..3 {
                    assert!(seen[k][o] <= b[k][o] * (1.0 + 1e-12) + 1e-12, "{c:?} {w:?}");
                }
            }
        }
    }
    let bs = &curves[2];
    let b = bs.coordinate_bounds(0.05, 0.15);
    let h = 1e-3;
    let d3 = (bs.jet(0.1 + h)[2][0] - bs.jet(0.1 - h)[2][0]) / (2.0 * h);
    assert!(
        (d3.abs() - b[0][3]).abs() < 1e-6 * b[0][3],
        "{d3} {}",
        b[0][3]
    );
    assert_eq!(b[0][4], 0.0);
}
