//! The solved patch: evaluation anywhere with exact partials, the spine, reports, and a fast
//! row evaluator for grids.

use super::{Condition, ConditionError, ModeFn, ModeReport, Operator};
use crate::curve::Curve;
use crate::fourier::FourierSeries;
use crate::surface::{Partials, RowEvaluator, Surface, VDomain};
use crate::{Vec3, TAU};

/// A solved Bloor–Wilson patch `X(u,v) = A₀(u) + Σ [Aₙ(u) cos nv + Bₙ(u) sin nv] + R(u,v)`
/// (Eqs. 4.36, 4.53). Evaluation is cheap and every partial derivative is exact.
#[derive(Debug)]
pub struct PdePatch {
    operator: Operator,
    conditions: Vec<Condition>,
    /// Mode `n` has 6 columns: `Aₙ` (x, y, z) then `Bₙ` (x, y, z).
    pub(super) modes: Vec<ModeFn>,
    /// The remainder `R(u,v) = Σ_i w_i(u) Δ_i(v)`: `w_i` are the cardinal functions of mode
    /// `M + 1` (`w_i^{(d_k)}(u_k) = δ_ik`), and `Δ_i(v) = g_i(v) − ∂ᵈX̃(u_i, v)` the part of
    /// condition `i` the `M` modes leave (Eqs. 4.50–4.52).
    remainder: Option<Remainder>,
    reports: Vec<ModeReport>,
    scale: f64,
}

#[derive(Debug)]
pub(crate) struct Remainder {
    pub(crate) cardinal: ModeFn,
    /// `∂ᵈX̃(u_i, v)` as a Fourier series, one per condition.
    pub(crate) fitted: Vec<FourierSeries>,
    /// Conditions that take part (`Δ_i ≠ 0`).
    pub(crate) active: Vec<bool>,
}

