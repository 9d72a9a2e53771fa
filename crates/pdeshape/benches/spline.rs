//! Evaluation of a 512 × 512 grid (positions and unit normals from exact derivatives) on a
//! bicubic B-spline surface with a 20 × 20 control net and uniform clamped knots: the row
//! evaluator alone on one thread, the whole f32 mesh (rows in parallel), and point-by-point
//! `partials` for comparison.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::mesh::tessellate;
use pdeshape::spline::BSplineSurface;
use pdeshape::surface::{RowBuf, Surface, VDomain};
use pdeshape::Vec3;
use std::hint::black_box;

/// A 20 × 20 net over [0, 1]² with heights from a fixed linear congruential sequence.
pub fn bench_surface() -> BSplineSurface {
    let mut state: u64 = 2024;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let n = 20;
    let mut ctrl = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            ctrl.push(Vec3::new(x, y, 0.2 * next()));
        }
    }
    BSplineSurface::clamped_uniform([3, 3], [n, n], ctrl).unwrap()
}

fn bench(c: &mut Criterion) {
    let s = bench_surface();
    let (nu, nv) = (512usize, 512usize);
    let VDomain::Interval(a, b) = s.v_domain() else {
        unreachable!()
    };
    let us: Vec<f64> = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    let vs: Vec<f64> = (0..nv)
        .map(|j| a + (b - a) * j as f64 / (nv - 1) as f64)
        .collect();
    // The grid values the SciPy peer prints too (bench/peers/scipy_bspline_grid.py).
    let mesh = pdeshape::mesh::sample(&s, nu, nv).unwrap();
    for (i, j) in [(0usize, 0usize), (100, 300), (511, 511), (257, 33)] {
        let (p, n) = (mesh.positions[i * nv + j], mesh.normals[i * nv + j]);
        println!(
            "X[{i},{j}] = {:.17e} {:.17e} {:.17e}  n = {:.17e} {:.17e} {:.17e}",
            p[0], p[1], p[2], n[0], n[1], n[2]
        );
    }
    let mut group = c.benchmark_group("bspline_bicubic_20x20");
    group.bench_function("512x512_rows_one_thread", |bch| {
        let mut row = RowBuf::new(nv);
        bch.iter(|| {
            let rows = s.row_evaluator(&vs);
            let mut acc = 0.0;
            for &u in &us {
                rows.eval_row(u, &mut row);
                acc += row.x[nv / 2] + row.nz[nv / 3];
            }
            black_box(acc)
        })
    });
    group.bench_function("512x512_mesh", |bch| {
        bch.iter_with_large_drop(|| tessellate(&s, nu, nv).unwrap())
    });
    group.sample_size(10);
    group.bench_function("512x512_pointwise_partials_one_thread", |bch| {
        bch.iter(|| {
            let mut acc = 0.0;
            for &u in &us {
                for &v in &vs {
                    let p = s.partials(u, v);
                    acc += p.x.x + p.normal().z;
                }
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
