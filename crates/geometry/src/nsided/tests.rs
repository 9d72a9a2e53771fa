//! Tests of n-sided patches against independent truth: planes, closed-form harmonic and
//! biharmonic functions, the sphere under refinement, exact boundaries and ribbons.

use super::*;
use crate::curve::{Curve, Domain};

/// The segment from `a` to `b` on `[0, 1]`.
#[derive(Debug)]
struct Line(Vec3, Vec3);

impl Curve for Line {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = match k {
                0 => self.0 + (self.1 - self.0) * t,
                1 => self.1 - self.0,
                _ => Vec3::zeros(),
            };
        }
    }
}

/// The great-circle arc of the sphere `|X − c| = r` from direction `a` to direction `b`.
#[derive(Debug)]
pub(super) struct GreatArc {
    c: Vec3,
    r: f64,
    a: Vec3,
    e: Vec3,
    omega: f64,
}

impl GreatArc {
    pub(super) fn new(c: Vec3, r: f64, a: Vec3, b: Vec3) -> GreatArc {
        let (a, b) = (a.normalize(), b.normalize());
        let e = (b - a * a.dot(&b)).normalize();
        GreatArc {
            c,
            r,
            a,
            e,
            omega: a.dot(&b).clamp(-1.0, 1.0).acos(),
        }
    }
}

impl Curve for GreatArc {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    /// `|C − c| = r`, `|C⁽ᵏ⁾| = r ωᵏ`.
    fn derivative_bounds(&self, _t0: f64, _t1: f64, out: &mut [f64]) -> bool {
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.r * self.omega.powi(k as i32) * (1.0 + 1e-15);
            if k == 0 {
                *o += self.c.norm();
            }
        }
        true
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        for (k, o) in out.iter_mut().enumerate() {
            let ph = t * self.omega + k as f64 * std::f64::consts::FRAC_PI_2;
            let w = self.omega.powi(k as i32) * self.r;
            *o = (self.a * ph.cos() + self.e * ph.sin()) * w;
            if k == 0 {
                *o += self.c;
            }
        }
    }
}

/// A function of `(u, v)` on the unit square with its partials to third order:
/// `f, f_u, f_v, f_uu, f_uv, f_vv, f_uuu, f_uuv, f_uvv, f_vvv`.
type Field = fn(f64, f64) -> [f64; 10];

/// The curve `(u, v, f(u, v))` along one side of the unit square, in loop order
/// (side 0: v = 0, side 1: u = 1, side 2: v = 1 backwards, side 3: u = 0 backwards), or its
/// cross derivative `∂/∂t` into the square (t in side lengths).
#[derive(Debug)]
struct SquareSide {
    side: usize,
    f: Field,
    cross: bool,
}

impl SquareSide {
    /// `(u, v)`, `d(u, v)/ds`, `d(u, v)/dt` of the side.
    fn frame(&self, s: f64) -> ([f64; 2], [f64; 2], [f64; 2]) {
        match self.side {
            0 => ([s, 0.0], [1.0, 0.0], [0.0, 1.0]),
            1 => ([1.0, s], [0.0, 1.0], [-1.0, 0.0]),
            2 => ([1.0 - s, 1.0], [-1.0, 0.0], [0.0, -1.0]),
            _ => ([0.0, 1.0 - s], [0.0, -1.0], [1.0, 0.0]),
        }
    }
}