impl Remainder {
    /// `Δ_i(v)` and its first two v-derivatives (zero for inactive conditions).
    fn delta(&self, conditions: &[Condition], i: usize, v: f64) -> [Vec3; 3] {
        if !self.active[i] {
            return [Vec3::zeros(); 3];
        }
        let mut g = [Vec3::zeros(); 3];
        let mut f = [Vec3::zeros(); 3];
        conditions[i].curve.jet(v, &mut g);
        self.fitted[i].jet(v, &mut f);
        [g[0] - f[0], g[1] - f[1], g[2] - f[2]]
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
        let scale = design_scale(&conditions);
        PdePatch {
            operator,
            conditions,
            modes,
            remainder,
            reports,
            scale,
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
        self.scale
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
                x += r.delta(&self.conditions, i, v)[0] * *wi;
            }
        }
        x
    }

    /// The error of every condition on `samples` equally spaced `v` (at least 1).
    pub fn condition_errors(&self, samples: usize) -> Vec<ConditionError> {
        let samples = samples.max(1);
        let k = self.conditions.len();
        self.conditions
            .iter()
            .map(|c| {
                let fitted = fitted_series(&self.modes, c.u, c.derivative);
                let mut w = vec![0.0; k];
                if let Some(r) = &self.remainder {
                    r.cardinal.eval(c.u, c.derivative, &mut w);
                }
                let (mut abs, mut size) = (0.0f64, 0.0f64);
                for j in 0..samples {
                    let v = TAU * j as f64 / samples as f64;
                    let g = c.curve.point(v);
                    let mut x = fitted.point(v);
                    if let Some(r) = &self.remainder {
                        for (i, wi) in w.iter().enumerate() {
                            if r.active[i] {
                                x += r.delta(&self.conditions, i, v)[0] * *wi;
                            }
                        }
                    }
                    abs = abs.max((x - g).norm());
                    size = size.max(g.norm());
                }
                let denom = if c.derivative == 0 {
                    self.scale
                } else {
                    self.scale.max(size)
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

    fn partials(&self, u: f64, v: f64) -> Partials {
        let mut p = Partials::default();
        let mut o = [[0.0; 6]; 3];
        for (n, mode) in self.modes.iter().enumerate() {
            for (d, od) in o.iter_mut().enumerate() {
                mode.eval(u, d, od);
            }
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
            for (d, wd) in w.iter_mut().enumerate() {
                r.cardinal.eval(u, d, wd);
            }
            for i in 0..k {
                let [dl, dl1, dl2] = r.delta(&self.conditions, i, v);
                p.x += dl * w[0][i];
                p.xu += dl * w[1][i];
                p.xuu += dl * w[2][i];
                p.xv += dl1 * w[0][i];
                p.xuv += dl1 * w[1][i];
                p.xvv += dl2 * w[0][i];
            }
        }
        p
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(PdeRows::new(self, vs))
    }
}

/// Grid rows of a [`PdePatch`]: per-column tables of `cos nv_j`, `sin nv_j` (and of the
/// remainder's `Δ_i(v_j)`, `Δ_i'(v_j)`), so a row is a handful of multiply–adds per vertex.
struct PdeRows<'a> {
    patch: &'a PdePatch,
    vs: &'a [f64],
    /// `cos[(n−1)·nv + j] = cos(n v_j)`, likewise `sin`.
    cos: Vec<f64>,
    sin: Vec<f64>,
    /// `delta[(i·2 + d)·nv + j] = ∂ᵈ_v Δ_i(v_j)` (d = 0, 1) as `Vec3`.
    delta: Vec<Vec3>,
}

impl<'a> PdeRows<'a> {
    fn new(patch: &'a PdePatch, vs: &'a [f64]) -> Self {
        let m = patch.modes();
        let nv = vs.len();
        let mut cos = vec![0.0; m * nv];
        let mut sin = vec![0.0; m * nv];
        for n in 1..=m {
            for (j, &v) in vs.iter().enumerate() {
                let (s, c) = (n as f64 * v).sin_cos();
                cos[(n - 1) * nv + j] = c;
                sin[(n - 1) * nv + j] = s;
            }
        }
        let mut delta = Vec::new();
        if let Some(r) = &patch.remainder {
            let k = patch.conditions.len();
            delta = vec![Vec3::zeros(); 2 * k * nv];
            for i in 0..k {
                for (j, &v) in vs.iter().enumerate() {
                    let d = r.delta(&patch.conditions, i, v);
                    delta[(2 * i) * nv + j] = d[0];
                    delta[(2 * i + 1) * nv + j] = d[1];
                }
            }
        }
        PdeRows {
            patch,
            vs,
            cos,
            sin,
            delta,
        }
    }
}

impl RowEvaluator for PdeRows<'_> {
    fn eval_row(&self, u: f64, pos: &mut [Vec3], nrm: &mut [Vec3]) {
        let nv = self.vs.len();
        let m = self.patch.modes();
        let mut o0 = [0.0; 6];
        let mut o1 = [0.0; 6];
        self.patch.modes[0].eval(u, 0, &mut o0);
        self.patch.modes[0].eval(u, 1, &mut o1);
        let mut xu = vec![col3(&o1, 0); nv];
        let mut xv = vec![Vec3::zeros(); nv];
        pos.iter_mut().for_each(|p| *p = col3(&o0, 0));
        for n in 1..=m {
            self.patch.modes[n].eval(u, 0, &mut o0);
            self.patch.modes[n].eval(u, 1, &mut o1);
            let (a, b, a1, b1) = (col3(&o0, 0), col3(&o0, 3), col3(&o1, 0), col3(&o1, 3));
            let nf = n as f64;
            let (an, bn) = (a * -nf, b * nf);
            let cs = &self.cos[(n - 1) * nv..n * nv];
            let sn = &self.sin[(n - 1) * nv..n * nv];
            for j in 0..nv {
                let (c, s) = (cs[j], sn[j]);
                pos[j] += a * c + b * s;
                xu[j] += a1 * c + b1 * s;
                xv[j] += bn * c + an * s;
            }
        }
        if let Some(r) = &self.patch.remainder {
            let k = self.patch.conditions.len();
            let mut w0 = vec![0.0; k];
            let mut w1 = vec![0.0; k];
            r.cardinal.eval(u, 0, &mut w0);
            r.cardinal.eval(u, 1, &mut w1);
            for i in 0..k {
                let d0 = &self.delta[(2 * i) * nv..(2 * i + 1) * nv];
                let d1 = &self.delta[(2 * i + 1) * nv..(2 * i + 2) * nv];
                for j in 0..nv {
                    pos[j] += d0[j] * w0[i];
                    xu[j] += d0[j] * w1[i];
                    xv[j] += d1[j] * w0[i];
                }
            }
        }
        for j in 0..nv {
            let n = xu[j].cross(&xv[j]);
            let len = n.norm();
            let size = xu[j].norm() * xv[j].norm();
            nrm[j] = if len > 1e-10 * size && len > 0.0 {
                n / len
            } else {
                self.patch.partials(u, self.vs[j]).normal()
            };
        }
    }
}
