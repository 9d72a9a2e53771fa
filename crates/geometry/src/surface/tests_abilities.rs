//! Tests of the abilities beside [`Surface`]: parameter domains, closest points and spines, on
//! every surface of the library.

use super::*;
use crate::bfs::{BfsSurface, Cylinder, Partition, Plane};
use crate::curve::{Ellipse, Point, SharedCurve};
use crate::elliptic::{solve, Condition, Operator, PdePatch, SolveOptions};
use crate::fd::{solve_four_sided, solve_periodic, FdSurface, FourSidedProblem, PeriodicProblem};
use crate::spline::{BSplineSurface, BezierSurface};
use crate::{Vec3, TAU};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

fn ellipse(centre: Vec3, a: Vec3, b: Vec3) -> SharedCurve {
    Arc::new(Ellipse::new(centre, a, b).unwrap())
}

fn circle(z: f64, r: f64) -> SharedCurve {
    ellipse(
        Vec3::new(0.0, 0.0, z),
        Vec3::new(r, 0.0, 0.0),
        Vec3::new(0.0, r, 0.0),
    )
}

fn point(p: Vec3) -> SharedCurve {
    Arc::new(Point::new(p))
}

fn cond(u: f64, derivative: usize, curve: SharedCurve) -> Condition {
    Condition {
        u,
        derivative,
        curve,
    }
}

fn biharmonic(conditions: Vec<Condition>) -> PdePatch {
    solve(
        &Operator::polyharmonic(2, 1.0).unwrap(),
        conditions,
        &SolveOptions::default(),
    )
    .unwrap()
}

/// A biharmonic surface of revolution about `z`: from the unit circle at `z = 0` to the circle
/// of radius 0.6 at `z = 1`, leaving both upwards.
fn tube() -> PdePatch {
    let up = point(Vec3::new(0.0, 0.0, 1.0));
    biharmonic(vec![
        cond(0.0, 0, circle(0.0, 1.0)),
        cond(0.0, 1, up.clone()),
        cond(1.0, 0, circle(1.0, 0.6)),
        cond(1.0, 1, up),
    ])
}

/// A dome: the unit circle at `z = 0` (leaving upwards) closed to a pole at `(0, 0, 1)` at
/// `u = 1`, where `X_u(1, v) = −(cos v, sin v, 0)` makes the cap smooth.
fn dome() -> PdePatch {
    biharmonic(vec![
        cond(0.0, 0, circle(0.0, 1.0)),
        cond(0.0, 1, point(Vec3::new(0.0, 0.0, 1.5))),
        cond(1.0, 0, point(Vec3::new(0.0, 0.0, 1.0))),
        cond(
            1.0,
            1,
            ellipse(
                Vec3::zeros(),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
            ),
        ),
    ])
}

/// A patch without symmetry: tilted, off-centre ellipses.
fn lumpy() -> PdePatch {
    biharmonic(vec![
        cond(
            0.0,
            0,
            ellipse(
                Vec3::new(0.1, 0.0, 0.0),
                Vec3::new(1.2, 0.0, 0.1),
                Vec3::new(0.0, 0.8, 0.0),
            ),
        ),
        cond(0.0, 1, point(Vec3::new(0.3, 0.0, 1.2))),
        cond(
            1.0,
            0,
            ellipse(
                Vec3::new(0.2, 0.1, 1.0),
                Vec3::new(0.5, 0.2, 0.0),
                Vec3::new(-0.1, 0.7, 0.1),
            ),
        ),
        cond(1.0, 1, point(Vec3::new(-0.2, 0.1, 1.0))),
    ])
}

