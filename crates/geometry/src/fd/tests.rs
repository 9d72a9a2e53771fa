use super::*;
use std::f64::consts::FRAC_PI_2;

/// `amp · sin(κu + φ) · cos(mv + ψ)` in component `c`: `L = ∂uu + a²∂vv` maps it to
/// `−(κ² + a²m²)` times itself, so `L^N` of a sum of such terms is known exactly.
#[derive(Clone, Copy)]
struct Term {
    c: usize,
    amp: f64,
    kappa: f64,
    phi: f64,
    m: f64,
    psi: f64,
}

const fn t(c: usize, amp: f64, kappa: f64, phi: f64, m: f64, psi: f64) -> Term {
    Term {
        c,
        amp,
        kappa,
        phi,
        m,
        psi,
    }
}

/// A smooth surface periodic in `v`, nontrivial in every component.
const PERIODIC: [Term; 6] = [
    t(0, 1.0, 1.3, 0.4, 1.0, 0.0),
    t(0, 0.5, 2.0, 1.0, 2.0, 0.3),
    t(1, 1.0, 0.9, 1.1, 1.0, -FRAC_PI_2),
    t(1, 0.3, 2.5, 0.0, 3.0, 0.0),
    t(2, 1.0, 1.7, 0.2, 0.0, 0.0),
    t(2, 0.2, 1.0, 0.5, 2.0, 1.0),
];

/// For the four-sided patch on `[0, 1] × [0, 1]`: non-integer wave numbers in `v` too.
const FOUR_SIDED: [Term; 5] = [
    t(0, 1.0, 1.3, 0.4, 1.1, 0.2),
    t(0, 0.5, 2.0, 1.0, 0.0, 0.0),
    t(1, 1.0, 0.9, 1.1, 1.7, -0.5),
    t(2, 1.0, 0.0, FRAC_PI_2, 2.3, 0.1),
    t(2, 0.4, 2.2, 0.3, 0.6, 1.3),
];

/// `∂u^du ∂v^dv` of the sum of terms.
fn eval(terms: &[Term], u: f64, v: f64, du: usize, dv: usize) -> Vec3 {
    let mut out = Vec3::zeros();
    for tm in terms {
        let fu = tm.kappa.powi(du as i32) * (tm.kappa * u + tm.phi + du as f64 * FRAC_PI_2).sin();
        let fv = tm.m.powi(dv as i32) * (tm.m * v + tm.psi + dv as f64 * FRAC_PI_2).cos();
        out[tm.c] += tm.amp * fu * fv;
    }
    out
}

/// `(∂uu + a²∂vv)^N` of the sum of terms.
fn source_of(terms: &[Term], n: usize, a: f64, u: f64, v: f64) -> Vec3 {
    let mut out = Vec3::zeros();
    for tm in terms {
        let lam = -(tm.kappa * tm.kappa + a * a * tm.m * tm.m);
        let val = (tm.kappa * u + tm.phi).sin() * (tm.m * v + tm.psi).cos();
        out[tm.c] += tm.amp * lam.powi(n as i32) * val;
    }
    out
}