impl Curve for SquareSide {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, s: f64, out: &mut [Vec3]) {
        let ([u, v], ds, dt) = self.frame(s);
        let [f, fu, fv, fuu, fuv, fvv, fuuu, fuuv, fuvv, fvvv] = (self.f)(u, v);
        let grad = |d: [f64; 2]| fu * d[0] + fv * d[1];
        let hess = |a: [f64; 2], b: [f64; 2]| {
            fuu * a[0] * b[0] + fuv * (a[0] * b[1] + a[1] * b[0]) + fvv * a[1] * b[1]
        };
        // The third derivative tensor, contracted with a, a, b.
        let third = |a: [f64; 2], b: [f64; 2]| {
            fuuu * a[0] * a[0] * b[0]
                + fuuv * (a[0] * a[0] * b[1] + 2.0 * a[0] * a[1] * b[0])
                + fuvv * (a[1] * a[1] * b[0] + 2.0 * a[0] * a[1] * b[1])
                + fvvv * a[1] * a[1] * b[1]
        };
        for (k, o) in out.iter_mut().enumerate() {
            *o = match (self.cross, k) {
                (false, 0) => Vec3::new(u, v, f),
                (false, 1) => Vec3::new(ds[0], ds[1], grad(ds)),
                (false, 2) => Vec3::new(0.0, 0.0, hess(ds, ds)),
                (true, 0) => Vec3::new(dt[0], dt[1], grad(dt)),
                (false, 3) => Vec3::new(0.0, 0.0, third(ds, ds)),
                (true, 1) => Vec3::new(0.0, 0.0, hess(ds, dt)),
                (true, 2) => Vec3::new(0.0, 0.0, third(ds, dt)),
                // Higher derivatives are not used by the patch.
                _ => Vec3::zeros(),
            };
        }
    }
}

fn square_sides(f: Field, ribbons: bool) -> Vec<Side> {
    (0..4)
        .map(|side| {
            let curve: crate::curve::SharedCurve = Arc::new(SquareSide {
                side,
                f,
                cross: false,
            });
            let ribbon = if ribbons {
                Ribbon::Derivative {
                    curve: Arc::new(SquareSide {
                        side,
                        f,
                        cross: true,
                    }),
                    t0: 0.0,
                    t1: 1.0,
                }
            } else {
                Ribbon::Position
            };
            Side {
                curve,
                t0: 0.0,
                t1: 1.0,
                ribbon,
            }
        })
        .collect()
}

/// The largest `|X(u, v) − (u, v, f(u, v))|` over a 21 × 21 grid of the square patch.
fn square_error(patch: &Arc<NSidedPatch>, f: Field) -> f64 {
    let s = &patch.surfaces()[0];
    let mut worst: f64 = 0.0;
    for i in 0..=20 {
        for j in 0..=20 {
            let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
            let x = s.partials(u, v).x;
            worst = worst.max((x - Vec3::new(u, v, f(u, v)[0])).norm());
        }
    }
    worst
}

/// The square patch of `biharmonic`'s data (order 2 and its ribbons, or positions only) or
/// `harmonic`'s (order 1, positions), degree 8.
pub(super) fn square_patch(order: usize, ribbons: bool) -> Arc<NSidedPatch> {
    let f: Field = if order == 1 { harmonic } else { biharmonic };
    let opts = NSidedOptions {
        order,
        degree: 8,
        ..Default::default()
    };
    Arc::new(NSidedPatch::solve(square_sides(f, ribbons), &opts).unwrap())
}

/// `e^u sin v`, harmonic.
fn harmonic(u: f64, v: f64) -> [f64; 10] {
    let (e, (s, c)) = (u.exp(), v.sin_cos());
    [
        e * s,
        e * s,
        e * c,
        e * s,
        e * c,
        -e * s,
        e * s,
        e * c,
        -e * s,
        -e * c,
    ]
}

/// `u e^u cos v`, biharmonic (`u` times a harmonic function).
fn biharmonic(u: f64, v: f64) -> [f64; 10] {
    let (e, (s, c)) = (u.exp(), v.sin_cos());
    [
        u * e * c,
        (1.0 + u) * e * c,
        -u * e * s,
        (2.0 + u) * e * c,
        -(1.0 + u) * e * s,
        -u * e * c,
        (3.0 + u) * e * c,
        -(2.0 + u) * e * s,
        -(1.0 + u) * e * c,
        u * e * s,
    ]
}

