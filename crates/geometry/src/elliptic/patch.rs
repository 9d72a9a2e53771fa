//! The solved patch: evaluation anywhere with exact partials, the spine, reports, and a fast
//! row evaluator for grids.

use super::{Condition, ConditionError, ModeFn, ModeReport, Operator};
use crate::curve::Curve;
use crate::fourier::FourierSeries;
use crate::surface::{
    normal_degenerates, Partials, PartialsRows, RowBuf, RowEvaluator, Spine, Surface, VDomain,
};

mod partial_rows;
use crate::{Vec3, TAU};
pub use partial_rows::RowTables;

/// A solved Bloor–Wilson patch `X(u,v) = A₀(u) + Σ [Aₙ(u) cos nv + Bₙ(u) sin nv] + R(u,v)`
/// (Eqs. 4.36, 4.53). Evaluation is cheap and every partial derivative is exact.
///
/// The patch is defined for `u ∈ [0, 1]`; outside, the same formulas extrapolate (modes in the
/// Chebyshev basis quickly grow without meaning there), so callers should stay inside.
#[derive(Debug)]
pub struct PdePatch {
    operator: Operator,
    conditions: Vec<Condition>,
    /// Mode `n` has 6 columns: `Aₙ` (x, y, z) then `Bₙ` (x, y, z).
    pub(super) modes: Vec<ModeFn>,
    /// The remainder `R(u,v) = Σ_i w_i(u) Δ_i(v)`: `w_i` are the cardinal functions of mode
    /// `M + 1` (`w_i^{(d_k)}(u_k) = δ_ik`), and `Δ_i(v) = g_i(v) − ∂ᵈX̃(u_i, v)` the part of
    /// condition `i` the `M` modes leave (Eqs. 4.50–4.52).
    pub(super) remainder: Option<Remainder>,
    reports: Vec<ModeReport>,
    /// [`design_scale`] of the conditions, measured when first asked for (a tangent solve's
    /// patches never are).
    scale: std::sync::OnceLock<f64>,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for PdePatch {}

#[derive(Debug)]
pub(crate) struct Remainder {
    pub(crate) cardinal: ModeFn,
    /// `∂ᵈX̃(u_i, v)` as a Fourier series, one per condition.
    pub(crate) fitted: Vec<FourierSeries>,
    /// Conditions that take part (`Δ_i ≠ 0`).
    pub(crate) active: Vec<bool>,
}

impl Remainder {
    /// `Δ_i(v)` and its v-derivatives up to `order ≤ 2` (the rest zero; all zero for inactive
    /// conditions). Asking only for what is used matters: a condition curve on another patch
    /// (an attachment's) evaluates that patch for each derivative it is asked for.
    pub(super) fn delta(
        &self,
        conditions: &[Condition],
        i: usize,
        v: f64,
        order: usize,
    ) -> [Vec3; 3] {
        let mut g = [Vec3::zeros(); 3];
        if !self.active[i] {
            return g;
        }
        let mut f = [Vec3::zeros(); 3];
        conditions[i].curve.jet(v, &mut g[..=order]);
        self.fitted[i].jet(v, &mut f[..=order]);
        for (g, f) in g.iter_mut().zip(f) {
            *g -= f;
        }
        g
    }
}

fn col3(v: &[f64], offset: usize) -> Vec3 {
    Vec3::new(v[offset], v[offset + 1], v[offset + 2])
}

impl PdePatch {
    pub(crate) fn new(
        operator: Operator,
        conditions: Vec<Condition>,
        modes: Vec<ModeFn>,
        remainder: Option<Remainder>,
        reports: Vec<ModeReport>,
    ) -> Self {
        PdePatch {
            operator,
            conditions,
            modes,
            remainder,
            reports,
            scale: std::sync::OnceLock::new(),
        }
    }

    /// The number of Fourier modes `M` solved analytically.
    pub fn modes(&self) -> usize {
        self.modes.len() - 1
    }

    /// True if the spectral remainder is active (some curve is not a finite Fourier series
    /// within `M` modes).
    pub fn has_remainder(&self) -> bool {
        self.remainder.is_some()
    }

    /// The spine `A₀(u)` (§5.3) and its u-derivatives: `spine(u, 0)` is the centre line.
    pub fn spine(&self, u: f64, derivative: usize) -> Vec3 {
        let mut out = [0.0; 6];
        self.modes[0].eval(u, derivative, &mut out);
        col3(&out, 0)
    }

