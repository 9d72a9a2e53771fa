//! Shared checks for the curve tests.

use super::{Curve, MAX_ORDER};
use crate::Vec3;

/// The full jet at `t`.
pub(crate) fn jet(curve: &dyn Curve, t: f64) -> [Vec3; MAX_ORDER + 1] {
    let mut out = [Vec3::zeros(); MAX_ORDER + 1];
    curve.jet(t, &mut out);
    out
}

/// Checks `C^(k+1)(t)` against the central difference of `C^(k)` with step `h`, for
/// `k = 0..=max_k` (`max_k + 3 ≤ MAX_ORDER`). The tolerance is the truncation bound
/// `h²/6 · max|C^(k+3)|` on `[t − h, t + h]` (taken at three points, times 2 for the variation in
/// between) plus a rounding term `64 ε · scale_k / h`, where `scale_k` bounds `|C^(k)|` near `t`.
pub(crate) fn check_fd(curve: &dyn Curve, ts: &[f64], h: f64, max_k: usize, scale: f64) {
    assert!(max_k + 3 <= MAX_ORDER);
    for &t in ts {
        let jm = jet(curve, t - h);
        let j0 = jet(curve, t);
        let jp = jet(curve, t + h);
        for k in 0..=max_k {
            let fd = (jp[k] - jm[k]) / (2.0 * h);
            let third = jm[k + 3].norm().max(j0[k + 3].norm()).max(jp[k + 3].norm());
            let size = jm[k].norm().max(j0[k].norm()).max(jp[k].norm()).max(scale);
            let tol = 2.0 * h * h / 6.0 * third + 64.0 * f64::EPSILON * size / h;
            let err = (fd - j0[k + 1]).norm();
            assert!(
                err <= tol,
                "{curve:?}: order {} at t = {t}: fd {fd:?} vs jet {:?} (err {err:e} > tol {tol:e})",
                k + 1,
                j0[k + 1]
            );
        }
    }
}

/// `|a − b| ≤ tol`, with a message.
pub(crate) fn assert_close(a: &Vec3, b: &Vec3, tol: f64, what: &str) {
    let err = (a - b).norm();
    assert!(err <= tol, "{what}: {a:?} vs {b:?} (err {err:e} > {tol:e})");
}

/// Checks [`Curve::derivative_bounds`] on `count` random intervals `(t0, t1)` of length up to
/// `max_len` inside the domain: each bound `out[k]`, `k ≤ 4`, is at least the largest
/// `|C⁽ᵏ⁾|` on a dense sample of every piece between breaks (400 points a piece, its ends
/// approached to `10⁻⁹` of its width for the one-sided derivatives). Returns the largest ratio
/// bound / sampled maximum per order (over orders whose sampled maximum is not negligible,
/// above `10⁻⁹` of the bound; `0` if none).
pub(crate) fn check_bounds(curve: &dyn Curve, seed: u64, count: usize, max_len: f64) -> [f64; 5] {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let periodic = curve.domain() == super::Domain::Periodic;
    let (lo, hi) = match curve.domain() {
        super::Domain::Periodic => (0.0, crate::TAU),
        super::Domain::Interval(a, b) => (a, b),
    };
    let mut worst = [0.0f64; 5];
    for _ in 0..count {
        let len = rng.gen_range(0.02..1.0) * max_len.min(hi - lo);
        let t0 = rng.gen_range(lo..hi - if periodic { 0.0 } else { len });
        let t1 = t0 + len;
        let mut bound = [0.0; 5];
        assert!(
            curve.derivative_bounds(t0, t1, &mut bound),
            "{curve:?}: no bounds on ({t0}, {t1})"
        );
        let mut seen = [0.0f64; 5];
        let mut breaks = curve.breaks();
        breaks.sort_by(f64::total_cmp);
        for (a, b) in super::pieces(&breaks, periodic, t0, t1) {
            let n = 400;
            for i in 0..=n {
                let s = match i {
                    0 => 1e-9,
                    _ if i == n => 1.0 - 1e-9,
                    _ => i as f64 / n as f64,
                };
                let j = jet(curve, a + (b - a) * s);
                for k in 0..5 {
                    seen[k] = seen[k].max(j[k].norm());
                }
            }
        }
        for k in 0..5 {
            assert!(
                seen[k] <= bound[k] * (1.0 + 1e-9) + 1e-12 * bound[0],
                "{curve:?}: order {k} on ({t0}, {t1}): sampled {} above the bound {}",
                seen[k],
                bound[k]
            );
            if seen[k] > 1e-9 * bound[k] {
                worst[k] = worst[k].max(bound[k] / seen[k]);
            }
        }
    }
    worst
}
