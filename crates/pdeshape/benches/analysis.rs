//! Surface analysis (area, volume, ∫H, ∫H², ∫K with curvature ranges) of the biharmonic patch
//! with 12 Fourier modes of BENCHMARKS.md: on a fixed 256 × 512 quadrature grid (fast row path
//! and pointwise partials), and with the default adaptive quadrature; and the whole bundled cup
//! (two patches, their shared edge, the cap) as `analyze` and the Python sweeps measure it.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::analysis::{analyze_surface, integrate_design, Quadrature};
use pdeshape::elliptic::{solve, Operator, PdePatch, SolveOptions};
use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape_testkit::curves::bench_conditions;
use std::hint::black_box;

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
    let spec = pdeshape_testkit::example_spec("cup.toml");
    let cup = pdeshape::design::solve_design(&spec).unwrap();
    group.bench_function("cup_design_default", |b| {
        b.iter(|| black_box(integrate_design(&cup, &Quadrature::default()).unwrap()))
    });
    group.bench_function("cup_design_fixed_64x128", |b| {
        b.iter(|| black_box(integrate_design(&cup, &Quadrature::fixed(64, 128)).unwrap()))
    });
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