    /// `Aₙ(u)` and `Bₙ(u)` (their `d`-th u-derivatives) of mode `n ≤ M`.
    pub fn mode(&self, n: usize, u: f64, derivative: usize) -> (Vec3, Vec3) {
        let mut out = [0.0; 6];
        self.modes[n].eval(u, derivative, &mut out);
        (col3(&out, 0), col3(&out, 3))
    }

    /// One report per mode system solved (modes `0..=M`, then `M + 1` for the remainder).
    pub fn mode_reports(&self) -> &[ModeReport] {
        &self.reports
    }

    /// The conditions this patch was solved for.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// The operator.
    pub fn operator(&self) -> &Operator {
        &self.operator
    }

    /// The size used to make condition errors relative: the largest distance of a position
    /// curve sample from the centroid of all of them.
    pub fn scale(&self) -> f64 {
        *self.scale.get_or_init(|| design_scale(&self.conditions))
    }

    /// `∂ᵈX/∂uᵈ (u, v)` for any order `d`.
    pub fn u_derivative(&self, u: f64, v: f64, d: usize) -> Vec3 {
        let mut out = [0.0; 6];
        self.modes[0].eval(u, d, &mut out);
        let mut x = col3(&out, 0);
        for (k, mode) in self.modes.iter().enumerate().skip(1) {
            mode.eval(u, d, &mut out);
            let (sin, cos) = ((k as f64) * v).sin_cos();
            x += col3(&out, 0) * cos + col3(&out, 3) * sin;
        }
        if let Some(r) = &self.remainder {
            let mut w = vec![0.0; self.conditions.len()];
            r.cardinal.eval(u, d, &mut w);
            for (i, wi) in w.iter().enumerate() {
                x += r.delta(&self.conditions, i, v, 0)[0] * *wi;
            }
        }
        x
    }

    /// The error of every condition on `samples` equally spaced `v` (at least 1).
    pub fn condition_errors(&self, samples: usize) -> Vec<ConditionError> {
        self.condition_errors_where(samples, |_| true)
    }

    /// [`Self::condition_errors`] for the conditions `pick` selects (zero for the others).
    pub(crate) fn condition_errors_where(
        &self,
        samples: usize,
        pick: impl Fn(usize) -> bool,
    ) -> Vec<ConditionError> {
        let samples = samples.max(1);
        let k = self.conditions.len();
        let vs: Vec<f64> = (0..samples)
            .map(|j| TAU * j as f64 / samples as f64)
            .collect();
        // `Δ_i(v_j)` of the remainder's conditions, once for every condition measured (a
        // condition curve on another patch evaluates that patch at each call).
        let deltas: Vec<Vec<Vec3>> = match &self.remainder {
            Some(r) if (0..k).any(&pick) => (0..k)
                .map(|i| match r.active[i] {
                    true => vs
                        .iter()
                        .map(|&v| r.delta(&self.conditions, i, v, 0)[0])
                        .collect(),
                    false => Vec::new(),
                })
                .collect(),
            _ => Vec::new(),
        };
        self.conditions
            .iter()
            .enumerate()
            .map(|(ci, c)| {
                if !pick(ci) {
                    return ConditionError {
                        u: c.u,
                        derivative: c.derivative,
                        absolute: 0.0,
                        relative: 0.0,
                    };
                }
                let fitted = fitted_series(&self.modes, c.u, c.derivative);
                let mut w = vec![0.0; k];
                if let Some(r) = &self.remainder {
                    r.cardinal.eval(c.u, c.derivative, &mut w);
                }
                let (mut abs, mut size) = (0.0f64, 0.0f64);
                for (j, &v) in vs.iter().enumerate() {
                    let g = c.curve.point(v);
                    let mut x = fitted.point(v);
                    if let Some(r) = &self.remainder {
                        for (i, wi) in w.iter().enumerate() {
                            if r.active[i] {
                                x += deltas[i][j] * *wi;
                            }
                        }
                    }
                    abs = abs.max((x - g).norm());
                    size = size.max(g.norm());
                }
                let denom = if c.derivative == 0 {
                    self.scale()
                } else {
                    self.scale().max(size)
                };
                ConditionError {
                    u: c.u,
                    derivative: c.derivative,
                    absolute: abs,
                    relative: abs / denom,
                }
            })
            .collect()
    }
}

/// `∂ᵈX̃(u, v)` of the mode sum as a Fourier series in `v`.
pub(crate) fn fitted_series(modes: &[ModeFn], u: f64, d: usize) -> FourierSeries {
    let mut out = [0.0; 6];
    modes[0].eval(u, d, &mut out);
    let a0 = col3(&out, 0);
    let (mut cos, mut sin) = (
        Vec::with_capacity(modes.len()),
        Vec::with_capacity(modes.len()),
    );
    for mode in &modes[1..] {
        mode.eval(u, d, &mut out);
        cos.push(col3(&out, 0));
        sin.push(col3(&out, 3));
    }
    FourierSeries { a0, cos, sin }
}

/// Largest distance of a position-curve sample from the centroid of all position samples (1 if
/// there is nothing to measure).
fn design_scale(conditions: &[Condition]) -> f64 {
    let pts: Vec<Vec3> = conditions
        .iter()
        .filter(|c| c.derivative == 0)
        .flat_map(|c| (0..64).map(move |j| c.curve.point(TAU * j as f64 / 64.0)))
        .collect();
    if pts.is_empty() {
        return 1.0;
    }
    let centroid = pts.iter().sum::<Vec3>() / pts.len() as f64;
    let r = pts
        .iter()
        .map(|p| (p - centroid).norm())
        .fold(0.0, f64::max);
    if r > 0.0 && r.is_finite() {
        r
    } else {
        1.0
    }
}

impl Surface for PdePatch {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }

