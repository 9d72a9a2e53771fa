//! The three-level scheme (6) on the §3.3 experiment of the dynamic-curve paper (a = 1, b = x/2,
//! d = x, exact solution (1 + e^{−t}) sin(πu), T = 15): J = 30, L = 450 (the paper's run) and
//! J = 2000, L = 30000. Coefficients are closures, as a library user writes them. The NumPy peer
//! `bench/peers/numpy_dynamic.py` runs the same scheme and prints the same L² errors.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::dynamic::{
    constant, constant_field, field, l2_norm, scalar, Component, Scheme, TimeGrid,
};
use std::f64::consts::PI;
use std::hint::black_box;

fn experiment() -> Component {
    let s = |t: f64| 1.0 + (-t).exp();
    Component {
        a: constant_field(1.0),
        b: field(|_, _, x| 0.5 * x),
        d: field(|_, _, x| x),
        f: field(move |u, t, _| {
            let (sn, cs) = (PI * u).sin_cos();
            s(t).powi(2) * (sn * sn - cs * cs) * (2.0 * PI.powi(4) + 0.5 * PI * PI)
        }),
        start: constant(0.0),
        end: constant(0.0),
        start_slope: scalar(move |t| PI * s(t)),
        end_slope: scalar(move |t| -PI * s(t)),
        position: scalar(|u| 2.0 * (PI * u).sin()),
        velocity: scalar(|u| -(PI * u).sin()),
    }
}

fn run(comp: &Component, j: usize, l: usize) -> Vec<f64> {
    let grid = TimeGrid {
        intervals: j,
        steps: l,
        t_end: 15.0,
    };
    let mut s = Scheme::new(comp, grid).expect("valid grid");
    s.run().expect("finite run");
    s.values().to_vec()
}

fn l2_error(x: &[f64]) -> f64 {
    let j = x.len() - 1;
    let h = 1.0 / j as f64;
    let e: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| v - (1.0 + (-15.0f64).exp()) * (PI * i as f64 * h).sin())
        .collect();
    l2_norm(&e, h)
}

/// CPU time of this thread in seconds (Linux: utime + stime of /proc/thread-self/stat, in clock
/// ticks of 10 ms), so that figures taken on a loaded machine can be told apart from waiting.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

fn bench(c: &mut Criterion) {
    let comp = experiment();
    for (j, l, reps) in [(30usize, 450usize, 500usize), (2000, 30000, 1)] {
        let wall = std::time::Instant::now();
        let cpu = cpu_seconds();
        let mut x = Vec::new();
        for _ in 0..reps {
            x = run(&comp, j, l);
        }
        let per_wall = wall.elapsed().as_secs_f64() / reps as f64;
        let per_cpu = cpu
            .zip(cpu_seconds())
            .map(|(a, b)| format!("{:.4e} s", (b - a) / reps as f64))
            .unwrap_or_else(|| "n/a".to_string());
        eprintln!(
            "J = {j}, L = {l}: L2 error at T = 15: {:.6e}; per run: wall {per_wall:.4e} s, CPU {per_cpu}",
            l2_error(&x)
        );
    }
    let mut g = c.benchmark_group("dynamic_section33");
    g.bench_function("J30_L450", |b| b.iter(|| run(black_box(&comp), 30, 450)));
    g.sample_size(10);
    g.bench_function("J2000_L30000", |b| {
        b.iter(|| run(black_box(&comp), 2000, 30000))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
