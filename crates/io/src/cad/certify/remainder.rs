//! The analytic PDE patch with an active spectral remainder: `PdePlan`, the bound column by
//! column on `v` nodes that include every break of the condition curves, and the `v` nodes shared
//! by a design's periodic patches (`shared_v_nodes`).

use super::analytic::intervals_for;
use super::formula::subdivide;
use super::sampled::approximate_sampled;
use super::{too_many_cells, Approximation, Certificate, MAX_CELLS, MAX_NODES, ROUNDING};
use crate::cad::hermite::{hermite_interpolant, uniform_nodes};
use crate::curve::Curve;
use crate::elliptic::PdePatch;
use crate::formula::short;
use crate::{Error, Result, Vec3, TAU};

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
pub(super) fn approximate_remainder(
    patch: &PdePatch,
    tolerance: f64,
    min_v: usize,
) -> Result<Approximation> {
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
