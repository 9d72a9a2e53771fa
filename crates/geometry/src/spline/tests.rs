//! Tests of the spline surfaces against independent truths: the recursive Cox–de Boor
//! definition, the Bernstein sum, finite differences, and invariance under knot insertion and
//! degree elevation.

use super::*;
use crate::surface::{RowBuf, Surface, VDomain};
use crate::Vec3;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::knots::cox_de_boor;

fn binom(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |b, i| b * (n - i) as f64 / (i + 1) as f64)
}

fn bernstein(n: usize, i: usize, t: f64) -> f64 {
    binom(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32)
}

fn rand_point(rng: &mut StdRng) -> Vec3 {
    Vec3::new(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    )
}

/// A random knot vector for `n` control points of degree `p` on `[a, b]`: clamped or not,
/// with random interior knots, some repeated (up to `p` times).
fn rand_knots(rng: &mut StdRng, p: usize, n: usize, clamped: bool) -> Vec<f64> {
    let total = n + p + 1;
    loop {
        let mut k: Vec<f64> = Vec::with_capacity(total);
        if clamped {
            k.extend(std::iter::repeat_n(-0.5, p + 1));
            let interior = n - p - 1;
            let mut inner: Vec<f64> = Vec::new();
            while inner.len() < interior {
                let x = (rng.gen_range(-0.45..1.45f64) * 8.0).round() / 8.0;
                let m = rng.gen_range(1..=p.max(1)).min(interior - inner.len());
                inner.extend(std::iter::repeat_n(x, m));
            }
            inner.sort_by(f64::total_cmp);
            k.extend(inner);
            k.extend(std::iter::repeat_n(1.5, p + 1));
        } else {
            let mut x = -1.0;
            for _ in 0..total {
                x += rng.gen_range(0.1..0.5);
                k.push(x);
            }
        }
        if super::knots::check_knots("k", p, n, &k).is_ok() {
            return k;
        }
    }
}

fn rand_bspline(rng: &mut StdRng, p: usize, q: usize) -> BSplineSurface {
    // Degree 0 admits no interior knot (the surface would break apart): one span only.
    let nu = if p == 0 {
        1
    } else {
        p + 1 + rng.gen_range(0..4)
    };
    let nv = if q == 0 {
        1
    } else {
        q + 1 + rng.gen_range(0..4)
    };
    let (cu, cv) = (rng.gen_bool(0.7), rng.gen_bool(0.7));
    let ku = rand_knots(rng, p, nu, cu);
    let kv = rand_knots(rng, q, nv, cv);
    let ctrl = (0..nu * nv).map(|_| rand_point(rng)).collect();
    BSplineSurface::new([p, q], ku, kv, ctrl).unwrap()
}

/// A random parameter pair inside the domain.
fn rand_uv(rng: &mut StdRng, s: &BSplineSurface) -> (f64, f64) {
    let [[a, b], [c, d]] = s.domain();
    (rng.gen_range(a..=b), rng.gen_range(c..=d))
}

/// Max |control point| — the scale of rounding errors in sums with non-negative weights ≤ 1.
fn scale(c: &[Vec3]) -> f64 {
    c.iter().map(|p| p.amax()).fold(0.0, f64::max).max(1e-300)
}

#[test]
fn bspline_values_match_recursive_cox_de_boor() {
    let mut rng = StdRng::seed_from_u64(1);
    for _ in 0..60 {
        let (p, q) = (rng.gen_range(0..=5), rng.gen_range(0..=5));
        let s = rand_bspline(&mut rng, p, q);
        let [nu, nv] = s.counts();
        let [[a, b], [c, d]] = s.domain();
        for k in 0..8 {
            let (u, v) = match k {
                0 => (a, c),
                1 => (b, d),
                _ => rand_uv(&mut rng, &s),
            };
            let mut want = Vec3::zeros();
            let mut sum = 0.0;
            for i in 0..nu {
                let bu = cox_de_boor(s.knots_u(), i, p, u, b);
                for j in 0..nv {
                    let bv = cox_de_boor(s.knots_v(), j, q, v, d);
                    want += s.control()[i * nv + j] * (bu * bv);
                    sum += bu * bv;
                }
            }
            assert!((sum - 1.0).abs() < 1e-14, "partition of unity: {sum}");
            let got = s.derivative(u, v, 0, 0);
            assert!(
                (got - want).amax() < 1e-14 * scale(s.control()) * 4.0,
                "p {p} q {q} at ({u}, {v}): {got:?} vs {want:?}"
            );
        }
    }
}

