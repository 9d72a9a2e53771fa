//! Patches bounded by one closed curve: the polyharmonic equation `Δ^N X = 0` (`N = 1, 2, 3`)
//! on the unit disk, solved exactly mode by mode (the disk's counterpart of the book's analytic
//! periodic solutions, §3.3).
//!
//! # Method
//!
//! The boundary data are samples at the equally spaced angles `θ_k = 2πk/S`, `k = 0 … S−1`: the
//! positions `P_k` and, for `N ≥ 2`, the cross-boundary derivatives `D_k = ∂X/∂r` (the ribbon,
//! pointing out of the disk), for `N = 3` also the second derivatives `E_k = ∂²X/∂r²`. Their
//! trigonometric interpolants (a real FFT; the series ends at mode `⌊S/2⌋`) pass through the
//! samples exactly. In polar coordinates `(r, θ)` the solutions of `Δ^N X = 0` regular at the
//! centre are spanned, for each mode `m`, by `r^{m+2j} e^{imθ}`, `j < N`
//! (`Δ(r^k e^{imθ}) = (k² − m²) r^{k−2} e^{imθ}`). Written as
//!
//! `X_m(r) = r^m (α_m + β_m s + γ_m s²)`, `s = r² − 1`,
//!
//! the conditions at `r = 1` (`s = 0`) are triangular:
//! - `X = P`: `α = p_m`;
//! - `∂X/∂r = D`: `m α + 2β = d_m`, so `β = (d_m − m p_m)/2`;
//! - `∂²X/∂r² = E`: `m(m−1) α + (4m + 2) β + 8γ = e_m`, so
//!   `γ = (e_m − m(m−1) p_m − (4m + 2) β)/8`.
//!
//! So the patch meets its boundary samples, ribbon samples and curvature samples to rounding
//! (not to a discretisation error): the solution is exact for the interpolated data. With `u = r`
//! and `v = θ` it is a [`Surface`] periodic in `v` with a pole at `u = 0`, the kind of surface
//! every tessellator, writer and analysis of pdeshape already takes; its normal `X_r × X_θ`
//! points to the side from which the boundary runs counterclockwise.
//!
//! A planar loop with ribbons in its plane gives a planar patch (every mode of the normal
//! coordinate vanishes); a circle with the ribbon `D = P_θ × N` gives the flat disc exactly
//! (`X = R r e^{iθ}`).
//!
//! The operator is the isotropic Laplacian: the book's smoothing parameter `a` scales one
//! parameter direction against the other, and the disk has no preferred one.

#[cfg(test)]
mod tests;

use crate::surface::{Partials, Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};
use realfft::num_complex::Complex;
use realfft::RealFftPlanner;
use rustfft::FftPlanner;

/// The largest number of boundary samples.
pub const MAX_SAMPLES: usize = 1 << 22;

/// A complex vector: the coefficient of `e^{imθ}` of the three coordinates.
type C3 = [Complex<f64>; 3];

const ZERO: C3 = [Complex { re: 0.0, im: 0.0 }; 3];

/// The boundary data of a [`DiskPatch`]: samples at `θ_k = 2πk/S` (see the module's
/// documentation).
#[derive(Clone, Copy, Debug)]
pub struct DiskData<'a> {
    /// The boundary positions `P_k` (`S ≥ 3` of them).
    pub positions: &'a [Vec3],
    /// The ribbon `∂X/∂r` at the same angles (outward): required for order 2 and 3.
    pub derivatives: Option<&'a [Vec3]>,
    /// `∂²X/∂r²` at the same angles: required for order 3.
    pub second: Option<&'a [Vec3]>,
}

/// The samples of a closed polyline through `points`, `per_edge` equally spaced ones per edge
/// (the points among them, at every `per_edge`-th sample): `P_k (1 − t) + P_{k+1} t`,
/// `t = j/per_edge`. Hole fills sample their loops so, and a design file's `[[disk]]` table
/// with `samples_per_edge` too, so both solve the same data bit for bit.
pub fn polyline(points: &[Vec3], per_edge: usize) -> Vec<Vec3> {
    let s = points.len();
    (0..s * per_edge)
        .map(|i| {
            let (k, t) = (i / per_edge, (i % per_edge) as f64 / per_edge as f64);
            points[k] * (1.0 - t) + points[(k + 1) % s] * t
        })
        .collect()
}

