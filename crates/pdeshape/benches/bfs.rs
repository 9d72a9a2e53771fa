//! BFS smoothing PDE splines: the §6 blend (8 × 4 elements, nine data points) and a clamped
//! biharmonic problem on 128 × 128 elements (the problem of bench/peers/skfem_bfs.py):
//! `Δ²u = f` on `[0, 1]²` with `u* = sin²(πx) sin²(πy)`, so `u = ∂ₙu = 0` on the boundary.
//! Prints the L² error once; times the whole solve (analysis, assembly, factorisation, solve)
//! and the refactorisation that reuses the symbolic analysis.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::bfs::{
    blend, BfsSurface, BlendProblem, Cylinder, Energy, Join, Partition, SplineSystem, GAUSS4,
};
use pdeshape::Vec3;
use std::f64::consts::PI;
use std::hint::black_box;

/// `sin²(πt)` and its second and fourth derivatives.
fn s(t: f64) -> [f64; 3] {
    let c = (2.0 * PI * t).cos();
    [(1.0 - c) / 2.0, 2.0 * PI * PI * c, -8.0 * PI.powi(4) * c]
}

fn exact(x: f64, y: f64) -> f64 {
    s(x)[0] * s(y)[0]
}

/// `Δ²u*` in every coordinate.
fn load(x: f64, y: f64) -> Vec3 {
    let (a, b) = (s(x), s(y));
    let f = a[2] * b[0] + 2.0 * a[1] * b[1] + a[0] * b[2];
    Vec3::new(f, f, f)
}

/// The clamped problem on `n × n` elements: every boundary dof fixed to 0.
fn clamped(n: usize) -> (Partition, Vec<bool>) {
    let p = Partition::uniform(n, n, false).unwrap();
    let mut fixed = vec![false; p.dofs()];
    for j in 0..=n {
        for i in 0..=n {
            if i == 0 || j == 0 || i == n || j == n {
                for k in 0..4 {
                    fixed[p.dof(i, j, k)] = true;
                }
            }
        }
    }
    (p, fixed)
}

fn solve_biharmonic(n: usize) -> BfsSurface {
    let (p, fixed) = clamped(n);
    let zeros = vec![Vec3::zeros(); p.dofs()];
    let sys = SplineSystem::new(p, &fixed).unwrap();
    let energy = Energy::section6(1.0).unwrap();
    let f = sys.factor(&energy, 1.0, &[]).unwrap();
    f.solve(&[], &zeros, Some(&load)).unwrap()
}

/// L² error of the first coordinate (4 × 4 Gauss points per element).
fn l2_error(u: &BfsSurface) -> f64 {
    let p = u.partition();
    let mut e = 0.0;
    for j in 0..p.ny() {
        for i in 0..p.nx() {
            let (x0, hx) = (p.xs()[i], p.xs()[i + 1] - p.xs()[i]);
            let (y0, hy) = (p.ys()[j], p.ys()[j + 1] - p.ys()[j]);
            for &(t, wt) in &GAUSS4 {
                for &(r, wr) in &GAUSS4 {
                    let (x, y) = (x0 + r * hx, y0 + t * hy);
                    let d = u.evaluate(x, y).x.x - exact(x, y);
                    e += wr * wt * hx * hy * d * d;
                }
            }
        }
    }
    e.sqrt()
}

fn section6_blend() -> f64 {
    let f = Cylinder::new(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), 2.0).unwrap();
    let g = Cylinder::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), 1.0).unwrap();
    let (sites, values) = (0..9)
        .map(|i| {
            let x = i as f64 / 9.0;
            let t = 2.0 * PI * x;
            ([x, 0.5], Vec3::new(0.0, 0.5 * t.cos(), 0.5 * t.sin()))
        })
        .unzip();
    let b = blend(&BlendProblem {
        start: Join {
            surface: &f,
            from: [0.0, 1.0],
            to: [1.0, 1.0],
            cross: [0.0, 1.0],
        },
        end: Join {
            surface: &g,
            from: [0.0, 0.0],
            to: [1.0, 0.0],
            cross: [0.0, 1.0],
        },
        nx: 8,
        ny: 4,
        periodic: true,
        energy: Energy::section6(10.0).unwrap(),
        epsilon: 1e-3,
        sites,
        values,
    })
    .unwrap();
    b.report.start.g0
}

fn bench(c: &mut Criterion) {
    for n in [32, 64, 128] {
        let t = std::time::Instant::now();
        let u = solve_biharmonic(n);
        let secs = t.elapsed().as_secs_f64();
        println!(
            "bfs_biharmonic n = {n}: dofs {}, L2 error {:.3e}, one solve {:.3} s",
            u.partition().dofs(),
            l2_error(&u),
            secs
        );
    }
    c.bench_function("blend_section6_8x4", |b| {
        b.iter(|| black_box(section6_blend()))
    });
    let mut g = c.benchmark_group("bfs_biharmonic_128");
    g.sample_size(10);
    g.bench_function("analyse_assemble_factor_solve", |b| {
        b.iter(|| black_box(solve_biharmonic(128)))
    });
    let (p, fixed) = clamped(128);
    let zeros = vec![Vec3::zeros(); p.dofs()];
    let sys = SplineSystem::new(p, &fixed).unwrap();
    let energy = Energy::section6(1.0).unwrap();
    g.bench_function("assemble_factor_solve_reusing_analysis", |b| {
        b.iter(|| {
            let f = sys.factor(&energy, 1.0, &[]).unwrap();
            black_box(f.solve(&[], &zeros, Some(&load)).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
