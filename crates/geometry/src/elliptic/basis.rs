//! Bounded bases for the solution space `V_n` of one Fourier mode's equation, and the mode
//! functions built from them.
//!
//! Two bases cover every regime:
//! - **Layers** (`n·|s|` large compared with `N`): for each characteristic root `s` (multiplicity
//!   `m`, `Re s = α > 0`) the functions `e^{−n s t} L_k(2nα t)`, `k < m`, with `t = u` (decaying
//!   away from `u = 0`) and `t = 1 − u` (decaying away from `u = 1`); `L_k` are Laguerre
//!   polynomials, so the functions are bounded by 1 on `[0, 1]` and close to orthonormal. This is
//!   the book's `u^k e^{±anu}` (Eqs. 4.13, 4.38) in a basis that never overflows: the book's
//!   `e^{anu}` reaches `e^{96}` for `a = 8, n = 12`.
//! - **Chebyshev** (`n·|s|` small or moderate, and always for the spine `n = 0`): `ψ_k = T_k(x) +
//!   tail_k(x)`, `x = 2u − 1`, `k < 2N`, where the tail (Chebyshev coefficients `≥ 2N`) is fixed by
//!   the mode equation integrated `2N` times. As `n → 0` the `ψ_k` become the Chebyshev
//!   polynomials themselves, so the basis stays as well conditioned as polynomial interpolation
//!   allows; exponential bases lose every digit there (they become nearly dependent).
//!
//! Both represent members of `V_n` exactly up to rounding (the Chebyshev tail is continued until
//! its coefficients fall below the unit roundoff).

use super::operator::{Operator, RootGroup};
use nalgebra::{Complex, DMatrix};
use std::sync::Arc;

/// Which basis a mode is represented in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasisKind {
    /// Chebyshev series in `x = 2u − 1`: the spine's basis (mode 0), and the fallback where the
    /// layer basis is ill-conditioned.
    Chebyshev,
    /// Exponential layers built from the operator's characteristic roots, decaying away from
    /// `u = 0` or from `u = 1` (modes `n ≥ 1`).
    Layers,
}

impl BasisKind {
    /// The name the solver reports ([`super::ModeReport::basis`]): `"chebyshev"` or
    /// `"exponential layers"`.
    pub fn name(self) -> &'static str {
        match self {
            BasisKind::Chebyshev => "chebyshev",
            BasisKind::Layers => "exponential layers",
        }
    }
}

/// The `2N` basis functions of `V_n` in one of the two representations.
#[derive(Clone, Debug)]
pub(crate) enum Basis {
    /// Chebyshev coefficients (in `x = 2u − 1`) of each basis function: `series[k][m]`, and
    /// those of its first three x-derivatives, `derivatives[d − 1][k]` ([`cheb_diff`] applied
    /// `d` times), made once so that evaluations do not differentiate the series again. Shared:
    /// the modes of a patch's tangents clone their bases.
    Chebyshev {
        series: Arc<Vec<Vec<f64>>>,
        derivatives: Arc<[Vec<Vec<f64>>; 3]>,
    },
    /// Layer functions.
    Layers(LayerBasis),
}

#[derive(Clone, Debug)]
pub(crate) struct LayerBasis {
    n: f64,
    groups: Vec<RootGroup>,
    /// (group, side (false: t = u, true: t = 1 − u), Laguerre index k, imaginary part?)
    funcs: Vec<(usize, bool, usize, bool)>,
}

impl Basis {
    /// The Chebyshev basis of the series `series[k]` with their derivatives' series.
    fn chebyshev_of(series: Vec<Vec<f64>>) -> Basis {
        let d1: Vec<Vec<f64>> = series.iter().map(|s| cheb_diff(s)).collect();
        let d2: Vec<Vec<f64>> = d1.iter().map(|s| cheb_diff(s)).collect();
        let d3: Vec<Vec<f64>> = d2.iter().map(|s| cheb_diff(s)).collect();
        Basis::Chebyshev {
            series: Arc::new(series),
            derivatives: Arc::new([d1, d2, d3]),
        }
    }

    pub(super) fn kind(&self) -> BasisKind {
        match self {
            Basis::Chebyshev { .. } => BasisKind::Chebyshev,
            Basis::Layers(_) => BasisKind::Layers,
        }
    }

