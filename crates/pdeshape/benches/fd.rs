//! The finite-difference biharmonic patch on a 256 × 256 grid (issue 5): `Δ²X = 0` on
//! `[0, 1]²` with a manufactured biharmonic solution, clamped (X and the cross-boundary
//! derivative on all four sides). Peer: `bench/peers/libigl_biharmonic.py` (same grid, same
//! solution). Prints the largest node error once, then times assembly + factorisation + solve.
//! Also the biharmonic patch periodic in `v` (issue 19), 256 × 256 on `[0, 1] × [0, 2π)`, by the
//! FFT-banded solver and by the sparse reference; peer: the same script with `--periodic` (libigl
//! on the cylinder mesh of the same grid). The four-sided patch is timed by `solve_four_sided`
//! (sine transforms and a capacitance matrix) and by the sparse LU it is tested against
//! (`solve_four_sided_sparse`).

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::fd::{
    solve_four_sided, solve_four_sided_sparse, solve_periodic, solve_periodic_sparse, FdSurface,
    FourSidedProblem, PeriodicProblem,
};
use pdeshape::Vec3;
use std::time::Duration;

/// `X = (eᵘ cos v, u eᵛ sin u, (u² + v²)(u − v)/2)`: each component is biharmonic.
fn exact(u: f64, v: f64) -> Vec3 {
    Vec3::new(
        u.exp() * v.cos(),
        u * v.exp() * u.sin(),
        (u * u + v * v) * (u - v) / 2.0,
    )
}
fn exact_u(u: f64, v: f64) -> Vec3 {
    Vec3::new(
        u.exp() * v.cos(),
        v.exp() * (u.sin() + u * u.cos()),
        (3.0 * u * u - 2.0 * u * v + v * v) / 2.0,
    )
}
fn exact_v(u: f64, v: f64) -> Vec3 {
    Vec3::new(
        -u.exp() * v.sin(),
        u * v.exp() * u.sin(),
        (-u * u + 2.0 * u * v - 3.0 * v * v) / 2.0,
    )
}

/// Laplace's equation (`N = 1`) on the same grid with the same boundary values: the cost of one
/// Poisson-type solve, the building block of the factored form `Δ(ΔX) = 0` (two such solves),
/// which the clamped conditions do not allow (no boundary values for `ΔX`).
fn solve_laplace(n: usize) -> FdSurface {
    let (a0, b0) = (|v: f64| exact(0.0, v), |v: f64| exact(1.0, v));
    let (c0, d0) = (|u: f64| exact(u, 0.0), |u: f64| exact(u, 1.0));
    solve_four_sided(&FourSidedProblem {
        order: 1,
        a: 1.0,
        nu: n,
        nv: n,
        v_range: (0.0, 1.0),
        u0: vec![&a0],
        u1: vec![&b0],
        v0: vec![&c0],
        v1: vec![&d0],
        source: None,
    })
    .expect("solves")
}