#[test]
fn a_harmonic_function_is_reproduced_by_order_one() {
    // The Ritz error at degree p is the best approximation of the remainder f − C by w·P_p.
    // The side-blended interpolant C is C² at the corners (the ribbons are matched to second
    // order there) but its third derivatives jump, so f − C is about H⁴ near a corner and the
    // error falls algebraically, like p^−4 in the maximum norm. Require at least p^−3 between
    // degrees 8 and 18, and the value it reaches.
    let mut errors = Vec::new();
    for degree in [4, 8, 12, 18] {
        let opts = NSidedOptions {
            order: 1,
            degree,
            ..Default::default()
        };
        let patch = Arc::new(NSidedPatch::solve(square_sides(harmonic, false), &opts).unwrap());
        errors.push(square_error(&patch, harmonic));
    }
    eprintln!("harmonic, degree 4, 8, 12, 18: {errors:?}");
    assert!(
        errors[3] < errors[1] * (8.0f64 / 18.0).powi(3),
        "{errors:?}"
    );
    assert!(errors[3] < 5e-5, "{errors:?}");
}

#[test]
fn a_biharmonic_function_is_reproduced_from_its_positions_and_ribbons() {
    let mut errors = Vec::new();
    for degree in [4, 8, 12, 18] {
        let opts = NSidedOptions {
            degree,
            ..Default::default()
        };
        let patch = Arc::new(NSidedPatch::solve(square_sides(biharmonic, true), &opts).unwrap());
        errors.push(square_error(&patch, biharmonic));
        let report = patch.report(50);
        for b in &report.boundary {
            assert!(*b <= 1e-14 * report.size, "{report:?}");
        }
        for g in &report.g1 {
            assert!(g.unwrap() <= 1e-13, "{report:?}");
        }
    }
    // As for the harmonic case: algebraic convergence, at least p^−3.
    eprintln!("biharmonic, degree 4, 8, 12, 18: {errors:?}");
    assert!(
        errors[3] < errors[1] * (8.0f64 / 18.0).powi(3),
        "{errors:?}"
    );
    assert!(errors[3] < 2e-5, "{errors:?}");
}

/// A non-regular convex pentagon in the plane through `o` spanned by `e1`, `e2`.
fn planar_pentagon() -> (Vec<Vec3>, Vec3) {
    let o = Vec3::new(1.0, -2.0, 0.5);
    let e1 = Vec3::new(1.0, 0.2, 0.3).normalize();
    let e2 = e1.cross(&Vec3::new(0.1, 0.3, 1.0)).normalize();
    let uv = [(0.0, 0.0), (3.0, -0.5), (4.0, 1.5), (2.0, 3.5), (-0.5, 2.0)];
    let pts = uv.iter().map(|(a, b)| o + e1 * *a + e2 * *b).collect();
    (pts, e1.cross(&e2))
}

#[test]
fn a_planar_loop_gives_the_plane() {
    let (pts, normal) = planar_pentagon();
    for g1 in [false, true] {
        let sides: Vec<Side> = (0..5)
            .map(|i| {
                let curve: crate::curve::SharedCurve = Arc::new(Line(pts[i], pts[(i + 1) % 5]));
                let ribbon = if g1 {
                    let n = normal;
                    Ribbon::TangentPlane(Arc::new(move |_| n))
                } else {
                    Ribbon::Position
                };
                Side {
                    curve,
                    t0: 0.0,
                    t1: 1.0,
                    ribbon,
                }
            })
            .collect();
        let patch = Arc::new(NSidedPatch::solve(sides, &NSidedOptions::default()).unwrap());
        let size = patch.size();
        let mut worst: f64 = 0.0;
        for s in patch.surfaces() {
            for i in 0..=10 {
                for j in 0..=10 {
                    let p = s.partials(i as f64 / 10.0, j as f64 / 10.0);
                    worst = worst.max((p.x - pts[0]).dot(&normal).abs());
                    if (i == 0 || i == 10) && (j == 0 || j == 10) {
                        // A polygon corner: the normal there is a one-sided limit.
                        continue;
                    }
                    let nrm = p.normal();
                    assert!(
                        line_angle(nrm, normal) < 1e-12,
                        "g1 {g1}: {nrm:?} at {i}, {j} of piece {:?}: {p:?}",
                        s.piece()
                    );
                }
            }
        }
        assert!(worst < 1e-13 * size, "g1 {g1}: {worst:e}");
        let report = patch.report(40);
        for c in &report.corners {
            assert!(c.tangent_mismatch < 1e-14, "{report:?}");
        }
    }
}