    pub(super) fn len(&self) -> usize {
        match self {
            Basis::Chebyshev { series, .. } => series.len(),
            Basis::Layers(l) => l.funcs.len(),
        }
    }

    /// The layer basis of mode `n ≥ 1`.
    pub(super) fn layers(op: &Operator, n: usize) -> Basis {
        let mut funcs = Vec::new();
        for (g, group) in op.roots().iter().enumerate() {
            for side in [false, true] {
                for k in 0..group.multiplicity {
                    funcs.push((g, side, k, false));
                    if group.is_complex() {
                        funcs.push((g, side, k, true));
                    }
                }
            }
        }
        Basis::Layers(LayerBasis {
            n: n as f64,
            groups: op.roots().to_vec(),
            funcs,
        })
    }

    /// The Chebyshev basis of mode `n` (exactly `T_0 … T_{2N−1}` for `n = 0`). `None` if the
    /// tail does not decay within the largest truncation we allow (modes far in the layer
    /// regime).
    pub(super) fn chebyshev(op: &Operator, n: usize) -> Option<Basis> {
        let two_n = 2 * op.half_order();
        if n == 0 {
            let series = (0..two_n)
                .map(|k| {
                    let mut c = vec![0.0; two_n];
                    c[k] = 1.0;
                    c
                })
                .collect();
            return Some(Basis::chebyshev_of(series));
        }
        let gammas = op.mode_gammas_x(n);
        // Growth rate in x is n|s|/2; Chebyshev coefficients of e^{zx} decay like I_k(z). Beyond
        // z ≈ 16 the tail system loses its digits (the layer basis is the right tool there).
        let z = n as f64 * op.root_scale() / 2.0;
        if z > MAX_CHEBYSHEV_RATE {
            return None;
        }
        let mut m = two_n + (z + 8.0 * z.sqrt()).ceil() as usize + 24 + 2 * two_n;
        while m <= MAX_CHEBYSHEV {
            if let Some(series) = chebyshev_tail(&gammas, two_n, m) {
                let basis = Basis::chebyshev_of(series);
                // A posteriori: every ψ_k must solve the mode equation.
                return (basis.mode_residual(&gammas) <= 1e-9).then_some(basis);
            }
            m = m * 3 / 2;
        }
        None
    }

    /// The largest relative residual of the mode equation `f^{(2N)} + Σ γ_j f^{(2N−2j)} = 0`
    /// (in `x`) over the Chebyshev basis functions, at the ends and the middle of `[−1, 1]`.
    fn mode_residual(&self, gammas: &[f64]) -> f64 {
        let Basis::Chebyshev { series, .. } = self else {
            return 0.0;
        };
        let nn = gammas.len();
        let mut worst = 0.0f64;
        for s in series.iter() {
            // Derivatives 0, 2, …, 2N of the series.
            let mut derivs = vec![s.clone()];
            for _ in 0..2 * nn {
                let next = cheb_diff(derivs.last().expect("non-empty"));
                derivs.push(next);
            }
            for &x in &[-1.0, 0.0, 1.0] {
                let mut sum = clenshaw(&derivs[2 * nn], x);
                let mut size = sum.abs();
                for (j, g) in gammas.iter().enumerate() {
                    let term = g * clenshaw(&derivs[2 * nn - 2 * (j + 1)], x);
                    sum += term;
                    size += term.abs();
                }
                if size > 0.0 {
                    worst = worst.max(sum.abs() / size);
                }
            }
        }
        worst
    }

    /// Values and first u-derivatives of every basis function at `u`.
    pub(super) fn eval01(&self, u: f64, out0: &mut [f64], out1: &mut [f64]) {
        match self {
            Basis::Chebyshev { .. } => {
                self.eval(u, 0, out0);
                self.eval(u, 1, out1);
            }
            Basis::Layers(l) => l.eval01(u, out0, out1),
        }
    }

    /// [`Basis::eval`] for `d = 0, 1, 2` into `out[d]`, the same values bit for bit (the layer
    /// basis shares its exponentials and Laguerre values between the three).
    pub(super) fn eval012(&self, u: f64, out: [&mut [f64]; 3]) {
        match self {
            Basis::Chebyshev { .. } => {
                for (d, o) in out.into_iter().enumerate() {
                    self.eval(u, d, o);
                }
            }
            Basis::Layers(l) => l.eval012(u, out),
        }
    }

