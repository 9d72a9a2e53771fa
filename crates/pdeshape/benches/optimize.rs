//! An optimisation of 5000 evaluations (the curvature example of §7.5,
//! examples/optimize_curvature.toml: 19 parameters, 4 chains, no polish) with 1 and 2 worker
//! threads: the chains run in parallel, and the result is the same for both.
//!
//! `gradient_7_5`: on one thread, one evaluation of §7.5's problem (a solve of the design and its
//! integrals) against one full gradient (the objective's and constraints' derivatives with
//! respect to all 19 parameters) at the starting point; their ratio is the cost of a gradient
//! in solves. Beside it: the sensitivities with each exact parameter by its own solves (the
//! path before the batched tangent solve), and the gradient of the same problem without `a`
//! (the 18 exact parameters only: the point's solve and one batched tangent solve).

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::optimize::Problem;
use pdeshape::spec::parse_design;
use std::time::Duration;

fn problem() -> Problem {
    let text = include_str!("../../../examples/optimize_curvature.toml");
    let mut p = Problem::new(&parse_design(text).expect("the example parses")).expect("valid");
    p.options.evaluations = 5000;
    p.options.chains = 4;
    p.options.polish = 0;
    p
}

fn bench(c: &mut Criterion) {
    let p = problem();
    let mut group = c.benchmark_group("optimize_5000");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(40));
    group.warm_up_time(Duration::from_secs(1));
    let mut values = Vec::new();
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        group.bench_function(format!("threads={threads}"), |b| {
            b.iter(|| {
                let out = pool.install(|| p.run(&|_, _| {}).expect("the search runs"));
                values.push(out.best.1.total());
            })
        });
    }
    group.finish();
    // The same result whatever the thread count.
    assert!(values.windows(2).all(|w| w[0] == w[1]), "{values:?}");
}

fn gradient(c: &mut Criterion) {
    let p = problem();
    let x = p.parameters.initial();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a thread pool");
    let mut group = c.benchmark_group("gradient_7_5");
    group.sample_size(30);
    group.measurement_time(Duration::from_secs(10));
    group.warm_up_time(Duration::from_secs(1));
    group.bench_function("solve", |b| {
        b.iter(|| pool.install(|| p.evaluate(&x).expect("the design solves").total()))
    });
    group.bench_function("gradient", |b| {
        b.iter(|| pool.install(|| p.gradient(&x).expect("the gradient").d_objective))
    });
    group.bench_function("sensitivities_per_parameter", |b| {
        b.iter(|| {
            pool.install(|| {
                p.sensitivities_per_parameter(&x)
                    .expect("the sensitivities")
                    .d_values
            })
        })
    });
    let text = include_str!("../../../examples/optimize_curvature.toml");
    let without_a: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("{ name = \"a\""))
        .map(|l| format!("{l}\n"))
        .collect();
    let q = Problem::new(&parse_design(&without_a).expect("parses")).expect("valid");
    assert_eq!(q.parameters.list.len(), 18);
    let y = q.parameters.initial();
    group.bench_function("gradient_without_a", |b| {
        b.iter(|| pool.install(|| q.gradient(&y).expect("the gradient").d_objective))
    });
    group.finish();
}

criterion_group!(benches, bench, gradient);
criterion_main!(benches);
