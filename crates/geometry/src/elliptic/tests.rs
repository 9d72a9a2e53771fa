//! Tests of the analytic solver against independent truth: closed forms, manufactured
//! solutions, the mode equations, finite differences of the evaluator and rigid motions.

use super::*;
use crate::curve::{Curve, Domain, Ellipse};
use crate::surface::{Partials, Surface};
use crate::{Vec3, TAU};
use std::sync::Arc;

fn circle(z: f64, r: f64) -> SharedCurve {
    Arc::new(
        Ellipse::new(
            Vec3::new(0.0, 0.0, z),
            Vec3::new(r, 0.0, 0.0),
            Vec3::new(0.0, r, 0.0),
        )
        .unwrap(),
    )
}

fn cond(u: f64, derivative: usize, curve: SharedCurve) -> Condition {
    Condition {
        u,
        derivative,
        curve,
    }
}

/// A periodic curve that is not a finite Fourier series: `(r cos v, r sin v, h + b e^{cos v})`,
/// with exact derivatives up to order 2.
#[derive(Debug)]
struct Bumpy {
    r: f64,
    h: f64,
    b: f64,
}

impl Curve for Bumpy {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let (s, c) = t.sin_cos();
        let e = c.exp();
        let vals = [
            Vec3::new(self.r * c, self.r * s, self.h + self.b * e),
            Vec3::new(-self.r * s, self.r * c, -self.b * s * e),
            Vec3::new(-self.r * c, -self.r * s, self.b * (s * s - c) * e),
        ];
        for (o, v) in out.iter_mut().zip(vals) {
            *o = v;
        }
    }
}

/// The correct Laplace blend of §4.2 with smoothing parameter `a`: radius, height `h u` (the book's Eq. 4.4 is wrong).
#[test]
fn laplace_blend_matches_the_closed_form() {
    for &a in &[0.1, 1.0, 3.0, 10.0] {
        let (b, r1, h) = (2.0, 1.0, 1.0);
        let op = Operator::polyharmonic(1, a).unwrap();
        let patch = solve(
            &op,
            vec![cond(0.0, 0, circle(0.0, b)), cond(1.0, 0, circle(h, r1))],
            &SolveOptions::default(),
        )
        .unwrap();
        assert!(!patch.has_remainder());
        for &u in &[0.0, 0.1, 0.37, 0.5, 0.93, 1.0] {
            // Written without cancellation: b sinh(a(1−u))/sinh a + r1 sinh(au)/sinh a.
            let radius = (b * (a * (1.0 - u)).sinh() + r1 * (a * u).sinh()) / a.sinh();
            for &v in &[0.0f64, 1.0, 2.5, 4.0] {
                let exact = Vec3::new(radius * v.cos(), radius * v.sin(), h * u);
                let got = patch.point(u, v);
                assert!(
                    (got - exact).norm() < 1e-14 * 4.0,
                    "a={a} u={u} v={v}: {got} vs {exact}"
                );
            }
        }
    }
}

/// The appendix's Maple example, solved independently in the plain exponential basis of
/// Eq. 4.13 (well conditioned for a = 1.1, n = 1) with the "derivative" values imposed as
/// positions at u = 0.2 and 0.8, as the Maple code does.
#[test]
fn maple_appendix_example() {
    let a = 1.1;
    let op = Operator::polyharmonic(2, a).unwrap();
    let us = [0.0, 0.2, 0.8, 1.0];
    let (zs, rs) = ([0.0, 0.5, 0.8, 1.0], [0.5, 0.5, 2.0, 2.0]);
    let conds = (0..4)
        .map(|i| cond(us[i], 0, circle(zs[i], rs[i])))
        .collect();
    let patch = solve(&op, conds, &SolveOptions::default()).unwrap();
    let basis = |u: f64| {
        [
            (a * u).exp(),
            u * (a * u).exp(),
            (-a * u).exp(),
            u * (-a * u).exp(),
        ]
    };
    let m = DMatrix::from_fn(4, 4, |i, k| basis(us[i])[k]);
    let coef = m
        .lu()
        .solve(&DMatrix::from_column_slice(4, 1, &rs))
        .unwrap();
    let cubic = DMatrix::from_fn(4, 4, |i, k| us[i].powi(k as i32))
        .lu()
        .solve(&DMatrix::from_column_slice(4, 1, &zs))
        .unwrap();
    for i in 0..=20 {
        let u = i as f64 / 20.0;
        let radius: f64 = (0..4).map(|k| coef[k] * basis(u)[k]).sum();
        let z: f64 = (0..4).map(|k| cubic[k] * u.powi(k as i32)).sum();
        let v = 0.3 + i as f64;
        let exact = Vec3::new(radius * v.cos(), radius * v.sin(), z);
        assert!((patch.point(u, v) - exact).norm() < 1e-13, "u={u}");
        assert!((patch.spine(u, 0) - Vec3::new(0.0, 0.0, z)).norm() < 1e-14);
    }
}

/// Random-ish smooth Fourier series with `m` modes and decaying amplitudes.
fn series(seed: u64, m: usize, size: f64) -> FourierSeries {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut v3 = |s: f64| Vec3::new(next() * s, next() * s, next() * s);
    FourierSeries {
        a0: v3(size),
        cos: (1..=m).map(|n| v3(size / (n * n) as f64)).collect(),
        sin: (1..=m).map(|n| v3(size / (n * n) as f64)).collect(),
    }
}

fn max_relative_condition_error(patch: &PdePatch) -> f64 {
    patch
        .condition_errors(257)
        .iter()
        .map(|e| e.relative)
        .fold(0.0, f64::max)
}