/// Central differences of the exact derivative of order `k` against order `k + 1`, at points
/// at least `2h` away from every knot (so all of `[t − h, t + h]` lies in one polynomial piece).
/// Error analysis: on a polynomial piece the central difference is exactly
/// `f'(t) + Σ_{odd j ≥ 3} h^{j−1}/j! f⁽ʲ⁾(t)` (a finite Taylor series), which bounds the
/// truncation part; rounding adds `≈ (p+1)(q+1) ε (|f(t+h)| + |f(t−h)|) / 2h` (counted 16×
/// for the cancellation inside high-order derivatives).
#[test]
fn bspline_derivatives_match_finite_differences() {
    let mut rng = StdRng::seed_from_u64(2);
    let h = 1e-3;
    let eps = f64::EPSILON;
    for _ in 0..40 {
        let (p, q) = (rng.gen_range(1..=5), rng.gen_range(1..=5));
        let s = rand_bspline(&mut rng, p, q);
        let near = |k: &[f64], t: f64| k.iter().any(|x| (x - t).abs() < 2.0 * h);
        let terms = ((p + 1) * (q + 1)) as f64;
        let mut checked = 0;
        while checked < 5 {
            let (u, v) = rand_uv(&mut rng, &s);
            if near(s.knots_u(), u) || near(s.knots_v(), v) {
                continue;
            }
            checked += 1;
            for ku in 0..=p + 1 {
                for kv in 0..=q + 1 {
                    // d/du of D^{ku,kv} against D^{ku+1,kv}.
                    let f = |x: f64| s.derivative(x, v, ku, kv);
                    let fd = (f(u + h) - f(u - h)) / (2.0 * h);
                    let exact = s.derivative(u, v, ku + 1, kv);
                    let mut trunc = 0.0;
                    let mut fact = 1.0;
                    for j in 2..=p + 2 {
                        fact *= j as f64;
                        if j % 2 == 1 {
                            trunc +=
                                h.powi(j as i32 - 1) / fact * s.derivative(u, v, ku + j, kv).amax();
                        }
                    }
                    let tol = trunc
                        + 16.0 * terms * eps * (f(u + h).amax() + f(u - h).amax()) / (2.0 * h);
                    assert!(
                        (fd - exact).amax() <= tol,
                        "u: p {p} ku {ku} kv {kv}: {fd:?} vs {exact:?}, tol {tol}"
                    );
                    let g = |y: f64| s.derivative(u, y, ku, kv);
                    let gd = (g(v + h) - g(v - h)) / (2.0 * h);
                    let exact = s.derivative(u, v, ku, kv + 1);
                    let mut trunc = 0.0;
                    let mut fact = 1.0;
                    for j in 2..=q + 2 {
                        fact *= j as f64;
                        if j % 2 == 1 {
                            trunc +=
                                h.powi(j as i32 - 1) / fact * s.derivative(u, v, ku, kv + j).amax();
                        }
                    }
                    let tol = trunc
                        + 16.0 * terms * eps * (g(v + h).amax() + g(v - h).amax()) / (2.0 * h);
                    assert!(
                        (gd - exact).amax() <= tol,
                        "v: q {q} ku {ku} kv {kv}: {gd:?} vs {exact:?}, tol {tol}"
                    );
                }
            }
            // Above the degrees: exactly zero.
            assert_eq!(s.derivative(u, v, p + 1, 0), Vec3::zeros());
            assert_eq!(s.derivative(u, v, 0, q + 1), Vec3::zeros());
        }
    }
}

