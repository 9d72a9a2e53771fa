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
