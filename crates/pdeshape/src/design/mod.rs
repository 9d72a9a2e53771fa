//! Designs of several patches sharing curves (the book's cup, §4.6), and the mismatch along
//! shared edges.

use crate::elliptic::PdePatch;
use crate::surface::Surface;

/// A named patch of a design.
#[derive(Debug)]
pub struct Patch {
    pub name: String,
    pub surface: PdePatch,
}

/// Position and normal mismatch along an edge shared by two patches.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeReport {
    /// Patch indices and the `u` of the edge on each.
    pub a: usize,
    pub ua: f64,
    pub b: usize,
    pub ub: f64,
    /// G0 error: `max_v |X_a(ua, v) − X_b(ub, v)|`.
    pub g0: f64,
    /// G1 error: the largest angle (radians) between the unit normals (up to orientation).
    pub g1: f64,
}

/// The G0 and G1 mismatch of two surfaces along `u = ua` on the first and `u = ub` on the second,
/// on `samples` equally spaced `v`.
pub fn edge_mismatch(
    a: &dyn Surface,
    ua: f64,
    b: &dyn Surface,
    ub: f64,
    samples: usize,
) -> (f64, f64) {
    let _ = (a, ua, b, ub, samples);
    todo!("design")
}