/// The biharmonic FD surface of revolution through the circles of [`tube`].
fn fd_tube(nu: usize, nv: usize) -> FdSurface {
    let c0 = |v: f64| Vec3::new(v.cos(), v.sin(), 0.0);
    let c1 = |v: f64| Vec3::new(0.6 * v.cos(), 0.6 * v.sin(), 1.0);
    let up = |_: f64| Vec3::new(0.0, 0.0, 1.0);
    solve_periodic(&PeriodicProblem {
        order: 2,
        a: 1.0,
        nu,
        nv,
        start: vec![&c0, &up],
        end: vec![&c1, &up],
        source: None,
    })
    .unwrap()
}

/// A harmonic four-sided FD patch on `[0, 1] × [−0.5, 1.5]`.
fn fd_sheet() -> FdSurface {
    let u0 = |v: f64| Vec3::new(0.0, v, 0.1 * v * v);
    let u1 = |v: f64| Vec3::new(1.0, v, 0.3 + 0.1 * v);
    let v0 = |u: f64| Vec3::new(u, -0.5, 0.025 + 0.225 * u);
    let v1 = |u: f64| Vec3::new(u, 1.5, 0.225 + 0.225 * u);
    solve_four_sided(&FourSidedProblem {
        order: 1,
        a: 1.0,
        nu: 8,
        nv: 10,
        v_range: (-0.5, 1.5),
        u0: vec![&u0],
        u1: vec![&u1],
        v0: vec![&v0],
        v1: vec![&v1],
        source: None,
    })
    .unwrap()
}

fn bspline() -> BSplineSurface {
    let control = (0..4)
        .flat_map(|i| (0..3).map(move |j| Vec3::new(i as f64, j as f64, ((i + j) % 3) as f64)))
        .collect();
    BSplineSurface::new(
        [2, 1],
        vec![1.0, 1.0, 1.0, 2.0, 3.0, 3.0, 3.0],
        vec![-1.0, -1.0, 0.5, 2.0, 2.0],
        control,
    )
    .unwrap()
}

fn bezier() -> BezierSurface {
    let control = (0..3)
        .flat_map(|i| {
            (0..4).map(move |j| Vec3::new(i as f64, j as f64, (i as f64 - 1.0) * (j as f64 - 1.5)))
        })
        .collect();
    BezierSurface::new([2, 3], control).unwrap()
}

fn spline_net() -> crate::splinepde::SplineNet<f64> {
    use crate::splinepde::{clamped_uniform, Operator as SplineOperator, SplineProblem};
    let dir = clamped_uniform::<f64>(3, 1);
    let fixed = (0..4)
        .flat_map(|j| {
            [
                ([0, j], [0.0, j as f64, 0.0]),
                ([3, j], [3.0, j as f64, 1.0]),
            ]
        })
        .collect();
    crate::splinepde::solve(&SplineProblem {
        u: dir.clone(),
        v: dir,
        operator: SplineOperator::laplace(),
        fixed,
    })
    .unwrap()
}

fn bfs(periodic: bool) -> BfsSurface {
    let partition = Partition::uniform(3, 2, periodic).unwrap();
    let coef = (0..partition.dofs())
        .map(|k| Vec3::new(k as f64 * 0.1, (k % 4) as f64, (k % 7) as f64 * 0.2))
        .collect();
    BfsSurface::new(partition, coef)
}

/// The sphere of radius 2 about `(1, 0, 0)` in latitude `u ∈ [−π/2, π/2]` and longitude `v`.
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

/// The unit cylinder `(cos v, sin v, u)`, `u ∈ [0, 1]`.
fn unit_cylinder() -> ParametricSurface {
    ParametricSurface::new("cos(v)", "sin(v)", "u", VDomain::Periodic).unwrap()
}

fn assert_finite_at_corners(s: &dyn Surface, what: &str) {
    for (u, v) in s.parameter_domain().corners() {
        let p = s.partials(u, v);
        for x in [p.x, p.xu, p.xv, p.xuu, p.xuv, p.xvv] {
            assert!(
                x.iter().all(|c| c.is_finite()),
                "{what}: {p:?} at ({u}, {v})"
            );
        }
    }
}

