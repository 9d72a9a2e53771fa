//! Sampled estimates for surfaces without derivative bounds: grids refined until the deviation
//! on a dense sample is at most half the tolerance (`Certificate::Sampled`).

use super::formula::net_size_of;
use super::{too_many_cells, Approximation, Certificate, MAX_CELLS, ROUNDING};
use crate::cad::hermite::{hermite_interpolant, uniform_nodes};
use crate::spline::BSplineSurface;
use crate::surface::{Partials, Surface, VDomain};
use crate::{Error, Result, TAU};

/// The `v` interval of a surface (`[0, 2π]` when periodic) and whether it closes.
pub(super) fn v_interval(s: &dyn Surface) -> (f64, f64, bool) {
    match s.v_domain() {
        VDomain::Periodic => (0.0, TAU, true),
        VDomain::Interval(a, b) => (a, b, false),
    }
}

/// The largest `|X − S|` on a `k × k` lattice in every cell of the net's knot grid.
pub fn sampled_deviation(surface: &dyn Surface, net: &BSplineSurface, k: usize) -> f64 {
    let distinct = |knots: &[f64]| {
        let mut d: Vec<f64> = knots.to_vec();
        d.dedup();
        d
    };
    let (ku, kv) = (distinct(net.knots_u()), distinct(net.knots_v()));
    let lattice = |c: &[f64]| {
        let (a, b) = (c[0], c[1]);
        (0..k).map(move |i| a + (b - a) * i as f64 / (k - 1) as f64)
    };
    // Whole rows `u = const` at once: surfaces with structure (the PDE patch) evaluate a row
    // from per-column tables, many times faster than point by point.
    let vs: Vec<f64> = kv.windows(2).flat_map(lattice).collect();
    let rows = surface.partials_rows(&vs);
    let mut row = vec![Partials::default(); vs.len()];
    let mut worst = 0.0f64;
    for u in ku.windows(2).flat_map(lattice) {
        rows.eval_row(u, &mut row);
        for (p, &v) in row.iter().zip(&vs) {
            let d = (p.x - net.derivative(u, v, 0, 0)).norm();
            if d.is_nan() || d > worst {
                worst = d;
            }
        }
    }
    worst
}

/// Any surface interpolated on uniform grids refined until the sampled deviation is at most
/// half the tolerance ([`Certificate::Sampled`]).
pub fn approximate_sampled(
    surface: &dyn Surface,
    tolerance: f64,
    min_v: usize,
) -> Result<Approximation> {
    let u = surface.u_range();
    let (v0, v1, v_closed) = v_interval(surface);
    let closed = [surface.u_periodic(), v_closed];
    let (mut m, mut n) = (8usize, min_v.max(8));
    loop {
        if m * n > MAX_CELLS {
            return Err(too_many_cells(tolerance));
        }
        let us = uniform_nodes(u.start, u.end, m);
        let vs = uniform_nodes(v0, v1, n);
        let net = hermite_interpolant(surface, &us, &vs, closed)?;
        let dev = sampled_deviation(surface, &net, 5);
        if !dev.is_finite() {
            return Err(Error::invalid("the surface has a value that is not finite"));
        }
        if dev <= 0.5 * tolerance {
            return Ok(Approximation {
                net,
                closed,
                deviation: dev + ROUNDING * net_size_of(surface, &us, &vs),
                certificate: Certificate::Sampled,
                note: None,
            });
        }
        // Both directions halved; `MAX_CELLS` (checked at the top) ends the refinement.
        m *= 2;
        n *= 2;
    }
}