type FourSidedSolver = fn(&FourSidedProblem<'_>) -> pdeshape::Result<FdSurface>;

fn solve(n: usize) -> FdSurface {
    solve_with(n, solve_four_sided)
}

fn solve_with(n: usize, solver: FourSidedSolver) -> FdSurface {
    let (a0, a1) = (|v: f64| exact(0.0, v), |v: f64| exact_u(0.0, v));
    let (b0, b1) = (|v: f64| exact(1.0, v), |v: f64| exact_u(1.0, v));
    let (c0, c1) = (|u: f64| exact(u, 0.0), |u: f64| exact_v(u, 0.0));
    let (d0, d1) = (|u: f64| exact(u, 1.0), |u: f64| exact_v(u, 1.0));
    solver(&FourSidedProblem {
        order: 2,
        a: 1.0,
        nu: n,
        nv: n,
        v_range: (0.0, 1.0),
        u0: vec![&a0, &a1],
        u1: vec![&b0, &b1],
        v0: vec![&c0, &c1],
        v1: vec![&d0, &d1],
        source: None,
    })
    .expect("solves")
}

/// `Y = (eᵘ cos v, u e²ᵘ sin 2v, u³ − u² + cosh u cos v)`: periodic in `v`, each component
/// biharmonic for `a = 1` (`eᵘ cos v` and `cosh u cos v` are harmonic, `u` times a harmonic
/// function is biharmonic, and so is the cubic).
fn periodic_exact(u: f64, v: f64) -> Vec3 {
    Vec3::new(
        u.exp() * v.cos(),
        u * (2.0 * u).exp() * (2.0 * v).sin(),
        u.powi(3) - u * u + u.cosh() * v.cos(),
    )
}
fn periodic_exact_u(u: f64, v: f64) -> Vec3 {
    Vec3::new(
        u.exp() * v.cos(),
        (1.0 + 2.0 * u) * (2.0 * u).exp() * (2.0 * v).sin(),
        3.0 * u * u - 2.0 * u + u.sinh() * v.cos(),
    )
}

type Solver = fn(&PeriodicProblem<'_>) -> pdeshape::Result<FdSurface>;

fn solve_cylinder(n: usize, solver: Solver) -> FdSurface {
    let (a0, a1) = (
        |v: f64| periodic_exact(0.0, v),
        |v: f64| periodic_exact_u(0.0, v),
    );
    let (b0, b1) = (
        |v: f64| periodic_exact(1.0, v),
        |v: f64| periodic_exact_u(1.0, v),
    );
    solver(&PeriodicProblem {
        order: 2,
        a: 1.0,
        nu: n,
        nv: n,
        start: vec![&a0, &a1],
        end: vec![&b0, &b1],
        source: None,
    })
    .expect("solves")
}

fn periodic_error(s: &FdSurface) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..=s.nu() {
        for j in 0..s.nodes_v() {
            e = e.max((s.node(i, j) - periodic_exact(s.u_node(i), s.v_node(j))).norm());
        }
    }
    e
}

fn max_error(s: &FdSurface) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..=s.nu() {
        for j in 0..s.nodes_v() {
            e = e.max((s.node(i, j) - exact(s.u_node(i), s.v_node(j))).norm());
        }
    }
    e
}

fn bench(c: &mut Criterion) {
    for n in [64, 128, 256] {
        let s = solve(n);
        let st = s.stats();
        let reference = solve_with(n, solve_four_sided_sparse);
        let mut diff: f64 = 0.0;
        for i in 0..=n {
            for j in 0..=n {
                diff = diff.max((s.node(i, j) - reference.node(i, j)).amax());
            }
        }
        println!(
            "fd biharmonic {n}x{n}: {} unknowns, {} nonzeros, max node error {:.3e} \
             (sparse LU {:.3e}, largest node difference {diff:.1e})",
            st.unknowns,
            st.nonzeros,
            max_error(&s),
            max_error(&reference)
        );
    }
    let t = std::time::Instant::now();
    let runs = 3;
    for _ in 0..runs {
        std::hint::black_box(solve_laplace(256));
    }
    println!(
        "fd laplace 256x256 (one Poisson-type solve): {:.1} ms per solve",
        t.elapsed().as_secs_f64() * 1e3 / runs as f64
    );
    for n in [64, 128, 256] {
        let s = solve_cylinder(n, solve_periodic);
        println!(
            "fd periodic biharmonic {n}x{n}: {} unknowns, max node error {:.3e}",
            s.stats().unknowns,
            periodic_error(&s)
        );
    }
    let mut g = c.benchmark_group("fd");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(10));
    g.bench_function("fd_biharmonic_256x256", |b| b.iter(|| solve(256)));
    g.bench_function("fd_biharmonic_256x256_sparse", |b| {
        b.iter(|| solve_with(256, solve_four_sided_sparse))
    });
    g.bench_function("fd_periodic_biharmonic_256x256_fft", |b| {
        b.iter(|| solve_cylinder(256, solve_periodic))
    });
    g.bench_function("fd_periodic_biharmonic_256x256_sparse", |b| {
        b.iter(|| solve_cylinder(256, solve_periodic_sparse))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
