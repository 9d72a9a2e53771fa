//! Proven bounds of the derivatives of the curves of an attachment: the image
//! `C(s) = X(u(s), v(s))` of a `(u, v)` curve on an analytic host patch ([`CurveOnSurface`]) and
//! its tangent field `D = f · w/|w|`, `w = C' × N`, `N = X_u × X_v` ([`TangentField`]).
//!
//! **The host near a piece of the curve.** On a piece `[s₀, s₁]` of the curve between breaks,
//! with middle `m` and half-width `r`, every point `(u(s), v(s))` lies within `ρ_u = r·sup|u'|`,
//! `ρ_v = r·sup|v'|` of the centre `c = (u(m), v(m))`, and the segment from `c` to it stays in
//! `u ∈ [0, 1]` (both ends do). Taylor's formula with the integral remainder along that segment
//! gives, for `f = ∂_u^a ∂_v^b X`,
//!
//! `|f(u, v)| ≤ Σ_{i+j<J} |∂_u^i ∂_v^j f(c)| ρ_uⁱ ρ_vʲ/(i! j!) + Σ_{i+j=J} G_{a+i,b+j} ρ_uⁱ ρ_vʲ/(i! j!)`
//!
//! (`J` = [`TAYLOR`]) with the exact partials at the centre
//! ([`PdePatch::fourier_partials_at`], each with a rounding allowance of `10⁻¹²` times its
//! global bound, which bounds the sum of the sizes of its terms) and `G` the bounds over the
//! whole patch ([`PdePatch::partial_bounds_table`]); the smaller of this and `G_{a,b}` is used.
//! On short pieces these local bounds follow the surface where the curve runs, where the
//! global ones (sums over all modes of their largest derivatives anywhere in `u`) may exceed
//! the true values a hundredfold.
//!
//! **Compositions.** With these `M_ab` and the path's increments, `X∘(u, v)`, `X_u∘(u, v)` and
//! `X_v∘(u, v)` are majorised on the piece ([`crate::majorant`]); `u'(σ + s) ≪ Σ_k U_{k+1} sᵏ/k!`
//! (`U_k` the path's bounds, [`TrimCurve::coordinate_bounds`]), so
//! `C' = X_u u' + X_v v' ≪ X̂_u Û' + X̂_v V̂'`, `N ≪ X̂_u X̂_v` and `w = C' × N ≪ Ĉ' N̂ = Ŵ`
//! (`|a × b| ≤ |a| |b|` term by term).
//!
//! **The normalisation.** `|w(s)| ≥ L = |w(m)| − r · Ŵ'` on the piece (`Ŵ' = 1!·Ŵ₁` bounds
//! `|w'|` there); the piece is halved until `L > 0` and `r Ŵ'` is at most a quarter of
//! `|w(m)|` (which keeps the powers of `1/L` below small). `D = f · n(w)` with
//! `n(y) = y/|y|`, homogeneous of degree 0, so `‖Dᵏn(y)‖ = ‖Dᵏn(ŷ)‖/|y|ᵏ`. For a unit `ŷ` and
//! a unit `e` at the angle `φ`, in the plane of the two (as the complex numbers `1` and
//! `e^{iφ}`), `n(ŷ + t e) = (1 + e^{iφ} t)^{1/2} (1 + e^{−iφ} t)^{−1/2}` for real `t`, whose
//! `k`-th Taylor coefficient is `Σ_j C(1/2, j) C(−1/2, k − j) e^{i(2j − k)φ}`: of size at most
//! `Σ_j |C(1/2, j) C(−1/2, k − j)|` = `1, 1, 3/4, 5/8, 35/64` (`k ≤ 4`). By Banach's theorem
//! (the norm of a symmetric multilinear map of a real Hilbert space is its largest value on
//! the diagonal) `‖Dᵏn(ŷ)‖ ≤ Nₖ = k!` times those (`UNIT`). About any `σ` of the piece,
//! `n(w(σ) + Δw) = Σ_k Dᵏn(w(σ))[Δw, …, Δw]/k!` with `Δw ≪ Ŵ − Ŵ₀`, so
//! `D ≪ |f| Σ_k Nₖ/(k! Lᵏ) (Ŵ − Ŵ₀)ᵏ` ([`Majorant::compose1`]). `|D| = |f|` exactly.

use super::{host_jet, image_derivatives, CurveOnSurface, TangentField, W};
use crate::curve::Curve;
use crate::design::SurfaceKind;
use crate::elliptic::PdePatch;
use crate::majorant::{Majorant, ORDER};
use crate::surface::Surface;
use crate::trim::TrimCurve;
use crate::Vec3;
use std::sync::Arc;