    /// The mode-0 solution `A₀(u)` ([`PdePatch::spine`]).
    fn as_spine(&self) -> Option<&dyn Spine> {
        Some(self)
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let mut p = Partials::default();
        let mut o = [[0.0; 6]; 3];
        // A mode with zero coefficients adds zeros (leaving it out changes at most the sign of
        // an exact zero).
        for (n, mode) in self.modes.iter().enumerate().filter(|(_, m)| !m.zero) {
            let [o0, o1, o2] = &mut o;
            mode.eval012(u, [o0, o1, o2]);
            let nf = n as f64;
            let (s, c) = (nf * v).sin_cos();
            let (a, b) = (
                [col3(&o[0], 0), col3(&o[1], 0), col3(&o[2], 0)],
                [col3(&o[0], 3), col3(&o[1], 3), col3(&o[2], 3)],
            );
            p.x += a[0] * c + b[0] * s;
            p.xu += a[1] * c + b[1] * s;
            p.xuu += a[2] * c + b[2] * s;
            p.xv += (b[0] * c - a[0] * s) * nf;
            p.xuv += (b[1] * c - a[1] * s) * nf;
            p.xvv -= (a[0] * c + b[0] * s) * (nf * nf);
        }
        if let Some(r) = &self.remainder {
            let k = self.conditions.len();
            let mut w = [vec![0.0; k], vec![0.0; k], vec![0.0; k]];
            let [w0, w1, w2] = &mut w;
            r.cardinal.eval012(u, [w0, w1, w2]);
            for (i, ((&w0, &w1), &w2)) in w[0].iter().zip(&w[1]).zip(&w[2]).enumerate() {
                let [dl, dl1, dl2] = r.delta(&self.conditions, i, v, 2);
                let w = [w0, w1, w2];
                p.x += dl * w[0];
                p.xu += dl * w[1];
                p.xuu += dl * w[2];
                p.xv += dl1 * w[0];
                p.xuv += dl1 * w[1];
                p.xvv += dl2 * w[0];
            }
        }
        p
    }

    /// `X` alone: [`Self::partials`]'s position by the same operations in the same order (so
    /// the same bits), without the derivatives (the basis, the remainder's cardinal functions
    /// and its condition curves are evaluated to order 0 only).
    fn point(&self, u: f64, v: f64) -> Vec3 {
        let mut x = Vec3::zeros();
        let mut o = [0.0; 6];
        for (n, mode) in self.modes.iter().enumerate().filter(|(_, m)| !m.zero) {
            mode.eval(u, 0, &mut o);
            let (s, c) = (n as f64 * v).sin_cos();
            x += col3(&o, 0) * c + col3(&o, 3) * s;
        }
        if let Some(r) = &self.remainder {
            let mut w = vec![0.0; self.conditions.len()];
            r.cardinal.eval(u, 0, &mut w);
            for (i, &w0) in w.iter().enumerate() {
                x += r.delta(&self.conditions, i, v, 0)[0] * w0;
            }
        }
        x
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(PdeRows::new(self, vs))
    }

    fn partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn PartialsRows + 'a> {
        Box::new(partial_rows::PdePartialRows::new(self, vs))
    }
}

impl PdePatch {
    /// [`Surface::partials_rows`] with the `cos n v_j`, `sin n v_j` tables of `tables` when
    /// they are of the nodes `vs` and of at least this patch's modes (else its own): the same
    /// values, for patches evaluated on the same nodes (a patch and its tangents).
    pub fn partials_rows_sharing<'a>(
        &'a self,
        vs: &'a [f64],
        tables: &'a RowTables,
    ) -> Box<dyn PartialsRows + 'a> {
        Box::new(partial_rows::PdePartialRows::with_tables(
            self,
            vs,
            Some(tables),
        ))
    }
}