/// Largest node error of the periodic problem with the manufactured solution.
fn periodic_error(n: usize, a: f64, nu: usize, nv: usize) -> f64 {
    let tr = &PERIODIC;
    let starts: Vec<Box<dyn Fn(f64) -> Vec3 + Sync>> = (0..n)
        .map(|d| Box::new(move |v| eval(tr, 0.0, v, d, 0)) as Box<dyn Fn(f64) -> Vec3 + Sync>)
        .collect();
    let ends: Vec<Box<dyn Fn(f64) -> Vec3 + Sync>> = (0..n)
        .map(|d| Box::new(move |v| eval(tr, 1.0, v, d, 0)) as Box<dyn Fn(f64) -> Vec3 + Sync>)
        .collect();
    let f = move |u: f64, v: f64| source_of(tr, n, a, u, v);
    let s = solve_periodic(&PeriodicProblem {
        order: n,
        a,
        nu,
        nv,
        start: starts.iter().map(|b| &**b as EdgeFn<'_>).collect(),
        end: ends.iter().map(|b| &**b as EdgeFn<'_>).collect(),
        source: Some(&f),
    })
    .expect("solves");
    let mut err: f64 = 0.0;
    for i in 0..=nu {
        for j in 0..s.nodes_v() {
            let (u, v) = (s.u_node(i), s.v_node(j));
            err = err.max((s.node(i, j) - eval(tr, u, v, 0, 0)).norm());
        }
    }
    err
}

type Boxed = Box<dyn Fn(f64) -> Vec3 + Sync>;

fn refs(b: &[Boxed]) -> Vec<EdgeFn<'_>> {
    b.iter().map(|f| &**f as EdgeFn<'_>).collect()
}

type FourSidedSolver = fn(&FourSidedProblem<'_>) -> Result<FdSurface>;

fn four_sided_surface(n: usize, a: f64, nu: usize, nv: usize) -> FdSurface {
    four_sided_surface_with(n, a, nu, nv, solve_four_sided)
}

fn four_sided_surface_with(
    n: usize,
    a: f64,
    nu: usize,
    nv: usize,
    solver: FourSidedSolver,
) -> FdSurface {
    let tr = &FOUR_SIDED;
    let side = |fixed_u: Option<f64>, fixed_v: Option<f64>| -> Vec<Boxed> {
        (0..n)
            .map(|d| -> Boxed {
                match (fixed_u, fixed_v) {
                    (Some(u), _) => Box::new(move |v| eval(tr, u, v, d, 0)),
                    (_, Some(v)) => Box::new(move |u| eval(tr, u, v, 0, d)),
                    _ => unreachable!(),
                }
            })
            .collect()
    };
    let (u0, u1, v0, v1) = (
        side(Some(0.0), None),
        side(Some(1.0), None),
        side(None, Some(0.0)),
        side(None, Some(1.0)),
    );
    let f = move |u: f64, v: f64| source_of(tr, n, a, u, v);
    solver(&FourSidedProblem {
        order: n,
        a,
        nu,
        nv,
        v_range: (0.0, 1.0),
        u0: refs(&u0),
        u1: refs(&u1),
        v0: refs(&v0),
        v1: refs(&v1),
        source: Some(&f),
    })
    .expect("solves")
}

fn four_sided_error(n: usize, a: f64, nu: usize, nv: usize) -> f64 {
    four_sided_error_with(n, a, nu, nv, solve_four_sided)
}

fn four_sided_error_with(n: usize, a: f64, nu: usize, nv: usize, solver: FourSidedSolver) -> f64 {
    let s = four_sided_surface_with(n, a, nu, nv, solver);
    let mut err: f64 = 0.0;
    for i in 0..=nu {
        for j in 0..s.nodes_v() {
            let (u, v) = (s.u_node(i), s.v_node(j));
            err = err.max((s.node(i, j) - eval(&FOUR_SIDED, u, v, 0, 0)).norm());
        }
    }
    err
}

/// Observed orders `log2(e_h / e_{h/2})` over three grids.
fn orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

#[test]
fn manufactured_solution_is_reproduced_by_the_formulas() {
    // The test's own derivatives agree with finite differences of its evaluator.
    let (u, v, e) = (0.3, 0.7, 1e-5);
    for terms in [&PERIODIC[..], &FOUR_SIDED[..]] {
        let fu = (eval(terms, u + e, v, 0, 0) - eval(terms, u - e, v, 0, 0)) / (2.0 * e);
        let fv = (eval(terms, u, v + e, 0, 0) - eval(terms, u, v - e, 0, 0)) / (2.0 * e);
        assert!((fu - eval(terms, u, v, 1, 0)).norm() < 1e-9);
        assert!((fv - eval(terms, u, v, 0, 1)).norm() < 1e-9);
        let lap = eval(terms, u, v, 2, 0) + eval(terms, u, v, 0, 2) * 4.0;
        assert!((lap - source_of(terms, 1, 2.0, u, v)).norm() < 1e-12);
    }
}

#[test]
fn periodic_scheme_is_second_order_for_n_1_2_3() {
    for (n, a) in [(1, 1.0), (2, 0.7), (3, 1.0)] {
        let e: Vec<f64> = [8, 16, 32]
            .iter()
            .map(|&k| periodic_error(n, a, k, 2 * k))
            .collect();
        let o = orders(&e);
        eprintln!("N = {n}: errors {e:?}, orders {o:?}");
        assert!(
            o.iter().all(|&o| o >= 1.8),
            "N = {n}: errors {e:?}, orders {o:?}"
        );
    }
}

#[test]
fn four_sided_scheme_is_second_order_for_n_1_2_3() {
    for (n, a) in [(1, 1.0), (2, 1.5), (3, 1.0)] {
        let e: Vec<f64> = [8, 16, 32]
            .iter()
            .map(|&k| four_sided_error(n, a, k, k))
            .collect();
        let o = orders(&e);
        eprintln!("N = {n}: errors {e:?}, orders {o:?}");
        assert!(
            o.iter().all(|&o| o >= 1.8),
            "N = {n}: errors {e:?}, orders {o:?}"
        );
    }
}

#[test]
fn interpolant_meets_the_nodes_and_has_consistent_partials() {
    let s = four_sided_surface(2, 1.0, 16, 12);
    assert_eq!(s.v_domain(), VDomain::Interval(0.0, 1.0));
    for (i, j) in [(0, 0), (3, 5), (16, 12), (9, 1)] {
        let p = s.partials(s.u_node(i), s.v_node(j));
        assert!((p.x - s.node(i, j)).norm() < 1e-14);
    }
    // Partials of the interpolant agree with its own finite differences.
    let (u, v, e) = (0.37, 0.61, 1e-6);
    let p = s.partials(u, v);
    let d = |du: f64, dv: f64| s.partials(u + du, v + dv);
    assert!(((d(e, 0.0).x - d(-e, 0.0).x) / (2.0 * e) - p.xu).norm() < 1e-7);
    assert!(((d(0.0, e).x - d(0.0, -e).x) / (2.0 * e) - p.xv).norm() < 1e-7);
    assert!(((d(e, 0.0).xu - d(-e, 0.0).xu) / (2.0 * e) - p.xuu).norm() < 1e-6);
    assert!(((d(0.0, e).xv - d(0.0, -e).xv) / (2.0 * e) - p.xvv).norm() < 1e-6);
    assert!(((d(0.0, e).xu - d(0.0, -e).xu) / (2.0 * e) - p.xuv).norm() < 1e-6);
    // Between the nodes the surface is as accurate as at them (O(h²) + O(h⁴)).
    let mut err: f64 = 0.0;
    for k in 0..50 {
        let (u, v) = (0.013 + 0.0191 * k as f64, 0.97 - 0.0187 * k as f64);
        err = err.max((s.point(u, v) - eval(&FOUR_SIDED, u, v, 0, 0)).norm());
    }
    let node_err = four_sided_error(2, 1.0, 16, 12);
    assert!(
        err < 2.0 * node_err,
        "between nodes {err:e}, at nodes {node_err:e}"
    );
}

#[test]
fn stencils_are_powers_of_the_five_point_laplacian() {
    assert_eq!(second_difference_power(1), vec![1.0, -2.0, 1.0]);
    assert_eq!(second_difference_power(2), vec![1.0, -4.0, 6.0, -4.0, 1.0]);
    let st = stencil(2, 1.0, 0.1, 0.1);
    assert_eq!(st.len(), 13);
    let centre = st.iter().find(|e| e.0 == 0 && e.1 == 0).unwrap().2;
    assert_eq!(centre, 20.0);
    assert_eq!(stencil(3, 1.0, 0.1, 0.1).len(), 25);
    // Every stencil annihilates constants.
    for n in 1..=3 {
        let s: f64 = stencil(n, 0.8, 0.1, 0.2).iter().map(|e| e.2).sum();
        assert!(s.abs() < 1e-12, "N = {n}: {s}");
    }
}

#[test]
fn bad_input_is_refused_with_its_place() {
    let zero = |_: f64| Vec3::zeros();
    let nan = |_: f64| Vec3::new(f64::NAN, 0.0, 0.0);
    let base = PeriodicProblem {
        order: 2,
        a: 1.0,
        nu: 16,
        nv: 16,
        start: vec![&zero, &zero],
        end: vec![&zero, &zero],
        source: None,
    };
    let place = |p: &PeriodicProblem<'_>| solve_periodic(p).unwrap_err().place().to_string();
    assert_eq!(
        place(&PeriodicProblem {
            nu: 3,
            ..base.clone()
        }),
        "nu"
    );
    assert_eq!(
        place(&PeriodicProblem {
            nv: 4,
            ..base.clone()
        }),
        "nv"
    );
    assert_eq!(
        place(&PeriodicProblem {
            a: 0.0,
            ..base.clone()
        }),
        "a"
    );
    assert_eq!(
        place(&PeriodicProblem {
            a: f64::NAN,
            ..base.clone()
        }),
        "a"
    );
    assert_eq!(
        place(&PeriodicProblem {
            a: -1.0,
            ..base.clone()
        }),
        "a"
    );
    assert_eq!(
        place(&PeriodicProblem {
            order: 0,
            ..base.clone()
        }),
        "order"
    );
    assert_eq!(
        place(&PeriodicProblem {
            order: 4,
            ..base.clone()
        }),
        "order"
    );
    assert_eq!(
        place(&PeriodicProblem {
            start: vec![&zero],
            ..base.clone()
        }),
        "start"
    );
    let e = solve_periodic(&PeriodicProblem {
        end: vec![&zero, &nan],
        ..base.clone()
    })
    .unwrap_err();
    assert_eq!(e.place(), "end[1]");
    assert!(e.to_string().contains("not finite"), "{e}");
    let huge = solve_periodic(&PeriodicProblem {
        nu: 1 << 12,
        nv: 1 << 12,
        ..base.clone()
    })
    .unwrap_err();
    assert_eq!(huge.place(), "nu × nv");
    // Four-sided: sides that do not meet at a corner.
    let one = |_: f64| Vec3::new(1.0, 0.0, 0.0);
    let e = solve_four_sided(&FourSidedProblem {
        order: 1,
        a: 1.0,
        nu: 8,
        nv: 8,
        v_range: (0.0, 1.0),
        u0: vec![&zero],
        u1: vec![&zero],
        v0: vec![&zero],
        v1: vec![&one],
        source: None,
    })
    .unwrap_err();
    assert_eq!(e.place(), "v1[0]");
    let e = solve_four_sided(&FourSidedProblem {
        order: 1,
        a: 1.0,
        nu: 8,
        nv: 8,
        v_range: (1.0, 1.0),
        u0: vec![&zero],
        u1: vec![&zero],
        v0: vec![&zero],
        v1: vec![&zero],
        source: None,
    })
    .unwrap_err();
    assert_eq!(e.place(), "v_range");
}

/// A plane is reproduced to rounding (the scheme is exact for linear data) in both settings.
#[test]
fn linear_data_are_reproduced_to_rounding() {
    let plane = |u: f64, v: f64| Vec3::new(u, v, 2.0 * u - 0.5 * v + 1.0);
    let f = [&(move |v: f64| plane(0.0, v)) as EdgeFn<'_>, &|_: f64| {
        Vec3::new(1.0, 0.0, 2.0)
    }];
    let g = [&(move |v: f64| plane(1.0, v)) as EdgeFn<'_>, &|_: f64| {
        Vec3::new(1.0, 0.0, 2.0)
    }];
    let h = [&(move |u: f64| plane(u, 0.0)) as EdgeFn<'_>, &|_: f64| {
        Vec3::new(0.0, 1.0, -0.5)
    }];
    let k = [&(move |u: f64| plane(u, 2.0)) as EdgeFn<'_>, &|_: f64| {
        Vec3::new(0.0, 1.0, -0.5)
    }];
    let s = solve_four_sided(&FourSidedProblem {
        order: 2,
        a: 0.8,
        nu: 10,
        nv: 12,
        v_range: (0.0, 2.0),
        u0: f.to_vec(),
        u1: g.to_vec(),
        v0: h.to_vec(),
        v1: k.to_vec(),
        source: None,
    })
    .unwrap();
    // Rounding: the scaled system's condition number grows like (nu)^{2N} ≈ 1e4 here, times
    // ε ≈ 2e-16 and |X| ≈ 3.
    for i in 0..=10 {
        for j in 0..=12 {
            let e = (s.node(i, j) - plane(s.u_node(i), s.v_node(j))).norm();
            assert!(e < 1e-11, "{i} {j}: {e:e}");
        }
    }
    assert!((s.point(0.33, 1.21) - plane(0.33, 1.21)).norm() < 1e-11);
}

