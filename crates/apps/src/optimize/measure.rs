//! An independent check of `analysis` (tests only): the integrals by a plain tensor quadrature over each patch: Gauss–Legendre in
//! `u` (nodes inside `(0, 1)`, so a pole at `u = 0` or `1` is never evaluated) and the
//! trapezoid rule in periodic `v` (spectrally accurate for smooth periodic integrands), Gauss–
//! Legendre in an open `v` interval.
//!
//! At each node, from the exact partials (book §1.4.1.1): `E = X_u·X_u`, `F = X_u·X_v`,
//! `G = X_v·X_v`, `n = X_u × X_v`, `N = n/|n|`, `L = X_uu·N`, `M = X_uv·N`, `N₂ = X_vv·N`,
//! `K = (L N₂ − M²)/(EG − F²)`, `H = −(E N₂ − 2F M + G L)/(2(EG − F²))` (positive on a sphere
//! whose normal points out), `dA = |n| du dv`, and the volume by the divergence theorem
//! `V = ⅓ ∫ X·n du dv`. The orientation of the whole design is taken from the sign of `V`: if
//! it is negative, `V` and `∫H dA` change sign (so `H > 0` on a sphere whatever the
//! parametrisation's direction). Patches must be oriented alike (as two patches that continue
//! one another in `u` with the same `v` are).

use crate::design::SolvedDesign;
use crate::surface::{Surface, VDomain};
use crate::{Error, Result};

use crate::analysis::Integrals as Totals;

/// Gauss–Legendre nodes and weights on `[0, 1]` (Newton's iteration on `P_n`).
pub(crate) fn gauss_legendre01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        // Initial guess (Tricomi), then Newton.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm1 = p0;
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes[i] = 0.5 * (1.0 - x);
        weights[i] = 1.0 / ((1.0 - x * x) * dp * dp);
    }
    (nodes, weights)
}

/// The integrals of one surface: `(area, 3·volume contribution ∫X·n, ∫H dA, ∫H² dA, ∫K dA)`
/// with `H` relative to the parametrisation's normal.
fn integrate(s: &dyn Surface, qu: usize, qv: usize) -> [f64; 5] {
    let (un, uw) = gauss_legendre01(qu);
    let (vn, vw): (Vec<f64>, Vec<f64>) = match s.v_domain() {
        VDomain::Periodic => (
            (0..qv).map(|j| crate::TAU * j as f64 / qv as f64).collect(),
            vec![crate::TAU / qv as f64; qv],
        ),
        VDomain::Interval(a, b) => {
            let (n, w) = gauss_legendre01(qv);
            (
                n.iter().map(|t| a + (b - a) * t).collect(),
                w.iter().map(|w| w * (b - a)).collect(),
            )
        }
    };
    let mut out = [0.0; 5];
    for (u, wu) in un.iter().zip(&uw) {
        for (v, wv) in vn.iter().zip(&vw) {
            let p = s.partials(*u, *v);
            let w = wu * wv;
            let n = p.xu.cross(&p.xv);
            let jac = n.norm();
            out[1] += w * p.x.dot(&n);
            if jac == 0.0 {
                continue;
            }
            let nn = n / jac;
            let (e, f, g) = (p.xu.dot(&p.xu), p.xu.dot(&p.xv), p.xv.dot(&p.xv));
            let (l, m, n2) = (p.xuu.dot(&nn), p.xuv.dot(&nn), p.xvv.dot(&nn));
            let det = e * g - f * f;
            let k = (l * n2 - m * m) / det;
            let h = -(e * n2 - 2.0 * f * m + g * l) / (2.0 * det);
            out[0] += w * jac;
            out[2] += w * h * jac;
            out[3] += w * h * h * jac;
            out[4] += w * k * jac;
        }
    }
    out
}

/// The integrals of a built design, all patches together, with `qu × qv` nodes per patch (see
/// the module documentation). A non-finite result is an error.
pub(crate) fn measure(built: &SolvedDesign, qu: usize, qv: usize) -> Result<Totals> {
    let surfaces: Vec<&dyn Surface> = built
        .surfaces
        .iter()
        .filter(|s| s.is_patch())
        .map(|s| s.surface())
        .collect();
    totals(&surfaces, qu, qv)
}

/// The integrals of several surfaces together (see [`measure`]).
pub(crate) fn totals(surfaces: &[&dyn Surface], qu: usize, qv: usize) -> Result<Totals> {
    let mut sum = [0.0; 5];
    for s in surfaces {
        let r = integrate(*s, qu, qv);
        for (s, x) in sum.iter_mut().zip(r) {
            *s += x;
        }
    }
    let volume = sum[1] / 3.0;
    let sign = if volume < 0.0 { -1.0 } else { 1.0 };
    let t = Totals {
        area: sum[0],
        volume: sign * volume,
        mean: sign * sum[2],
        mean_sq: sum[3],
        gauss: sum[4],
    };
    if [t.area, t.volume, t.mean, t.mean_sq, t.gauss]
        .iter()
        .all(|x| x.is_finite())
    {
        Ok(t)
    } else {
        Err(Error::invalid(format!(
            "the design's integrals are not finite (area {}, volume {}, ∫H² dA {})",
            t.area, t.volume, t.mean_sq
        )))
    }
}
