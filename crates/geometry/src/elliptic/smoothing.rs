//! The derivative of a solved patch with respect to the smoothing parameter `a` of its operator
//! `(∂²/∂u² + a² ∂²/∂v²)^N`, as `(u/a) X_u` plus one more tangent solve.
//!
//! Mode `n`'s equation is `(D² − a²n²)^N f = 0`, whose solutions are `u^k e^{±anu}` (`k < N`):
//! the space `V_n(a)` is `{g(a u) : g ∈ V_n(1)}`. A member `f_a(u) = g(a u)` with `g` fixed has
//! `∂_a f_a = u g'(a u) = (u/a) f_a'`, so differentiating `L_a f_a = 0` in `a` shows that
//! `(u/a) f'` is a particular solution of the differentiated equation
//! `L_a Y = −(∂_a L_a) f` for every `f ∈ V_n(a)` (mode 0, `D^{2N} f = 0`, is a polynomial
//! space, mapped into itself). The conditions do not depend on `a`, so the derivative of mode
//! `n`'s solution is `Y = (u/a) f' + H` with `H ∈ V_n(a)` meeting the conditions
//! `H^{(d_i)}(u_i) = −(1/a) D^{d_i}[u f'](u_i) = −(1/a)(u_i f^{(d_i+1)}(u_i) + d_i f^{(d_i)}(u_i))`:
//! the same operator with other condition data, one more right-hand side of every mode system
//! ([`PdePatch::solve_tangents`]).
//!
//! The spectral remainder `R = Σ_i w_i(u) Δ_i(v)` has its cardinal functions `w_i` in
//! `V_{M+1}(a)` and `Δ_i = g_i − ∂^{d_i} X̃(u_i, ·)` independent of `a` (the modes meet the
//! `a`-independent Fourier coefficients of the conditions), so `∂_a R = Σ_i (∂_a w_i) Δ_i` with
//! `∂_a w_i = (u/a) w_i' + (a member of V_{M+1}(a) with conditions −(1/a) D^{d_k}[u w_i'](u_k))`.
//! Both parts are taken by one tangent solve of the whole patch: with
//! `h_i(v) = −(1/a)(u_i ∂_u^{d_i+1} X(u_i, v) + d_i ∂_u^{d_i} X(u_i, v))` (`X` with its remainder),
//!
//! ```text
//! ∂X/∂a = (u/a) X_u + T,   T = the patch's tangent solve of the conditions h_i.
//! ```
//!
//! `T`'s modes take the Fourier coefficients of `h_i` up to `M`, which are those of the modes'
//! part (the remainder's part of `h_i` is a combination of the `Δ_j`, whose sampled
//! coefficients up to `M` vanish: the fitted series is the sampled one), and `T`'s remainder
//! takes the rest, which is the remainder's part. The one approximation: a condition curve with
//! an exact Fourier series of more than `samples − M` modes puts the aliases of its top modes
//! into `T`'s modes instead of its remainder (the base solve's sampling of other curves has the
//! same aliasing). Without a remainder, `h_i`'s exact series is known from the modes.

use super::PdePatch;
use crate::curve::{Curve, Domain, SharedCurve, MAX_ORDER};
use crate::fourier::FourierSeries;
use crate::Vec3;
use std::sync::Arc;

/// `h_i(v) = −s (u_i ∂_u^{d_i+1} X(u_i, v) + d_i ∂_u^{d_i} X(u_i, v))` of condition `i` of a
/// patch, `s = 1/a`.
#[derive(Debug)]
struct StretchCurve {
    patch: Arc<PdePatch>,
    condition: usize,
    stretch: f64,
}

