//! The constraint engine on a 20 × 20 bicubic B-spline net (17 × 17 spans) with the biharmonic
//! operator (4th-order constraints) and the boundary control points fixed; and the evaluation of
//! the solved surface on a 512 × 512 grid.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::splinepde::{clamped_uniform, ring_indices, solve, Operator, SplineProblem};

fn problem() -> SplineProblem<f64> {
    let n = 20;
    let dir = clamped_uniform::<f64>(3, n - 3);
    let fixed = ring_indices([n - 1, n - 1], 1)
        .into_iter()
        .map(|[i, j]| {
            let (x, y) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            let z = (3.0 * x).sin() * (2.0 * y).cos() + 0.3 * x * y;
            ([i, j], [x, y, z])
        })
        .collect();
    SplineProblem {
        u: dir.clone(),
        v: dir,
        operator: Operator::biharmonic(),
        fixed,
    }
}

fn bench(c: &mut Criterion) {
    let p = problem();
    let net = solve(&p).expect("the benchmark problem is consistent");
    eprintln!(
        "20x20 bicubic biharmonic: {} equations, rank {}, {} unknowns, freedom {}",
        net.report.equations, net.report.rank, net.report.unknowns, net.report.freedom
    );
    let mut g = c.benchmark_group("splinepde");
    g.sample_size(10);
    g.bench_function("solve_20x20_bicubic_biharmonic", |b| {
        b.iter(|| solve(std::hint::black_box(&p)).unwrap())
    });
    let surface = net.to_bspline().unwrap();
    g.bench_function("evaluate_512x512", |b| {
        b.iter(|| pdeshape::mesh::sample(std::hint::black_box(&surface), 512, 512).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
