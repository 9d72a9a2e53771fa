//! Pointwise differential geometry of a parametric surface from its exact partial derivatives
//! (book §1.4.1.1).
//!
//! Conventions (those of §1.4.1.1): the unit normal is `n = X_u × X_v / |X_u × X_v|`; the second
//! fundamental form is `L = X_uu·n`, `M = X_uv·n`, `N = X_vv·n`; `K = (LN − M²)/(EG − F²)` and
//! `H = (EN − 2FM + GL)/(2(EG − F²))`. Both `H` and the principal curvatures `κ₁ ≥ κ₂` are
//! taken with respect to `n`: reversing the orientation (swapping `u` and `v`, or `u ↦ 1 − u`)
//! negates `H`, `κ₁`, `κ₂` and leaves `K` unchanged. A sphere with the outward normal has
//! `H = −1/R` and `κ₁ = κ₂ = −1/R`; with the inward normal, `H = +1/R`.

use crate::surface::{normal_degenerates, Partials, Surface};
use crate::Vec3;

/// Both fundamental forms at one point: `I = E du² + 2F du dv + G dv²`,
/// `II = L du² + 2M du dv + N dv²` (book §1.4.1.1).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FundamentalForms {
    /// `E = X_u·X_u`.
    pub e: f64,
    /// `F = X_u·X_v`.
    pub f: f64,
    /// `G = X_v·X_v`.
    pub g: f64,
    /// `L = X_uu·n`.
    pub l: f64,
    /// `M = X_uv·n`.
    pub m: f64,
    /// `N = X_vv·n`.
    pub n: f64,
}

/// Curvature of a surface at one point, all with respect to [`Curvature::normal`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Curvature {
    /// `n = X_u × X_v / |X_u × X_v|`.
    pub normal: Vec3,
    /// `E, F, G; L, M, N`.
    pub forms: FundamentalForms,
    /// The area element `|X_u × X_v| = √(EG − F²)`.
    pub jacobian: f64,
    /// Gaussian curvature `K = κ₁κ₂` (Eq. 7.4, there called `G`).
    pub gauss: f64,
    /// Mean curvature `H = (κ₁ + κ₂)/2` (Eq. 7.5).
    pub mean: f64,
    /// The larger principal curvature `κ₁ = H + √(H² − K)`.
    pub k1: f64,
    /// The smaller principal curvature `κ₂ = H − √(H² − K) ≤ κ₁`.
    pub k2: f64,
    /// Unit principal direction of `κ₁` in space (tangent to the surface): `II(d) = κ I(d)`.
    /// At an umbilic (`κ₁ = κ₂`) every direction is principal; then `d₁ = X_u/|X_u|`.
    pub d1: Vec3,
    /// Unit principal direction of `κ₂`: `d₂ = n × d₁`, so that `d₁ ⟂ d₂` and `d₁ × d₂ = n`.
    pub d2: Vec3,
}

/// The curvature at a point from the exact partials `p`, or `None` where the parametrisation is
/// degenerate (`|X_u × X_v| ≤ 1e-10 (|X_u|² + |X_v|²)`, the rule of
/// [`crate::surface::normal_degenerates`], e.g. at a pole) or not finite. See
/// [`curvature_at`] for the limit at a pole.
pub fn curvature(p: &Partials) -> Option<Curvature> {
    let Core {
        normal: n,
        jac,
        forms,
        gauss,
        mean,
    } = core(p)?;
    let disc = (mean * mean - gauss).max(0.0).sqrt();
    let (k1, k2) = (mean + disc, mean - disc);
    let d1 = principal_direction(&forms, k1, p.xu, p.xv)
        .unwrap_or_else(|| p.xu / p.xu.norm().max(f64::MIN_POSITIVE));
    let d2 = n.cross(&d1);
    Some(Curvature {
        normal: n,
        forms,
        jacobian: jac,
        gauss,
        mean,
        k1,
        k2,
        d1,
        d2,
    })
}

/// What the integrals need at one point.
pub(crate) struct Core {
    pub normal: Vec3,
    pub jac: f64,
    pub forms: FundamentalForms,
    pub gauss: f64,
    pub mean: f64,
}