/// The relative agreement of two surfaces at random points of the first one's domain.
fn assert_same_surface(a: &BSplineSurface, b: &BSplineSurface, rng: &mut StdRng, what: &str) {
    assert_eq!(a.domain(), b.domain(), "{what}: domain");
    let tol = 1e-13 * scale(a.control());
    for _ in 0..20 {
        let (u, v) = rand_uv(rng, a);
        let (x, y) = (a.derivative(u, v, 0, 0), b.derivative(u, v, 0, 0));
        assert!((x - y).amax() < tol, "{what} at ({u}, {v}): {x:?} vs {y:?}");
        // First derivatives too (they scale with the inverse knot spacing).
        let (x, y) = (a.derivative(u, v, 1, 1), b.derivative(u, v, 1, 1));
        assert!(
            (x - y).amax() < 1e-11 * x.amax().max(scale(a.control())),
            "{what} mixed derivative at ({u}, {v}): {x:?} vs {y:?}"
        );
    }
}

#[test]
fn knot_insertion_keeps_the_surface() {
    let mut rng = StdRng::seed_from_u64(3);
    for _ in 0..40 {
        let (p, q) = (rng.gen_range(1..=4), rng.gen_range(1..=4));
        let s = rand_bspline(&mut rng, p, q);
        let [[a, b], [c, d]] = s.domain();
        let mut t = s.clone();
        for _ in 0..3 {
            // A random value, or an existing knot (raising its multiplicity when allowed).
            let tu = if rng.gen_bool(0.5) {
                rng.gen_range(a..b)
            } else {
                s.knots_u()[rng.gen_range(p..=s.counts()[0])]
            };
            if let Ok(n) = t.insert_knot_u(tu) {
                assert_eq!(n.counts()[0], t.counts()[0] + 1);
                t = n;
            }
            let tv = rng.gen_range(c..d);
            t = t.insert_knot_v(tv).unwrap();
        }
        assert!(t.counts()[1] == s.counts()[1] + 3);
        assert_same_surface(&s, &t, &mut rng, "knot insertion");
    }
}

#[test]
fn knot_insertion_rejects_what_new_would_reject() {
    let ctrl = vec![Vec3::zeros(); 16];
    let s = BSplineSurface::clamped_uniform([3, 3], [4, 4], ctrl).unwrap();
    let e = s.insert_knot_u(1.5).unwrap_err().to_string();
    assert!(e.contains("1.5") && e.contains("outside"), "{e}");
    let e = s.insert_knot_v(f64::NAN).unwrap_err().to_string();
    assert!(e.contains("NaN") && e.contains("knots_v"), "{e}");
    // The end knot already has multiplicity p + 1.
    let e = s.insert_knot_u(0.0).unwrap_err().to_string();
    assert!(e.contains("repeated 5 times"), "{e}");
    // An interior knot may reach multiplicity p, not p + 1.
    let t = s
        .insert_knot_v(0.5)
        .and_then(|t| t.insert_knot_v(0.5))
        .and_then(|t| t.insert_knot_v(0.5))
        .unwrap();
    let e = t.insert_knot_v(0.5).unwrap_err().to_string();
    assert!(
        e.contains("knots_v") && e.contains("repeated 4 times"),
        "{e}"
    );
}