/// A polyharmonic patch on the unit disk (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct DiskPatch {
    order: usize,
    samples: usize,
    /// `[α, β, γ]` per mode `m = 0 …`.
    modes: Vec<[C3; 3]>,
}

/// One point of a ring: the position and its two first partials.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RingPoint {
    /// `X(r, θ)`.
    pub x: Vec3,
    /// `∂X/∂r`.
    pub xr: Vec3,
    /// `∂X/∂θ`.
    pub xt: Vec3,
}

impl DiskPatch {
    /// Solves `Δ^order X = 0` with the boundary data (`order` 1, 2 or 3). Refused, naming the
    /// offending input: an order outside 1–3, fewer than 3 or more than [`MAX_SAMPLES`]
    /// samples, a missing or differently sized ribbon, a value that is not finite.
    pub fn solve(order: usize, data: &DiskData) -> Result<Self> {
        if !(1..=3).contains(&order) {
            return Err(Error::invalid(format!("is 1, 2 or 3, not {order}")).at("order"));
        }
        let s = data.positions.len();
        if !(3..=MAX_SAMPLES).contains(&s) {
            return Err(Error::invalid(format!(
                "needs 3 to {MAX_SAMPLES} boundary samples, not {s}"
            ))
            .at("positions"));
        }
        let need = |v: Option<&[Vec3]>, name: &str, needed: bool| -> Result<Option<Vec<C3>>> {
            match (v, needed) {
                (None, true) => Err(Error::invalid(format!(
                    "order {order} needs the {name} at the boundary samples"
                ))
                .at(name)),
                (Some(v), true) => {
                    if v.len() != s {
                        return Err(Error::invalid(format!(
                            "has {} samples, not {s} like the positions",
                            v.len()
                        ))
                        .at(name));
                    }
                    Ok(Some(series(v, name)?))
                }
                _ => Ok(None),
            }
        };
        let p = series(data.positions, "positions")?;
        let d = need(data.derivatives, "derivatives", order >= 2)?;
        let e = need(data.second, "second", order >= 3)?;
        let modes = (0..p.len())
            .map(|m| {
                let mf = m as f64;
                let alpha = p[m];
                let beta = match &d {
                    Some(d) => std::array::from_fn(|c| (d[m][c] - alpha[c] * mf) * 0.5),
                    None => ZERO,
                };
                let gamma = match &e {
                    Some(e) => std::array::from_fn(|c| {
                        (e[m][c] - alpha[c] * (mf * (mf - 1.0)) - beta[c] * (4.0 * mf + 2.0))
                            * 0.125
                    }),
                    None => ZERO,
                };
                [alpha, beta, gamma]
            })
            .collect();
        Ok(DiskPatch {
            order,
            samples: s,
            modes,
        })
    }

    /// The order `N` of `Δ^N X = 0`.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The number of boundary samples `S`.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The angle of boundary sample `k`: `2πk/S`.
    pub fn sample_angle(&self, k: usize) -> f64 {
        TAU * k as f64 / self.samples as f64
    }

    /// `X`, `∂X/∂r`, `∂X/∂θ` at `count` equally spaced angles `θ_l = 2π(l + phase)/count` of the
    /// circle of radius `r`, by one inverse FFT per quantity (the modes folded onto `count`).
    pub fn ring(&self, r: f64, count: usize, phase: f64) -> Vec<RingPoint> {
        if count == 0 {
            return Vec::new();
        }
        // Folded coefficients of X, X_r, X_θ per coordinate.
        let mut h: [Vec<Complex<f64>>; 9] =
            std::array::from_fn(|_| vec![Complex::default(); count]);
        let shift = TAU * phase / count as f64;
        for (m, [a, b, g]) in self.modes.iter().enumerate() {
            let [q, dq, _] = radial(m, r, a, b, g);
            let rot = Complex::from_polar(1.0, m as f64 * shift);
            let slot = m % count;
            let im = Complex::new(0.0, m as f64);
            for c in 0..3 {
                let qv = q[c] * rot;
                h[c][slot] += qv;
                h[3 + c][slot] += dq[c] * rot;
                h[6 + c][slot] += qv * im;
            }
        }
        let fft = FftPlanner::new().plan_fft_inverse(count);
        for v in &mut h {
            fft.process(v);
        }
        (0..count)
            .map(|l| RingPoint {
                x: Vec3::new(h[0][l].re, h[1][l].re, h[2][l].re),
                xr: Vec3::new(h[3][l].re, h[4][l].re, h[5][l].re),
                xt: Vec3::new(h[6][l].re, h[7][l].re, h[8][l].re),
            })
            .collect()
    }
}