/// The spine is the mode-0 solution `A₀(u)` (§5.3). The modes `n ≥ 1` average to zero over
/// `v`; the remainder averages to the difference between each condition curve's mean and the
/// sampled mean its mode 0 was fitted to, a sampling error, so `A₀` is the mean of `X` over `v`
/// up to that.
impl Spine for PdePatch {
    fn spine(&self, u: f64, order: usize) -> Vec3 {
        PdePatch::spine(self, u, order)
    }
}

/// Grid rows of a [`PdePatch`]: per-column tables of `cos nv_j`, `sin nv_j` (and of the
/// remainder's `Δ_i(v_j)`, `Δ_i'(v_j)`), so a row is a handful of multiply–adds per vertex.
///
/// On the standard periodic grid `v_j = 2πj/nv` with `4 | nv`, the quarter-wave symmetries
/// `cos n(π ∓ v) = (−1)ⁿ cos nv`, `sin n(π ∓ v) = ∓(−1)ⁿ sin nv` and `v ↦ 2π − v` give the four
/// columns `j, nv/2 − j, nv/2 + j, nv − j` from the even/odd cosine and sine sums at `j`, so each
/// mode costs one multiply–add per quantity per four vertices.
struct PdeRows<'a> {
    patch: &'a PdePatch,
    vs: &'a [f64],
    /// Columns the tables cover: `nv/4 + 1` on the symmetric grid, else `nv`.
    cols: usize,
    symmetric: bool,
    /// The modes `n ≥ 1` whose coefficients are not all zero, the only ones summed (a mode of
    /// zeros adds exact zeros, so leaving it out changes at most the sign of an exact zero).
    live: Vec<usize>,
    /// `cos[(n−1)·cols + j] = cos(n v_j)`, likewise `sin` (for the live modes).
    cos: Vec<f64>,
    sin: Vec<f64>,
    /// `delta[(i·2 + d)·nv + j] = ∂ᵈ_v Δ_i(v_j)` (d = 0, 1).
    delta: Vec<Vec3>,
}

/// Quantities accumulated per vertex: X, X_u, X_v (x, y, z each).
const Q: usize = 9;
/// Columns per block of the accumulation (the accumulators of a block stay in L1).
const BLOCK: usize = 64;

impl<'a> PdeRows<'a> {
    fn new(patch: &'a PdePatch, vs: &'a [f64]) -> Self {
        let m = patch.modes();
        let nv = vs.len();
        let symmetric = nv.is_multiple_of(4)
            && nv >= 8
            && vs
                .iter()
                .enumerate()
                .all(|(j, &v)| v == TAU * j as f64 / nv as f64);
        let cols = if symmetric { nv / 4 + 1 } else { nv };
        let live: Vec<usize> = (1..=m).filter(|&n| !patch.modes[n].zero).collect();
        let mut cos = vec![0.0; m * cols];
        let mut sin = vec![0.0; m * cols];
        for &n in &live {
            for (j, &v) in vs.iter().take(cols).enumerate() {
                let (s, c) = (n as f64 * v).sin_cos();
                cos[(n - 1) * cols + j] = c;
                sin[(n - 1) * cols + j] = s;
            }
        }
        let mut delta = Vec::new();
        if let Some(r) = &patch.remainder {
            let k = patch.conditions.len();
            delta = vec![Vec3::zeros(); 2 * k * nv];
            for i in 0..k {
                for (j, &v) in vs.iter().enumerate() {
                    let d = r.delta(&patch.conditions, i, v, 1);
                    delta[(2 * i) * nv + j] = d[0];
                    delta[(2 * i + 1) * nv + j] = d[1];
                }
            }
        }
        PdeRows {
            patch,
            vs,
            cols,
            symmetric,
            live,
            cos,
            sin,
            delta,
        }
    }

    /// Cosine and sine coefficients of the nine quantities for every mode at `u`:
    /// `alpha[n·Q + q]`, `beta[n·Q + q]`.
    fn row_coefficients(&self, u: f64, alpha: &mut [f64], beta: &mut [f64]) {
        let mut o0 = [0.0; 6];
        let mut o1 = [0.0; 6];
        let live = std::iter::once(0).chain(self.live.iter().copied());
        for (n, mode) in live.map(|n| (n, &self.patch.modes[n])) {
            mode.eval01(u, &mut o0, &mut o1);
            let nf = n as f64;
            let (a, b) = (
                &mut alpha[n * Q..(n + 1) * Q],
                &mut beta[n * Q..(n + 1) * Q],
            );
            for k in 0..3 {
                a[k] = o0[k];
                b[k] = o0[3 + k];
                a[3 + k] = o1[k];
                b[3 + k] = o1[3 + k];
                // X_v: n(B cos − A sin).
                a[6 + k] = nf * o0[3 + k];
                b[6 + k] = -nf * o0[k];
            }
        }
    }
}