/// The spherical n-gon of angular radius `rho` about the north pole of the unit sphere, its
/// sides great-circle arcs, tangent to the sphere (G1) on every side.
pub(super) fn spherical_polygon(n: usize, rho: f64) -> Vec<Side> {
    let offset = 0.37;
    let verts: Vec<Vec3> = (0..n)
        .map(|k| {
            let t = offset + std::f64::consts::TAU * k as f64 / n as f64;
            Vec3::new(rho.sin() * t.cos(), rho.sin() * t.sin(), rho.cos())
        })
        .collect();
    (0..n)
        .map(|i| {
            let arc = Arc::new(GreatArc::new(
                Vec3::zeros(),
                1.0,
                verts[i],
                verts[(i + 1) % n],
            ));
            let on = arc.clone();
            Side {
                curve: arc,
                t0: 0.0,
                t1: 1.0,
                ribbon: Ribbon::TangentPlane(Arc::new(move |s| on.point(s))),
            }
        })
        .collect()
}

/// The largest distance of the patch from the unit sphere over a grid of every piece.
pub(super) fn sphere_distance(patch: &Arc<NSidedPatch>) -> f64 {
    let mut worst: f64 = 0.0;
    for s in patch.surfaces() {
        for i in 0..=12 {
            for j in 0..=12 {
                let x = s.partials(i as f64 / 12.0, j as f64 / 12.0).x;
                worst = worst.max((x.norm() - 1.0).abs());
            }
        }
    }
    worst
}

#[test]
fn boundaries_and_ribbons_are_met_exactly_for_three_to_eight_sides() {
    for n in 3..=8 {
        let patch = NSidedPatch::solve(spherical_polygon(n, 0.6), &NSidedOptions::default())
            .unwrap_or_else(|e| panic!("n = {n}: {e}"));
        let report = patch.report(64);
        for (i, b) in report.boundary.iter().enumerate() {
            assert!(*b <= 1e-12 * report.size, "n = {n}, side {i}: {b:e}");
        }
        for (i, g) in report.g1.iter().enumerate() {
            // The normal field is a Chebyshev series fitted to 1e-14; the patch's tangent
            // plane contains the ribbon exactly.
            assert!(g.unwrap() <= 1e-12, "n = {n}, side {i}: {g:?}");
        }
        for (k, c) in report.corners.iter().enumerate() {
            // Great circles through a corner are both tangent to the sphere there.
            assert!(c.tangent_mismatch <= 1e-12, "n = {n}, corner {k}: {c:?}");
        }
    }
}

#[test]
fn the_distance_to_the_sphere_falls_at_order_four_under_refinement() {
    // Boundary and tangent planes from the unit sphere; the patch is not the sphere, but a
    // smooth surface that interpolates positions and tangent planes of a surface on a region
    // of size h deviates from it by O(h⁴)... measured: the ratio of deviations when h halves.
    for n in [3, 4, 5, 6] {
        let devs: Vec<f64> = [0.4, 0.2, 0.1]
            .iter()
            .map(|rho| {
                // Degree 18, so that the Ritz error stays below the h⁴ term being measured.
                let opts = NSidedOptions {
                    degree: 18,
                    ..Default::default()
                };
                let p = Arc::new(NSidedPatch::solve(spherical_polygon(n, *rho), &opts).unwrap());
                sphere_distance(&p)
            })
            .collect();
        let orders: Vec<f64> = devs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("n = {n}: deviations {devs:?}, orders {orders:.2?}");
        for o in &orders {
            assert!(*o > 3.7, "n = {n}: {devs:?} {orders:?}");
        }
    }
}