/// Knot insertion to full multiplicity `p` at every interior knot splits the surface into
/// Bézier patches: the subnet of each span, as a [`BezierSurface`] in local coordinates,
/// reproduces the surface (an independent check of insertion and evaluation alike).
#[test]
fn full_insertion_gives_the_bezier_pieces() {
    let mut rng = StdRng::seed_from_u64(4);
    for _ in 0..10 {
        let (p, q) = (rng.gen_range(1..=4), rng.gen_range(1..=4));
        let nu = p + 3;
        let nv = q + 2;
        let ku = rand_knots(&mut rng, p, nu, true);
        let kv = rand_knots(&mut rng, q, nv, true);
        let ctrl = (0..nu * nv).map(|_| rand_point(&mut rng)).collect();
        let s = BSplineSurface::new([p, q], ku.clone(), kv.clone(), ctrl).unwrap();
        let mut t = s.clone();
        let split = |k: &[f64], deg: usize| -> Vec<f64> {
            let mut d: Vec<f64> = k[deg + 1..k.len() - deg - 1].to_vec();
            d.dedup();
            d
        };
        for x in split(&ku, p) {
            while t.knots_u().iter().filter(|&&k| k == x).count() < p {
                t = t.insert_knot_u(x).unwrap();
            }
        }
        for x in split(&kv, q) {
            while t.knots_v().iter().filter(|&&k| k == x).count() < q {
                t = t.insert_knot_v(x).unwrap();
            }
        }
        // Spans: consecutive distinct knots; the Bézier net of span (a, b) starts at the
        // control index of the first knot equal to a, minus... (index of a's last copy − p).
        let spans = |k: &[f64], deg: usize| -> Vec<(usize, f64, f64)> {
            let mut out = Vec::new();
            for s in deg..k.len() - deg - 1 {
                if k[s] < k[s + 1] {
                    out.push((s - deg, k[s], k[s + 1]));
                }
            }
            out
        };
        let nv2 = t.counts()[1];
        for &(i0, a, b) in &spans(t.knots_u(), p) {
            for &(j0, c, d) in &spans(t.knots_v(), q) {
                let mut net = Vec::new();
                for i in 0..=p {
                    for j in 0..=q {
                        net.push(t.control()[(i0 + i) * nv2 + j0 + j]);
                    }
                }
                let z = BezierSurface::new([p, q], net).unwrap();
                for _ in 0..3 {
                    let (x, y) = (rng.gen_range(0.0..=1.0), rng.gen_range(0.0..=1.0));
                    let want = s.derivative(a + (b - a) * x, c + (d - c) * y, 0, 0);
                    let got = z.point_at(x, y);
                    assert!((want - got).amax() < 1e-13, "{want:?} vs {got:?}");
                }
            }
        }
    }
}

#[test]
fn degree_elevation_keeps_the_surface() {
    let mut rng = StdRng::seed_from_u64(5);
    for _ in 0..40 {
        let (p, q) = (rng.gen_range(0..=4), rng.gen_range(0..=4));
        let s = rand_bspline(&mut rng, p, q);
        let e = s.elevate_degree_u().unwrap();
        assert_eq!(e.degree(), [p + 1, q]);
        assert_same_surface(&s, &e, &mut rng, "elevation in u");
        let e = e.elevate_degree_v().unwrap().elevate_degree_v().unwrap();
        assert_eq!(e.degree(), [p + 1, q + 2]);
        assert_same_surface(&s, &e, &mut rng, "elevation in u and v");
        // Continuity is kept: each interior knot of the domain gained exactly one copy.
        let [[a, b], _] = s.domain();
        for &k in s.knots_u().iter().filter(|&&k| k > a && k < b) {
            let m0 = s.knots_u().iter().filter(|&&x| x == k).count();
            let m1 = e.knots_u().iter().filter(|&&x| x == k).count();
            assert_eq!(m1, m0 + 1);
        }
    }
}

fn rand_bezier(rng: &mut StdRng, n: usize, m: usize) -> BezierSurface {
    BezierSurface::new(
        [n, m],
        (0..(n + 1) * (m + 1)).map(|_| rand_point(rng)).collect(),
    )
    .unwrap()
}

