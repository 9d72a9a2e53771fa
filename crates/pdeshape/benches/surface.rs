//! Solve + tessellate with normals: the biharmonic patch with 12 Fourier modes of BENCHMARKS.md,
//! at 256×512 and 1024×1024 (f32 positions and normals, as every mesh format stores them).

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::elliptic::{solve, Operator, SolveOptions};
use pdeshape::mesh::{tessellate, tessellate_into};
use pdeshape_testkit::curves::bench_conditions;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let op = Operator::polyharmonic(2, 2.0).unwrap();
    let conds = bench_conditions();
    let opts = SolveOptions {
        modes: 12,
        ..Default::default()
    };
    let mut group = c.benchmark_group("solve_tessellate");
    for (nu, nv) in [(256usize, 512usize), (1024, 1024)] {
        group.bench_function(format!("{nu}x{nv}"), |b| {
            // The mesh is dropped outside the timing: freeing is not part of solving.
            b.iter_with_large_drop(|| {
                let patch = solve(&op, conds.clone(), &opts).unwrap();
                tessellate(&patch, nu, nv).unwrap()
            })
        });
    }
    // The interactive case: re-solve and tessellate into the mesh of the previous frame.
    for (nu, nv) in [(256usize, 512usize), (1024, 1024)] {
        let mut mesh = tessellate(&solve(&op, conds.clone(), &opts).unwrap(), nu, nv).unwrap();
        group.bench_function(format!("{nu}x{nv}_into_existing_mesh"), |b| {
            b.iter(|| {
                let patch = solve(&op, conds.clone(), &opts).unwrap();
                tessellate_into(&patch, nu, nv, &mut mesh).unwrap();
                black_box(mesh.positions.len())
            })
        });
    }
    group.bench_function("solve_only", |b| {
        b.iter(|| black_box(solve(&op, conds.clone(), &opts).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
