//! Closest points on the biharmonic patch with 12 Fourier modes of BENCHMARKS.md: building the
//! sample index, queries from points near the surface (mesh fitting) and anywhere in its
//! bounding box (picking), warm-started refinement (tracking), and a one-shot query that builds
//! its own index. One `partials` evaluation is timed for scale, and the mean number of
//! evaluations per query is printed once.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pdeshape::elliptic::{solve, Operator, PdePatch, SolveOptions};
use pdeshape::surface::{
    closest_point, ClosestOptions, ClosestPointIndex, Partials, RowEvaluator, Surface, VDomain,
};
use pdeshape::{Vec3, TAU};
use pdeshape_testkit::curves::bench_conditions;
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fixed pseudo-random sequence in `[0, 1)`.
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The patch, counting its `partials` evaluations.
struct Counted<'a> {
    patch: &'a PdePatch,
    calls: AtomicUsize,
}

impl Surface for Counted<'_> {
    fn v_domain(&self) -> VDomain {
        self.patch.v_domain()
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.patch.partials(u, v)
    }
    fn row_evaluator<'b>(&'b self, vs: &'b [f64]) -> Box<dyn RowEvaluator + 'b> {
        self.patch.row_evaluator(vs)
    }
}

fn bench(c: &mut Criterion) {
    let op = Operator::polyharmonic(2, 2.0).unwrap();
    let opts = SolveOptions {
        modes: 12,
        ..Default::default()
    };
    let patch = solve(&op, bench_conditions(), &opts).unwrap();
    let copts = ClosestOptions::default();
    let n = 256;
    // Near the surface: X + d n with |d| ≤ 0.05 (the patch is about 2 across).
    let mut rnd = uniform(7);
    let near: Vec<(Vec3, f64, f64)> = (0..n)
        .map(|_| {
            let (u, v, d) = (rnd(), TAU * rnd(), 0.1 * rnd() - 0.05);
            let q = patch.partials(u, v);
            (q.x + q.normal() * d, u, v)
        })
        .collect();
    // Anywhere in a box around the patch.
    let far: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(3.0 * rnd() - 1.5, 3.0 * rnd() - 1.5, 2.0 * rnd() - 0.5))
        .collect();
    let index = ClosestPointIndex::new(&patch, &copts);

    let counted = Counted {
        patch: &patch,
        calls: AtomicUsize::new(0),
    };
    let cindex = ClosestPointIndex::new(&counted, &copts);
    for (what, points) in [
        ("near", near.iter().map(|p| p.0).collect::<Vec<_>>()),
        ("box", far.clone()),
    ] {
        counted.calls.store(0, Ordering::Relaxed);
        let unconverged = points
            .iter()
            .filter(|&&p| !cindex.closest(p).unwrap().converged)
            .count();
        eprintln!(
            "closest {what}: {:.1} partials evaluations per query, {unconverged} of {} not converged",
            counted.calls.load(Ordering::Relaxed) as f64 / points.len() as f64,
            points.len()
        );
    }

    let mut g = c.benchmark_group("closest");
    g.bench_function("partials (one evaluation)", |b| {
        b.iter(|| patch.partials(black_box(0.37), black_box(1.9)))
    });
    g.bench_function("index 16x32", |b| {
        b.iter(|| ClosestPointIndex::new(black_box(&patch), &copts))
    });
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("query near (256)", |b| {
        b.iter(|| {
            for &(p, _, _) in &near {
                black_box(index.closest(black_box(p)));
            }
        })
    });
    g.bench_function("query box (256)", |b| {
        b.iter(|| {
            for &p in &far {
                black_box(index.closest(black_box(p)));
            }
        })
    });
    g.bench_function("refine near (256)", |b| {
        b.iter(|| {
            for &(p, u, v) in &near {
                black_box(index.refine(black_box(p), (u + 0.01).min(1.0), v + 0.02));
            }
        })
    });
    g.throughput(Throughput::Elements(1));
    g.bench_function("closest_point one-shot", |b| {
        b.iter(|| closest_point(&patch, black_box(far[3]), &copts))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