#[test]
fn bezier_de_casteljau_matches_bernstein_sum_and_bspline() {
    let mut rng = StdRng::seed_from_u64(6);
    for _ in 0..30 {
        let (n, m) = (rng.gen_range(0..=7), rng.gen_range(0..=7));
        let z = rand_bezier(&mut rng, n, m);
        let b = z.to_bspline();
        for _ in 0..6 {
            let (u, v) = (rng.gen_range(-0.2..1.2), rng.gen_range(-0.2..1.2));
            let mut want = Vec3::zeros();
            for i in 0..=n {
                for j in 0..=m {
                    want += z.control_point(i, j) * (bernstein(n, i, u) * bernstein(m, j, v));
                }
            }
            assert!((z.point_at(u, v) - want).amax() < 1e-13, "n {n} m {m}");
            // Every derivative order, Bézier forward differences against Cox–de Boor basis
            // derivatives: two independent algorithms.
            for ku in 0..=n + 1 {
                for kv in 0..=m + 1 {
                    let (x, y) = (z.derivative(u, v, ku, kv), b.derivative(u, v, ku, kv));
                    let tol = 1e-13
                        * (2f64.powi((ku + kv) as i32))
                        * crate_falling(n, ku)
                        * crate_falling(m, kv);
                    assert!(
                        (x - y).amax() <= tol,
                        "n {n} m {m} k ({ku}, {kv}): {x:?} vs {y:?}"
                    );
                }
            }
        }
        // Corners interpolate.
        assert_eq!(z.point_at(0.0, 0.0), z.control_point(0, 0));
        assert_eq!(z.point_at(1.0, 1.0), z.control_point(n, m));
    }
}

fn crate_falling(n: usize, k: usize) -> f64 {
    if k > n {
        1.0
    } else {
        super::bezier::falling(n, k)
    }
}

#[test]
fn bezier_elevation_keeps_the_patch() {
    let mut rng = StdRng::seed_from_u64(7);
    for _ in 0..20 {
        let (n, m) = (rng.gen_range(0..=6), rng.gen_range(0..=6));
        let z = rand_bezier(&mut rng, n, m);
        let e = z.elevate_degree_u().elevate_degree_v().elevate_degree_u();
        assert_eq!(e.degree(), [n + 2, m + 1]);
        for _ in 0..10 {
            let (u, v) = (rng.gen_range(0.0..=1.0), rng.gen_range(0.0..=1.0));
            let (x, y) = (z.point_at(u, v), e.point_at(u, v));
            assert!((x - y).amax() < 1e-14 * 8.0, "{x:?} vs {y:?}");
        }
    }
}