/// The per-row coefficients and per-column tables one accumulation works on.
struct Sums<'t> {
    /// `alpha[n·Q + q]`, `beta[n·Q + q]`: cosine and sine coefficients of quantity `q`, mode `n`.
    alpha: &'t [f64],
    beta: &'t [f64],
    /// The modes `n ≥ 1` summed.
    live: &'t [usize],
    /// `cos[(n−1)·cols + j]`, `sin[(n−1)·cols + j]`.
    cos: &'t [f64],
    sin: &'t [f64],
    cols: usize,
}

/// `acc[q][j] += Σ_n alpha[n][q]·cos_n[j] + beta[n][q]·sin_n[j]` over columns `j0..j0+len`. With
/// `4Q` accumulators the sums are split by the parity of `n` and into cosine and sine parts
/// (even cos, odd cos, even sin, odd sin); with `Q` they are not split.
///
/// `FMA` selects fused multiply–adds (one rounding instead of two), used where the processor
/// has them.
#[inline(always)]
fn accumulate_block<const FMA: bool>(t: &Sums, j0: usize, len: usize, acc: &mut [[f64; BLOCK]]) {
    let madd = |a: f64, x: f64, acc: f64| if FMA { a.mul_add(x, acc) } else { acc + a * x };
    let split = acc.len() == 4 * Q;
    for &n in t.live {
        let c = &t.cos[(n - 1) * t.cols + j0..(n - 1) * t.cols + j0 + len];
        let s = &t.sin[(n - 1) * t.cols + j0..(n - 1) * t.cols + j0 + len];
        let parity = n % 2;
        for q in 0..Q {
            let (an, bn) = (t.alpha[n * Q + q], t.beta[n * Q + q]);
            if split {
                for (a, x) in acc[parity * Q + q][..len].iter_mut().zip(c) {
                    *a = madd(an, *x, *a);
                }
                for (a, x) in acc[2 * Q + parity * Q + q][..len].iter_mut().zip(s) {
                    *a = madd(bn, *x, *a);
                }
            } else {
                for ((a, x), y) in acc[q][..len].iter_mut().zip(c).zip(s) {
                    *a = madd(bn, *y, madd(an, *x, *a));
                }
            }
        }
    }
}

/// Unit normals of a block: `unit[0..3][j]` from `X_u = vals[3..6][j]`, `X_v = vals[6..9][j]`;
/// `unit[3][j]` is 1 where the normal is defined and 0 where it degenerates (a pole).
#[inline(always)]
fn normals_block(vals: &[[f64; BLOCK]], len: usize, unit: &mut [[f64; BLOCK]]) {
    for j in 0..len {
        let (ax, ay, az) = (vals[3][j], vals[4][j], vals[5][j]);
        let (bx, by, bz) = (vals[6][j], vals[7][j], vals[8][j]);
        let (nx, ny, nz) = (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx);
        let len = (nx * nx + ny * ny + nz * nz).sqrt();
        // Degenerate (a pole) by the rule of `Partials::normal`.
        let size = ax * ax + ay * ay + az * az + bx * bx + by * by + bz * bz;
        let ok = !normal_degenerates(len, size) && len > 0.0;
        let inv = if ok { 1.0 / len } else { 0.0 };
        unit[0][j] = nx * inv;
        unit[1][j] = ny * inv;
        unit[2][j] = nz * inv;
        unit[3][j] = if ok { 1.0 } else { 0.0 };
    }
}

/// Unit normal `X_u × X_v / |X_u × X_v|`, or `None` where it degenerates (a pole) by the rule
/// of `Partials::normal`.
#[inline(always)]
fn unit_normal(xu: [f64; 3], xv: [f64; 3]) -> Option<Vec3> {
    let n = [
        xu[1] * xv[2] - xu[2] * xv[1],
        xu[2] * xv[0] - xu[0] * xv[2],
        xu[0] * xv[1] - xu[1] * xv[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let size = xu[0] * xu[0]
        + xu[1] * xu[1]
        + xu[2] * xu[2]
        + xv[0] * xv[0]
        + xv[1] * xv[1]
        + xv[2] * xv[2];
    if !normal_degenerates(len, size) && len > 0.0 {
        let inv = 1.0 / len;
        Some(Vec3::new(n[0] * inv, n[1] * inv, n[2] * inv))
    } else {
        None
    }
}

impl RowEvaluator for PdeRows<'_> {
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the processor supports the features the function was compiled for.
            return unsafe { self.eval_row_avx2(u, row) };
        }
        self.eval_row_generic::<false>(u, row)
    }
}