/// `q(r)`, `q'(r)` and `q''(r)` of one mode (module documentation), `q = r^m F(s)`,
/// `s = r² − 1`: `q' = m r^{m−1} F + 2 r^{m+1} F_s`,
/// `q'' = m(m−1) r^{m−2} F + (4m + 2) r^m F_s + 8 r^{m+2} γ`.
fn radial(m: usize, r: f64, a: &C3, b: &C3, g: &C3) -> [C3; 3] {
    let s = r * r - 1.0;
    let mf = m as f64;
    let rm = pow(r, m as i32);
    let c1 = if m == 0 {
        0.0
    } else {
        mf * pow(r, m as i32 - 1)
    };
    let c2 = if m < 2 {
        0.0
    } else {
        mf * (mf - 1.0) * pow(r, m as i32 - 2)
    };
    let mut out = [ZERO; 3];
    for c in 0..3 {
        let f = a[c] + b[c] * s + g[c] * (s * s);
        let fs = b[c] + g[c] * (2.0 * s);
        out[0][c] = f * rm;
        out[1][c] = f * c1 + fs * (2.0 * rm * r);
        out[2][c] = f * c2 + fs * ((4.0 * mf + 2.0) * rm) + g[c] * (8.0 * rm * r * r);
    }
    out
}

/// `r^k` for `k ≥ 0`, with `0^0 = 1`.
fn pow(r: f64, k: i32) -> f64 {
    if k == 0 {
        1.0
    } else {
        r.powi(k)
    }
}

/// The coefficients `c_m` (`m = 0 … ⌊S/2⌋`) of the trigonometric interpolant
/// `Σ Re(c_m e^{imθ})` through samples at `θ_k = 2πk/S`.
fn series(samples: &[Vec3], name: &str) -> Result<Vec<C3>> {
    let s = samples.len();
    if let Some(k) = samples
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid("is not finite").at(&format!("{name}[{k}]")));
    }
    let mut planner = RealFftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(s);
    let mut out = vec![ZERO; s / 2 + 1];
    let mut input = fft.make_input_vec();
    let mut spectrum = fft.make_output_vec();
    for c in 0..3 {
        for (x, p) in input.iter_mut().zip(samples) {
            *x = p[c];
        }
        fft.process(&mut input, &mut spectrum)
            .map_err(|e| Error::invalid(format!("the FFT failed: {e}")).at(name))?;
        for (m, v) in spectrum.iter().enumerate() {
            // The mean and (S even) the alternating mode once, every other mode twice.
            let w = if m == 0 || 2 * m == s { 1.0 } else { 2.0 };
            out[m][c] = v * (w / s as f64);
        }
    }
    Ok(out)
}

impl Surface for DiskPatch {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }

    /// `u = r ∈ [0, 1]`, `v = θ`.
    fn partials(&self, u: f64, v: f64) -> Partials {
        let step = Complex::from_polar(1.0, v);
        let mut rot = Complex::new(1.0, 0.0);
        let mut out = Partials::default();
        for (m, [a, b, g]) in self.modes.iter().enumerate() {
            let mf = m as f64;
            let [q, dq, ddq] = radial(m, u, a, b, g);
            for c in 0..3 {
                let (q, dq, ddq) = (q[c] * rot, dq[c] * rot, ddq[c] * rot);
                out.x[c] += q.re;
                out.xu[c] += dq.re;
                out.xuu[c] += ddq.re;
                // ∂/∂θ multiplies by i m: Re(i m z) = −m Im z.
                out.xv[c] -= mf * q.im;
                out.xuv[c] -= mf * dq.im;
                out.xvv[c] -= mf * mf * q.re;
            }
            rot *= step;
        }
        out
    }
}
