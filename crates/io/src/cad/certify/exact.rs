//! Exact nets: surfaces that are B-splines already or bicubic Hermite interpolants on their own
//! nodes, with the rounding allowance as their bound.

use super::{Approximation, Certificate, ROUNDING};
use crate::spline::BSplineSurface;
use crate::Result;

/// The size of a net: the largest control point's distance from the origin (at least 1).
fn net_size(net: &BSplineSurface) -> f64 {
    net.control().iter().fold(1.0f64, |m, p| m.max(p.norm()))
}

/// The exact B-spline of a surface that is one already or a Hermite bicubic on known nodes.
pub(super) fn exact(net: BSplineSurface, closed: [bool; 2]) -> Approximation {
    let deviation = ROUNDING * net_size(&net);
    Approximation {
        net,
        closed,
        deviation,
        certificate: Certificate::Exact,
        note: None,
    }
}

/// The same surface on a knot vector in `u` clamped at the domain's ends (end knots of
/// multiplicity `p + 1`, by knot insertion), so its boundary rows are its boundary curves.
pub(super) fn clamp_u(net: &BSplineSurface) -> Result<BSplineSurface> {
    let p = net.degree()[0];
    let [[a, b], _] = net.domain();
    let mult = |n: &BSplineSurface, x: f64| n.knots_u().iter().filter(|&&k| k == x).count();
    let mut n = net.clone();
    while mult(&n, a) < p + 1 {
        n = n.insert_knot_u(a)?;
    }
    while mult(&n, b) < p + 1 {
        n = n.insert_knot_u(b)?;
    }
    let k = n.knots_u();
    let i0 = k.iter().position(|&x| x == a).unwrap_or(0);
    let i1 = k.iter().rposition(|&x| x == b).unwrap_or(k.len() - 1);
    let knots = k[i0..=i1].to_vec();
    let count = knots.len() - p - 1;
    let nv = n.counts()[1];
    let control = n.control()[i0 * nv..(i0 + count) * nv].to_vec();
    BSplineSurface::new(n.degree(), knots, n.knots_v().to_vec(), control)
}
