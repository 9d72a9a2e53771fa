//! Tensor B-spline approximations of every kind of design surface, each with the largest
//! deviation it may have from the surface and how that number is known ([`Certificate`]).
//!
//! # The bound for the analytic PDE patch
//!
//! The approximant is the bicubic Hermite interpolant `H = H_u H_v` on a uniform grid of steps
//! `h_u`, `h_v` ([`super::hermite`]). In one variable, for `t ∈ [t_0, t_1]`,
//! `f(t) − H f(t) = (t − t_0)²(t − t_1)² f[t_0, t_0, t_1, t_1, t]`, and by the Hermite–Genocchi
//! formula the divided difference is a mean of `f⁗/24` with a non-negative weight of integral
//! one, so `|f − H f| ≤ h⁴/384 · sup|f⁗|` for vector-valued `f` in the Euclidean norm. On the
//! tensor grid, `X − H_u H_v X = (X − H_u X) + H_u (X − H_v X)`; the cubic Hermite interpolant
//! of `e` is bounded by `max|e| + h_u/4 · max|e_u|` over the nodes (its value weights are
//! non-negative and sum to one; its slope weights are `t(1 − t)²` and `t²(1 − t)`, of total
//! size `t(1 − t) ≤ 1/4`, times `h_u`), and `e_u = X_u − H_v X_u`. Hence
//!
//! `|X − H X| ≤ h_u⁴/384 · sup|∂_u⁴X| + h_v⁴/384 · (sup|∂_v⁴X| + h_u/4 · sup|∂_u∂_v⁴X|)`.
//!
//! For `X = A₀(u) + Σ Aₙ(u) cos nv + Bₙ(u) sin nv`, `|a cos θ + b sin θ| ≤ (|a|² + |b|²)^{1/2}`
//! gives `sup|∂_u^d ∂_v^k X| ≤ Σ_n n^k (αₙ² + βₙ²)^{1/2}` with `αₙ, βₙ` the bounds of
//! `sup|Aₙ^{(d)}|, sup|Bₙ^{(d)}|` over `u ∈ [0, 1]` from the stored series
//! (`PdePatch::mode_derivative_bounds`). The steps are chosen so that each of the two terms is at
//! most half the tolerance; a rounding allowance of `ROUNDING` times the size of the patch is
//! added (the nodal data and the control points are computed in floating point).
//!
//! # Exact kinds
//!
//! The finite-difference surface and the BFS blend are C¹ piecewise bicubics with nodal data
//! `X, X_u, X_v, X_uv`: their Hermite interpolant on their own nodes is themselves. A spline
//! net is a B-spline already (its `u` knots mapped onto `[0, 1]` as its [`Surface`] does). Their
//! bound is the rounding allowance.
//!
//! # The bound for formula surfaces
//!
//! The argument above holds cell by cell: on a cell `[u_i, u_{i+1}] × [v_j, v_{j+1}]` the error
//! of the bicubic Hermite interpolant involves only the cell's own nodal data, so with the
//! suprema taken over the cell and its own steps,
//!
//! `|X − H X| ≤ h_u⁴/384 · M_u4 + h_v⁴/384 · (M_v4 + h_u/4 · M_u1v4)` on the cell,
//!
//! and the grid need not be uniform. For a formula surface (`[[parametric]]`) the fourth-order
//! partials `∂u⁴, ∂v⁴, ∂u∂v⁴` of each component are derived symbolically (exmex's
//! differentiation over the formula's tree, [`ParametricSurface::fourth_partials`]) and
//! evaluated over the cell in interval arithmetic with outward rounding
//! ([`crate::formula::interval`]); the Euclidean norm of the three components' enclosures
//! bounds each `M`. The formula itself is evaluated over the cell first, and every function
//! refuses an interval on which it is not analytic (a pole of `tan`, a division by an interval
//! containing 0, `sqrt` or `ln` reaching 0, a kink of `abs`, …): a cell with enclosures is one
//! on which the components are analytic, so the symbolic partials are the true ones and the
//! Hermite remainder applies. Rows and columns of cells whose bound exceeds the tolerance
//! (less the rounding allowance) are cut into the number of equal pieces that the fourth root
//! of the excess asks for, until every cell meets it ([`approximate_formula`]); the figure
//! reported is the largest cell bound plus the rounding allowance,
//! [`Certificate::Intervals`]. A cell without enclosures is halved in the direction that
//! isolates the trouble; if it still has none after [`MAX_DEPTH`] halvings (a singular point
//! of the formulas on the surface, e.g. `u^2.5` at `u = 0`), or the grid would exceed
//! [`MAX_CELLS`], the surface is sampled instead and the reason is reported.
//!
//! # The bound for the analytic PDE patch with a spectral remainder
//!
//! With an active remainder `X = X̃ + Σ_i w_i(u) Δ_i(v)`: `X̃` the `M` Fourier modes, `w_i` the
//! scalar cardinal functions of mode `M + 1` and `Δ_i = g_i − fitted_i` (condition curve `g_i`
//! less the Fourier series `fitted_i = ∂ᵈX̃(u_i, ·)`), so `∂_u^a ∂_v^b X = ∂_u^a ∂_v^b X̃ +
//! Σ_i w_i^{(a)} Δ_i^{(b)}`. The cell argument above needs `X` C⁴ inside each cell: every break
//! of every active condition curve ([`crate::curve::Curve::breaks`]) is a `v` node. On a
//! column `[v_a, v_b]` of cells, with `F` the Fourier part's sums above
//! ([`PdePatch::fourier_partial_bound`]), `Wd_i ≥ sup|w_i^{(d)}|` from the cardinal
//! functions' stored series (as for the modes, per scalar column), `|g_i⁽ᵏ⁾|` from
//! [`crate::curve::Curve::derivative_bounds`] on the column and `|fitted_i⁽ᵏ⁾| ≤ Σ nᵏ σₙ`:
//!
//! `M_u4 ≤ F_u4 + Σ W4_i D0_i`, `M_v4 ≤ F_v4 + Σ W0_i D4_i`, `M_u1v4 ≤ F_u1v4 + Σ W1_i D4_i`,
//!
//! `D4_i = sup|g_i⁗| + sup|fitted_i⁗|` and `D0_i ≥ sup|Δ_i|` on the column: the smaller of
//! `sup|g_i| + sup|fitted_i|` and Taylor's formula about the column's middle `m` with
//! half-width `r`, `Σ_{j<4} |Δ_i⁽ʲ⁾(m)| rʲ/j! + D4_i r⁴/24` (the remainder is small, so this is
//! what keeps the `u` term small). At a node that is a break, the Hermite interpolant takes
//! `X_v`, `X_uv` from the curve's jet there, one side's; if `g_i'` jumped, the cell on the
//! other side would see slope data off by the jump. A bound `J_i` of the jump comes from
//! Taylor's formula on each side (`slope_jump`: `g'(b∓) = g'(x) + (b − x) g''(x) +
//! (b − x)²/2 · g'''(x) + ρ`, `|ρ| ≤ δ³/6 · sup|g⁗|`, `x = b ± δ`; rounding size for the C¹
//! curves of practice), and slope data off by `e` at the two `v` ends of a cell move the
//! bicubic by at most `h_v · t(1 − t) · max e ≤ h_v/4 · max e` (then through `H_u`: `+ h_u/4`
//! times that of the `u`-derivative), adding `h_v/4 · Σ_i J_i (W0_i + h_u/4 · W1_i)` to the
//! `v` term of the cells next to the break. `u` nodes stay uniform (`W` are bounds over all
//! of `[0, 1]`); columns whose `v` term exceeds half the budget are cut, as for formula
//! surfaces ([`shared_v_nodes`]). The periodic analytic patches of one design share their `v`
//! nodes (the union of every patch's breaks, cut until each patch's columns meet its budget),
//! so the boundary rows of patches that meet stay identical (`approximate_design`). The
//! figure is reported as [`Certificate::Intervals`] (largest column bounds, number of cells).
//!
//! # The bound for spine-edited patches
//!
//! `X̃ = Ã₀(u) + R(u) D(u, v)` with the base patch's radial part `D` (modes `n ≥ 1`), the new
//! spine `Ã₀` (Bézier curve plus wave) and the rotation `R` (one Chebyshev series in frame
//! mode, `I` when translating) has the derivative sums of
//! `crate::design::SpineEdited::derivative_sums` (Leibniz's rule with the bounds of each
//! factor over the whole patch); the uniform grid and the bound are then those of the analytic
//! patch. A base with an active remainder, or frames without a settled series, leave the patch
//! sampled.
//!
//! # Sampled kinds
//!
//! PDE patches with an active spectral remainder whose condition curves give no derivative
//! bounds (arc-length reparametrisations, ODE curves, formula curves touching a pole; the note
//! names the condition), the spine edits above without bounds and formula surfaces without
//! interval bounds carry no derivative bounds. They are interpolated on grids refined
//! until the deviation on a dense sample (a 5 × 5 lattice in every cell, corners included) is
//! at most half the tolerance; the reported figure is that sampled maximum, marked
//! [`Certificate::Sampled`]: an estimate, not a bound.