/// Writes `src[jj]` to `dst[col]` for the columns target `t` of a block starting at `j0` covers:
/// `j` (t = 0), `nv/2 − j` (1), `nv/2 + j` (2), `nv − j mod nv` (3): contiguous runs, two of them
/// reversed.
#[inline(always)]
fn store(dst: &mut [f64], t: usize, j0: usize, src: &[f64]) {
    let (nv, len, h) = (dst.len(), src.len(), dst.len() / 2);
    match t {
        0 => dst[j0..j0 + len].copy_from_slice(src),
        2 => dst[h + j0..h + j0 + len].copy_from_slice(src),
        1 => {
            for (d, s) in dst[h + 1 - j0 - len..=h - j0].iter_mut().rev().zip(src) {
                *d = *s;
            }
        }
        _ => {
            // nv − j for j = j0 + jj; j = 0 wraps to column 0.
            let (first, rest) = if j0 == 0 { (1, &src[1..]) } else { (0, src) };
            if first == 1 {
                dst[0] = src[0];
            }
            let hi = nv - j0 - first;
            for (d, s) in dst[hi + 1 - rest.len()..=hi].iter_mut().rev().zip(rest) {
                *d = *s;
            }
        }
    }
}

impl PdeRows<'_> {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn eval_row_avx2(&self, u: f64, row: &mut RowBuf) {
        self.eval_row_generic::<true>(u, row)
    }

    /// The row: mode coefficients at `u`, block-wise sums over the modes, the symmetric
    /// combination into columns, remainder, unit normals.
    #[inline(always)]
    fn eval_row_generic<const FMA: bool>(&self, u: f64, row: &mut RowBuf) {
        let nv = self.vs.len();
        let nm = self.patch.modes.len();
        // Scratch kept in the row buffer between rows: coefficients, then the accumulators.
        let mut scratch = std::mem::take(&mut row.scratch);
        let need = 2 * nm * Q + (5 * Q + 4) * BLOCK;
        if scratch.len() < need {
            scratch.resize(need, 0.0);
        }
        let (coefs, acc_flat) = scratch.split_at_mut(2 * nm * Q);
        let (alpha, beta) = coefs.split_at_mut(nm * Q);
        self.row_coefficients(u, alpha, beta);
        let (alpha, beta) = (&*alpha, &*beta);
        // With a remainder, X_u and X_v are kept (as x, y, z columns) until it has been added.
        let with_remainder = self.patch.remainder.is_some();
        let mut deriv = if with_remainder {
            vec![vec![0.0; nv]; 6]
        } else {
            Vec::new()
        };
        let groups = if self.symmetric { 4 * Q } else { Q };
        // Every accumulator a block uses is filled before it is read.
        let blocks: &mut [[f64; BLOCK]] = acc_flat.as_chunks_mut::<BLOCK>().0;
        let (acc, rest) = blocks.split_at_mut(4 * Q);
        let acc = &mut acc[..groups];
        let (vals, unit) = rest.split_at_mut(Q);
        let unit = &mut unit[..4];
        let mut poles = with_remainder;
        let mut j0 = 0;
        while j0 < self.cols {
            let len = BLOCK.min(self.cols - j0);
            for (g, a) in acc.iter_mut().enumerate() {
                // The mean (n = 0) belongs to the even cosine sums.
                a[..len].fill(if g < Q { alpha[g] } else { 0.0 });
            }
            let sums = Sums {
                alpha,
                beta,
                live: &self.live,
                cos: &self.cos,
                sin: &self.sin,
                cols: self.cols,
            };
            accumulate_block::<FMA>(&sums, j0, len, acc);
            let targets = if self.symmetric { 4 } else { 1 };
            for t in 0..targets {
                // P, Q, R, S (even cos, odd cos, even sin, odd sin) combine into the four
                // columns j, nv/2 − j, nv/2 + j, nv − j with the signs (+ + + +), (+ − − +),
                // (+ − + −), (+ + − −).
                for (q, vq) in vals.iter_mut().enumerate() {
                    if self.symmetric {
                        let (p, o, e, d) = (&acc[q], &acc[Q + q], &acc[2 * Q + q], &acc[3 * Q + q]);
                        let (p, o, e, d) = (&p[..len], &o[..len], &e[..len], &d[..len]);
                        let out = &mut vq[..len];
                        match t {
                            0 => {
                                (0..len).for_each(|jj| out[jj] = (p[jj] + o[jj]) + (e[jj] + d[jj]))
                            }
                            1 => {
                                (0..len).for_each(|jj| out[jj] = (p[jj] - o[jj]) + (d[jj] - e[jj]))
                            }
                            2 => {
                                (0..len).for_each(|jj| out[jj] = (p[jj] - o[jj]) + (e[jj] - d[jj]))
                            }
                            _ => {
                                (0..len).for_each(|jj| out[jj] = (p[jj] + o[jj]) - (e[jj] + d[jj]))
                            }
                        }
                    } else {
                        vq[..len].copy_from_slice(&acc[q][..len]);
                    }
                }
                let cols = [&mut row.x, &mut row.y, &mut row.z];
                for (k, dst) in cols.into_iter().enumerate() {
                    store(dst, t, j0, &vals[k][..len]);
                }
                if with_remainder {
                    for (k, dst) in deriv.iter_mut().enumerate() {
                        store(dst, t, j0, &vals[3 + k][..len]);
                    }
                    continue;
                }
                normals_block(vals, len, unit);
                poles |= unit[3][..len].contains(&0.0);
                let cols = [&mut row.nx, &mut row.ny, &mut row.nz];
                for (k, dst) in cols.into_iter().enumerate() {
                    store(dst, t, j0, &unit[k][..len]);
                }
            }
            j0 += len;
        }
        if let Some(r) = &self.patch.remainder {
            let k = self.patch.conditions.len();
            let mut w0 = vec![0.0; k];
            let mut w1 = vec![0.0; k];
            r.cardinal.eval(u, 0, &mut w0);
            r.cardinal.eval(u, 1, &mut w1);
            for i in (0..k).filter(|&i| r.active[i]) {
                let d0 = &self.delta[(2 * i) * nv..(2 * i + 1) * nv];
                let d1 = &self.delta[(2 * i + 1) * nv..(2 * i + 2) * nv];
                for j in 0..nv {
                    row.x[j] += d0[j].x * w0[i];
                    row.y[j] += d0[j].y * w0[i];
                    row.z[j] += d0[j].z * w0[i];
                    for c in 0..3 {
                        deriv[c][j] += d0[j][c] * w1[i];
                        deriv[3 + c][j] += d1[j][c] * w0[i];
                    }
                }
            }
            #[allow(clippy::needless_range_loop)] // j indexes nine columns
            for j in 0..nv {
                let xu = [deriv[0][j], deriv[1][j], deriv[2][j]];
                let xv = [deriv[3][j], deriv[4][j], deriv[5][j]];
                let n = unit_normal(xu, xv).unwrap_or_else(Vec3::zeros);
                (row.nx[j], row.ny[j], row.nz[j]) = (n.x, n.y, n.z);
            }
        }
        // Where X_u × X_v vanishes (a pole) the normal is the limit one.
        if poles {
            for j in 0..nv {
                if row.nx[j] == 0.0 && row.ny[j] == 0.0 && row.nz[j] == 0.0 {
                    let n = self.patch.partials(u, self.vs[j]).normal();
                    (row.nx[j], row.ny[j], row.nz[j]) = (n.x, n.y, n.z);
                }
            }
        }
        row.scratch = scratch;
    }
}