impl StretchCurve {
    /// Adds `f · ∂_v^k ∂_u^e X(u, v)` into `out[k]`.
    fn add(&self, u: f64, e: usize, f: f64, v: f64, out: &mut [Vec3]) {
        let p = &*self.patch;
        let mut o = [0.0; 6];
        for (n, mode) in p.modes.iter().enumerate().filter(|(_, m)| !m.zero) {
            mode.eval(u, e, &mut o);
            let a = Vec3::new(o[0], o[1], o[2]);
            let b = Vec3::new(o[3], o[4], o[5]);
            let nf = n as f64;
            let (s, c) = (nf * v).sin_cos();
            let mut nk = 1.0;
            for (k, out) in out.iter_mut().enumerate() {
                let (ck, sk) = match k % 4 {
                    0 => (c, s),
                    1 => (-s, c),
                    2 => (-c, -s),
                    _ => (s, -c),
                };
                *out += (a * ck + b * sk) * (f * nk);
                nk *= nf;
            }
        }
        if let Some(r) = &p.remainder {
            let conditions = p.conditions();
            let mut w = vec![0.0; conditions.len()];
            r.cardinal.eval(u, e, &mut w);
            let len = out.len();
            let (mut g, mut h) = (
                [Vec3::zeros(); MAX_ORDER + 1],
                [Vec3::zeros(); MAX_ORDER + 1],
            );
            for (j, wj) in w.iter().enumerate().filter(|&(j, _)| r.active[j]) {
                conditions[j].curve.jet(v, &mut g[..len]);
                r.fitted[j].jet(v, &mut h[..len]);
                for (k, out) in out.iter_mut().enumerate() {
                    *out += (g[k] - h[k]) * (f * wj);
                }
            }
        }
    }
}

impl Curve for StretchCurve {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }

    fn jet(&self, t: f64, out: &mut [Vec3]) {
        out.iter_mut().for_each(|o| *o = Vec3::zeros());
        let c = &self.patch.conditions()[self.condition];
        let len = out.len().min(MAX_ORDER + 1);
        let out = &mut out[..len];
        self.add(c.u, c.derivative + 1, -self.stretch * c.u, t, out);
        if c.derivative > 0 {
            self.add(
                c.u,
                c.derivative,
                -self.stretch * c.derivative as f64,
                t,
                out,
            );
        }
    }

    /// The exact series from the modes when the patch has no remainder.
    fn fourier(&self) -> Option<FourierSeries> {
        let p = &*self.patch;
        if p.remainder.is_some() {
            return None;
        }
        let c = &p.conditions()[self.condition];
        let (s, d) = (self.stretch, c.derivative);
        let term = |n: usize| {
            let mut hi = [0.0; 6];
            let mut lo = [0.0; 6];
            p.modes[n].eval(c.u, d + 1, &mut hi);
            p.modes[n].eval(c.u, d, &mut lo);
            let x: [f64; 6] = std::array::from_fn(|k| -s * (c.u * hi[k] + d as f64 * lo[k]));
            (Vec3::new(x[0], x[1], x[2]), Vec3::new(x[3], x[4], x[5]))
        };
        let m = p.modes.len() - 1;
        let (cos, sin) = (1..=m).map(term).unzip();
        FourierSeries::new(term(0).0, cos, sin).ok()
    }
}

impl PdePatch {
    /// The derivative of this patch with respect to the smoothing parameter `a` of its
    /// polyharmonic operator `(∂²/∂u² + a² ∂²/∂v²)^N` is `s · u X_u + T` with `s = 1/a` and `T`
    /// this patch's tangent solve ([`PdePatch::solve_tangents`], the options it was solved
    /// with) of the returned condition curves (see the module documentation). `None` when the
    /// operator has no smoothing parameter (its patch does not depend on `a`).
    pub fn smoothing_tangent_curves(self: &Arc<Self>) -> Option<(f64, Vec<SharedCurve>)> {
        let a = self.operator().smoothing_parameter()?;
        if !(a > 0.0 && a.is_finite()) {
            return None;
        }
        let stretch = 1.0 / a;
        let curves = (0..self.conditions().len())
            .map(|condition| {
                Arc::new(StretchCurve {
                    patch: self.clone(),
                    condition,
                    stretch,
                }) as SharedCurve
            })
            .collect();
        Some((stretch, curves))
    }
}