/// Terms of the Taylor expansion of the host's partials about a piece's centre; the term of
/// this order takes the host's global bounds.
const TAYLOR: usize = 2;
/// The highest order of the host's partials used: `X_u`, `X_v` differentiated [`ORDER`] times
/// along the curve, expanded to [`TAYLOR`].
const TOP: usize = 1 + ORDER + TAYLOR;
/// Halvings of an interval at most (the tangent field's pieces).
const MAX_DEPTH: usize = 14;
/// `Nₖ ≥ ‖Dᵏn(ŷ)‖` for `n(y) = y/|y|` at a unit `ŷ`, `k ≤ 4`: `k!` times
/// `1, 1, 3/4, 5/8, 35/64` (module docs).
const UNIT: [f64; ORDER + 1] = [1.0, 1.0, 1.5, 3.75, 13.125];
/// `k!`, `k ≤ TAYLOR`.
const FACTORIAL: [f64; 3] = [1.0, 1.0, 2.0];

/// Bounds of one order-≤-4 table of partials: `m[a][b] ≥ sup|∂_u^{a+e_u} ∂_v^{b+e_v} X|`.
type Table = [[f64; ORDER + 1]; ORDER + 1];

/// An analytic host without an active remainder, periodic in `v`, with a curve in
/// `u ∈ [0, 1]`, and its global bounds `G[a][b]`, `a + b ≤` [`TOP`].
#[derive(Debug)]
pub(super) struct Host {
    patch: Arc<PdePatch>,
    global: Vec<Vec<f64>>,
}

impl Host {
    /// `None` unless the host and the curve qualify (see the type).
    pub(super) fn new(host: &SurfaceKind, path: &TrimCurve) -> Option<Arc<Host>> {
        let SurfaceKind::Pde(patch) = host else {
            return None;
        };
        let [u_range, _] = path.coordinate_range();
        if !(patch.v_domain().is_periodic() && u_range[0] >= 0.0 && u_range[1] <= 1.0) {
            return None;
        }
        let global = patch.partial_bounds_table(TOP)?;
        global.iter().flatten().all(|x| x.is_finite()).then(|| {
            Arc::new(Host {
                patch: patch.clone(),
                global,
            })
        })
    }

    /// The bounds over the whole patch, shifted by `e`.
    fn global(&self, e: [usize; 2]) -> Table {
        let mut m = [[0.0; ORDER + 1]; ORDER + 1];
        for (a, row) in m.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate().take(ORDER + 1 - a) {
                *x = self.global[a + e[0]][b + e[1]];
            }
        }
        m
    }

    /// The bounds over the points of the piece `p` (module docs), shifted by `e`.
    fn local(&self, p: &Piece, at: &[Vec<Vec3>], e: [usize; 2]) -> Table {
        let mut m = self.global(e);
        for (a, row) in m.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate().take(ORDER + 1 - a) {
                let (a1, b1) = (a + e[0], b + e[1]);
                let mut sum = 0.0;
                for i in 0..=TAYLOR {
                    for j in 0..=TAYLOR - i {
                        let g = self.global[a1 + i][b1 + j];
                        let size = if i + j < TAYLOR {
                            at[a1 + i][b1 + j].norm() + 1e-12 * g
                        } else {
                            g
                        };
                        sum += size * p.rho[0].powi(i as i32) * p.rho[1].powi(j as i32)
                            / (FACTORIAL[i] * FACTORIAL[j]);
                    }
                }
                *x = x.min(sum * (1.0 + 1e-12));
            }
        }
        m
    }
}

/// A piece `[s₀, s₁]` of the curve: its middle and half-width, the majorants of the path's
/// increments and slopes there, its centre in `(u, v)` and the reach `ρ` about it.
struct Piece {
    mid: f64,
    half: f64,
    increment: [Majorant; 2],
    slope: [Majorant; 2],
    centre: [f64; 2],
    rho: [f64; 2],
}

impl Piece {
    fn new(path: &TrimCurve, s0: f64, s1: f64) -> Piece {
        let mut uv = path.coordinate_bounds(s0 / W, s1 / W);
        for c in &mut uv {
            for (k, x) in c.iter_mut().enumerate() {
                *x /= W.powi(k as i32);
            }
        }
        let (mid, half) = (0.5 * (s0 + s1), 0.5 * (s1 - s0));
        Piece {
            mid,
            half,
            increment: [0, 1].map(|c| Majorant::increment(&uv[c][..=ORDER])),
            slope: [0, 1].map(|c| {
                let u = &uv[c];
                Majorant([u[1], u[2], u[3] / 2.0, u[4] / 6.0, u[5] / 24.0])
            }),
            centre: path.point(mid / W),
            rho: [uv[0][1] * half, uv[1][1] * half],
        }
    }

    /// The exact partials of the host at the piece's centre, orders below [`TOP`].
    fn centre_partials(&self, host: &Host) -> Vec<Vec<Vec3>> {
        let v = crate::curve::reduce_periodic(self.centre[1]);
        host.patch.fourier_partials_at(self.centre[0], v, TOP - 1)
    }