#[cfg(test)]
mod row_tests {
    use super::*;
    use crate::elliptic::{solve, Condition, SolveOptions};
    use crate::fourier::FourierSeries;
    use std::sync::Arc;

    /// At a pole (a position curve shrunk to a point) rows carry the limit normal.
    #[test]
    fn rows_at_a_pole_have_the_limit_normal() {
        let op = Operator::polyharmonic(2, 1.0).unwrap();
        let series = |a0: Vec3, r: f64| {
            Arc::new(FourierSeries {
                a0,
                cos: vec![Vec3::new(r, 0.0, 0.0)],
                sin: vec![Vec3::new(0.0, r, 0.0)],
            }) as crate::curve::SharedCurve
        };
        let conds = vec![
            Condition {
                u: 0.0,
                derivative: 0,
                curve: series(Vec3::zeros(), 0.0),
            },
            Condition {
                u: 0.0,
                derivative: 1,
                curve: series(Vec3::zeros(), 2.0),
            },
            Condition {
                u: 1.0,
                derivative: 0,
                curve: series(Vec3::new(0.0, 0.0, 1.0), 1.0),
            },
            Condition {
                u: 1.0,
                derivative: 1,
                curve: series(Vec3::new(0.0, 0.0, 1.0), 0.0),
            },
        ];
        let patch = solve(
            &op,
            conds,
            &SolveOptions {
                modes: 1,
                ..Default::default()
            },
        )
        .unwrap();
        let vs: Vec<f64> = (0..16).map(|j| TAU * j as f64 / 16.0).collect();
        let mut row = RowBuf::new(16);
        PdeRows::new(&patch, &vs).eval_row(0.0, &mut row);
        for (j, &v) in vs.iter().enumerate() {
            let n = row.normal(j);
            assert!((n.norm() - 1.0).abs() < 1e-12, "column {j}: {n}");
            assert!((n - patch.partials(0.0, v).normal()).norm() < 1e-12);
            // The pole's normal is the axis (the surface leaves the point radially, X_u ⟂ z).
            assert!(n.z.abs() > 1.0 - 1e-9, "column {j}: {n}");
        }
    }