#[test]
fn every_surface_reports_its_parameter_domain() {
    let unit = Interval::UNIT;
    let check = |s: &dyn Surface, what: &str, u: Interval, u_periodic: bool, v: VDomain| {
        assert_eq!(
            s.parameter_domain(),
            ParameterDomain { u, u_periodic, v },
            "{what}"
        );
        assert_eq!(
            (s.u_range(), s.u_periodic(), s.v_domain()),
            (u, u_periodic, v)
        );
        assert_finite_at_corners(s, what);
    };
    check(&tube(), "PDE patch", unit, false, VDomain::Periodic);
    check(
        &fd_tube(8, 16),
        "FD periodic",
        unit,
        false,
        VDomain::Periodic,
    );
    check(
        &fd_sheet(),
        "FD four-sided",
        unit,
        false,
        VDomain::Interval(-0.5, 1.5),
    );
    check(
        &bfs(true),
        "BFS tube",
        unit,
        true,
        VDomain::Interval(0.0, 1.0),
    );
    check(
        &bfs(false),
        "BFS sheet",
        unit,
        false,
        VDomain::Interval(0.0, 1.0),
    );
    let cyl = Cylinder::new(Vec3::zeros(), Vec3::new(0.0, 0.0, 2.0), 1.5).unwrap();
    check(&cyl, "cylinder", unit, true, VDomain::Interval(0.0, 1.0));
    let plane = Plane::new(Vec3::zeros(), Vec3::x(), Vec3::y()).unwrap();
    check(&plane, "plane", unit, false, VDomain::Interval(0.0, 1.0));
    check(
        &bezier(),
        "Bézier",
        unit,
        false,
        VDomain::Interval(0.0, 1.0),
    );
    check(
        &spline_net(),
        "spline net",
        unit,
        false,
        VDomain::Interval(0.0, 1.0),
    );
    check(&unit_cylinder(), "formula", unit, false, VDomain::Periodic);
    check(
        &sphere(),
        "formula on a u range",
        Interval::new(-FRAC_PI_2, FRAC_PI_2),
        false,
        VDomain::Periodic,
    );
    // The B-spline surface maps u ∈ [0, 1] onto its knot domain [1, 3] (and keeps v in knot
    // parameters): its u range is the unit interval it is evaluated on.
    let b = bspline();
    check(&b, "B-spline", unit, false, VDomain::Interval(-1.0, 2.0));
    for v in [-1.0, 0.3, 2.0] {
        assert_eq!(b.partials(0.0, v).x, b.derivative(1.0, v, 0, 0));
        assert_eq!(b.partials(1.0, v).x, b.derivative(3.0, v, 0, 0));
    }
    // A formula surface's u range is checked like its v interval.
    let bad = ParametricSurface::with_u_range(
        "u",
        "v",
        "0",
        Interval::new(2.0, 2.0),
        VDomain::Interval(0.0, 1.0),
    );
    assert_eq!(
        bad.unwrap_err().to_string(),
        "u_range: the u range [2, 2] must be finite with start < end"
    );
    // … and its formulas are checked over it.
    let e = ParametricSurface::with_u_range(
        "1/u",
        "v",
        "0",
        Interval::new(-1.0, 1.0),
        VDomain::Interval(0.0, 1.0),
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with("x: evaluates to inf at u = 0"),
        "{e}"
    );
}

