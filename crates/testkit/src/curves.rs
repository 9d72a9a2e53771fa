//! Curve builders: the boundary data of the 12-mode biharmonic patch of BENCHMARKS.md.

use pdeshape::curve::{FourierSeries, SharedCurve};
use pdeshape::elliptic::Condition;
use pdeshape::Vec3;
use std::sync::Arc;

/// The boundary data of the surface benchmark: four curves with 12 modes
/// and 1/n² decay from the same linear congruential sequence.
pub fn bench_conditions() -> Vec<Condition> {
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