/// Conditions hold to a relative 1e-10 for a from 0.1 to 10, up to 64 modes and N up to 5:
/// positions and derivatives up to N − 1 at both ends (random curves with 1/n² decay), and then
/// the same surface's section at u = 0.4 used as an intermediate position curve in place of the
/// highest derivative at u = 1 (a manufactured intermediate condition: random intermediate data
/// with high modes would ask for solutions as large as e^{a n u}).
#[test]
fn conditions_hold_across_orders_parameters_and_modes() {
    for nn in 1..=5usize {
        for &a in &[0.1, 0.5, 1.0, 3.0, 10.0] {
            for &m in &[1usize, 12, 64] {
                let op = Operator::polyharmonic(nn, a).unwrap();
                let opts = SolveOptions {
                    modes: m,
                    ..Default::default()
                };
                let mut conds = vec![
                    cond(0.0, 0, Arc::new(series(1, m, 1.0))),
                    cond(1.0, 0, Arc::new(series(2, m, 1.0))),
                ];
                for d in 1..nn {
                    conds.push(cond(0.0, d, Arc::new(series(2 * d as u64 + 1, m, 1.0))));
                    conds.push(cond(1.0, d, Arc::new(series(2 * d as u64 + 2, m, 1.0))));
                }
                let patch = solve(&op, conds.clone(), &opts).unwrap();
                let err = max_relative_condition_error(&patch);
                assert!(
                    err < 1e-10,
                    "N={nn} a={a} M={m}: relative condition error {err:e}"
                );
                // Mode n of a section at u_i reaches the far end amplified by up to
                // e^{a n (1 − u_i)}, so the rounding in a manufactured section limits this check
                // to a·M(1 − u_i) ≲ 40 (beyond, no double-precision section determines the
                // surface; the remainder still meets the conditions when curves are not series).
                if nn >= 2 && a * m as f64 * 0.6 <= 40.0 {
                    let section = patch::fitted_series(&patch.modes, 0.4, 0);
                    conds.pop();
                    conds.push(cond(0.4, 0, Arc::new(section)));
                    let again = solve(&op, conds, &opts).unwrap();
                    let err = max_relative_condition_error(&again);
                    assert!(
                        err < 1e-10,
                        "N={nn} a={a} M={m} with an intermediate curve: {err:e}"
                    );
                }
            }
        }
    }
}

/// Every mode function solves its mode equation `Σ_k c_k (−n²)^k f^{(2N−2k)} = 0`, so `L X = 0`
/// holds pointwise (checked from exact derivatives).
#[test]
fn pde_residual_vanishes_from_exact_derivatives() {
    for op in [
        Operator::polyharmonic(2, 1.5).unwrap(),
        Operator::polyharmonic(3, 0.7).unwrap(),
        Operator::sixth_order(1.0, 2.0, 2.0, 1.0).unwrap(),
    ] {
        let nn = op.half_order();
        let m = 8;
        let conds = (0..2 * nn)
            .map(|i| {
                cond(
                    i as f64 / (2 * nn - 1) as f64,
                    0,
                    Arc::new(series(10 + i as u64, m, 1.0)) as SharedCurve,
                )
            })
            .collect();
        let patch = solve(
            &op,
            conds,
            &SolveOptions {
                modes: m,
                ..Default::default()
            },
        )
        .unwrap();
        for &u in &[0.13, 0.5, 0.71] {
            for n in 0..=m {
                let r = mode_equation_residual(&patch, n, u);
                assert!(r <= 1e-11, "n={n} u={u}: relative residual {r:e}");
            }
        }
    }
}

/// The biharmonic residual `Δ_a(Δ_a X)` from central differences of the evaluator's exact second
/// derivatives: O(h²) truncation plus O(ε/h²) rounding.
#[test]
fn pde_residual_vanishes_by_finite_differences() {
    let a = 1.3;
    let op = Operator::polyharmonic(2, a).unwrap();
    let conds = vec![
        cond(0.0, 0, Arc::new(series(5, 4, 1.0)) as SharedCurve),
        cond(0.0, 1, Arc::new(series(6, 4, 1.0))),
        cond(1.0, 0, Arc::new(series(7, 4, 1.0))),
        cond(1.0, 1, Arc::new(series(8, 4, 1.0))),
    ];
    let patch = solve(
        &op,
        conds,
        &SolveOptions {
            modes: 4,
            ..Default::default()
        },
    )
    .unwrap();
    let lap = |u: f64, v: f64| {
        let p = patch.partials(u, v);
        p.xuu + p.xvv * (a * a)
    };
    let h = 1e-3;
    for &(u, v) in &[(0.3, 0.4), (0.5, 2.0), (0.8, 5.5)] {
        let center = lap(u, v);
        let duu = (lap(u + h, v) - center * 2.0 + lap(u - h, v)) / (h * h);
        let dvv = (lap(u, v + h) - center * 2.0 + lap(u, v - h)) / (h * h);
        let res = duu + dvv * (a * a);
        let scale = duu.norm() + dvv.norm() * a * a + center.norm();
        assert!(
            res.norm() < 1e-5 * scale,
            "residual {} vs {}",
            res.norm(),
            scale
        );
        // And the exact second derivatives agree with differences of the positions.
        let p = patch.partials(u, v);
        let fd_uu = (patch.point(u + h, v) - p.x * 2.0 + patch.point(u - h, v)) / (h * h);
        let fd_uv =
            (patch.point(u + h, v + h) - patch.point(u + h, v - h) - patch.point(u - h, v + h)
                + patch.point(u - h, v - h))
                / (4.0 * h * h);
        assert!((fd_uu - p.xuu).norm() < 1e-5 * (1.0 + p.xuu.norm()));
        assert!((fd_uv - p.xuv).norm() < 1e-5 * (1.0 + p.xuv.norm()));
        let fd_u = (patch.point(u + h, v) - patch.point(u - h, v)) / (2.0 * h);
        assert!((fd_u - p.xu).norm() < 1e-5 * (1.0 + p.xu.norm()));
    }
}