/// Normal, area element, fundamental forms, `K` and `H` (the book's formulas), or `None` at a
/// degenerate or non-finite point.
#[inline]
pub(crate) fn core(p: &Partials) -> Option<Core> {
    let cross = p.xu.cross(&p.xv);
    let jac = cross.norm();
    let size = p.xu.norm_squared() + p.xv.norm_squared();
    if normal_degenerates(jac, size) || !jac.is_finite() {
        return None;
    }
    let n = cross / jac;
    let (e, f, g) = (p.xu.dot(&p.xu), p.xu.dot(&p.xv), p.xv.dot(&p.xv));
    let (l, m, nn) = (p.xuu.dot(&n), p.xuv.dot(&n), p.xvv.dot(&n));
    // EG − F² = |X_u × X_v|², without the cancellation of the difference.
    let w = jac * jac;
    let gauss = (l * nn - m * m) / w;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * w);
    if !gauss.is_finite() || !mean.is_finite() {
        return None;
    }
    Some(Core {
        normal: n,
        jac,
        forms: FundamentalForms {
            e,
            f,
            g,
            l,
            m,
            n: nn,
        },
        gauss,
        mean,
    })
}

/// The unit tangent `d = a X_u + b X_v` with `(II − κ I)(a, b) = 0`, from the better conditioned
/// row of that 2 × 2 system; `None` at an umbilic (both rows vanish to rounding).
fn principal_direction(f: &FundamentalForms, k: f64, xu: Vec3, xv: Vec3) -> Option<Vec3> {
    let r1 = (f.l - k * f.e, f.m - k * f.f);
    let r2 = (f.m - k * f.f, f.n - k * f.g);
    let (n1, n2) = (r1.0.hypot(r1.1), r2.0.hypot(r2.1));
    // Rows small against the curvature scale of II mean an umbilic.
    let scale = (f.l.abs() + f.m.abs() + f.n.abs()) + k.abs() * (f.e + f.f.abs() + f.g);
    if n1.max(n2) <= 1e-8 * scale || scale == 0.0 {
        return None;
    }
    let (a, b) = if n1 >= n2 {
        (-r1.1, r1.0)
    } else {
        (r2.1, -r2.0)
    };
    let d = xu * a + xv * b;
    let len = d.norm();
    (len > 0.0 && len.is_finite()).then(|| d / len)
}

/// Step of the one-sided extrapolation at degenerate points.
const POLE_STEP: f64 = 1e-3;

/// The curvature of `s` at `(u, v)`. Where the parametrisation is degenerate (a pole: a position
/// curve shrunk to a point, so `X_v = 0`), the value is the limit along `u`: `K`, `H`, `κ₁`, `κ₂`
/// are extrapolated from `u₀ ± h, ±2h, ±3h` (`h = 10⁻³`, stepping into `[0, 1]`) with the cubic
/// extrapolation `3f(h) − 3f(2h) + f(3h)` (error `O(h³)`); the normal, directions and forms are
/// those at `u₀ ± h` (so `H` keeps the sign it has next to the pole), and `jacobian` is 0.
/// Returns `None` only if the surface is degenerate at those points too.
pub fn curvature_at(s: &dyn Surface, u: f64, v: f64) -> Option<Curvature> {
    let p = s.partials(u, v);
    if let Some(c) = curvature(&p) {
        return Some(c);
    }
    let step = if u <= 0.5 { POLE_STEP } else { -POLE_STEP };
    let near: Vec<Curvature> = (1..=3)
        .map(|k| curvature(&s.partials(u + k as f64 * step, v)))
        .collect::<Option<Vec<_>>>()?;
    let ex = |f: fn(&Curvature) -> f64| 3.0 * f(&near[0]) - 3.0 * f(&near[1]) + f(&near[2]);
    let mut c = near[0];
    c.gauss = ex(|c| c.gauss);
    c.mean = ex(|c| c.mean);
    c.k1 = ex(|c| c.k1);
    c.k2 = ex(|c| c.k2).min(c.k1);
    c.jacobian = 0.0;
    Some(c)
}