use super::hermite::{hermite_interpolant, uniform_nodes};
use crate::curve::Curve;
use crate::design::SurfaceKind;
use crate::elliptic::{mode_sum, PdePatch};
use crate::formula::interval::Unbounded;
use crate::formula::short;
use crate::spline::BSplineSurface;
use crate::surface::{ParametricSurface, Partials, Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};

/// Relative rounding allowance added to every bound.
pub const ROUNDING: f64 = 1e-12;
/// The most nodes per direction an approximation may use.
pub const MAX_NODES: usize = 4096;
/// The most grid cells (`m × n` intervals) one surface's approximation may use: a net of about
/// a million control points (≈ 25 MB), and for a sampled surface about 7 million evaluations
/// of its deviation. Beyond it the tolerance is refused rather than the export run for minutes.
pub const MAX_CELLS: usize = 1 << 18;

fn too_many_cells(tolerance: f64) -> Error {
    Error::invalid(format!(
        "the tolerance {tolerance:e} needs more than {MAX_CELLS} grid cells on one surface"
    ))
    .at("tolerance")
}

/// How the deviation of an approximation is known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Certificate {
    /// The surface is piecewise polynomial and reproduced exactly (up to rounding).
    Exact,
    /// A proven bound from bounds of the surface's derivatives (the analytic PDE patch).
    Derivatives {
        /// `sup|∂_u⁴X|`, `sup|∂_v⁴X|`, `sup|∂_u∂_v⁴X|`.
        m_u4: f64,
        m_v4: f64,
        m_u1v4: f64,
    },
    /// A proven bound from interval enclosures of the fourth-order partials over every grid
    /// cell (formula surfaces); the largest enclosures over the cells and the number of cells.
    Intervals {
        m_u4: f64,
        m_v4: f64,
        m_u1v4: f64,
        cells: usize,
    },
    /// The largest deviation on a dense sample: an estimate, not a bound.
    Sampled,
}

