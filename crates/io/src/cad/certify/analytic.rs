//! The proven bound of the analytic PDE patch (and of spine-edited patches, from their derivative
//! sums): the derivative bounds, the Hermite remainder and the uniform grid that meets the
//! tolerance (see the module documentation, "The bound for the analytic PDE patch").

use super::{too_many_cells, Approximation, Certificate, MAX_CELLS, MAX_NODES, ROUNDING};
use crate::cad::hermite::{hermite_interpolant, uniform_nodes};
use crate::elliptic::{mode_sum, PdePatch};
use crate::surface::Surface;
use crate::{Error, Result, TAU};

/// The derivative sums of the analytic bound: `sup|∂_u⁴X|`, `sup|∂_v⁴X|`, `sup|∂_u∂_v⁴X|` and
/// the size `Σ_n (αₙ² + βₙ²)^{1/2}` of the patch. `None` with an active remainder.
pub(crate) fn pde_derivative_bounds(patch: &PdePatch) -> Option<[f64; 4]> {
    let b0 = patch.mode_derivative_bounds(0)?;
    let b1 = patch.mode_derivative_bounds(1)?;
    let b4 = patch.mode_derivative_bounds(4)?;
    let sum = |b: &[[f64; 2]], k: usize| mode_sum(b, k, 0);
    Some([sum(&b4, 0), sum(&b0, 4), sum(&b1, 4), sum(&b0, 0)])
}

/// The analytic bound for steps `hu`, `hv`.
pub(crate) fn hermite_bound(m: [f64; 3], hu: f64, hv: f64) -> f64 {
    let [mu4, mv4, mu1v4] = m;
    hu.powi(4) / 384.0 * mu4 + hv.powi(4) / 384.0 * (mv4 + hu / 4.0 * mu1v4)
}

/// Intervals needed on `[0, length]` so that `h⁴/384 · m ≤ budget`.
pub(super) fn intervals_for(length: f64, m: f64, budget: f64) -> Result<usize> {
    let n = if m <= 0.0 {
        1.0
    } else {
        (length * (m / (384.0 * budget)).powf(0.25)).ceil().max(1.0)
    };
    if n.is_nan() || n > MAX_NODES as f64 {
        return Err(Error::invalid(format!(
            "the tolerance {budget:e} needs more than {MAX_NODES} nodes in one direction"
        ))
        .at("tolerance"));
    }
    Ok(n as usize)
}

/// The grid the analytic bound asks for: `(m, n, bound)` with `m` intervals in `u` and `n` in
/// `v` (`n` at least `min_v`).
pub fn pde_grid(patch: &PdePatch, tolerance: f64, min_v: usize) -> Option<Result<(usize, usize)>> {
    Some(sums_grid(pde_derivative_bounds(patch)?, tolerance, min_v))
}

/// The uniform grid on which the bound from the derivative sums `[M_u4, M_v4, M_u1v4, size]`
/// meets `tolerance` (each term at most half of it, less the rounding allowance).
pub(super) fn sums_grid(sums: [f64; 4], tolerance: f64, min_v: usize) -> Result<(usize, usize)> {
    let [mu4, mv4, mu1v4, size] = sums;
    let budget = 0.5 * (tolerance - ROUNDING * size);
    if budget <= 0.0 {
        return Err(Error::invalid(format!(
            "the tolerance {tolerance:e} is below the rounding allowance of the patch"
        ))
        .at("tolerance"));
    }
    let m = intervals_for(1.0, mu4, budget)?;
    let hu = 1.0 / m as f64;
    let n = intervals_for(TAU, mv4 + hu / 4.0 * mu1v4, budget)?.max(min_v);
    if m * n > MAX_CELLS {
        return Err(too_many_cells(tolerance));
    }
    Ok((m, n))
}

/// The analytic patch interpolated on `m × n` intervals with its certified deviation.
pub fn approximate_pde(patch: &PdePatch, m: usize, n: usize) -> Result<Approximation> {
    let sums = pde_derivative_bounds(patch)
        .ok_or_else(|| Error::invalid("the patch has an active spectral remainder"))?;
    approximate_with_sums(patch, sums, m, n)
}

/// A surface on `u ∈ [0, 1]`, periodic in `v`, whose derivative sums `[M_u4, M_v4, M_u1v4,
/// size]` hold over the whole patch, interpolated on `m × n` uniform intervals with the
/// certified deviation of the module docs.
pub(super) fn approximate_with_sums(
    surface: &dyn Surface,
    sums: [f64; 4],
    m: usize,
    n: usize,
) -> Result<Approximation> {
    let [mu4, mv4, mu1v4, size] = sums;
    let us = uniform_nodes(0.0, 1.0, m);
    let vs = uniform_nodes(0.0, TAU, n);
    let net = hermite_interpolant(surface, &us, &vs, [false, true])?;
    let m3 = [mu4, mv4, mu1v4];
    let deviation = hermite_bound(m3, 1.0 / m as f64, TAU / n as f64) + ROUNDING * size;
    Ok(Approximation {
        net,
        closed: [false, true],
        deviation,
        certificate: Certificate::Derivatives {
            m_u4: mu4,
            m_v4: mv4,
            m_u1v4: mu1v4,
        },
        note: None,
    })
}