    /// The layer basis's bounds of `sup_{[0, 1]} |ψ_k^{(d)}|` ([`LayerBasis::derivative_sups`]);
    /// `None` for the Chebyshev basis (bounded through its series instead).
    pub(super) fn layer_derivative_sups(&self, d: usize) -> Option<Vec<f64>> {
        match self {
            Basis::Chebyshev { .. } => None,
            Basis::Layers(l) => Some(l.derivative_sups(d)),
        }
    }

    /// `d`-th u-derivatives of every basis function at `u`: `out[k]`.
    pub(super) fn eval(&self, u: f64, d: usize, out: &mut [f64]) {
        match self {
            Basis::Chebyshev {
                series,
                derivatives,
            } => {
                // The same values as `cheb_derivative_at` of `series`, bit for bit: its
                // derivative series are those kept, and the functions' recurrences run
                // interleaved (`clenshaw_lanes`, the operations of `clenshaw`).
                let scale = 2f64.powi(d as i32);
                let x = 2.0 * u - 1.0;
                match d {
                    0 => clenshaw_lanes(series.as_slice(), x, scale, out),
                    1..=3 => clenshaw_lanes(derivatives[d - 1].as_slice(), x, scale, out),
                    _ => {
                        for (k, s) in series.iter().enumerate() {
                            out[k] = cheb_derivative_at(s, x, d) * scale;
                        }
                    }
                }
            }
            Basis::Layers(l) => l.eval(u, d, out),
        }
    }
}

/// Largest Chebyshev truncation tried.
const MAX_CHEBYSHEV: usize = 640;
/// Largest growth rate `n|s|/2` (in `x = 2u − 1`) for which the Chebyshev basis is built.
const MAX_CHEBYSHEV_RATE: f64 = 16.0;

/// Chebyshev integration `J` (zero constant), truncated to the length of `a`.
fn integrate(a: &[f64], out: &mut [f64]) {
    let m = a.len();
    out[0] = 0.0;
    if m > 1 {
        out[1] = a[0] - if m > 2 { a[2] / 2.0 } else { 0.0 };
    }
    for k in 2..m {
        let next = if k + 1 < m { a[k + 1] } else { 0.0 };
        out[k] = (a[k - 1] - next) / (2.0 * k as f64);
    }
}

/// Tails of `ψ_k = T_k + Σ_{j ≥ 2N} t_{kj} T_j`: the mode equation `f^{(2N)} + Σ γ_j f^{(2N−2j)} =
/// 0` integrated `2N` times reads `f + Σ γ_j J^{2j} f = p` with `p` of degree `< 2N`, so the
/// Chebyshev coefficients `≥ 2N` of `f + Σ γ_j J^{2j} f` vanish. Those rows form a square system
/// for the tail given the head. Returns `None` if the last coefficients have not decayed to
/// rounding level (the truncation `m` is too short).
fn chebyshev_tail(gammas: &[f64], two_n: usize, m: usize) -> Option<Vec<Vec<f64>>> {
    let len = m + 1;
    let tail = len - two_n;
    // Columns of B = I + Σ γ_j J^{2j}, rows ≥ 2N.
    let mut b = DMatrix::<f64>::zeros(tail, len);
    let mut v = vec![0.0; len];
    let mut w = vec![0.0; len];
    for c in 0..len {
        v.iter_mut().for_each(|x| *x = 0.0);
        v[c] = 1.0;
        let mut acc = v.clone();
        for &g in gammas {
            integrate(&v, &mut w);
            integrate(&w, &mut v);
            for (a, x) in acc.iter_mut().zip(&v) {
                *a += g * x;
            }
        }
        for r in 0..tail {
            b[(r, c)] = acc[two_n + r];
        }
    }
    let btt = b.columns(two_n, tail).into_owned();
    let rhs = -b.columns(0, two_n).into_owned();
    let lu = btt.lu();
    let sol = lu.solve(&rhs)?;
    let mut series = Vec::with_capacity(two_n);
    for k in 0..two_n {
        let mut s = vec![0.0; len];
        s[k] = 1.0;
        for r in 0..tail {
            s[two_n + r] = sol[(r, k)];
        }
        if s.iter().any(|x| !x.is_finite()) {
            return None;
        }
        // The highest derivative a condition may ask for is 2N − 1, and T_j^{(d)}(±1) grows like
        // j^{2d}: the truncated coefficients must be negligible even after that growth.
        let weight = |j: usize| {
            (0..two_n - 1).fold(1.0f64, |w, i| {
                w * (((j * j) as f64 - (i * i) as f64) / (2 * i + 1) as f64).max(1.0)
            })
        };
        let size = s
            .iter()
            .enumerate()
            .fold(0.0f64, |a, (j, x)| a.max(x.abs() * weight(j)));
        let last = (len - 3..len).map(|j| s[j].abs() * weight(j)).sum::<f64>();
        if last > 1e-17 * size {
            return None;
        }
        let mut end = len;
        while end > two_n && s[end - 1] == 0.0 {
            end -= 1;
        }
        s.truncate(end);
        series.push(s);
    }
    Some(series)
}