    /// The fast row evaluator (symmetric and general paths, with and without remainder) agrees
    /// with pointwise evaluation.
    #[test]
    fn rows_match_pointwise_partials() {
        let op = Operator::polyharmonic(2, 1.7).unwrap();
        let f = |a0: f64, r: f64, extra: f64| {
            Arc::new(FourierSeries {
                a0: Vec3::new(0.1, 0.0, a0),
                cos: vec![
                    Vec3::new(r, 0.1, 0.0),
                    Vec3::new(0.0, extra, 0.05),
                    Vec3::new(0.02, 0.0, 0.0),
                ],
                sin: vec![
                    Vec3::new(0.0, r, 0.1),
                    Vec3::new(extra, 0.0, 0.0),
                    Vec3::new(0.0, 0.01, 0.03),
                ],
            }) as crate::curve::SharedCurve
        };
        let conds = vec![
            Condition {
                u: 0.0,
                derivative: 0,
                curve: f(0.0, 1.0, 0.2),
            },
            Condition {
                u: 0.0,
                derivative: 1,
                curve: f(1.0, 0.3, 0.1),
            },
            Condition {
                u: 1.0,
                derivative: 0,
                curve: f(1.0, 0.7, -0.1),
            },
            Condition {
                u: 1.0,
                derivative: 1,
                curve: f(1.0, -0.2, 0.0),
            },
        ];
        // 2 modes leave the third to the remainder.
        let solved = |modes: usize| {
            let options = SolveOptions {
                modes,
                ..Default::default()
            };
            solve(&op, conds.clone(), &options).unwrap()
        };
        let nodes =
            |nv: usize| -> Vec<f64> { (0..nv).map(|j| TAU * j as f64 / nv as f64).collect() };
        for modes in [3usize, 2] {
            let patch = solved(modes);
            assert_eq!(patch.has_remainder(), modes == 2);
            for nv in [16usize, 15, 8, 4 * BLOCK + 8, 4 * BLOCK] {
                let vs = nodes(nv);
                let rows = PdeRows::new(&patch, &vs);
                assert_eq!(rows.symmetric, nv.is_multiple_of(4));
                let mut row = RowBuf::new(nv);
                for &u in &[0.0, 0.3, 1.0] {
                    rows.eval_row(u, &mut row);
                    for (j, &v) in vs.iter().enumerate() {
                        let p = patch.partials(u, v);
                        assert!((row.point(j) - p.x).norm() < 1e-14, "nv={nv} u={u} j={j}");
                        assert!((row.normal(j) - p.normal()).norm() < 1e-12);
                    }
                }
            }
        }
        // Shared tables of more modes (3) serve both patches with the very values of their own
        // tables, bit for bit (with and without remainder, symmetric grid or not); tables of
        // other nodes, or of fewer modes, are not used.
        for nv in [16usize, 15] {
            let vs = nodes(nv);
            let tables = RowTables::new(&vs, 3);
            let other = RowTables::new(&nodes(nv + 4), 3);
            let fewer = RowTables::new(&vs, 1);
            for modes in [3usize, 2] {
                let patch = solved(modes);
                for &u in &[0.0, 0.3, 1.0] {
                    let mut own = vec![Partials::default(); nv];
                    patch.partials_rows(&vs).eval_row(u, &mut own);
                    for t in [&tables, &other, &fewer] {
                        let mut row = vec![Partials::default(); nv];
                        patch.partials_rows_sharing(&vs, t).eval_row(u, &mut row);
                        assert_eq!(row, own, "nv={nv} modes={modes} u={u}");
                    }
                }
            }
        }
    }
}
