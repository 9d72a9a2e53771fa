//! The mismatch of two surfaces along an edge they share (the book's cup, §4.6).

use crate::surface::Surface;
use crate::TAU;

/// Position and normal mismatch along an edge shared by two patches.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeReport {
    /// Index of the first patch (in [`super::SolvedDesign::surfaces`]).
    pub a: usize,
    /// The `u` of the edge on patch `a`.
    pub ua: f64,
    /// Index of the second patch, `b > a`.
    pub b: usize,
    /// The `u` of the edge on patch `b`.
    pub ub: f64,
    /// G0 error: `max_v |X_a(ua, v) − X_b(ub, v)|`.
    pub g0: f64,
    /// G1 error: the largest angle (radians) between the unit normals (up to orientation).
    pub g1: f64,
}

/// The G0 and G1 mismatch of two surfaces along `u = ua` on the first and `u = ub` on the second,
/// on `samples` equally spaced `v ∈ [0, 2π)`: `(max |X_a − X_b|, max angle between normals)`.
/// Normals are compared up to orientation (two patches may run in opposite directions); points
/// where either normal is undefined (a pole) are skipped for G1.
pub fn edge_mismatch(
    a: &dyn Surface,
    ua: f64,
    b: &dyn Surface,
    ub: f64,
    samples: usize,
) -> (f64, f64) {
    let samples = samples.max(1);
    let (mut g0, mut g1) = (0.0f64, 0.0f64);
    for j in 0..samples {
        let v = TAU * j as f64 / samples as f64;
        let (pa, pb) = (a.partials(ua, v), b.partials(ub, v));
        let d = (pa.x - pb.x).norm();
        // NaN must show, not vanish in max().
        if d.is_nan() || d > g0 {
            g0 = d;
        }
        if let (Some(na), Some(nb)) = (pa.normal_or_none(), pb.normal_or_none()) {
            // Angle between lines: atan2(|na × nb|, |na · nb|), accurate for tiny angles.
            let angle = na.cross(&nb).norm().atan2(na.dot(&nb).abs());
            if angle.is_nan() || angle > g1 {
                g1 = angle;
            }
        }
    }
    (g0, g1)
}