/// Chebyshev coefficients of the derivative of `Σ a_m T_m`.
pub(crate) fn cheb_diff(a: &[f64]) -> Vec<f64> {
    let m = a.len();
    if m <= 1 {
        return vec![0.0];
    }
    let mut b = vec![0.0; m + 1];
    for k in (1..m).rev() {
        b[k - 1] = b[k + 1] + 2.0 * k as f64 * a[k];
    }
    b[0] /= 2.0;
    b.truncate(m - 1);
    b
}

/// `Σ a_m T_m(x)` by Clenshaw's recurrence.
pub(crate) fn clenshaw(a: &[f64], x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &c in a.iter().skip(1).rev() {
        let b0 = 2.0 * x * b1 - b2 + c;
        b2 = b1;
        b1 = b0;
    }
    x * b1 - b2 + a.first().copied().unwrap_or(0.0)
}

/// [`clenshaw`] of several series of one length at once: `out[l] = Σ_m a_l[m] T_m(x)`. The
/// recurrences are interleaved (independent chains, so the processor overlaps their latencies)
/// and every lane performs exactly the operations of [`clenshaw`], so the values are the same
/// bit for bit. Series of other lengths and lanes beyond twelve go through [`clenshaw`].
pub(crate) fn clenshaw_lanes<S: AsRef<[f64]>>(series: &[S], x: f64, scale: f64, out: &mut [f64]) {
    const LANES: usize = 12;
    let n = series.len().min(out.len());
    let len = series.first().map_or(0, |s| s.as_ref().len());
    if n > LANES || series[..n].iter().any(|s| s.as_ref().len() != len) {
        for (o, s) in out.iter_mut().zip(series) {
            *o = clenshaw(s.as_ref(), x) * scale;
        }
        return;
    }
    let (mut b1, mut b2) = ([0.0; LANES], [0.0; LANES]);
    for k in (1..len).rev() {
        for l in 0..n {
            let b0 = 2.0 * x * b1[l] - b2[l] + series[l].as_ref()[k];
            b2[l] = b1[l];
            b1[l] = b0;
        }
    }
    for l in 0..n {
        let a0 = series[l].as_ref().first().copied().unwrap_or(0.0);
        out[l] = (x * b1[l] - b2[l] + a0) * scale;
    }
}

/// `d`-th x-derivative of `Σ a_m T_m` at `x`.
fn cheb_derivative_at(a: &[f64], x: f64, d: usize) -> f64 {
    if d == 0 {
        return clenshaw(a, x);
    }
    let mut s = cheb_diff(a);
    for _ in 1..d {
        s = cheb_diff(&s);
    }
    clenshaw(&s, x)
}

/// One run of layer functions sharing a root and a side, evaluated at one `u`.
struct Run<'a> {
    /// Index of the run's first function.
    slot: usize,
    group: &'a RootGroup,
    /// `λ = n s`, `2 Re λ`, `e^{−λt}`, and `−1` on the side `t = 1 − u` (else `1`).
    lambda: Complex<f64>,
    alpha2: f64,
    e: Complex<f64>,
    side_sign: f64,
    /// `L_0(x) … L_{m−1}(x)` at `x = 2 Re λ · t`.
    lag: &'a [f64],
}

