//! Surface analysis (area, volume, ∫H, ∫H², ∫K with curvature ranges) of the biharmonic patch
//! with 12 Fourier modes of BENCHMARKS.md: on a fixed 256 × 512 quadrature grid (fast row path
//! and pointwise partials), and with the default adaptive quadrature.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::analysis::{analyze_surface, Quadrature};
use pdeshape::curve::{FourierSeries, SharedCurve};
use pdeshape::elliptic::{solve, Condition, Operator, PdePatch, SolveOptions};
use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape::Vec3;
use std::hint::black_box;
use std::sync::Arc;

/// The boundary data of the surface benchmark (benches/surface.rs): four curves with 12 modes
/// and 1/n² decay from the same linear congruential sequence.
fn bench_conditions() -> Vec<Condition> {
    let mut state: u64 = 12345;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut curve = |base: Vec3, radius: f64| -> SharedCurve {
        let (mut cos, mut sin) = (Vec::new(), Vec::new());
        for n in 1..=12usize {
            let s = 0.2 / (n * n) as f64;
            let mut c = Vec3::new(next() * s, next() * s, next() * s);
            let mut d = Vec3::new(next() * s, next() * s, next() * s);
            if n == 1 {
                c.x += radius;
                d.y += radius;
            }
            cos.push(c);
            sin.push(d);
        }
        Arc::new(FourierSeries { a0: base, cos, sin })
    };
    let cond = |u: f64, derivative: usize, curve: SharedCurve| Condition {
        u,
        derivative,
        curve,
    };
    vec![
        cond(0.0, 0, curve(Vec3::new(0.0, 0.0, 0.0), 1.0)),
        cond(0.0, 1, curve(Vec3::new(0.0, 0.0, 2.0), 0.5)),
        cond(1.0, 0, curve(Vec3::new(0.0, 0.0, 1.0), 0.6)),
        cond(1.0, 1, curve(Vec3::new(0.0, 0.0, 2.0), -0.3)),
    ]
}

/// The patch seen only through `partials` (the trait's pointwise row path).
struct Pointwise<'a>(&'a PdePatch);

impl Surface for Pointwise<'_> {
    fn v_domain(&self) -> VDomain {
        self.0.v_domain()
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        self.0.partials(u, v)
    }
}

fn bench(c: &mut Criterion) {
    let op = Operator::polyharmonic(2, 2.0).unwrap();
    let opts = SolveOptions {
        modes: 12,
        ..Default::default()
    };
    let patch = solve(&op, bench_conditions(), &opts).unwrap();
    let fixed = Quadrature::fixed(256, 512);
    let mut group = c.benchmark_group("analysis");
    group.bench_function("256x512", |b| {
        b.iter(|| black_box(analyze_surface(&patch, &fixed).unwrap()))
    });
    let adaptive = analyze_surface(&patch, &Quadrature::default()).unwrap();
    group.bench_function(
        format!("adaptive_default_{}x{}", adaptive.u_nodes, adaptive.v_nodes),
        |b| b.iter(|| black_box(analyze_surface(&patch, &Quadrature::default()).unwrap())),
    );
    group.finish();
    // About 1.5 s per run: few samples.
    let mut slow = c.benchmark_group("analysis_slow");
    slow.sample_size(10);
    slow.bench_function("256x512_pointwise_partials", |b| {
        b.iter(|| black_box(analyze_surface(&Pointwise(&patch), &fixed).unwrap()))
    });
    slow.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