/// `Surface::partials` of both kinds against `derivative` (with the `u` map of the B-spline),
/// and the row evaluator against `partials`.
#[test]
fn surface_impls_agree_with_derivative_and_rows() {
    let mut rng = StdRng::seed_from_u64(8);
    for _ in 0..10 {
        let s = rand_bspline(&mut rng, 3, 2);
        let [[a, b], [c, d]] = s.domain();
        assert_eq!(s.v_domain(), VDomain::Interval(c, d));
        let h = b - a;
        for _ in 0..5 {
            let (u, v) = (rng.gen_range(0.0..=1.0), rng.gen_range(c..=d));
            let p = s.partials(u, v);
            let t = a + h * u;
            let close = |x: Vec3, y: Vec3| (x - y).amax() <= 1e-13 * y.amax().max(1.0);
            assert!(close(p.x, s.derivative(t, v, 0, 0)));
            assert!(close(p.xu, s.derivative(t, v, 1, 0) * h));
            assert!(close(p.xv, s.derivative(t, v, 0, 1)));
            assert!(close(p.xuu, s.derivative(t, v, 2, 0) * (h * h)));
            assert!(close(p.xuv, s.derivative(t, v, 1, 1) * h));
            assert!(close(p.xvv, s.derivative(t, v, 0, 2)));
        }
        let vs: Vec<f64> = (0..37).map(|j| c + (d - c) * j as f64 / 36.0).collect();
        let rows = s.row_evaluator(&vs);
        let mut row = RowBuf::new(vs.len());
        for &u in &[0.0, 0.3, 0.71, 1.0] {
            rows.eval_row(u, &mut row);
            for (j, &v) in vs.iter().enumerate() {
                let p = s.partials(u, v);
                assert!((row.point(j) - p.x).amax() < 1e-13, "row point");
                assert!((row.normal(j) - p.normal()).amax() < 1e-11, "row normal");
            }
        }
    }
    // A pole: the first row of the net collapsed to one point, so X_v = 0 at u = 0 and the
    // rows must fall back to the limit normal of `Partials::normal`.
    let mut s = rand_bspline(&mut rng, 3, 3);
    let nv = s.counts()[1];
    let apex = Vec3::new(0.1, 0.2, 0.3);
    let mut ctrl = s.control().to_vec();
    ctrl[..nv].fill(apex);
    s = BSplineSurface::new(s.degree(), s.knots_u().to_vec(), s.knots_v().to_vec(), ctrl).unwrap();
    let [_, [c, d]] = s.domain();
    let vs: Vec<f64> = (0..9).map(|j| c + (d - c) * j as f64 / 8.0).collect();
    let mut row = RowBuf::new(vs.len());
    s.row_evaluator(&vs).eval_row(0.0, &mut row);
    for (j, &v) in vs.iter().enumerate() {
        let p = s.partials(0.0, v);
        assert!(p.xv.amax() < 1e-15, "X_v is rounding noise at the pole");
        assert!((row.point(j) - apex).amax() < 1e-15);
        let n = p.normal();
        assert!((n.norm() - 1.0).abs() < 1e-12, "limit normal exists");
        assert!(
            (row.normal(j) - n).amax() < 1e-12,
            "{:?} vs {n:?}",
            row.normal(j)
        );
    }
    let z = rand_bezier(&mut rng, 3, 4);
    assert_eq!(z.v_domain(), VDomain::Interval(0.0, 1.0));
    // Bernstein tables (partials, rows) against de Casteljau on forward differences.
    let close = |x: Vec3, y: Vec3| (x - y).amax() <= 1e-13 * y.amax().max(1.0);
    for &(u, v) in &[(0.3, 0.6), (0.0, 1.0), (0.9, 0.05)] {
        let p = z.partials(u, v);
        assert!(close(p.x, z.point_at(u, v)));
        assert!(close(p.xu, z.derivative(u, v, 1, 0)));
        assert!(close(p.xv, z.derivative(u, v, 0, 1)));
        assert!(close(p.xuu, z.derivative(u, v, 2, 0)));
        assert!(close(p.xuv, z.derivative(u, v, 1, 1)));
        assert!(close(p.xvv, z.derivative(u, v, 0, 2)));
    }
    let vs = [0.0, 0.25, 0.5, 1.0];
    let mut row = RowBuf::new(4);
    z.row_evaluator(&vs).eval_row(0.4, &mut row);
    for (j, &v) in vs.iter().enumerate() {
        assert!(close(row.point(j), z.point_at(0.4, v)));
        assert!((row.normal(j) - z.partials(0.4, v).normal()).amax() < 1e-12);
    }
}