impl LayerBasis {
    /// Calls `f` for each run of functions (`k = 0..m`, real and imaginary parts) that share a
    /// root and a side: the exponential and the Laguerre values are computed once per run.
    fn for_each_run(&self, u: f64, mut f: impl FnMut(&Run)) {
        let mut lag = [0.0f64; 2 * super::MAX_HALF_ORDER];
        let mut slot = 0;
        while slot < self.funcs.len() {
            let (g, side, _, _) = self.funcs[slot];
            let group = &self.groups[g];
            let m = group.multiplicity;
            let t = if side { 1.0 - u } else { u };
            let lambda = group.s * self.n;
            let alpha2 = 2.0 * lambda.re;
            laguerre(alpha2 * t, &mut lag[..m]);
            let e = if lambda.im == 0.0 {
                Complex::new((-lambda.re * t).exp(), 0.0)
            } else {
                (-lambda * t).exp()
            };
            let side_sign = if side { -1.0 } else { 1.0 };
            f(&Run {
                slot,
                group,
                lambda,
                alpha2,
                e,
                side_sign,
                lag: &lag[..m],
            });
            slot += m * if group.is_complex() { 2 } else { 1 };
        }
    }

    /// Bounds of `sup_{u ∈ [0, 1]} |ψ^{(d)}(u)|` for every layer function `ψ` (in the order of
    /// [`Self::eval`]). The `d`-th derivative is `e^{−λt} Σ_j q_j L_j(2αt)` (`α = Re λ > 0`,
    /// the coefficients `q_j` of [`Self::eval`]), and `|L_j(x)| ≤ e^{x/2}` for `x ≥ 0`
    /// (Szegő), so `|e^{−λt} L_j(2αt)| ≤ 1` and the derivative is at most `Σ_j |q_j|` (its real
    /// and imaginary parts too).
    pub(super) fn derivative_sups(&self, d: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.funcs.len()];
        let mut coef = [Complex::new(0.0, 0.0); 2 * super::MAX_HALF_ORDER];
        let mut slot = 0;
        while slot < self.funcs.len() {
            let (g, _, _, _) = self.funcs[slot];
            let group = &self.groups[g];
            let lambda = group.s * self.n;
            let alpha2 = 2.0 * lambda.re;
            for k in 0..group.multiplicity {
                for (j, c) in coef[..=k].iter_mut().enumerate() {
                    *c = Complex::new(if j == k { 1.0 } else { 0.0 }, 0.0);
                }
                for _ in 0..d {
                    let mut suffix = Complex::new(0.0, 0.0);
                    for j in (0..=k).rev() {
                        let p = coef[j];
                        coef[j] = (-suffix - p * 0.5) * alpha2 - Complex::new(0.0, lambda.im) * p;
                        suffix += p;
                    }
                }
                let sup: f64 = coef[..=k].iter().map(|c| c.norm()).sum();
                out[slot] = sup;
                slot += 1;
                if group.is_complex() {
                    out[slot] = sup;
                    slot += 1;
                }
            }
        }
        out
    }

    /// `d`-th u-derivatives of every layer function at `u`.
    fn eval(&self, u: f64, d: usize, out: &mut [f64]) {
        let mut coef = [Complex::new(0.0, 0.0); 2 * super::MAX_HALF_ORDER];
        self.for_each_run(u, |r| {
            let sign = if d % 2 == 1 { r.side_sign } else { 1.0 };
            let mut slot = r.slot;
            for k in 0..r.lag.len() {
                // Laguerre coefficients of the d-th t-derivative of e^{−λt} L_k(x), divided by
                // e^{−λt}: q_j = 2α(−Σ_{i>j} p_i − p_j/2) − iβ p_j per derivative.
                for (j, c) in coef[..=k].iter_mut().enumerate() {
                    *c = Complex::new(if j == k { 1.0 } else { 0.0 }, 0.0);
                }
                for _ in 0..d {
                    let mut suffix = Complex::new(0.0, 0.0);
                    for j in (0..=k).rev() {
                        let p = coef[j];
                        coef[j] =
                            (-suffix - p * 0.5) * r.alpha2 - Complex::new(0.0, r.lambda.im) * p;
                        suffix += p;
                    }
                }
                let sum: Complex<f64> = (0..=k).map(|j| coef[j] * r.lag[j]).sum();
                let value = r.e * sum * sign;
                out[slot] = value.re;
                slot += 1;
                if r.group.is_complex() {
                    out[slot] = value.im;
                    slot += 1;
                }
            }
        });
    }

    /// [`Self::eval`] for `d = 0, 1, 2` at once: one pass over the runs (one exponential and
    /// one set of Laguerre values per run instead of three), and the second derivative's
    /// coefficients continue from the first's. Every value is computed by the operations
    /// [`Self::eval`] performs, so it is the same bit for bit.
    fn eval012(&self, u: f64, out: [&mut [f64]; 3]) {
        let mut coef = [Complex::new(0.0, 0.0); 2 * super::MAX_HALF_ORDER];
        let [o0, o1, o2] = out;
        self.for_each_run(u, |r| {
            let mut slot = r.slot;
            for k in 0..r.lag.len() {
                for (j, c) in coef[..=k].iter_mut().enumerate() {
                    *c = Complex::new(if j == k { 1.0 } else { 0.0 }, 0.0);
                }
                for (d, o) in [&mut *o0, &mut *o1, &mut *o2].into_iter().enumerate() {
                    if d > 0 {
                        let mut suffix = Complex::new(0.0, 0.0);
                        for j in (0..=k).rev() {
                            let p = coef[j];
                            coef[j] =
                                (-suffix - p * 0.5) * r.alpha2 - Complex::new(0.0, r.lambda.im) * p;
                            suffix += p;
                        }
                    }
                    let sign = if d % 2 == 1 { r.side_sign } else { 1.0 };
                    let sum: Complex<f64> = (0..=k).map(|j| coef[j] * r.lag[j]).sum();
                    let value = r.e * sum * sign;
                    o[slot] = value.re;
                    if r.group.is_complex() {
                        o[slot + 1] = value.im;
                    }
                }
                slot += if r.group.is_complex() { 2 } else { 1 };
            }
        });
    }

    /// Values and first u-derivatives of every layer function (the hot path of grid rows):
    /// for `p = e_k` the derivative's Laguerre coefficients are `q_j = −2α` (`j < k`) and
    /// `q_k = −α − iβ`.
    fn eval01(&self, u: f64, out0: &mut [f64], out1: &mut [f64]) {
        self.for_each_run(u, |r| {
            let mut slot = r.slot;
            let mut below = 0.0; // Σ_{j<k} L_j(x)
            for &lk in r.lag {
                let sum1 = Complex::new(-r.alpha2 * below - 0.5 * r.alpha2 * lk, -r.lambda.im * lk);
                let (v0, v1) = (r.e * lk, r.e * sum1 * r.side_sign);
                out0[slot] = v0.re;
                out1[slot] = v1.re;
                slot += 1;
                if r.group.is_complex() {
                    out0[slot] = v0.im;
                    out1[slot] = v1.im;
                    slot += 1;
                }
                below += lk;
            }
        });
    }
}