/// Curves that are not finite Fourier series are met to rounding thanks to the remainder, with
/// only a few modes.
#[test]
fn spectral_remainder_meets_arbitrary_curves() {
    for &(nn, a, m) in &[(2usize, 1.0, 3usize), (2, 5.0, 6), (3, 0.5, 4), (1, 2.0, 2)] {
        let op = Operator::polyharmonic(nn, a).unwrap();
        let mut conds: Vec<Condition> = Vec::new();
        for i in 0..2 * nn {
            let u = i as f64 / (2 * nn - 1) as f64;
            let curve: SharedCurve = Arc::new(Bumpy {
                r: 1.0 + 0.3 * i as f64,
                h: u,
                b: 0.2,
            });
            conds.push(cond(u, 0, curve));
        }
        let patch = solve(
            &op,
            conds.clone(),
            &SolveOptions {
                modes: m,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(patch.has_remainder());
        let err = max_relative_condition_error(&patch);
        assert!(err < 1e-13, "N={nn} a={a} M={m}: {err:e}");
        // Without the remainder the truncation shows.
        let plain = solve(
            &op,
            conds,
            &SolveOptions {
                modes: m,
                remainder: false,
                ..Default::default()
            },
        )
        .unwrap();
        let plain_err = max_relative_condition_error(&plain);
        assert!(
            plain_err > 1e3 * err.max(1e-16),
            "the Fourier truncation {plain_err:e} should show without the remainder"
        );
    }
}

/// Moving every condition curve by a rigid motion moves the surface by the same motion.
#[test]
fn rigid_motions_commute_with_solving() {
    let q = nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vec3::new(1.0, 2.0, -0.5)),
        0.9,
    )
    .into_inner();
    let t = Vec3::new(3.0, -1.0, 2.0);
    let mv = |f: &FourierSeries| FourierSeries {
        a0: q * f.a0 + t,
        cos: f.cos.iter().map(|c| q * c).collect(),
        sin: f.sin.iter().map(|c| q * c).collect(),
    };
    let mvd = |f: &FourierSeries| FourierSeries {
        a0: q * f.a0,
        cos: f.cos.iter().map(|c| q * c).collect(),
        sin: f.sin.iter().map(|c| q * c).collect(),
    };
    let op = Operator::polyharmonic(2, 2.0).unwrap();
    let s: Vec<FourierSeries> = (0..4).map(|i| series(20 + i, 6, 1.0)).collect();
    let ds = [0, 1, 0, 1];
    let us = [0.0, 0.0, 1.0, 1.0];
    let make = |f: &dyn Fn(&FourierSeries) -> FourierSeries,
                g: &dyn Fn(&FourierSeries) -> FourierSeries| {
        (0..4)
            .map(|i| {
                cond(
                    us[i],
                    ds[i],
                    Arc::new(if ds[i] == 0 { f(&s[i]) } else { g(&s[i]) }) as SharedCurve,
                )
            })
            .collect::<Vec<_>>()
    };
    let opts = SolveOptions {
        modes: 6,
        ..Default::default()
    };
    let p0 = solve(&op, make(&|f| f.clone(), &|f| f.clone()), &opts).unwrap();
    let p1 = solve(&op, make(&mv, &mvd), &opts).unwrap();
    for &(u, v) in &[(0.1, 0.2), (0.5, 3.0), (0.9, 6.0)] {
        let (a, b) = (p0.partials(u, v), p1.partials(u, v));
        assert!((q * a.x + t - b.x).norm() < 1e-13 * 8.0);
        assert!((q * a.normal() - b.normal()).norm() < 1e-12);
    }
}

#[test]
fn bad_condition_sets_are_refused() {
    let op = Operator::polyharmonic(2, 1.0).unwrap();
    let c = || circle(0.0, 1.0);
    let three = vec![cond(0.0, 0, c()), cond(1.0, 0, c()), cond(0.0, 1, c())];
    assert!(matches!(
        solve(&op, three, &SolveOptions::default()),
        Err(e) if e.kind() == crate::ErrorKind::NotUnique
    ));
    let twice = vec![
        cond(0.0, 0, c()),
        cond(1.0, 0, c()),
        cond(0.0, 1, c()),
        cond(1.0, 0, c()),
    ];
    let e = solve(&op, twice, &SolveOptions::default()).unwrap_err();
    assert!(e.to_string().contains("conditions[3]"), "{e}");
    let no_position = vec![
        cond(0.0, 1, c()),
        cond(1.0, 1, c()),
        cond(0.0, 2, c()),
        cond(1.0, 2, c()),
    ];
    let e = solve(&op, no_position, &SolveOptions::default()).unwrap_err();
    assert!(e.to_string().contains("singular"), "{e}");
    let outside = vec![
        cond(0.0, 0, c()),
        cond(1.5, 0, c()),
        cond(0.0, 1, c()),
        cond(1.0, 1, c()),
    ];
    assert!(solve(&op, outside, &SolveOptions::default())
        .unwrap_err()
        .to_string()
        .contains("conditions[1].u"));
    let too_high = vec![
        cond(0.0, 0, c()),
        cond(1.0, 0, c()),
        cond(0.0, 4, c()),
        cond(1.0, 1, c()),
    ];
    assert!(solve(&op, too_high, &SolveOptions::default()).is_err());
}