impl Certificate {
    /// A word for reports.
    pub fn word(&self) -> &'static str {
        match self {
            Certificate::Exact => "exact",
            Certificate::Derivatives { .. } | Certificate::Intervals { .. } => "certified",
            Certificate::Sampled => "sampled, not certified",
        }
    }
    /// The relation a report prints between "deviation" and its figure: `≤` for a bound, `≈`
    /// for an estimate.
    pub fn relation(&self) -> &'static str {
        if self.is_certified() {
            "≤"
        } else {
            "≈"
        }
    }
    /// True if the deviation is proven to hold everywhere on the surface.
    pub fn is_certified(&self) -> bool {
        !matches!(self, Certificate::Sampled)
    }
}

/// A B-spline approximation of one surface, in the surface's own parameters.
#[derive(Clone, Debug)]
pub struct Approximation {
    pub net: BSplineSurface,
    /// Closed in `[u, v]`: the first and last control rows are the same points.
    pub closed: [bool; 2],
    /// The largest deviation `|X − S|` over the whole patch (see `certificate`).
    pub deviation: f64,
    pub certificate: Certificate,
    /// Why a surface of a kind that is usually certified was only sampled.
    pub note: Option<String>,
}

/// The derivative sums of the analytic bound: `sup|∂_u⁴X|`, `sup|∂_v⁴X|`, `sup|∂_u∂_v⁴X|` and
/// the size `Σ_n (αₙ² + βₙ²)^{1/2}` of the patch. `None` with an active remainder.
pub fn pde_derivative_bounds(patch: &PdePatch) -> Option<[f64; 4]> {
    let b0 = patch.mode_derivative_bounds(0)?;
    let b1 = patch.mode_derivative_bounds(1)?;
    let b4 = patch.mode_derivative_bounds(4)?;
    let sum = |b: &[[f64; 2]], k: usize| mode_sum(b, k, 0);
    Some([sum(&b4, 0), sum(&b0, 4), sum(&b1, 4), sum(&b0, 0)])
}

