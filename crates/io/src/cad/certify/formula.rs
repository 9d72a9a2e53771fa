//! Formula surfaces bounded by interval enclosures of their fourth partials per grid cell,
//! cells subdivided until each meets the tolerance (see the module documentation, "The bound for
//! formula surfaces").

use super::sampled::{approximate_sampled, v_interval};
use super::{Approximation, Certificate, MAX_CELLS, ROUNDING};
use crate::cad::hermite::{hermite_interpolant, uniform_nodes};
use crate::formula::interval::Unbounded;
use crate::formula::short;
use crate::surface::{ParametricSurface, Surface};
use crate::{Error, Result};

/// The most halvings of a row or column of cells on which a formula has no bound (a pole, a
/// square root reaching 0) before the surface falls back to sampling.
const MAX_DEPTH: u32 = 12;

/// Per cell: the bound of [`hermite_bound`] from the cell's enclosures, its `u` and `v` terms,
/// and the enclosures with the size `sup|X|`; or why there is none.
type CellBound = std::result::Result<([f64; 2], [f64; 4]), Unbounded>;

/// A formula surface interpolated on a tensor grid whose rows and columns of cells are
/// subdivided until the bound of every cell, from interval enclosures of its fourth-order
/// partials over the cell ([`crate::surface::FourthPartials`]), meets the tolerance
/// ([`Certificate::Intervals`]). Where the formulas have no bound (a cell keeps touching a
/// pole after [`MAX_DEPTH`] halvings) or the grid would exceed [`MAX_CELLS`], the surface is
/// sampled instead ([`approximate_sampled`]) and the reason kept in [`Approximation::note`].
pub fn approximate_formula(p: &ParametricSurface, tolerance: f64) -> Result<Approximation> {
    let partials = p.fourth_partials()?;
    let u = p.u_range();
    let (v0, v1, v_closed) = v_interval(p);
    let closed = [p.u_periodic(), v_closed];
    let mut us = uniform_nodes(u.start, u.end, 8);
    let mut vs = uniform_nodes(v0, v1, 8);
    let min_h = [
        (u.end - u.start) / 8.0 / f64::from(1u32 << MAX_DEPTH),
        (v1 - v0) / 8.0 / f64::from(1u32 << MAX_DEPTH),
    ];
    let sampled = |why: String| -> Result<Approximation> {
        let mut a = approximate_sampled(p, tolerance, 8)?;
        a.note = Some(why);
        Ok(a)
    };
    loop {
        let (mu, mv) = (us.len() - 1, vs.len() - 1);
        if mu * mv > MAX_CELLS {
            return sampled(format!(
                "the interval bounds would need more than {MAX_CELLS} grid cells"
            ));
        }
        let cells: Vec<CellBound> = (0..mu * mv)
            .map(|k| {
                let (i, j) = (k / mv, k % mv);
                let (hu, hv) = (us[i + 1] - us[i], vs[j + 1] - vs[j]);
                let b = partials.bounds([us[i], us[i + 1]], [vs[j], vs[j + 1]])?;
                let tu = hu.powi(4) / 384.0 * b[0];
                let tv = hv.powi(4) / 384.0 * (b[1] + hu / 4.0 * b[2]);
                Ok(([tu, tv], b))
            })
            .collect();
        let size = cells
            .iter()
            .filter_map(|c| c.as_ref().ok())
            .fold(1.0f64, |m, (_, b)| m.max(b[3]));
        let budget = tolerance - ROUNDING * size;
        if budget <= 0.0 {
            return Err(Error::invalid(format!(
                "the tolerance {tolerance:e} is below the rounding allowance of the surface"
            ))
            .at("tolerance"));
        }
        // Pieces each interval of `u` and `v` is cut into.
        let (mut cut_u, mut cut_v) = (vec![1usize; mu], vec![1usize; mv]);
        let pieces = |t: f64| ((t / (0.5 * budget)).powf(0.25).ceil() as usize).clamp(2, 64);
        let mut worst = 0.0f64;
        let mut m = [0.0f64; 3];
        for (k, c) in cells.iter().enumerate() {
            let (i, j) = (k / mv, k % mv);
            match c {
                Ok(([tu, tv], b)) => {
                    worst = worst.max(tu + tv);
                    for (mk, bk) in m.iter_mut().zip(b) {
                        *mk = mk.max(*bk);
                    }
                    if tu + tv > budget {
                        if *tu > 0.5 * budget {
                            cut_u[i] = cut_u[i].max(pieces(*tu));
                        }
                        if *tv > 0.5 * budget {
                            cut_v[j] = cut_v[j].max(pieces(*tv));
                        }
                    }
                }
                Err(why) => {
                    // Cut the direction that isolates the trouble: the one in which a half of
                    // the cell has a bound (both if both or neither do).
                    let (a, b) = ([us[i], us[i + 1]], [vs[j], vs[j + 1]]);
                    let (um, vm) = (0.5 * (a[0] + a[1]), 0.5 * (b[0] + b[1]));
                    let ok = |u: [f64; 2], v: [f64; 2]| partials.bounds(u, v).is_ok();
                    let in_u = ok([a[0], um], b) || ok([um, a[1]], b);
                    let in_v = ok(a, [b[0], vm]) || ok(a, [vm, b[1]]);
                    let (mut want_u, mut want_v) = (in_u || !in_v, in_v || !in_u);
                    want_u &= a[1] - a[0] > min_h[0];
                    want_v &= b[1] - b[0] > min_h[1];
                    if !(want_u || want_v) {
                        return sampled(format!(
                            "{why} on the cell [{}, {}] × [{}, {}]",
                            short(a[0]),
                            short(a[1]),
                            short(b[0]),
                            short(b[1])
                        ));
                    }
                    if want_u {
                        cut_u[i] = cut_u[i].max(2);
                    }
                    if want_v {
                        cut_v[j] = cut_v[j].max(2);
                    }
                }
            }
        }
        if cut_u.iter().chain(&cut_v).all(|&c| c == 1) {
            let net = hermite_interpolant(p, &us, &vs, closed)?;
            return Ok(Approximation {
                net,
                closed,
                deviation: worst + ROUNDING * size,
                certificate: Certificate::Intervals {
                    m_u4: m[0],
                    m_v4: m[1],
                    m_u1v4: m[2],
                    cells: mu * mv,
                },
                note: None,
            });
        }
        us = subdivide(&us, &cut_u);
        vs = subdivide(&vs, &cut_v);
    }
}

/// Nodes with interval `i` cut into `cut[i]` equal pieces (the old nodes kept bit for bit).
pub(super) fn subdivide(nodes: &[f64], cut: &[usize]) -> Vec<f64> {
    let mut out = vec![nodes[0]];
    for (w, &c) in nodes.windows(2).zip(cut) {
        for k in 1..c {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / c as f64);
        }
        out.push(w[1]);
    }
    out
}

pub(super) fn net_size_of(surface: &dyn Surface, us: &[f64], vs: &[f64]) -> f64 {
    let mut s = 1.0f64;
    for &u in us {
        for &v in vs {
            s = s.max(surface.point(u, v).norm());
        }
    }
    s
}