/// Laguerre polynomials `L_0(x) … L_{m−1}(x)`.
fn laguerre(x: f64, out: &mut [f64]) {
    if out.is_empty() {
        return;
    }
    out[0] = 1.0;
    if out.len() > 1 {
        out[1] = 1.0 - x;
    }
    for j in 1..out.len().saturating_sub(1) {
        out[j + 1] = ((2 * j + 1) as f64 - x) / (j + 1) as f64 * out[j]
            - j as f64 / (j + 1) as f64 * out[j - 1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interleaved_clenshaw_is_bit_identical() {
        let mut state = 99u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for len in [0usize, 1, 2, 3, 17, 64] {
            for lanes in [1usize, 6, 8, 9] {
                let series: Vec<Vec<f64>> = (0..lanes)
                    .map(|l| {
                        (0..len)
                            .map(|k| if (k + l) % 5 == 0 { 0.0 } else { next() * 1e3 })
                            .collect()
                    })
                    .collect();
                for x in [-1.0, -0.73, -0.0, 0.0, 0.31, 1.0] {
                    let mut out = vec![0.0; lanes];
                    clenshaw_lanes(&series, x, 4.0, &mut out);
                    for (o, s) in out.iter().zip(&series) {
                        assert_eq!(o.to_bits(), (clenshaw(s, x) * 4.0).to_bits());
                    }
                }
            }
        }
        // Unequal lengths take the scalar path.
        let series = vec![vec![1.0, 2.0, 3.0], vec![4.0, 5.0]];
        let mut out = [0.0; 2];
        clenshaw_lanes(&series, 0.5, 1.0, &mut out);
        assert_eq!(out, [clenshaw(&series[0], 0.5), clenshaw(&series[1], 0.5)]);
    }

    /// Residual of the mode equation `Σ_k c_k (−n²)^k f^{(2N−2k)}(u)` for basis function `k`,
    /// relative to the size of its terms.
    fn mode_residual(op: &Operator, basis: &Basis, n: usize, u: f64, k: usize) -> f64 {
        let nn = op.half_order();
        let mut vals = vec![0.0; basis.len()];
        let (mut sum, mut size) = (0.0, 0.0);
        for (j, &c) in op.coefficients().iter().enumerate() {
            basis.eval(u, 2 * nn - 2 * j, &mut vals);
            let term = c * (-((n * n) as f64)).powi(j as i32) * vals[k];
            sum += term;
            size += term.abs();
        }
        sum.abs() / size.max(1e-300)
    }

    #[test]
    fn both_bases_solve_the_mode_equation() {
        for (op, n) in [
            (Operator::polyharmonic(2, 1.0).unwrap(), 3),
            (Operator::polyharmonic(3, 0.5).unwrap(), 1),
            (Operator::polyharmonic(5, 0.1).unwrap(), 2),
            (Operator::sixth_order(1.0, 2.0, 2.0, 1.0).unwrap(), 4),
        ] {
            for basis in [Basis::layers(&op, n), Basis::chebyshev(&op, n).unwrap()] {
                assert_eq!(basis.len(), 2 * op.half_order());
                for k in 0..basis.len() {
                    for &u in &[0.0, 0.23, 0.5, 0.91, 1.0] {
                        let r = mode_residual(&op, &basis, n, u, k);
                        assert!(
                            r < 1e-10,
                            "{:?} n={n} k={k} u={u}: residual {r:e}",
                            basis.kind()
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn first_derivatives_in_one_pass_match_the_general_path() {
        for op in [
            Operator::polyharmonic(3, 1.2).unwrap(),
            Operator::sixth_order(1.0, 2.0, 2.0, 1.0).unwrap(),
        ] {
            let basis = Basis::layers(&op, 5);
            let k = basis.len();
            let (mut a0, mut a1, mut b0, mut b1) =
                (vec![0.0; k], vec![0.0; k], vec![0.0; k], vec![0.0; k]);
            for &u in &[0.0, 0.3, 0.77, 1.0] {
                basis.eval01(u, &mut a0, &mut a1);
                basis.eval(u, 0, &mut b0);
                basis.eval(u, 1, &mut b1);
                for j in 0..k {
                    assert!((a0[j] - b0[j]).abs() <= 1e-15 * (1.0 + b0[j].abs()));
                    assert!(
                        (a1[j] - b1[j]).abs() <= 1e-13 * (1.0 + b1[j].abs()),
                        "u={u} j={j}: {} vs {}",
                        a1[j],
                        b1[j]
                    );
                }
            }
        }
    }

    #[test]
    fn layer_functions_are_bounded_by_one() {
        let op = Operator::polyharmonic(4, 8.0).unwrap();
        let basis = Basis::layers(&op, 12);
        let mut v = vec![0.0; 8];
        for i in 0..=200 {
            basis.eval(i as f64 / 200.0, 0, &mut v);
            assert!(v.iter().all(|x| x.abs() <= 1.0 + 1e-15));
        }
    }

    #[test]
    fn chebyshev_derivative_matches_closed_form() {
        // T_3 = 4x³ − 3x: derivative 12x² − 3 = 6 T_2 + 3 T_0.
        assert_eq!(cheb_diff(&[0.0, 0.0, 0.0, 1.0]), vec![3.0, 0.0, 6.0]);
        let x: f64 = 0.3;
        assert!(
            (clenshaw(&[1.0, 2.0, 3.0], x) - (1.0 + 2.0 * x + 3.0 * (2.0 * x * x - 1.0))).abs()
                < 1e-15
        );
    }
}