/// The FFT-banded solver and the sparse LU of the whole system give the same discrete solution:
/// every node agrees to `1e-12` of the solution's size, for `N = 1, 2, 3`, odd and even `nv`,
/// with a source term and with data that are not band-limited. The sparse solve's own rounding is
/// about `κ ε`; the mode systems' condition numbers grow like `nu^{2N}` (≈ 1e7 for `N = 3`,
/// `nu = 16`), so the grids are kept small enough for `κ ε` to stay below the tolerance.
#[test]
fn fft_periodic_solver_equals_the_sparse_one() {
    let tr = &PERIODIC;
    for (n, a, nu, nv) in [
        (1, 0.7, 24, 33),
        (1, 2.0, 40, 64),
        (2, 1.0, 20, 32),
        (2, 0.4, 17, 25),
        (3, 1.3, 16, 24),
        (3, 0.8, 15, 19),
    ] {
        // Non-band-limited data: an exponential of the sum of terms.
        let starts: Vec<Boxed> = (0..n)
            .map(|d| -> Boxed {
                Box::new(move |v: f64| eval(tr, 0.0, v, d, 0).map(|c| (0.5 * c).exp()))
            })
            .collect();
        let ends: Vec<Boxed> = (0..n)
            .map(|d| -> Boxed {
                Box::new(move |v: f64| eval(tr, 1.0, v, d, 0) + eval(tr, 0.5, v, 0, 0))
            })
            .collect();
        let f = move |u: f64, v: f64| {
            source_of(tr, n, a, u, v) + Vec3::new(u * v.sin(), 1.0, v.cos().exp())
        };
        let problem = PeriodicProblem {
            order: n,
            a,
            nu,
            nv,
            start: refs(&starts),
            end: refs(&ends),
            source: Some(&f),
        };
        let fast = solve_periodic(&problem).expect("solves");
        let reference = solve_periodic_sparse(&problem).expect("solves");
        assert_eq!(fast.stats(), reference.stats(), "N = {n}");
        let mut size: f64 = 0.0;
        let mut diff: f64 = 0.0;
        for i in 0..=nu {
            for j in 0..nv {
                size = size.max(reference.node(i, j).amax());
                diff = diff.max((fast.node(i, j) - reference.node(i, j)).amax());
            }
        }
        assert!(
            diff <= 1e-12 * size,
            "N = {n}, a = {a}, {nu} × {nv}: {diff:e} of {size:e}"
        );
        // Both really solve: the reference is not the trivial solution.
        assert!(size > 0.1);
    }
}

