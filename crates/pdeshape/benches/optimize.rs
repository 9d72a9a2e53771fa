//! An optimisation of 5000 evaluations (the curvature example of §7.5,
//! examples/optimize_curvature.toml: 19 parameters, 4 chains, no polish) with 1 and 2 worker
//! threads: the chains run in parallel, and the result is the same for both.

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

criterion_group!(benches, bench);
criterion_main!(benches);
