//! Solve + tessellate the benchmark patch `ITER` times at `NU × NV` and print the median time:
//! `cargo bench -p pdeshape --bench grid_timing -- 256 512 200`. (The figures in BENCHMARKS.md
//! come from `cargo bench`; this is for quick profiling.)

use pdeshape::curve::{FourierSeries, SharedCurve};
use pdeshape::elliptic::{solve, Condition, Operator, SolveOptions};
use pdeshape::mesh::tessellate;
use pdeshape::Vec3;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let args: Vec<usize> = std::env::args()
        .filter(|a| a != "--bench")
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let (nu, nv, iters) = (
        *args.first().unwrap_or(&256),
        *args.get(1).unwrap_or(&512),
        *args.get(2).unwrap_or(&100),
    );
    let f = |a0: f64, r: f64| -> SharedCurve {
        Arc::new(FourierSeries {
            a0: Vec3::new(0.0, 0.0, a0),
            cos: (1..=12)
                .map(|n| {
                    Vec3::new(
                        if n == 1 { r } else { 0.01 / n as f64 },
                        0.02 / (n * n) as f64,
                        0.0,
                    )
                })
                .collect(),
            sin: (1..=12)
                .map(|n| {
                    Vec3::new(
                        0.0,
                        if n == 1 { r } else { 0.01 / n as f64 },
                        0.03 / (n * n) as f64,
                    )
                })
                .collect(),
        })
    };
    let conds = vec![
        Condition {
            u: 0.0,
            derivative: 0,
            curve: f(0.0, 1.0),
        },
        Condition {
            u: 0.0,
            derivative: 1,
            curve: f(2.0, 0.5),
        },
        Condition {
            u: 1.0,
            derivative: 0,
            curve: f(1.0, 0.6),
        },
        Condition {
            u: 1.0,
            derivative: 1,
            curve: f(2.0, -0.3),
        },
    ];
    let op = Operator::polyharmonic(2, 2.0).unwrap();
    let opts = SolveOptions {
        modes: 12,
        ..Default::default()
    };
    let mut times = Vec::with_capacity(iters);
    for _ in 0..iters {
        let t = Instant::now();
        let patch = solve(&op, conds.clone(), &opts).unwrap();
        let mesh = tessellate(&patch, nu, nv).unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        drop(std::hint::black_box(mesh));
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{nu}x{nv}: median {:.3} ms, min {:.3} ms over {iters}",
        times[iters / 2],
        times[0]
    );
}