/// Wrapped difference of two angles.
fn angle_gap(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

#[test]
fn points_on_a_pde_patch_are_found_exactly() {
    let opts = ClosestOptions::default();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for (patch, what) in [(tube(), "tube"), (lumpy(), "lumpy")] {
        let index = ClosestPointIndex::new(&patch, &opts);
        for _ in 0..200 {
            let (u, v) = (rng.gen_range(0.0..=1.0), rng.gen_range(0.0..TAU));
            let p = patch.point(u, v);
            let c = index.closest(p).unwrap();
            assert!(c.converged, "{what} {u} {v}: {c:?}");
            assert!(c.distance <= 1e-12 * 2.0, "{what} {u} {v}: {c:?}");
            assert!((c.u - u).abs() < 1e-9, "{what} {u} {v}: {c:?}");
            assert!(angle_gap(c.v, v) < 1e-9, "{what} {u} {v}: {c:?}");
            assert!((0.0..TAU).contains(&c.v) && (0.0..=1.0).contains(&c.u));
        }
    }
}

#[test]
fn points_off_the_surface_along_the_normal_find_their_foot() {
    let opts = ClosestOptions::default();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let surfaces: Vec<(Box<dyn Surface>, &str, f64)> = vec![
        (Box::new(tube()), "tube", 0.1),
        (Box::new(lumpy()), "lumpy", 0.05),
        (Box::new(fd_tube(16, 32)), "FD tube", 0.1),
        (Box::new(sphere()), "sphere", 0.5),
    ];
    for (s, what, reach) in &surfaces {
        let index = ClosestPointIndex::new(&**s, &opts);
        for _ in 0..100 {
            let (u, v) = (rng.gen_range(0.05..0.95), rng.gen_range(0.0..TAU));
            let u = s.u_range().lerp(u);
            let d = rng.gen_range(-*reach..*reach);
            let q = s.partials(u, v);
            let p = q.x + q.normal() * d;
            let c = index.closest(p).unwrap();
            assert!(c.converged, "{what}: {c:?}");
            assert!(
                (c.distance - d.abs()).abs() < 1e-10,
                "{what} d = {d}: {c:?}"
            );
            assert!((c.point - q.x).norm() < 1e-9, "{what} d = {d}: {c:?}");
            assert!(
                (c.u - u).abs() < 1e-8 && angle_gap(c.v, v) < 1e-8,
                "{what}: {c:?}"
            );
        }
    }
}

#[test]
fn a_sphere_has_its_closed_form_answer_inside_and_out() {
    let s = sphere();
    let centre = Vec3::new(1.0, 0.0, 0.0);
    let index = ClosestPointIndex::new(&s, &ClosestOptions::default());
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..200 {
        let dir = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if dir.norm() < 0.1 {
            continue;
        }
        let p = centre + dir.normalize() * rng.gen_range(0.05..8.0);
        let want = centre + (p - centre).normalize() * 2.0;
        let c = index.closest(p).unwrap();
        assert!(c.converged, "{p:?}: {c:?}");
        assert!(
            (c.distance - ((p - centre).norm() - 2.0).abs()).abs() < 1e-12,
            "{p:?}: {c:?}"
        );
        assert!((c.point - want).norm() < 1e-9, "{p:?}: {c:?}");
    }
    // The centre is at distance 2 from every point: any answer, but the right distance.
    let c = closest_point(&s, centre, &ClosestOptions::default()).unwrap();
    assert!((c.distance - 2.0).abs() < 1e-12, "{c:?}");
}

#[test]
fn poles_are_found_and_left() {
    let s = sphere();
    let index = ClosestPointIndex::new(&s, &ClosestOptions::default());
    // On the axis above the north pole: the pole itself, at the end of the u range.
    let c = index.closest(Vec3::new(1.0, 0.0, 5.0)).unwrap();
    assert!(c.converged && (c.distance - 3.0).abs() < 1e-12, "{c:?}");
    assert_eq!(c.u, FRAC_PI_2);
    // Just off the axis: the radial projection, a hair away from the pole.
    for (dx, dy) in [(1e-3, 0.0), (-2e-4, 3e-4), (0.0, -1e-6)] {
        let p = Vec3::new(1.0 + dx, dy, -3.0);
        let want = Vec3::new(1.0, 0.0, 0.0) + (p - Vec3::new(1.0, 0.0, 0.0)).normalize() * 2.0;
        let c = index.closest(p).unwrap();
        assert!(c.converged, "{p:?}: {c:?}");
        assert!((c.point - want).norm() < 1e-10, "{p:?}: {c:?}");
    }
    // The dome closes at u = 1 to the pole (0, 0, 1).
    let d = dome();
    let apex = d.point(1.0, 0.3);
    assert!((apex - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    let index = ClosestPointIndex::new(&d, &ClosestOptions::default());
    let c = index.closest(Vec3::new(0.0, 0.0, 1.5)).unwrap();
    assert!(c.converged && (c.distance - 0.5).abs() < 1e-12, "{c:?}");
    assert_eq!(c.u, 1.0);
    // Beside the apex the answer is a true foot point (r ⟂ the surface) no farther than a fine
    // grid's best.
    for p in [
        Vec3::new(0.02, 0.01, 1.3),
        Vec3::new(-0.2, 0.1, 1.1),
        Vec3::new(0.0, -0.05, 0.9),
    ] {
        let c = index.closest(p).unwrap();
        assert!(c.converged, "{p:?}: {c:?}");
        let q = d.partials(c.u, c.v);
        let r = (p - q.x).normalize();
        assert!(r.dot(&q.normal()).abs() > 1.0 - 1e-10, "{p:?}: {c:?}");
        let brute = brute_force(&d, p, 400, 200);
        assert!(c.distance <= brute + 1e-12, "{p:?}: {c:?} vs {brute}");
    }
}

/// The smallest distance from `p` to the samples of an `nu × nv` grid (both ends in u).
fn brute_force(s: &dyn Surface, p: Vec3, nu: usize, nv: usize) -> f64 {
    let d = s.parameter_domain();
    let (ui, vi) = (d.u, d.v_interval());
    let mut best = f64::INFINITY;
    for i in 0..=nu {
        for j in 0..=nv {
            let x = s.point(ui.lerp(i as f64 / nu as f64), vi.lerp(j as f64 / nv as f64));
            best = best.min((x - p).norm());
        }
    }
    best
}

#[test]
fn boundary_minima_hold_the_parameter_at_its_end() {
    let s = unit_cylinder();
    let index = ClosestPointIndex::new(&s, &ClosestOptions::default());
    let c = index.closest(Vec3::new(2.0, 0.0, -1.0)).unwrap();
    assert!(c.converged, "{c:?}");
    assert_eq!(c.u, 0.0);
    assert!(angle_gap(c.v, 0.0) < 1e-12 && (c.distance - 2f64.sqrt()).abs() < 1e-12);
    let c = index.closest(Vec3::new(0.0, -3.0, 2.5)).unwrap();
    assert!(c.converged, "{c:?}");
    assert_eq!(c.u, 1.0);
    assert!(angle_gap(c.v, 1.5 * PI) < 1e-12 && (c.distance - 2.5).abs() < 1e-12);
    // A corner of a patch bounded in both parameters.
    let b = bezier();
    let corner = b.point(1.0, 0.0);
    let away = b.partials(1.0, 0.0);
    let p = corner + away.xu.normalize() * 0.3 - away.xv.normalize() * 0.2;
    let c = closest_point(&b, p, &ClosestOptions::default()).unwrap();
    assert!(c.converged, "{c:?}");
    assert!(c.distance <= brute_force(&b, p, 300, 300) + 1e-12, "{c:?}");
}

#[test]
fn the_general_search_agrees_with_closed_forms() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let opts = ClosestOptions::default();
    let cyl = Cylinder::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::new(2.0, 0.3, -0.4), 0.8).unwrap();
    let plane = Plane::new(
        Vec3::new(0.2, -0.1, 0.3),
        Vec3::new(1.0, 0.2, 0.0),
        Vec3::new(0.4, 1.0, 0.5),
    )
    .unwrap();
    let shapes: [(&dyn SurfaceNearest, &str); 2] = [(&cyl, "cylinder"), (&plane, "plane")];
    for (s, what) in shapes {
        let index = ClosestPointIndex::new(s, &opts);
        for _ in 0..300 {
            let p = Vec3::new(
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
            );
            let exact = s.nearest(p, &opts).unwrap();
            let found = index.closest(p).unwrap();
            assert!(found.converged, "{what} {p:?}: {found:?}");
            assert!(
                (found.distance - exact.distance).abs() < 1e-10,
                "{what} {p:?}: {found:?} vs {exact:?}"
            );
            assert!((s.point(exact.u, exact.v) - exact.point).norm() < 1e-12);
            assert!((exact.point - p).norm() == exact.distance);
        }
    }
    // On the cylinder's axis every angle is as close.
    let on_axis = Vec3::new(-1.0, 0.5, 0.0) + Vec3::new(2.0, 0.3, -0.4) * 0.4;
    let c = closest_point(&cyl, on_axis, &opts).unwrap();
    assert!((c.distance - 0.8).abs() < 1e-12, "{c:?}");
    assert_eq!(cyl.nearest(on_axis, &opts).unwrap().u, 0.0);
    assert!(cyl.nearest(Vec3::new(f64::NAN, 0.0, 0.0), &opts).is_none());
    assert!(plane
        .nearest(Vec3::new(0.0, f64::INFINITY, 0.0), &opts)
        .is_none());
}

#[test]
fn every_surface_answers_through_the_trait() {
    let opts = ClosestOptions::default();
    let surfaces: Vec<(Box<dyn SurfaceNearest>, &str)> = vec![
        (Box::new(tube()), "PDE patch"),
        (Box::new(fd_tube(8, 16)), "FD periodic"),
        (Box::new(fd_sheet()), "FD four-sided"),
        (Box::new(bfs(true)), "BFS tube"),
        (Box::new(bfs(false)), "BFS sheet"),
        (Box::new(bspline()), "B-spline"),
        (Box::new(bezier()), "Bézier"),
        (Box::new(spline_net()), "spline net"),
        (Box::new(sphere()), "formula"),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for (s, what) in &surfaces {
        let dom = s.parameter_domain();
        for _ in 0..20 {
            let u = dom.u.lerp(rng.gen_range(0.0..=1.0));
            let v = dom.v_interval().lerp(rng.gen_range(0.0..=1.0));
            let q = s.partials(u, v);
            let p = q.x + q.normal() * 0.01;
            let c = s.nearest(p, &opts).unwrap();
            assert!(c.converged, "{what}: {c:?}");
            assert!(c.distance <= 0.01 + 1e-12, "{what} at ({u}, {v}): {c:?}");
            assert!(dom.contains(c.u, c.v), "{what}: {c:?}");
            assert_eq!(s.point(c.u, c.v), c.point);
        }
        assert!(s.nearest(Vec3::new(f64::NAN, 0.0, 0.0), &opts).is_none());
    }
}

#[test]
fn ties_bad_input_and_bad_surfaces_do_not_panic() {
    let opts = ClosestOptions::default();
    let s = unit_cylinder();
    // Every point of the circle u = 0.5 is as close to the axis point.
    let c = closest_point(&s, Vec3::new(0.0, 0.0, 0.5), &opts).unwrap();
    assert!(
        (c.distance - 1.0).abs() < 1e-12 && (c.u - 0.5).abs() < 1e-12,
        "{c:?}"
    );
    for p in [
        Vec3::new(f64::NAN, 0.0, 0.0),
        Vec3::new(0.0, f64::INFINITY, 0.0),
        Vec3::new(0.0, 0.0, f64::NEG_INFINITY),
    ] {
        assert!(closest_point(&s, p, &opts).is_none());
        assert!(ClosestPointIndex::new(&s, &opts)
            .refine(p, 0.5, 0.0)
            .is_none());
    }
    // Very far away: still the right answer.
    let c = closest_point(&s, Vec3::new(1e9, 0.0, 0.5), &opts).unwrap();
    assert!(
        (c.distance - (1e9 - 1.0)).abs() < 1e-6 && angle_gap(c.v, 0.0) < 1e-9,
        "{c:?}"
    );
    // Zero samples or iterations are raised to the least that works; no iterations is honest.
    let few = ClosestOptions {
        samples_u: 0,
        samples_v: 0,
        max_starts: 0,
        max_iterations: 0,
        tolerance: 1e-12,
    };
    let c = closest_point(&s, Vec3::new(2.0, 0.3, 0.3), &few).unwrap();
    assert!(!c.converged, "{c:?}");
    /// The plane z = 0 on [0, 1]², not finite for u > 0.6.
    struct HalfBroken;
    impl Surface for HalfBroken {
        fn v_domain(&self) -> VDomain {
            VDomain::Interval(0.0, 1.0)
        }
        fn partials(&self, u: f64, v: f64) -> Partials {
            if u > 0.6 {
                return Partials {
                    x: Vec3::repeat(f64::NAN),
                    ..Default::default()
                };
            }
            Partials {
                x: Vec3::new(u, v, 0.0),
                xu: Vec3::x(),
                xv: Vec3::y(),
                ..Default::default()
            }
        }
    }
    let c = closest_point(&HalfBroken, Vec3::new(0.2, 0.3, 1.0), &opts).unwrap();
    assert!(c.converged && (c.distance - 1.0).abs() < 1e-12, "{c:?}");
    let c = closest_point(&HalfBroken, Vec3::new(0.9, 0.3, 0.0), &opts).unwrap();
    assert!(c.distance.is_finite() && c.u <= 0.6, "{c:?}");
    /// A surface with an empty u range has no samples.
    struct Empty;
    impl Surface for Empty {
        fn v_domain(&self) -> VDomain {
            VDomain::Periodic
        }
        fn u_range(&self) -> Interval {
            Interval::new(1.0, 0.0)
        }
        fn partials(&self, _: f64, _: f64) -> Partials {
            Partials::default()
        }
    }
    assert!(closest_point(&Empty, Vec3::zeros(), &opts).is_none());
}

#[test]
fn refine_tracks_a_moving_point() {
    let patch = lumpy();
    let index = ClosestPointIndex::new(&patch, &ClosestOptions::default());
    let (mut u, mut v) = (0.4, 1.0);
    for k in 0..20 {
        let t = k as f64 * 0.01;
        let q = patch.partials(0.4 + t, 1.0 + 2.0 * t);
        let p = q.x + q.normal() * 0.02;
        let c = index.refine(p, u, v).unwrap();
        assert!(
            c.converged && (c.distance - 0.02).abs() < 1e-10,
            "{k}: {c:?}"
        );
        (u, v) = (c.u, c.v);
    }
    fn is_send_sync<T: Send + Sync>(_: &T) {}
    is_send_sync(&index);
}

#[test]
fn the_pde_spine_through_the_trait_is_the_inherent_spine() {
    let patch = lumpy();
    let spine = (&patch as &dyn Surface)
        .as_spine()
        .expect("a PDE patch has a spine");
    for u in [0.0, 0.13, 0.5, 0.97, 1.0] {
        for order in 0..4 {
            assert_eq!(spine.spine(u, order), patch.spine(u, order));
        }
    }
    // The spine is the mean of X over v (here without a remainder: exactly, up to rounding).
    let n = 64;
    for u in [0.2, 0.7] {
        let mean = (0..n)
            .map(|j| patch.point(u, TAU * j as f64 / n as f64))
            .sum::<Vec3>()
            / n as f64;
        assert!((mean - spine.spine(u, 0)).norm() < 1e-14, "{u}");
    }
}

#[test]
fn spines_of_surfaces_of_revolution_lie_on_the_axis() {
    let pde = tube();
    let fd = fd_tube(16, 32);
    for (s, what) in [(&pde as &dyn Surface, "PDE"), (&fd, "FD")] {
        let spine = s.as_spine().unwrap();
        for k in 0..=10 {
            let u = k as f64 / 10.0;
            let a = spine.spine(u, 0);
            assert!(a.x.abs() < 1e-13 && a.y.abs() < 1e-13, "{what} {u}: {a}");
            let d = spine.spine(u, 1);
            assert!(d.x.abs() < 1e-12 && d.y.abs() < 1e-12, "{what} {u}: {d}");
        }
        // Ends: the centres of the two circles.
        assert!(
            (spine.spine(0.0, 0) - Vec3::zeros()).norm() < 1e-12,
            "{what}"
        );
        assert!((spine.spine(1.0, 0) - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    }
    // The dome's spine ends at its pole.
    let dome = dome();
    let top = dome.as_spine().unwrap().spine(1.0, 0);
    assert!((top - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
}

/// The mean over `v` of `∂ᵈX/∂uᵈ` by two-point Gauss on each of `cells` equal cells of the `v`
/// interval (exact for the FD surface's piecewise cubics when the cells are its own).
fn mean_over_v(s: &dyn Surface, u: f64, d: usize, cells: usize) -> Vec3 {
    let vi = s.v_domain().interval();
    let h = vi.length() / cells as f64;
    let g = 0.5 / 3f64.sqrt();
    let mut acc = Vec3::zeros();
    for k in 0..cells {
        for t in [0.5 - g, 0.5 + g] {
            let p = s.partials(u, vi.start + h * (k as f64 + t));
            acc += [p.x, p.xu, p.xuu][d];
        }
    }
    acc / (2 * cells) as f64
}

#[test]
fn the_fd_spine_is_the_exact_mean_over_v() {
    let (fd, sheet) = (
        {
            let c0 = |v: f64| Vec3::new(v.cos() + 0.2 * (2.0 * v).sin(), v.sin(), 0.1 * v.cos());
            let c1 = |v: f64| Vec3::new(0.5 * v.cos(), 0.7 * v.sin(), 1.0);
            let d0 = |v: f64| Vec3::new(0.1 * v.sin(), 0.0, 1.0);
            let d1 = |_: f64| Vec3::new(0.3, 0.0, 1.0);
            solve_periodic(&PeriodicProblem {
                order: 2,
                a: 1.0,
                nu: 12,
                nv: 20,
                start: vec![&c0, &d0],
                end: vec![&c1, &d1],
                source: None,
            })
            .unwrap()
        },
        fd_sheet(),
    );
    assert!(sheet.as_spine().is_none());
    for (s, cells) in [(&fd, fd.nodes_v()), (&sheet, sheet.nodes_v() - 1)] {
        for u in [0.0, 0.04, 0.37, 0.5, 0.91, 1.0] {
            for d in 0..3 {
                let want = mean_over_v(s, u, d, cells);
                let got = Spine::spine(s, u, d);
                assert!(
                    (got - want).norm() < 1e-12 * want.norm().max(1.0),
                    "u = {u}, d = {d}: {got} vs {want}"
                );
            }
        }
        // The third derivative: the second's slope, constant on the node interval
        // [5/12, 1/2] (resp. [3/8, 1/2]).
        let (a, b) = (Spine::spine(s, 0.42, 2), Spine::spine(s, 0.49, 2));
        let third = Spine::spine(s, 0.45, 3);
        assert!((third - (b - a) / 0.07).norm() < 1e-9 * third.norm().max(1.0));
        assert_eq!(Spine::spine(s, 0.45, 4), Vec3::zeros());
    }
}

#[test]
fn surfaces_without_a_spine_say_so() {
    assert!(bezier().as_spine().is_none());
    assert!(bspline().as_spine().is_none());
    assert!(bfs(true).as_spine().is_none());
    assert!(sphere().as_spine().is_none());
}
