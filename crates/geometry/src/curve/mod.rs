//! Curves in R³ with exact derivatives.
//!
//! Periodic curves (the boundary conditions of the analytic PDE method) live on `[0, 2π)`; open
//! curves on an interval. Every kind implements [`Curve`]; transforms and reparametrisations wrap
//! a curve (§5.1 and §6.1 of the book).

mod arclength;
mod bezier;
mod bspline;
mod conic;
mod formula;
pub(crate) mod hermite;
mod local;
mod rational;
mod samples;
mod series;
mod taylor;
#[cfg(test)]
pub(crate) mod testutil;
mod transform;

pub use arclength::ArcLength;
pub use bezier::Bezier;
pub use bspline::BSpline;
pub use conic::{Ellipse, Point};
pub use formula::Formula;
pub use hermite::Hermite;
pub use local::{LocalEdit, LocalFrame};
pub use rational::RationalBSpline;
pub use samples::{PointSamples, SampleParam};
pub use transform::{Affine, Combination, OriginShift, Transformed};

pub use crate::fourier::FourierSeries;

use crate::Vec3;
use std::sync::Arc;

/// Highest derivative order any curve must provide through [`Curve::jet`].
pub const MAX_ORDER: usize = 8;

/// The parameter domain of a curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// Periodic with period 2π; the parameter is usually called `v` and lives on `[0, 2π)`.
    Periodic,
    /// An open curve on `[start, end]` (`start < end`).
    Interval(f64, f64),
}

/// A parametric curve `C(t)` in R³ with exact derivatives.
pub trait Curve: Send + Sync + std::fmt::Debug {
    /// Where the parameter lives.
    fn domain(&self) -> Domain;

    /// Writes `C(t), C'(t), …, C⁽ᵏ⁾(t)` into `out[0..=k]` with `k = out.len() - 1 ≤ MAX_ORDER`.
    /// Derivatives are exact (analytic), not finite differences. Periodic curves accept any real
    /// `t` (reduced modulo 2π); open curves extend their end pieces outside the interval.
    fn jet(&self, t: f64, out: &mut [Vec3]);

    /// The exact finite Fourier series of this curve, if it is one (circle, ellipse, Fourier
    /// series, point, and affine images of these). Lets the solver skip sampling.
    fn fourier(&self) -> Option<FourierSeries> {
        None
    }

    /// Parameters inside the domain (`[0, 2π)` for a periodic curve) where a derivative of
    /// order ≤ 4 may jump: B-spline knots, polyline corners, the ends of a local edit. A caller
    /// that needs the curve `C⁴` on a cell (a Hermite remainder) cuts its cells there.
    fn breaks(&self) -> Vec<f64> {
        Vec::new()
    }

    /// The order `c` such that the derivatives of orders `0 ..= c` are continuous across every
    /// one of [`Curve::breaks`] (a B-spline of degree `p` whose inner knots repeat at most `m`
    /// times: `p − m`). Taylor's formula with the remainder of order `c + 1`, bounded by
    /// [`Curve::derivative_bounds`] over the pieces, then holds across the breaks. The default
    /// is `usize::MAX` for a curve without breaks (smooth everywhere) and 0 for one with breaks
    /// (a claim only that it is continuous), so wrappers may take the least of their parts'.
    fn continuity(&self) -> usize {
        if self.breaks().is_empty() {
            usize::MAX
        } else {
            0
        }
    }

    /// The highest order up to which [`Curve::jet`] is exact (analytic); above it the kind
    /// differences a lower derivative. A Taylor polynomial that must hold with a proven
    /// remainder (the n-sided models of the CAD export) stops at this order.
    fn exact_order(&self) -> usize {
        MAX_ORDER
    }

    /// Proven bounds `out[k] ≥ sup |C⁽ᵏ⁾(t)|` (Euclidean norm) for `k = 0 ..= out.len() − 1
    /// ≤ 5` (kinds whose bounds stop at order 4 answer `false` to a longer `out`), over the open pieces of `(t0, t1)` between [`Curve::breaks`] (one-sided
    /// derivatives at a break), `t0 < t1` inside one period for a periodic curve. `false` if the
    /// curve kind has no such bounds (`out` is then unspecified): the caller falls back to a
    /// sampled estimate.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let _ = (t0, t1, out);
        false
    }

    /// `C(t)`.
    fn point(&self, t: f64) -> Vec3 {
        let mut out = [Vec3::zeros(); 1];
        self.jet(t, &mut out);
        out[0]
    }

    /// `dᵏC/dtᵏ (t)` for `k = order ≤ MAX_ORDER` (zero beyond).
    fn derivative(&self, t: f64, order: usize) -> Vec3 {
        if order > MAX_ORDER {
            return Vec3::zeros();
        }
        let mut out = [Vec3::zeros(); MAX_ORDER + 1];
        self.jet(t, &mut out[..=order]);
        out[order]
    }
}

/// A curve shared between conditions, patches and wrappers.
pub type SharedCurve = Arc<dyn Curve>;