/// The Klein bottle of §4.6: 40 cross-sections, a 40th-order PDE. Polynomial interpolation at 40
/// equally spaced points has a Lebesgue constant near 2.5e9, so 6–7 digits is what double
/// precision allows; require 1e-6.
#[test]
fn klein_bottle_forty_sections() {
    let (alpha, beta) = (6.0, 16.0);
    let conds: Vec<Condition> = (0..40)
        .map(|k| {
            let uu = TAU * k as f64 / 39.0;
            let gamma = 4.0 * (1.0 - uu.cos() / 2.0);
            let center = Vec3::new(alpha * uu.cos() * (1.0 + uu.sin()), beta * uu.sin(), 0.0);
            let (a1, a2) = if uu < std::f64::consts::PI {
                (
                    Vec3::new(uu.cos(), uu.sin(), 0.0) * gamma,
                    Vec3::new(0.0, 0.0, gamma),
                )
            } else {
                (Vec3::new(-gamma, 0.0, 0.0), Vec3::new(0.0, 0.0, gamma))
            };
            cond(
                k as f64 / 39.0,
                0,
                Arc::new(Ellipse::new(center, a1, a2).unwrap()) as SharedCurve,
            )
        })
        .collect();
    let op = Operator::polyharmonic(20, 1.0).unwrap();
    let patch = solve(
        &op,
        conds,
        &SolveOptions {
            modes: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let err = max_relative_condition_error(&patch);
    assert!(err < 1e-6, "relative condition error {err:e}");
    for r in patch.mode_reports() {
        assert!(r.condition_number < 1e13, "{r:?}");
    }
}

/// Small `n|s|` uses the Chebyshev basis, large the layer basis; both give the same surface
/// where both are usable.
#[test]
fn basis_choice_follows_the_regime() {
    let op = Operator::polyharmonic(5, 0.1).unwrap();
    let m = 64;
    let conds = (0..10)
        .map(|i| {
            cond(
                i as f64 / 9.0,
                0,
                Arc::new(series(40 + i, m, 1.0)) as SharedCurve,
            )
        })
        .collect();
    let patch = solve(
        &op,
        conds,
        &SolveOptions {
            modes: m,
            ..Default::default()
        },
    )
    .unwrap();
    let reports = patch.mode_reports();
    assert_eq!(reports[0].basis, "chebyshev");
    assert_eq!(reports[1].basis, "chebyshev");
    assert_eq!(reports[64].basis, "exponential layers");
}

/// Relative residual of mode `n`'s equation `Σ_k c_k (−n²)^k f^{(2N−2k)}(u)` for both `Aₙ` and
/// `Bₙ`, relative to the size of its terms.
fn mode_equation_residual(patch: &PdePatch, n: usize, u: f64) -> f64 {
    let op = patch.operator();
    let nn = op.half_order();
    let (mut ra, mut rb, mut size) = (Vec3::zeros(), Vec3::zeros(), 0.0);
    for (k, &c) in op.coefficients().iter().enumerate() {
        let (a, b) = patch.mode(n, u, 2 * nn - 2 * k);
        let w = c * (-((n * n) as f64)).powi(k as i32);
        ra += a * w;
        rb += b * w;
        size += (a.norm() + b.norm()) * w.abs();
    }
    (ra.norm() + rb.norm()) / size.max(1e-300)
}

/// Intermediate position curves with many modes and large `a` are where the bases are pushed
/// hardest: every solution returned must solve the PDE mode by mode and meet its conditions;
/// where double precision cannot, the solver must refuse rather than return a wrong surface.
#[test]
fn solutions_are_pde_solutions_or_refused() {
    let mut solved = 0;
    for nn in [2usize, 5] {
        for &a in &[1.0, 3.0, 10.0] {
            for &m in &[12usize, 64] {
                let op = Operator::polyharmonic(nn, a).unwrap();
                let conds = (0..2 * nn)
                    .map(|i| {
                        cond(
                            i as f64 / (2 * nn - 1) as f64,
                            0,
                            Arc::new(series(60 + i as u64, m, 1.0)) as SharedCurve,
                        )
                    })
                    .collect();
                match solve(
                    &op,
                    conds,
                    &SolveOptions {
                        modes: m,
                        ..Default::default()
                    },
                ) {
                    Ok(patch) => {
                        solved += 1;
                        assert!(
                            max_relative_condition_error(&patch) < 1e-5,
                            "N={nn} a={a} M={m}"
                        );
                        for n in 0..=m {
                            for &u in &[0.0, 0.37, 1.0] {
                                let r = mode_equation_residual(&patch, n, u);
                                assert!(
                                    r < 1e-8,
                                    "N={nn} a={a} M={m}: mode {n} residual {r:e} at u={u}"
                                );
                            }
                        }
                    }
                    Err(e) => {
                        let text = e.to_string();
                        assert!(
                            text.contains("ill-conditioned") || text.contains("singular"),
                            "{text}"
                        );
                    }
                }
            }
        }
    }
    assert!(solved >= 4, "only {solved} of the designs were solved");
}

/// The Klein bottle's layout with many modes (N = 20, 40 evenly spaced sections, 64 modes):
/// modes beyond the Chebyshev regime must not come back with a wrong basis.
#[test]
fn high_order_with_many_modes_is_a_solution_or_refused() {
    let op = Operator::polyharmonic(20, 1.0).unwrap();
    let conds = (0..40)
        .map(|i| {
            cond(
                i as f64 / 39.0,
                0,
                Arc::new(series(200 + i as u64, 64, 1.0)) as SharedCurve,
            )
        })
        .collect();
    match solve(
        &op,
        conds,
        &SolveOptions {
            modes: 64,
            ..Default::default()
        },
    ) {
        Ok(patch) => {
            for n in [1usize, 10, 38, 64] {
                let r = mode_equation_residual(&patch, n, 0.5);
                assert!(r < 1e-8, "mode {n}: residual {r:e}");
            }
        }
        Err(e) => assert!(
            e.to_string().contains("ill-conditioned") || e.to_string().contains("singular"),
            "{e}"
        ),
    }
}

/// The joint evaluation of orders 0, 1, 2 that `partials` uses gives the values of three
/// separate evaluations bit for bit, in both bases, for the modes and the remainder; and
/// `point` gives `partials`' position bit for bit.
#[test]
fn joint_derivative_evaluation_is_bit_identical() {
    let mut kinds = Vec::new();
    let mut remainders = 0;
    for (nn, a, m, bumpy) in [
        (2usize, 2.0, 12usize, false),
        (3, 0.3, 8, false),
        (2, 1.0, 3, true),
    ] {
        let op = Operator::polyharmonic(nn, a).unwrap();
        let conds: Vec<Condition> = (0..2 * nn)
            .map(|i| {
                let u = i as f64 / (2 * nn - 1) as f64;
                let curve: SharedCurve = if bumpy {
                    Arc::new(Bumpy {
                        r: 1.0 + 0.3 * i as f64,
                        h: u,
                        b: 0.2,
                    })
                } else {
                    Arc::new(series(70 + i as u64, m, 1.0))
                };
                cond(u, 0, curve)
            })
            .collect();
        let patch = solve(
            &op,
            conds,
            &SolveOptions {
                modes: m,
                ..Default::default()
            },
        )
        .unwrap();
        // `point` is `partials`' position without the derivatives, bit for bit.
        for u in [0.0, 1e-3, 0.27, 0.5, 0.999, 1.0] {
            for v in [0.0, 0.7, 3.0, 6.2] {
                let (p, x) = (patch.point(u, v), patch.partials(u, v).x);
                let same = p
                    .iter()
                    .zip(x.iter())
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "u = {u}, v = {v}: point {p:?} vs partials {x:?}");
            }
        }
        remainders += usize::from(patch.remainder.is_some());
        let mut fns: Vec<&ModeFn> = patch.modes.iter().collect();
        if let Some(r) = &patch.remainder {
            fns.push(&r.cardinal);
        }
        for f in fns {
            kinds.push(f.basis.kind());
            let n = f.ncols();
            for u in [0.0, 1e-3, 0.27, 0.5, 0.999, 1.0] {
                let mut joint = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
                let [a, b, c] = &mut joint;
                f.eval012(u, [a, b, c]);
                for (d, got) in joint.iter().enumerate() {
                    let mut want = vec![0.0; n];
                    f.eval(u, d, &mut want);
                    let same = got
                        .iter()
                        .zip(&want)
                        .all(|(x, y)| x.to_bits() == y.to_bits());
                    assert!(same, "u = {u}, d = {d}: {got:?} vs {want:?}");
                }
            }
        }
    }
    assert!(kinds.contains(&BasisKind::Layers) && kinds.contains(&BasisKind::Chebyshev));
    assert!(remainders > 0, "no case had a spectral remainder");
}

/// A mode system whose SVD does not converge within the iteration cap is an error naming the
/// mode and the cap (the subnormal `a = 1e-320` once made this SVD run forever); an operator
/// whose characteristic roots do not converge is an error at `coefficients`.
#[test]
fn mode_systems_and_roots_past_the_iteration_cap_are_errors_naming_them() {
    let op = Operator::polyharmonic(2, 1.0).unwrap();
    let conds = vec![
        cond(0.0, 0, circle(0.0, 1.0)),
        cond(0.0, 1, circle(1.0, 0.5)),
        cond(1.0, 0, circle(1.0, 1.0)),
        cond(1.0, 1, circle(1.0, 0.5)),
    ];
    let e = crate::linalg::decomp::with_cap(1, || {
        solve(&op, conds.clone(), &SolveOptions::default()).unwrap_err()
    })
    .to_string();
    assert!(
        e.contains("the system for the spine (mode 0)")
            && e.contains("its singular values could not be computed within 1 sweeps"),
        "{e}"
    );
    // The same conditions solve with the cap of every run.
    assert!(solve(&op, conds, &SolveOptions::default()).is_ok());
    let coefficients = vec![1.0, 3.0, 4.0, 2.0, 5.0];
    assert!(Operator::general(coefficients.clone()).is_ok());
    let e = crate::linalg::decomp::with_cap(1, || Operator::general(coefficients).unwrap_err());
    assert_eq!(e.place(), "coefficients", "{e}");
    assert!(
        e.to_string()
            .contains("the roots of the characteristic equation could not be computed"),
        "{e}"
    );
}

/// The batched tangent solve equals solving each direction's curves on their own
/// ([`solve`] of the combination curves: the same mode systems, the same set-ups, one block of
/// right-hand sides instead of six columns each, so the same arithmetic per column), and the
/// derivative of a patch along an affine family of curves is the difference quotient of two
/// solves: the solution is linear in the curves, so `(X(p + h) − X(p))/h` is exact up to the
/// rounding of the two solves divided by `h` (relative `10⁻¹³ · |X|/h` here, well-conditioned
/// mode systems). Curves with and without exact Fourier series, so the remainder takes part.
#[test]
fn tangent_solves_equal_solves_of_the_tangent_curves() {
    let op = Operator::polyharmonic(2, 1.5).unwrap();
    let options = SolveOptions {
        modes: 4,
        ..Default::default()
    };
    let bumpy = |b: f64| -> SharedCurve { Arc::new(Bumpy { r: 0.8, h: 1.0, b }) };
    let at = |s: f64| {
        vec![
            cond(0.0, 0, circle(0.0, 1.0 + s)),
            cond(0.0, 1, circle(1.0, 0.5)),
            cond(1.0, 0, bumpy(0.2 + s)),
            cond(1.0, 1, circle(1.0 + 2.0 * s, 0.3)),
        ]
    };
    let base = solve(&op, at(0.0), &options).unwrap();
    assert!(base.has_remainder());
    let h = 0.25;
    let plus = solve(&op, at(h), &options).unwrap();
    let curves =
        |c: Vec<Condition>| -> Vec<SharedCurve> { c.into_iter().map(|c| c.curve).collect() };
    let (cp, c0) = (curves(at(h)), curves(at(0.0)));
    let difference: Vec<SharedCurve> = cp
        .iter()
        .zip(&c0)
        .map(|(p, b)| combination(vec![(1.0 / h, p.clone()), (-1.0 / h, b.clone())]))
        .collect();
    // A second direction: only the lower circle, an exact series.
    let lower: Vec<SharedCurve> = vec![
        circle(0.0, 1.0),
        combination(vec![(0.0, circle(1.0, 0.5))]),
        combination(vec![(0.0, bumpy(0.2))]),
        combination(vec![(0.0, circle(1.0, 0.3))]),
    ];
    let dirs = vec![difference.clone(), lower.clone()];
    let tangents = base.solve_tangents(&dirs, &options).unwrap();
    assert_eq!(tangents.len(), 2);
    assert!(tangents[0].has_remainder());
    assert!(!tangents[1].has_remainder());
    let alone: Vec<PdePatch> = dirs
        .iter()
        .map(|d| {
            let c = d
                .iter()
                .zip(base.conditions())
                .map(|(curve, c)| cond(c.u, c.derivative, curve.clone()))
                .collect();
            solve(&op, c, &options).unwrap()
        })
        .collect();
    let scale = base.scale();
    for i in 0..=6 {
        for j in 0..8 {
            let (u, v) = (i as f64 / 6.0, j as f64 * TAU / 8.0 + 0.1);
            for (t, a) in tangents.iter().zip(&alone) {
                let (pt, pa) = (t.partials(u, v), a.partials(u, v));
                for (x, y) in [
                    (pt.x, pa.x),
                    (pt.xu, pa.xu),
                    (pt.xv, pa.xv),
                    (pt.xuu, pa.xuu),
                ] {
                    assert!((x - y).norm() <= 1e-13 * scale, "{x:?} vs {y:?}");
                }
            }
            let (t, p, b) = (
                tangents[0].partials(u, v),
                plus.partials(u, v),
                base.partials(u, v),
            );
            for (x, (y, z)) in [
                (t.x, (p.x, b.x)),
                (t.xu, (p.xu, b.xu)),
                (t.xvv, (p.xvv, b.xvv)),
            ] {
                let q = (y - z) / h;
                assert!((x - q).norm() <= 1e-13 * scale / h, "{x:?} vs {q:?}");
            }
        }
    }
    // Directions of the wrong length are refused.
    assert!(base
        .solve_tangents(&[lower[..3].to_vec()], &options)
        .is_err());
}

/// The adjoint of a quadrature ([`PdePatch::quadrature_adjoint`]) against the same functional
/// summed node by node over each tangent's own partials. Both are the same finite sum of
/// products `G · ψ⁽ᵈ⁾(u) · coefficient · (n^k cos | sin)` (and `G · w⁽ᵈ⁾ · Δ⁽ᵏ⁾` for the remainder)
/// in different orders, so each is within `γ_N · A` of the exact sum (recursive summation of
/// `N` products of at most four rounded factors, Higham's `γ_N = Nε/(1 − Nε)`), with `A` the
/// sum of the products' magnitudes computed here from the bases' and cardinal functions' values;
/// `N` counts every product, a Chebyshev basis function counting its series' length (the
/// forward path sums the combined series by Clenshaw's recurrence).
#[test]
fn quadrature_adjoint_equals_the_functional_node_by_node() {
    let op = Operator::polyharmonic(2, 1.5).unwrap();
    let options = SolveOptions {
        modes: 4,
        ..Default::default()
    };
    let bumpy = |b: f64| -> SharedCurve { Arc::new(Bumpy { r: 0.8, h: 1.0, b }) };
    let base = solve(
        &op,
        vec![
            cond(0.0, 0, circle(0.0, 1.0)),
            cond(0.0, 1, circle(1.0, 0.5)),
            cond(1.0, 0, bumpy(0.2)),
            cond(1.0, 1, circle(1.0, 0.3)),
        ],
        &options,
    )
    .unwrap();
    assert!(base.has_remainder());
    let zero = |c: SharedCurve| combination(vec![(0.0, c)]);
    let dirs = vec![
        // A remainder (the bumpy curve) and every mode.
        vec![
            zero(circle(0.0, 1.0)),
            circle(0.3, 0.2),
            bumpy(0.5),
            Arc::new(FourierSeries {
                a0: Vec3::new(0.1, 0.2, 0.3),
                cos: (1..=4)
                    .map(|n| Vec3::new(0.3, -0.1, 0.2) / n as f64)
                    .collect(),
                sin: (1..=4)
                    .map(|n| Vec3::new(-0.2, 0.1, 0.4) / n as f64)
                    .collect(),
            }) as SharedCurve,
        ],
        // Exact series only: no remainder.
        vec![
            circle(0.0, 1.0),
            zero(circle(1.0, 0.5)),
            zero(bumpy(0.2)),
            circle(0.5, 0.7),
        ],
    ];
    let tangents = base.solve_tangents(&dirs, &options).unwrap();
    assert!(tangents[0].has_remainder() && !tangents[1].has_remainder());
    let us: Vec<f64> = (0..9).map(|a| (a as f64 + 0.5) / 9.0).collect();
    let vs: Vec<f64> = (0..16).map(|b| TAU * b as f64 / 16.0).collect();
    let outputs = 3;
    let g = |a: usize, b: usize, o: usize, q: usize| {
        let (u, v) = (us[a], vs[b]);
        ((1 + q + 3 * o) as f64 * 0.37 + u * (q as f64 + 1.0)).sin() * (v * (o + 1) as f64).cos()
            + 0.1 * (q as f64 - 8.0) * u
    };
    let weights = |a: usize, row: &mut [f64]| {
        for b in 0..vs.len() {
            for o in 0..outputs {
                for q in 0..NODE_WEIGHTS {
                    row[(b * outputs + o) * NODE_WEIGHTS + q] = g(a, b, o, q);
                }
            }
        }
    };
    let list: Vec<AdjointTangent> = tangents
        .iter()
        .map(|patch| AdjointTangent {
            patch,
            stretch: 0.0,
        })
        .collect();
    let adjoint = base
        .quadrature_adjoint(&us, &vs, outputs, &weights, &list)
        .unwrap();
    let eps = f64::EPSILON;
    for (t, adj) in tangents.iter().zip(&adjoint) {
        // The node-by-node sums, and the magnitudes of their products.
        let mut forward = vec![0.0; outputs];
        let mut magnitude = vec![0.0; outputs];
        let mut terms = 0usize;
        for (a, &u) in us.iter().enumerate() {
            // |Σ_j ψ_j^{(d)} coef_j| ≤ Σ_j |ψ_j^{(d)}| |coef_j| per mode, derivative and column.
            let mut bound = vec![[[0.0f64; 6]; 3]; t.modes.len()];
            for (n, mode) in t.modes.iter().enumerate() {
                let len = mode.basis.len();
                let mut phi = vec![0.0; len];
                for (d, bd) in bound[n].iter_mut().enumerate() {
                    mode.basis.eval(u, d, &mut phi);
                    for (c, x) in bd.iter_mut().enumerate() {
                        *x = (0..len)
                            .map(|j| phi[j].abs() * mode.coef[(j, c)].abs())
                            .sum();
                    }
                }
                terms += match &mode.basis {
                    basis::Basis::Chebyshev { series, .. } => series.iter().map(Vec::len).sum(),
                    basis::Basis::Layers(_) => len,
                } * 6;
            }
            for (b, &v) in vs.iter().enumerate() {
                let p = t.partials(u, v);
                let parts = [p.x, p.xu, p.xv, p.xuu, p.xuv, p.xvv];
                // (u-derivative, power of n) of each partial.
                let orders = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
                for o in 0..outputs {
                    for (k, (part, (d, e))) in parts.iter().zip(orders).enumerate() {
                        let mut size = Vec3::zeros();
                        for (n, bn) in bound.iter().enumerate() {
                            let f = (n as f64).powi(e);
                            for c in 0..3 {
                                size[c] += f * (bn[d][c] + bn[d][3 + c]);
                            }
                        }
                        if let Some(r) = &t.remainder {
                            let mut w = vec![0.0; t.conditions().len()];
                            r.cardinal.eval(u, d, &mut w);
                            for (i, wi) in w.iter().enumerate() {
                                let dl = r.delta(t.conditions(), i, v, 2)[e as usize];
                                size += dl.abs() * wi.abs();
                            }
                        }
                        for c in 0..3 {
                            let gq = g(a, b, o, 3 * k + c);
                            forward[o] += gq * part[c];
                            magnitude[o] += gq.abs() * size[c];
                        }
                    }
                }
            }
        }
        let n_terms = (terms + 4 * t.conditions().len()) * vs.len() * 3 + 4;
        let gamma = n_terms as f64 * eps / (1.0 - n_terms as f64 * eps);
        for o in 0..outputs {
            let bound = 2.0 * gamma * magnitude[o];
            assert!(
                (adj[o] - forward[o]).abs() <= bound,
                "{o}: adjoint {} forward {} bound {bound}",
                adj[o],
                forward[o]
            );
            assert!(
                forward[o].abs() > 1e3 * bound,
                "{o}: a functional near zero"
            );
        }
    }
}

/// [`PdePatch::quadrature_adjoint_using`] with a subset of the partials (a boundary row's `X`,
/// `X_v`): the same sums as [`PdePatch::quadrature_adjoint`] of weights that are zero on the
/// other partials, in the same order, so the same bits, whatever the callback writes into the
/// places of the partials it does not use; with a remainder and a stretched tangent.
#[test]
fn quadrature_adjoint_using_a_subset_equals_zero_weights_elsewhere() {
    let op = Operator::polyharmonic(2, 1.5).unwrap();
    let options = SolveOptions {
        modes: 4,
        ..Default::default()
    };
    let bumpy = |b: f64| -> SharedCurve { Arc::new(Bumpy { r: 0.8, h: 1.0, b }) };
    let base = solve(
        &op,
        vec![
            cond(0.0, 0, circle(0.0, 1.0)),
            cond(0.0, 1, circle(1.0, 0.5)),
            cond(1.0, 0, bumpy(0.2)),
            cond(1.0, 1, circle(1.0, 0.3)),
        ],
        &options,
    )
    .unwrap();
    let dirs = vec![
        vec![
            circle(0.1, 0.4),
            circle(0.3, 0.2),
            bumpy(0.5),
            circle(0.5, 0.7),
        ],
        vec![
            circle(0.0, 1.0),
            circle(1.0, 0.5),
            circle(0.2, 0.2),
            circle(0.5, 0.7),
        ],
    ];
    let tangents = base.solve_tangents(&dirs, &options).unwrap();
    assert!(base.has_remainder() && tangents[0].has_remainder());
    let us = [0.0, 0.37, 1.0];
    let vs: Vec<f64> = (0..64).map(|b| TAU * b as f64 / 64.0).collect();
    let uses = [Partial::X, Partial::Xv];
    let kept = |q: usize| q < 3 || (6..9).contains(&q);
    let vs = &vs;
    let g = move |a: usize, b: usize, q: usize| ((1 + q + 5 * a) as f64 * 0.37 + vs[b]).sin();
    let with = move |zero_others: bool| {
        move |a: usize, row: &mut [f64]| {
            for b in 0..vs.len() {
                for q in 0..NODE_WEIGHTS {
                    row[b * NODE_WEIGHTS + q] = if kept(q) || !zero_others {
                        g(a, b, q)
                    } else {
                        0.0
                    };
                }
            }
        }
    };
    let list: Vec<AdjointTangent> = tangents
        .iter()
        .zip([0.0, 0.8])
        .map(|(patch, stretch)| AdjointTangent { patch, stretch })
        .collect();
    let full = base
        .quadrature_adjoint(&us, vs, 1, &with(true), &list)
        .unwrap();
    let subset = base
        .quadrature_adjoint_using(&us, vs, 1, &uses, &with(false), &list)
        .unwrap();
    assert_eq!(full, subset);
    assert!(full.iter().all(|d| d[0].abs() > 1e-3), "{full:?}");
    // The weights of the other partials do count in the full adjoint.
    let all = base
        .quadrature_adjoint(&us, vs, 1, &with(false), &list)
        .unwrap();
    assert!(all.iter().zip(&full).all(|(a, f)| a[0] != f[0]));
}

/// The derivative with respect to the smoothing parameter, `(1/a) u X_u + T`
/// ([`PdePatch::smoothing_tangent_curves`]), against central differences of solves at `a ± h`:
/// `D(h) = (X(a + h) − X(a − h))/(2h)` errs by the truncation `h²/6 |X'''|` (with `X'''` estimated
/// by the third difference `(X(a + 2h) − 2X(a + h) + 2X(a − h) − X(a − 2h))/(2h³)`) plus the
/// rounding of the solves (relative `10⁻¹³` of the design's size each, as in the tangent test
/// above) divided by `h`; the estimate's own rounding (`6 · 10⁻¹³ · size/(2h³) · h²/6`) is of the
/// same order and counted in. Biharmonic with and without a remainder, and a triharmonic patch
/// with second-derivative conditions.
#[test]
fn smoothing_derivative_matches_central_differences() {
    let options = SolveOptions {
        modes: 4,
        ..Default::default()
    };
    let bumpy: SharedCurve = Arc::new(Bumpy {
        r: 0.8,
        h: 1.0,
        b: 0.2,
    });
    let shifted = |z: f64, r: f64, dx: f64| -> SharedCurve {
        Arc::new(
            Ellipse::new(
                Vec3::new(dx, 0.1, z),
                Vec3::new(r, 0.2 * r, 0.0),
                Vec3::new(0.0, r, 0.3 * r),
            )
            .unwrap(),
        )
    };
    let cases: Vec<(usize, Vec<Condition>)> = vec![
        (
            2,
            vec![
                cond(0.0, 0, shifted(0.0, 1.0, 0.0)),
                cond(0.0, 1, shifted(1.0, 0.5, 0.2)),
                cond(1.0, 0, shifted(1.0, 0.7, -0.1)),
                cond(1.0, 1, shifted(1.0, 0.3, 0.0)),
            ],
        ),
        (
            2,
            vec![
                cond(0.0, 0, shifted(0.0, 1.0, 0.0)),
                cond(0.0, 1, shifted(1.0, 0.5, 0.2)),
                cond(1.0, 0, bumpy.clone()),
                cond(1.0, 1, shifted(1.0, 0.3, 0.0)),
            ],
        ),
        (
            3,
            vec![
                cond(0.0, 0, shifted(0.0, 1.0, 0.0)),
                cond(0.0, 1, shifted(1.0, 0.5, 0.2)),
                cond(0.0, 2, shifted(0.3, 0.4, 0.1)),
                cond(1.0, 0, shifted(1.0, 0.7, -0.1)),
                cond(1.0, 1, shifted(1.0, 0.3, 0.0)),
                cond(1.0, 2, shifted(-0.2, 0.2, 0.0)),
            ],
        ),
    ];
    for (case, (order, conditions)) in cases.into_iter().enumerate() {
        let a = 1.2;
        let at = |a: f64| {
            solve(
                &Operator::polyharmonic(order, a).unwrap(),
                conditions.clone(),
                &options,
            )
            .unwrap()
        };
        let base = Arc::new(at(a));
        assert_eq!(base.has_remainder(), case == 1);
        let (s, curves) = base.smoothing_tangent_curves().unwrap();
        assert_eq!(s, 1.0 / a);
        let t = base.solve_tangents(&[curves], &options).unwrap().remove(0);
        let h = 1e-3 * a;
        let x: Vec<PdePatch> = [-2.0, -1.0, 1.0, 2.0]
            .iter()
            .map(|k| at(a + k * h))
            .collect();
        let size = base.scale();
        for i in 0..=6 {
            for j in 0..7 {
                let (u, v) = (i as f64 / 6.0, j as f64 * TAU / 7.0 + 0.2);
                let (pb, pt) = (base.partials(u, v), t.partials(u, v));
                let exact = [
                    pb.xu * (s * u) + pt.x,
                    (pb.xu + pb.xuu * u) * s + pt.xu,
                    pb.xuv * (s * u) + pt.xv,
                ];
                let p: Vec<Partials> = x.iter().map(|x| x.partials(u, v)).collect();
                let parts = |p: &Partials| [p.x, p.xu, p.xv];
                for (c, exact) in exact.iter().enumerate() {
                    let (m2, m1, p1, p2) = (
                        parts(&p[0])[c],
                        parts(&p[1])[c],
                        parts(&p[2])[c],
                        parts(&p[3])[c],
                    );
                    let d = (p1 - m1) / (2.0 * h);
                    let third = (p2 - p1 * 2.0 + m1 * 2.0 - m2) / (2.0 * h * h * h);
                    let bound = 2.0 * h * h / 6.0 * third.norm() + 4.0 * 1e-13 * size / h;
                    let err = (exact - d).norm();
                    assert!(
                        err <= bound,
                        "case {case}, ({u}, {v}), partial {c}: {exact:?} vs {d:?} ({err:e} > {bound:e})",
                    );
                }
            }
        }
    }
}