/// The sine-transform solver and the sparse LU of the whole system give the same discrete
/// solution for `N = 1, 2`: every node agrees to `1e-12` of the solution's size, on square and
/// oblong grids, odd and even sizes, `a ≠ 1`, a `v` range other than `[0, 1]`, with a source
/// term and with data that are not the trace of a smooth solution. The sparse solve's own
/// rounding is about `κ ε` with `κ ≈ nu^{2N}`, so the grids stay moderate.
#[test]
fn fast_four_sided_solver_equals_the_sparse_one() {
    let tr = &FOUR_SIDED;
    for (n, a, nu, nv, v1) in [
        (1, 1.0, 8, 8, 1.0),
        (1, 0.7, 24, 17, 2.5),
        (1, 2.0, 40, 64, 1.0),
        (2, 1.0, 4, 4, 1.0),
        (2, 1.0, 16, 16, 1.0),
        (2, 1.5, 20, 13, 1.0),
        (2, 0.6, 13, 30, 3.0),
        (2, 1.0, 32, 32, 1.0),
    ] {
        // Sides: the trace of the manufactured solution plus terms that vanish at the corners
        // (so the corner values still agree) and are not the trace of any smooth solution.
        let bump = |t: f64, w: f64| (t * (w - t)).powi(2) * (3.0 * t).exp();
        let side = |fixed_u: Option<f64>, fixed_v: Option<f64>| -> Vec<Boxed> {
            (0..n)
                .map(|d| -> Boxed {
                    match (fixed_u, fixed_v) {
                        (Some(u), _) => Box::new(move |v| {
                            eval(tr, u, v, d, 0) + Vec3::new(bump(v, v1), 0.3 * u, -bump(v, v1))
                        }),
                        (_, Some(v)) => Box::new(move |u| {
                            eval(tr, u, v, 0, d)
                                + Vec3::new(
                                    0.0,
                                    0.3 * u * (d == 0) as u8 as f64 + bump(u, 1.0),
                                    v * bump(u, 1.0),
                                )
                        }),
                        _ => unreachable!(),
                    }
                })
                .collect()
        };
        let (u0, u1, v0, v1s) = (
            side(Some(0.0), None),
            side(Some(1.0), None),
            side(None, Some(0.0)),
            side(None, Some(v1)),
        );
        let f = move |u: f64, v: f64| {
            source_of(tr, n, a, u, v) + Vec3::new(u * v.sin(), 1.0, (v - u).cos().exp())
        };
        let problem = FourSidedProblem {
            order: n,
            a,
            nu,
            nv,
            v_range: (0.0, v1),
            u0: refs(&u0),
            u1: refs(&u1),
            v0: refs(&v0),
            v1: refs(&v1s),
            source: Some(&f),
        };
        let fast = solve_four_sided(&problem).expect("solves");
        let reference = solve_four_sided_sparse(&problem).expect("solves");
        assert_eq!(fast.stats(), reference.stats(), "N = {n}");
        let mut size: f64 = 0.0;
        let mut diff: f64 = 0.0;
        for i in 0..=nu {
            for j in 0..=nv {
                size = size.max(reference.node(i, j).amax());
                diff = diff.max((fast.node(i, j) - reference.node(i, j)).amax());
            }
        }
        eprintln!("N = {n}, a = {a}, {nu} × {nv}: {diff:e} of {size:e}");
        assert!(
            diff <= 1e-12 * size,
            "N = {n}, a = {a}, {nu} × {nv}: {diff:e} of {size:e}"
        );
        assert!(size > 0.1);
    }
}

/// The sparse reference gives the same errors as the fast solver on the convergence test's
/// problems (so the same orders, `four_sided_scheme_is_second_order_for_n_1_2_3`).
#[test]
fn sparse_four_sided_reference_has_the_same_errors() {
    for (n, a) in [(1, 1.0), (2, 1.5)] {
        for k in [8, 16, 32] {
            let fast = four_sided_error_with(n, a, k, k, solve_four_sided);
            let sparse = four_sided_error_with(n, a, k, k, solve_four_sided_sparse);
            assert!(
                (sparse - fast).abs() <= 1e-9 * sparse,
                "N = {n}, {k}²: sparse {sparse:e}, fast {fast:e}"
            );
        }
    }
}