/// Reduces a periodic parameter to `[0, 2π)` (robust for negative and huge values).
pub fn reduce_periodic(t: f64) -> f64 {
    let r = t.rem_euclid(crate::TAU);
    // `rem_euclid` may round up to exactly 2π for tiny negative inputs.
    if r >= crate::TAU {
        0.0
    } else {
        r
    }
}

/// Writes the value and derivatives at `x` of the polynomial `Σ_j c_j x^j` (vector coefficients)
/// into `out[0..=k]`; derivatives beyond the degree are zero.
pub(crate) fn poly_jet(coeffs: &[Vec3], x: f64, out: &mut [Vec3]) {
    let n = coeffs.len();
    for (k, o) in out.iter_mut().enumerate() {
        if k >= n {
            *o = Vec3::zeros();
            continue;
        }
        // d^k/dx^k Σ c_j x^j = Σ_{j≥k} j!/(j−k)! c_j x^{j−k}, by Horner from the top.
        let mut acc = Vec3::zeros();
        for j in (k..n).rev() {
            let mut f = 1.0;
            for m in (j - k + 1)..=j {
                f *= m as f64;
            }
            acc = acc * x + coeffs[j] * f;
        }
        *o = acc;
    }
}

/// Relative allowance for rounding in the bounds of [`Curve::derivative_bounds`]: the jets
/// they start from are computed in floating point.
pub(crate) const BOUND_ROUNDING: f64 = 1e-9;

/// The open pieces of `(t0, t1)` between the sorted `breaks` (a periodic curve's breaks in
/// `[0, 2π)` repeat with period 2π). Empty if `t0 < t1` fails or either end is not finite.
pub(crate) fn pieces(breaks: &[f64], periodic: bool, t0: f64, t1: f64) -> Vec<(f64, f64)> {
    if !(t0.is_finite() && t1.is_finite() && t0 < t1) {
        return Vec::new();
    }
    let mut cuts: Vec<f64> = Vec::new();
    if periodic && !breaks.is_empty() {
        let first = (t0 / crate::TAU).floor() - 1.0;
        let last = (t1 / crate::TAU).ceil() + 1.0;
        if last - first > 1e6 {
            return Vec::new();
        }
        let mut q = first;
        while q <= last {
            for &b in breaks {
                let x = b + q * crate::TAU;
                if x > t0 && x < t1 {
                    cuts.push(x);
                }
            }
            q += 1.0;
        }
    } else {
        cuts.extend(breaks.iter().copied().filter(|&b| b > t0 && b < t1));
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut out = Vec::with_capacity(cuts.len() + 1);
    let mut a = t0;
    for c in cuts {
        out.push((a, c));
        a = c;
    }
    out.push((a, t1));
    out
}

/// For a curve that is a polynomial of degree `≤ degree ≤ MAX_ORDER` on each of the open
/// `pieces`: by Taylor's formula about the middle `m` of a piece of half-width `r` (exact for a
/// polynomial), `|C⁽ᵏ⁾(m + y)| ≤ Σ_{j ≤ degree − k} |C⁽ᵏ⁺ʲ⁾(m)| rʲ/j!` for `|y| ≤ r`. The
/// largest over the pieces goes to `out[k]` (with [`BOUND_ROUNDING`]).
pub(crate) fn polynomial_piece_bounds(
    curve: &dyn Curve,
    degree: usize,
    pieces: &[(f64, f64)],
    out: &mut [f64],
) -> bool {
    if degree > MAX_ORDER || pieces.is_empty() {
        return false;
    }
    out.iter_mut().for_each(|o| *o = 0.0);
    let mut jet = [Vec3::zeros(); MAX_ORDER + 1];
    for &(a, b) in pieces {
        let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
        curve.jet(m, &mut jet[..=degree]);
        for (k, o) in out.iter_mut().enumerate() {
            let mut sum = 0.0;
            let mut f = 1.0;
            for j in 0..=degree.saturating_sub(k) {
                if k + j > degree {
                    break;
                }
                sum += jet[k + j].norm() * f;
                f *= r / (j + 1) as f64;
            }
            *o = o.max(sum * (1.0 + BOUND_ROUNDING));
        }
    }
    out.iter().all(|o| o.is_finite())
}

/// `(t0, t1)` of a periodic curve as at most two intervals inside `[0, 2π]` (the whole period
/// if it is at least 2π long). Empty if `t0 < t1` fails or either end is not finite.
pub(crate) fn periodic_windows(t0: f64, t1: f64) -> Vec<(f64, f64)> {
    if !(t0.is_finite() && t1.is_finite() && t0 < t1) {
        return Vec::new();
    }
    if t1 - t0 >= crate::TAU {
        return vec![(0.0, crate::TAU)];
    }
    let a = reduce_periodic(t0);
    let b = a + (t1 - t0);
    if b <= crate::TAU {
        vec![(a, b)]
    } else {
        vec![(a, crate::TAU), (0.0, b - crate::TAU)]
    }
}

/// Checks that a vector is finite, naming it in the error.
pub(crate) fn check_finite(name: &str, v: &Vec3) -> crate::Result<()> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(crate::Error::invalid(format!(
            "{name} = ({}, {}, {}) is not finite",
            v.x, v.y, v.z
        )))
    }
}