    /// The majorant of `∂^e X` along the piece (`at`: [`Piece::centre_partials`]).
    fn along(&self, host: &Host, at: &[Vec<Vec3>], e: [usize; 2]) -> Majorant {
        Majorant::compose2(
            &host.local(self, at, e),
            &self.increment[0],
            &self.increment[1],
        )
    }
}

/// The open pieces of `(s0, s1)` between the curve's breaks `breaks` (in `[0, 2π)`, repeated
/// with period `2π`).
fn pieces(breaks: &[f64], s0: f64, s1: f64) -> Vec<[f64; 2]> {
    let mut cuts = vec![s0];
    if !breaks.is_empty() && s1 > s0 {
        let first = (s0 / crate::TAU).floor() as i64;
        let last = (s1 / crate::TAU).ceil() as i64;
        for k in first..=last {
            for &b in breaks {
                let x = b + k as f64 * crate::TAU;
                if x > s0 && x < s1 {
                    cuts.push(x);
                }
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.push(s1);
    cuts.windows(2).map(|w| [w[0], w[1]]).collect()
}

/// A request the bounds can answer: orders up to [`ORDER`] on `s0 ≤ s1`.
fn request_ok(s0: f64, s1: f64, out: &[f64]) -> bool {
    out.len() <= ORDER + 1 && s0 <= s1
}

impl CurveOnSurface {
    /// `out[k] ≥ sup|C⁽ᵏ⁾|` on the pieces of `(s0, s1)` (module docs); `false` without a
    /// qualifying host.
    pub(super) fn bounds(&self, s0: f64, s1: f64, out: &mut [f64]) -> bool {
        let Some(host) = self.on.host_bounds().filter(|_| request_ok(s0, s1, out)) else {
            return false;
        };
        out.fill(0.0);
        for [a, b] in pieces(&self.breaks(), s0, s1) {
            let p = Piece::new(&self.on.path, a, b);
            let series = p.along(host, &p.centre_partials(host), [0, 0]);
            for (k, o) in out.iter_mut().enumerate() {
                *o = o.max(series.derivative(k));
            }
        }
        out.iter().all(|x| x.is_finite())
    }
}

impl TangentField {
    /// `out[k] ≥ sup|D⁽ᵏ⁾|` on the pieces of `(s0, s1)` (module docs); `false` without a
    /// qualifying host or where no positive lower bound of `|w|` is found within
    /// [`MAX_DEPTH`] halvings.
    pub(super) fn bounds(&self, s0: f64, s1: f64, out: &mut [f64]) -> bool {
        let Some(host) = self.on.host_bounds().filter(|_| request_ok(s0, s1, out)) else {
            return false;
        };
        let mut worst = [0.0; ORDER + 1];
        for [a, b] in pieces(&self.breaks(), s0, s1) {
            if !self.bound_piece(host, a, b, 0, &mut worst) {
                return false;
            }
        }
        worst[0] = self.factor.abs() * (1.0 + 1e-12);
        out.copy_from_slice(&worst[..out.len()]);
        out.iter().all(|x| x.is_finite())
    }

    /// The bounds on `[s0, s1]` into `worst`, halving the interval until the lower bound of
    /// `|w|` holds with a margin (or at [`MAX_DEPTH`], holds at all).
    fn bound_piece(
        &self,
        host: &Host,
        s0: f64,
        s1: f64,
        depth: usize,
        worst: &mut [f64; ORDER + 1],
    ) -> bool {
        let p = Piece::new(&self.on.path, s0, s1);
        let at = p.centre_partials(host);
        let xu = p.along(host, &at, [1, 0]);
        let xv = p.along(host, &at, [0, 1]);
        let c1 = xu.mul(&p.slope[0]).add(&xv.mul(&p.slope[1]));
        let w = c1.mul(&xu.mul(&xv));
        let (pt, d1, d2) = host_jet(self.on.host.surface(), &self.on.path, p.mid);
        let (c1m, _) = image_derivatives(&pt, d1, d2);
        let wm = c1m.cross(&pt.xu.cross(&pt.xv)).norm() * (1.0 - 1e-9);
        let drop = p.half * w.derivative(1);
        let lower = wm - drop;
        let settled = lower > 0.0 && drop <= 0.25 * wm;
        if !settled && depth < MAX_DEPTH {
            let mid = p.mid;
            return self.bound_piece(host, s0, mid, depth + 1, worst)
                && self.bound_piece(host, mid, s1, depth + 1, worst);
        }
        if lower.is_nan() || lower <= 0.0 {
            return false;
        }
        let mut increment = w;
        increment.0[0] = 0.0;
        let m: [f64; ORDER + 1] = std::array::from_fn(|k| UNIT[k] / lower.powi(k as i32));
        let d = Majorant::compose1(&m, &increment).scale(self.factor);
        for (k, o) in worst.iter_mut().enumerate() {
            *o = o.max(d.derivative(k));
        }
        true
    }
}
