//! Solve + tessellate with normals: the biharmonic patch with 12 Fourier modes of BENCHMARKS.md,
//! at 256×512 and 1024×1024 (f32 positions and normals, as every mesh format stores them).

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::curve::{FourierSeries, SharedCurve};
use pdeshape::elliptic::{solve, Condition, Operator, SolveOptions};
use pdeshape::mesh::{tessellate, tessellate_into};
use pdeshape::Vec3;
use std::hint::black_box;
use std::sync::Arc;

/// The benchmark's boundary data: four curves with 12 modes and 1/n² decay, from a fixed
/// linear congruential sequence (the NumPy peer script rebuilds the same numbers).
pub fn bench_conditions() -> Vec<Condition> {
    let mut state: u64 = 12345;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut curve = |base: Vec3, radius: f64| -> SharedCurve {
        let mut cos = Vec::new();
        let mut sin = Vec::new();
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
    vec![
        Condition {
            u: 0.0,
            derivative: 0,
            curve: curve(Vec3::new(0.0, 0.0, 0.0), 1.0),
        },
        Condition {
            u: 0.0,
            derivative: 1,
            curve: curve(Vec3::new(0.0, 0.0, 2.0), 0.5),
        },
        Condition {
            u: 1.0,
            derivative: 0,
            curve: curve(Vec3::new(0.0, 0.0, 1.0), 0.6),
        },
        Condition {
            u: 1.0,
            derivative: 1,
            curve: curve(Vec3::new(0.0, 0.0, 2.0), -0.3),
        },
    ]
}

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