#[test]
fn bad_input_is_rejected_with_the_value_named() {
    let c = |n: usize| vec![Vec3::zeros(); n];
    let k4 = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let e = BSplineSurface::new([3, 3], k4.clone(), k4.clone(), c(15))
        .unwrap_err()
        .to_string();
    assert!(e.contains("4 × 4 = 16") && e.contains("15"), "{e}");
    let mut bad = k4.clone();
    bad[4] = 0.5;
    bad[5] = 0.25;
    let e = BSplineSurface::new([3, 3], k4.clone(), bad, c(16))
        .unwrap_err()
        .to_string();
    assert!(e.contains("knots_v[5] = 0.25"), "{e}");
    let e = BSplineSurface::new([3, 3], vec![0.0; 8], k4.clone(), c(16))
        .unwrap_err()
        .to_string();
    assert!(e.contains("knots_u") && e.contains("empty"), "{e}");
    let e = BSplineSurface::new([4, 3], k4.clone(), k4.clone(), c(16))
        .unwrap_err()
        .to_string();
    assert!(e.contains("knots_u") && e.contains("degree 4"), "{e}");
    let mut cc = c(16);
    cc[6].z = f64::NAN;
    let e = BSplineSurface::new([3, 3], k4.clone(), k4.clone(), cc.clone())
        .unwrap_err()
        .to_string();
    assert!(e.contains("control[6] (row 1, column 2)"), "{e}");
    let e = BezierSurface::new([3, 3], cc).unwrap_err().to_string();
    assert!(e.contains("control[6]"), "{e}");
    let e = BezierSurface::new([2, 3], c(16)).unwrap_err().to_string();
    assert!(e.contains("got 16"), "{e}");
    assert!(BezierSurface::new([usize::MAX, 3], c(16)).is_err());
    let mut inf = k4.clone();
    inf[7] = f64::INFINITY;
    assert!(BSplineSurface::new([3, 3], k4, inf, c(16)).is_err());
}

/// The public basis: partition of unity, derivatives summing to zero, values against the
/// recursive definition, and the derivative recurrence
/// `N'_{i,p} = p (N_{i,p−1}/(t_{i+p} − t_i) − N_{i+1,p−1}/(t_{i+p+1} − t_{i+1}))`
/// evaluated with the recursive lower-degree functions.
#[test]
fn public_basis_matches_the_definitions() {
    let mut rng = StdRng::seed_from_u64(9);
    for _ in 0..30 {
        let p = rng.gen_range(1..=5);
        let n = p + 1 + rng.gen_range(0..5);
        let clamped = rng.gen_bool(0.5);
        let k = rand_knots(&mut rng, p, n, clamped);
        let (a, b) = (k[p], k[n]);
        let t = rng.gen_range(a..b);
        let (s, out) = bspline_basis(&k, p, t, p + 1).unwrap();
        assert!(k[s] <= t && t < k[s + 1]);
        let w = p + 1;
        let sum: f64 = out[..w].iter().sum();
        assert!((sum - 1.0).abs() < 1e-14);
        for ord in 1..=p + 1 {
            let d: f64 = out[ord * w..(ord + 1) * w].iter().sum();
            let mag: f64 = out[ord * w..(ord + 1) * w].iter().map(|x| x.abs()).sum();
            assert!(d.abs() <= 1e-13 * mag.max(1.0), "order {ord}: Σ = {d}");
        }
        for r in 0..w {
            let i = s - p + r;
            assert!((out[r] - cox_de_boor(&k, i, p, t, b)).abs() < 1e-14);
            let mut want = 0.0;
            let d1 = k[i + p] - k[i];
            if d1 > 0.0 {
                want += p as f64 / d1 * cox_de_boor(&k, i, p - 1, t, b);
            }
            let d2 = k[i + p + 1] - k[i + 1];
            if d2 > 0.0 {
                want -= p as f64 / d2 * cox_de_boor(&k, i + 1, p - 1, t, b);
            }
            assert!((out[w + r] - want).abs() <= 1e-13 * want.abs().max(1.0));
        }
        assert!(out[(p + 1) * w..].iter().all(|&x| x == 0.0));
    }
    assert!(bspline_basis(&[0.0, 1.0], 1, 0.5, 1).is_err());
    assert!(bspline_basis(&[0.0, 0.0, 1.0, 1.0], 1, 0.5, usize::MAX).is_err());
    let e = bspline_basis(&[0.0, 0.0, 1.0, 0.5], 1, 0.5, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("knots[3] = 0.5"), "{e}");
}