#[test]
fn the_pieces_meet_g1_across_their_cuts() {
    let patch =
        Arc::new(NSidedPatch::solve(spherical_polygon(5, 0.6), &Default::default()).unwrap());
    let pieces = patch.surfaces();
    for k in 0..5 {
        let (a, b) = (&pieces[k], &pieces[(k + 1) % 5]);
        for j in 0..=10 {
            let t = j as f64 / 10.0;
            let (pa, pb) = (a.partials(1.0, t), b.partials(t, 1.0));
            assert_eq!(pa.x, pb.x, "piece {k}, t = {t}");
            if t < 1.0 {
                assert!(line_angle(pa.normal(), pb.normal()) < 1e-12);
            }
        }
    }
}

#[test]
fn bad_loops_are_refused_with_the_place() {
    let (pts, _) = planar_pentagon();
    let line = |a: Vec3, b: Vec3| -> crate::curve::SharedCurve { Arc::new(Line(a, b)) };
    let loop_of = |pts: &[Vec3]| -> Vec<Side> {
        (0..pts.len())
            .map(|i| Side::position(line(pts[i], pts[(i + 1) % pts.len()]), 0.0, 1.0))
            .collect()
    };
    let opts = NSidedOptions::default();
    let e = NSidedPatch::solve(loop_of(&pts[..2]), &opts).unwrap_err();
    assert!(e.to_string().contains("3 to 8 sides, not 2"), "{e}");
    let nine: Vec<Vec3> = (0..9)
        .map(|k| {
            let t = k as f64 * 0.7;
            Vec3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let e = NSidedPatch::solve(loop_of(&nine), &opts).unwrap_err();
    assert!(e.to_string().contains("not 9"), "{e}");
    // A gap at corner 2.
    let mut sides = loop_of(&pts);
    sides[2] = Side::position(line(pts[2] + Vec3::new(0.0, 0.0, 1e-3), pts[3]), 0.0, 1.0);
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(e.to_string().contains("corner 2"), "{e}");
    // A degenerate side.
    let mut sides = loop_of(&pts);
    sides.insert(2, Side::position(line(pts[2], pts[2]), 0.0, 1.0));
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(
        e.to_string().contains("sides[2]") && e.to_string().contains("degenerate"),
        "{e}"
    );
    // A corner that does not turn: a side split in two at its middle.
    let mut sides = loop_of(&pts);
    let mid = (pts[0] + pts[1]) / 2.0;
    sides[0] = Side::position(line(pts[0], mid), 0.0, 1.0);
    sides.insert(1, Side::position(line(mid, pts[1]), 0.0, 1.0));
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(
        e.to_string().contains("without a corner at corner 1"),
        "{e}"
    );
    // A parameter outside the curve.
    let mut sides = loop_of(&pts);
    sides[1].t1 = 1.5;
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(e.to_string().contains("sides[1]"), "{e}");
    // Order 3 without a ribbon, and a ribbon with order 1.
    let e = NSidedPatch::solve(
        loop_of(&pts),
        &NSidedOptions {
            order: 3,
            ..opts.clone()
        },
    );
    assert!(e.unwrap_err().to_string().contains("needs a ribbon"));
    let mut sides = loop_of(&pts);
    sides[0].ribbon = Ribbon::TangentPlane(Arc::new(|_| Vec3::z()));
    let e = NSidedPatch::solve(
        sides,
        &NSidedOptions {
            order: 1,
            ..opts.clone()
        },
    );
    assert!(e.unwrap_err().to_string().contains("sides[0]"));
    // A normal field that vanishes.
    let mut sides = loop_of(&pts);
    sides[3].ribbon = Ribbon::TangentPlane(Arc::new(|_| Vec3::zeros()));
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(e.to_string().contains("sides[3].ribbon"), "{e}");
    // A bow tie: sides 0 and 2 cross at (0.5, 0.5).
    let bow = [
        Vec3::zeros(),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let e = NSidedPatch::solve(loop_of(&bow), &opts).unwrap_err();
    assert!(
        e.to_string()
            .contains("side 0 (at s = 0.5000) meets side 2 (at s = 0.5000)"),
        "{e}"
    );
    // A side that crosses itself: a cubic Bézier with a loop, closed below by two lines.
    let looped: crate::curve::SharedCurve = Arc::new(
        crate::curve::Bezier::new(vec![
            Vec3::zeros(),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        ])
        .unwrap(),
    );
    let sides = vec![
        Side::position(looped, 0.0, 1.0),
        Side::position(
            line(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.5, -1.0, 0.0)),
            0.0,
            1.0,
        ),
        Side::position(line(Vec3::new(0.5, -1.0, 0.0), Vec3::zeros()), 0.0, 1.0),
    ];
    let e = NSidedPatch::solve(sides, &opts).unwrap_err();
    assert!(e.to_string().contains("side 0 crosses itself"), "{e}");
}

/// The operator applied to the interpolant at the quadrature points from the precomputed
/// weights of the sides' data agrees with the interpolant evaluated point by point, for three
/// to eight sides and the three orders: the two differ by rounding only (the weights are the
/// same chain rule, linear in the data, summed in another order).
#[test]
fn the_operator_from_weights_is_the_interpolants() {
    for n in 3..=MAX_SIDES {
        for order in 1..=3 {
            let sides = match order {
                3 => super::tests_g2::spherical_polygon_g2(n, 0.6),
                2 => spherical_polygon(n, 0.6),
                _ => spherical_polygon(n, 0.6)
                    .into_iter()
                    .map(|s| Side {
                        ribbon: Ribbon::Position,
                        ..s
                    })
                    .collect(),
            };
            let options = NSidedOptions {
                order,
                a: 0.8,
                degree: 6,
                ..NSidedOptions::default()
            };
            let patch = NSidedPatch::solve(sides, &options).unwrap();
            let galerkin = Galerkin::get(&patch.poly, &patch.basis, order, options.a);
            let Some(w) = &galerkin.weights else {
                // Only the large tables of order 3 (six sides and more at this degree) go
                // without weights.
                assert!(order == 3 && n >= 6, "n = {n}, order {order}");
                continue;
            };
            let direct = patch.operator_at_points(&galerkin);
            let weighted = patch.operator_by_weights(&galerkin, w);
            assert_eq!(direct.len(), weighted.len());
            // Rounding's scale at each point and component: the sum of the terms' sizes
            // `Σ |α| |f^(k)|`.
            let comps = galerkin.comps;
            for (j, (x, y)) in direct.iter().zip(&weighted).enumerate() {
                let (q, c) = (j / comps, j % comps);
                let mut size = 0.0;
                for (i, side) in patch.sides.iter().enumerate() {
                    let data = side.data::<3>(w.s[q * n + i]);
                    let at = ((q * n + i) * comps + c) * w.stride;
                    let alpha = &w.alpha[at..at + w.stride];
                    for (f, a) in data.iter().zip(alpha.chunks_exact(w.derivatives)) {
                        for (v, a) in f.iter().zip(a) {
                            size += a.abs() * v.amax();
                        }
                    }
                }
                let diff = (x - y).amax();
                assert!(
                    diff <= 1e-13 * size,
                    "n = {n}, order {order}, point {q}: {diff:e} of {size:e}"
                );
            }
        }
    }
}