/// The analytic bound for steps `hu`, `hv`.
pub fn hermite_bound(m: [f64; 3], hu: f64, hv: f64) -> f64 {
    let [mu4, mv4, mu1v4] = m;
    hu.powi(4) / 384.0 * mu4 + hv.powi(4) / 384.0 * (mv4 + hu / 4.0 * mu1v4)
}

/// Intervals needed on `[0, length]` so that `h⁴/384 · m ≤ budget`.
fn intervals_for(length: f64, m: f64, budget: f64) -> Result<usize> {
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
fn sums_grid(sums: [f64; 4], tolerance: f64, min_v: usize) -> Result<(usize, usize)> {
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
fn approximate_with_sums(
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

/// Width below which a uniform node next to a curve's break is dropped for it (a knot span of
/// rounding size would only trouble readers of the net).
const NODE_MERGE: f64 = 1e-9 * TAU;

/// What the certified bound of a periodic analytic patch needs on any `v` grid: the Fourier
/// part's derivative sums and, for each active remainder term `w_i(u) Δ_i(v)`, the bounds of
/// `w_i`, its condition curve's breaks and the slope jumps there (module docs, "Remainder").
#[derive(Clone, Debug)]
pub struct PdePlan {
    /// `F_u4, F_v4, F_u1v4` and the size `Σ_n (αₙ² + βₙ²)^{1/2}` of the Fourier part.
    fourier: [f64; 4],
    terms: Vec<crate::elliptic::RemainderTerm>,
    /// `sup|fitted_i⁽ᵏ⁾|`, `k = 0 ..= 4`, per term.
    fitted: Vec<[f64; 5]>,
    /// Per term: its curve's breaks in `[0, 2π)`, each with a bound of the jump of `g_i'`.
    jumps: Vec<Vec<(f64, f64)>>,
    /// A bound of `sup|X|`, for the rounding allowance.
    size: f64,
}

/// The short name of a curve's kind (its type's name).
fn kind_name(c: &dyn crate::curve::Curve) -> String {
    let d = format!("{c:?}");
    d.split(|ch: char| !ch.is_alphanumeric() && ch != '_')
        .next()
        .unwrap_or("curve")
        .to_string()
}

/// A bound of the difference between `g'(b)` as [`crate::curve::Curve::jet`] gives it and
/// either one-sided limit of `g'` at the break `b` (rounding size for a C¹ curve): with
/// `x = b ± δ` on one piece, Taylor's formula gives `g'(b∓) = g'(x) + (b − x) g''(x) +
/// (b − x)²/2 · g'''(x) + ρ`, `|ρ| ≤ δ³/6 · sup|g⁗|` on `(x, b)`. `None` without bounds.
fn slope_jump(g: &dyn crate::curve::Curve, b: f64, gap: f64) -> Option<f64> {
    let delta = (0.25 * gap).min(1e-3);
    let mut at = [Vec3::zeros(); 2];
    g.jet(b, &mut at);
    let mut worst = 0.0f64;
    for side in [-1.0, 1.0] {
        let x = b + side * delta;
        let mut j = [Vec3::zeros(); 4];
        g.jet(x, &mut j);
        let mut d = [0.0; 5];
        if !g.derivative_bounds(x.min(b), x.max(b), &mut d) {
            return None;
        }
        let h = b - x;
        let t = j[1] + j[2] * h + j[3] * (0.5 * h * h);
        let scale = j[1].norm() + (j[2] * h).norm() + (j[3] * (0.5 * h * h)).norm() + at[1].norm();
        let e = (at[1] - t).norm() + delta.powi(3) / 6.0 * d[4] + 1e-12 * scale;
        worst = worst.max(e);
    }
    worst.is_finite().then_some(worst)
}

/// The bounds of one column of a `v` grid: `[A, B, C, J0, J1]` (see [`PdePlan::column`]).
type Column = [f64; 5];

impl PdePlan {
    /// The plan of a periodic analytic patch; `Err` names a condition curve without derivative
    /// bounds (the patch is then sampled).
    pub fn new(patch: &PdePatch) -> std::result::Result<PdePlan, String> {
        let fourier = [
            patch.fourier_partial_bound(4, 0),
            patch.fourier_partial_bound(0, 4),
            patch.fourier_partial_bound(1, 4),
            patch.fourier_partial_bound(0, 0),
        ];
        let terms = patch.remainder_terms();
        let (mut fitted, mut jumps) = (Vec::new(), Vec::new());
        let mut size = fourier[3];
        for t in &terms {
            let c = &patch.conditions()[t.condition];
            let refuse = || {
                format!(
                    "the curve of condition {} (u = {}, derivative {}; {}) has no derivative \
                     bounds",
                    t.condition,
                    short(c.u),
                    c.derivative,
                    kind_name(&*t.curve)
                )
            };
            let (mut g, mut f) = ([0.0; 5], [0.0; 5]);
            if !t.curve.derivative_bounds(0.0, TAU, &mut g)
                || !t.fitted.derivative_bounds(0.0, TAU, &mut f)
                || !t.w.iter().all(|w| w.is_finite())
            {
                return Err(refuse());
            }
            size += t.w[0] * (g[0] + f[0]);
            let mut breaks: Vec<f64> = t
                .curve
                .breaks()
                .into_iter()
                .map(crate::curve::reduce_periodic)
                .collect();
            breaks.sort_by(f64::total_cmp);
            breaks.dedup();
            let n = breaks.len();
            let mut js = Vec::with_capacity(n);
            for (k, &b) in breaks.iter().enumerate() {
                let gap = if n == 1 {
                    TAU
                } else {
                    let next = if k + 1 == n {
                        breaks[0] + TAU
                    } else {
                        breaks[k + 1]
                    };
                    let prev = if k == 0 {
                        breaks[n - 1] - TAU
                    } else {
                        breaks[k - 1]
                    };
                    (next - b).min(b - prev)
                };
                js.push((b, slope_jump(&*t.curve, b, gap).ok_or_else(refuse)?));
            }
            fitted.push(f);
            jumps.push(js);
        }
        if !size.is_finite() || !fourier.iter().all(|x| x.is_finite()) {
            return Err("the patch's derivative bounds are not finite".into());
        }
        Ok(PdePlan {
            fourier,
            terms,
            fitted,
            jumps,
            size,
        })
    }

    /// The breaks of every active condition curve, in `[0, 2π)`.
    pub fn breaks(&self) -> Vec<f64> {
        self.jumps.iter().flatten().map(|&(b, _)| b).collect()
    }

    /// True if the patch has active remainder terms.
    pub fn has_remainder(&self) -> bool {
        !self.terms.is_empty()
    }

    /// The bounds of one column `[va, vb]` (no break inside): `[A, B, C, J0, J1]` with
    /// `M_u4 ≤ A`, `M_v4 ≤ B`, `M_u1v4 ≤ C` on every cell of the column and `J0 = Σ_i J_i W0_i`,
    /// `J1 = Σ_i J_i W1_i` from the larger slope jump `J_i` of `g_i` at the column's two ends.
    fn column(&self, va: f64, vb: f64) -> Option<Column> {
        let [fu4, fv4, fu1v4, _] = self.fourier;
        let mut col = [fu4, fv4, fu1v4, 0.0, 0.0];
        let (m, r) = (0.5 * (va + vb), 0.5 * (vb - va));
        for ((t, f), js) in self.terms.iter().zip(&self.fitted).zip(&self.jumps) {
            let mut g = [0.0; 5];
            if !t.curve.derivative_bounds(va, vb, &mut g) {
                return None;
            }
            let d4 = g[4] + f[4];
            // sup|Δ_i| on the column: Taylor about the middle with the fourth-order remainder,
            // or the curves' sizes, whichever is smaller.
            let (mut gj, mut fj) = ([Vec3::zeros(); 4], [Vec3::zeros(); 4]);
            t.curve.jet(m, &mut gj);
            t.fitted.jet(m, &mut fj);
            let (mut taylor, mut c) = (0.0, 1.0);
            for j in 0..4 {
                taylor += (gj[j] - fj[j]).norm() * c;
                c *= r / (j + 1) as f64;
            }
            taylor = taylor * (1.0 + 1e-9) + d4 * c;
            let d0 = taylor.min(g[0] + f[0]);
            col[0] += t.w[4] * d0;
            col[1] += t.w[0] * d4;
            col[2] += t.w[1] * d4;
            let at = |x: f64| {
                let x = crate::curve::reduce_periodic(x);
                js.iter().find(|(b, _)| *b == x).map_or(0.0, |(_, j)| *j)
            };
            let jump = at(va).max(at(vb));
            col[3] += jump * t.w[0];
            col[4] += jump * t.w[1];
        }
        col.iter().all(|x| x.is_finite()).then_some(col)
    }

    /// The `u` and `v` terms of the bound on a cell of column `col` with steps `hu`, `hv`:
    /// `hu⁴/384 · A` and `hv⁴/384 · (B + hu/4 · C) + hv/4 · (J0 + hu/4 · J1)`.
    fn cell_terms(col: &Column, hu: f64, hv: f64) -> [f64; 2] {
        let [a, b, c, j0, j1] = *col;
        [
            hu.powi(4) / 384.0 * a,
            hv.powi(4) / 384.0 * (b + hu / 4.0 * c) + hv / 4.0 * (j0 + hu / 4.0 * j1),
        ]
    }

    fn budget(&self, tolerance: f64) -> Result<f64> {
        let budget = tolerance - ROUNDING * self.size;
        if budget <= 0.0 {
            return Err(Error::invalid(format!(
                "the tolerance {tolerance:e} is below the rounding allowance of the patch"
            ))
            .at("tolerance"));
        }
        Ok(budget)
    }

    /// The columns of `vs` and the number of uniform `u` intervals that make the `u` term at
    /// most half the budget.
    fn columns(&self, vs: &[f64], budget: f64) -> Result<(Vec<Column>, usize)> {
        let cols: Vec<Column> = vs
            .windows(2)
            .map(|w| self.column(w[0], w[1]))
            .collect::<Option<_>>()
            .ok_or_else(|| Error::invalid("a condition curve has no derivative bounds"))?;
        let a = cols.iter().fold(0.0f64, |m, c| m.max(c[0]));
        let m = intervals_for(1.0, a, 0.5 * budget)?;
        Ok((cols, m))
    }

    /// Pieces every column of `vs` must be cut into so that its `v` term is at most half the
    /// budget (all 1: the grid is fine).
    fn cuts(&self, vs: &[f64], tolerance: f64) -> Result<Vec<usize>> {
        let budget = self.budget(tolerance)?;
        let (cols, m) = self.columns(vs, budget)?;
        let hu = 1.0 / m as f64;
        Ok(cols
            .iter()
            .zip(vs.windows(2))
            .map(|(c, w)| {
                let [_, tv] = Self::cell_terms(c, hu, w[1] - w[0]);
                if tv <= 0.5 * budget {
                    1
                } else {
                    ((tv / (0.5 * budget)).powf(0.25).ceil() as usize).clamp(2, 64)
                }
            })
            .collect())
    }
}

/// One `v` grid on `[0, 2π]` for periodic analytic patches: `n` uniform intervals, the breaks
/// of every plan's condition curves (a uniform node within [`NODE_MERGE`] of a break gives way
/// to it), and columns cut until every plan's `v` term meets half its budget.
pub fn shared_v_nodes(plans: &[&PdePlan], tolerance: f64, n: usize) -> Result<Vec<f64>> {
    let mut breaks: Vec<f64> = plans.iter().flat_map(|p| p.breaks()).collect();
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let mut vs: Vec<f64> = uniform_nodes(0.0, TAU, n.max(1))
        .into_iter()
        .filter(|&x| {
            x == 0.0
                || x == TAU
                || breaks
                    .iter()
                    .chain(&[TAU])
                    .all(|&b| (x - b).abs() > NODE_MERGE)
        })
        .collect();
    vs.extend(
        breaks
            .iter()
            .copied()
            .filter(|&b| b > NODE_MERGE && b < TAU - NODE_MERGE),
    );
    vs.sort_by(f64::total_cmp);
    vs.dedup();
    loop {
        if vs.len() > MAX_NODES {
            return Err(Error::invalid(format!(
                "the tolerance {tolerance:e} needs more than {MAX_NODES} nodes in one direction"
            ))
            .at("tolerance"));
        }
        let mut cut = vec![1usize; vs.len() - 1];
        for p in plans {
            for (c, k) in cut.iter_mut().zip(p.cuts(&vs, tolerance)?) {
                *c = (*c).max(k);
            }
        }
        if cut.iter().all(|&c| c == 1) {
            return Ok(vs);
        }
        vs = subdivide(&vs, &cut);
    }
}

/// A periodic analytic patch interpolated on the `v` nodes `vs` (from [`shared_v_nodes`], so
/// that every column meets its budget) and uniform `u` nodes, with the certified bound of the
/// module docs (with or without a spectral remainder).
pub fn approximate_pde_on(
    patch: &PdePatch,
    plan: &PdePlan,
    vs: &[f64],
    tolerance: f64,
) -> Result<Approximation> {
    let budget = plan.budget(tolerance)?;
    let (cols, m) = plan.columns(vs, budget)?;
    if m * cols.len() > MAX_CELLS {
        return Err(too_many_cells(tolerance));
    }
    let hu = 1.0 / m as f64;
    let mut worst = 0.0f64;
    let mut big = [0.0f64; 3];
    for (c, w) in cols.iter().zip(vs.windows(2)) {
        let [tu, tv] = PdePlan::cell_terms(c, hu, w[1] - w[0]);
        worst = worst.max(tu + tv);
        for k in 0..3 {
            big[k] = big[k].max(c[k]);
        }
    }
    let us = uniform_nodes(0.0, 1.0, m);
    let net = hermite_interpolant(patch, &us, vs, [false, true])?;
    let (m_u4, m_v4, m_u1v4) = (big[0], big[1], big[2]);
    Ok(Approximation {
        net,
        closed: [false, true],
        deviation: worst + ROUNDING * plan.size,
        certificate: if plan.has_remainder() {
            Certificate::Intervals {
                m_u4,
                m_v4,
                m_u1v4,
                cells: m * cols.len(),
            }
        } else {
            Certificate::Derivatives { m_u4, m_v4, m_u1v4 }
        },
        note: None,
    })
}

/// A patch with an active remainder: certified on its own grid ([`shared_v_nodes`] from
/// `min_v` uniform intervals) if its condition curves have bounds, else sampled with the reason.
fn approximate_remainder(patch: &PdePatch, tolerance: f64, min_v: usize) -> Result<Approximation> {
    match PdePlan::new(patch) {
        Ok(plan) => {
            let vs = shared_v_nodes(&[&plan], tolerance, min_v.max(8))?;
            approximate_pde_on(patch, &plan, &vs, tolerance)
        }
        Err(why) => {
            let mut a = approximate_sampled(patch, tolerance, min_v)?;
            a.note = Some(why);
            Ok(a)
        }
    }
}

/// The `v` interval of a surface (`[0, 2π]` when periodic) and whether it closes.
fn v_interval(s: &dyn Surface) -> (f64, f64, bool) {
    match s.v_domain() {
        VDomain::Periodic => (0.0, TAU, true),
        VDomain::Interval(a, b) => (a, b, false),
    }
}

/// The size of a net: the largest control point's distance from the origin (at least 1).
fn net_size(net: &BSplineSurface) -> f64 {
    net.control().iter().fold(1.0f64, |m, p| m.max(p.norm()))
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
fn subdivide(nodes: &[f64], cut: &[usize]) -> Vec<f64> {
    let mut out = vec![nodes[0]];
    for (w, &c) in nodes.windows(2).zip(cut) {
        for k in 1..c {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / c as f64);
        }
        out.push(w[1]);
    }
    out
}

fn net_size_of(surface: &dyn Surface, us: &[f64], vs: &[f64]) -> f64 {
    let mut s = 1.0f64;
    for &u in us {
        for &v in vs {
            s = s.max(surface.point(u, v).norm());
        }
    }
    s
}

/// The exact B-spline of a surface that is one already or a Hermite bicubic on known nodes.
fn exact(net: BSplineSurface, closed: [bool; 2]) -> Approximation {
    let deviation = ROUNDING * net_size(&net);
    Approximation {
        net,
        closed,
        deviation,
        certificate: Certificate::Exact,
        note: None,
    }
}

/// The approximation of a design surface at `tolerance`; periodic analytic PDE patches use at
/// least `min_v` intervals in `v` (so that patches meeting along an edge can share it).
pub fn approximate(kind: &SurfaceKind, tolerance: f64, min_v: usize) -> Result<Approximation> {
    match kind {
        SurfaceKind::Pde(p) => match pde_grid(p, tolerance, min_v) {
            Some(grid) => {
                let (m, n) = grid?;
                approximate_pde(p, m, n)
            }
            None => approximate_remainder(p, tolerance, min_v),
        },
        SurfaceKind::Fd(f) => {
            let us: Vec<f64> = (0..=f.nu()).map(|i| f.u_node(i)).collect();
            let periodic = f.periodic();
            let cols = f.nodes_v() + usize::from(periodic);
            let vs: Vec<f64> = (0..cols).map(|j| f.v_node(j)).collect();
            Ok(exact(
                hermite_interpolant(&**f, &us, &vs, [false, periodic])?,
                [false, periodic],
            ))
        }
        SurfaceKind::Blend(b) => {
            let part = b.surface.partition();
            let closed = [part.periodic_x(), false];
            Ok(exact(
                hermite_interpolant(&b.surface, part.xs(), part.ys(), closed)?,
                closed,
            ))
        }
        SurfaceKind::Spline(_, net) => {
            let b = clamp_u(&clamp_u(&net.to_bspline()?)?.transposed())?.transposed();
            let [[a, e], _] = b.domain();
            let ku: Vec<f64> = b.knots_u().iter().map(|k| (k - a) / (e - a)).collect();
            let b =
                BSplineSurface::new(b.degree(), ku, b.knots_v().to_vec(), b.control().to_vec())?;
            Ok(exact(b, [false, false]))
        }
        SurfaceKind::Parametric(p) => approximate_formula(p, tolerance),
        SurfaceKind::SpineEdited(s) => match s.derivative_sums() {
            Some(sums) => {
                let (m, n) = sums_grid(sums, tolerance, min_v)?;
                approximate_with_sums(&**s, sums, m, n)
            }
            None => {
                let mut a = approximate_sampled(&**s, tolerance, min_v)?;
                a.note = Some(
                    "the spine edit has no derivative bounds (its base patch has a spectral \
                     remainder, or its frames have no settled Chebyshev series)"
                        .into(),
                );
                Ok(a)
            }
        },
    }
}

/// The largest distance between two rows of points.
pub(crate) fn row_distance(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// The same surface on a knot vector in `u` clamped at the domain's ends (end knots of
/// multiplicity `p + 1`, by knot insertion), so its boundary rows are its boundary curves.
fn clamp_u(net: &BSplineSurface) -> Result<BSplineSurface> {
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
