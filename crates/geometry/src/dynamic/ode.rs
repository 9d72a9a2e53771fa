//! ODE curves (paper Eq. 1), the static limit of the dynamic curves: `C''''(u) = F(u)` on
//! `[0, 1]` with `C(0) = C₀`, `C(1) = C₁`, `C'(0) = C₀'`, `C'(1) = C₁'`.
//!
//! Solved directly, without a grid: with the Hermite cubic `H` of the end data and
//! `P(u) = (1/3!) ∫₀ᵘ (u − s)³ F(s) ds` (so `P'''' = F`, `P(0) = P'(0) = 0`),
//!
//! ```text
//! C(u) = H(u) + P(u) + α u² + β u³,   β = 2P(1) − P'(1),   α = P'(1) − 3P(1),
//! ```
//!
//! where `α, β` make the correction vanish with its slope at `u = 1`. The derivatives are
//! `P⁽ᵏ⁾(u) = ∫₀ᵘ (u − s)^{3−k}/(3−k)! F(s) ds` (`k ≤ 3`) and `C⁽⁴⁺ᵐ⁾ = F⁽ᵐ⁾`. The integrals use
//! composite Gauss–Legendre quadrature (16 panels × 8 points, exact for polynomial `F` of degree
//! ≤ 12 and spectrally accurate for smooth `F`).

use std::sync::Arc;

use crate::curve::{Curve, Domain, Hermite, MAX_ORDER};
use crate::{Error, Result, Vec3};

use crate::quadrature::gauss_legendre;

const PANELS: usize = 16;
const POINTS: usize = 8;

/// The ODE curve of Eq. (1) for a force `F` given as a core curve (evaluated on `[0, 1]`).
#[derive(Debug, Clone)]
pub struct OdeCurve {
    hermite: Hermite,
    force: Arc<dyn Curve>,
    alpha: Vec3,
    beta: Vec3,
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl OdeCurve {
    /// Builds the curve from end points `c0, c1`, end tangents `t0, t1` and the force `F`.
    /// Fails if a datum or `F` on `[0, 1]` is not finite.
    pub fn new(c0: Vec3, c1: Vec3, t0: Vec3, t1: Vec3, force: Arc<dyn Curve>) -> Result<Self> {
        for (name, v) in [("c0", c0), ("c1", c1), ("t0", t0), ("t1", t1)] {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(Error::invalid(format!("{name} = {v:?} is not finite")).at(name));
            }
        }
        let (nodes, weights) = gauss_legendre(POINTS);
        let mut curve = OdeCurve {
            hermite: Hermite::new(c0, c1, t0, t1),
            force,
            alpha: Vec3::zeros(),
            beta: Vec3::zeros(),
            nodes,
            weights,
        };
        let p = curve.particular(1.0, 2);
        if !p.iter().all(|v| v.iter().all(|x| x.is_finite())) {
            return Err(Error::invalid("the force is not finite on [0, 1]").at("force"));
        }
        curve.beta = p[0] * 2.0 - p[1];
        curve.alpha = p[1] - p[0] * 3.0;
        Ok(curve)
    }

    /// `P⁽ᵏ⁾(u)` for `k = 0 ..= kmax ≤ 3`.
    fn particular(&self, u: f64, kmax: usize) -> Vec<Vec3> {
        let mut out = vec![Vec3::zeros(); kmax + 1];
        if u == 0.0 {
            return out;
        }
        let width = u / PANELS as f64;
        for p in 0..PANELS {
            let mid = (p as f64 + 0.5) * width;
            for (x, w) in self.nodes.iter().zip(&self.weights) {
                let s = mid + 0.5 * width * x;
                let f = self.force.point(s) * (0.5 * width * w);
                let r = u - s;
                let powers = [r * r * r / 6.0, r * r / 2.0, r, 1.0];
                for (k, o) in out.iter_mut().enumerate() {
                    *o += f * powers[k];
                }
            }
        }
        out
    }
}

impl Curve for OdeCurve {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }

    fn jet(&self, u: f64, out: &mut [Vec3]) {
        let k = out.len().min(MAX_ORDER + 1);
        if k == 0 {
            return;
        }
        self.hermite.jet(u, &mut out[..k.min(4)]);
        let p = self.particular(u, (k - 1).min(3));
        let (a, b) = (self.alpha, self.beta);
        let correction = [
            a * (u * u) + b * (u * u * u),
            a * (2.0 * u) + b * (3.0 * u * u),
            a * 2.0 + b * (6.0 * u),
            b * 6.0,
        ];
        for i in 0..k.min(4) {
            out[i] += p[i] + correction[i];
        }
        if k > 4 {
            self.force.jet(u, &mut out[4..k]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::Bezier;

    /// Gauss–Legendre rule: integrates x^k exactly up to k = 2n − 1.
    #[test]
    fn gauss_rule_is_exact_for_polynomials() {
        let (x, w) = gauss_legendre(POINTS);
        for k in 0..2 * POINTS {
            let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
            let want = if k % 2 == 1 {
                0.0
            } else {
                2.0 / (k as f64 + 1.0)
            };
            assert!((got - want).abs() < 1e-15, "k = {k}: {got} vs {want}");
        }
    }

    /// Manufactured solution: a cubic force `F(u) = Σ c_i u^i` has the particular solution
    /// `c₀u⁴/24 + c₁u⁵/120 + c₂u⁶/360 + c₃u⁷/840`; adding a cubic and taking its end data, the
    /// ODE curve must reproduce it (value, derivatives 1–4) to rounding.
    #[test]
    fn reproduces_a_polynomial_solution() {
        // Force as a cubic Bézier with control points chosen freely; its power form from the jet.
        let ctrl = vec![
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(3.0, 0.0, -1.0),
            Vec3::new(-1.0, 4.0, 2.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let force: Arc<dyn Curve> = Arc::new(Bezier::new(ctrl).unwrap());
        let mut jet0 = [Vec3::zeros(); 4];
        force.jet(0.0, &mut jet0);
        let c = [jet0[0], jet0[1], jet0[2] / 2.0, jet0[3] / 6.0];
        let cubic = [
            Vec3::new(0.3, 1.0, -2.0),
            Vec3::new(1.0, -0.5, 0.2),
            Vec3::new(-2.0, 0.7, 1.0),
            Vec3::new(0.4, 0.1, -0.3),
        ];
        // Exact solution and its first four derivatives.
        let exact = |u: f64| -> [Vec3; 5] {
            let fact = |n: i32| (1..=n).product::<i32>() as f64;
            let mut out = [Vec3::zeros(); 5];
            for (i, ci) in c.iter().enumerate() {
                let n = i as i32 + 4; // u^n / (n!/i!)
                let scale = fact(i as i32) / fact(n);
                for (k, o) in out.iter_mut().enumerate() {
                    let k = k as i32;
                    if k <= n {
                        *o += ci * (scale * fact(n) / fact(n - k) * u.powi(n - k));
                    }
                }
            }
            for (i, ci) in cubic.iter().enumerate() {
                let i = i as i32;
                for (k, o) in out.iter_mut().enumerate() {
                    let k = k as i32;
                    if k <= i {
                        *o += ci * (fact(i) / fact(i - k) * u.powi(i - k));
                    }
                }
            }
            out
        };
        let (e0, e1) = (exact(0.0), exact(1.0));
        let curve = OdeCurve::new(e0[0], e1[0], e0[1], e1[1], force).unwrap();
        for &u in &[0.0, 0.1, 0.37, 0.5, 0.81, 1.0] {
            let mut jet = [Vec3::zeros(); 5];
            curve.jet(u, &mut jet);
            let want = exact(u);
            for k in 0..5 {
                let err = (jet[k] - want[k]).amax();
                assert!(
                    err < 1e-13 * (1.0 + want[k].amax()),
                    "u = {u}, order {k}: {:?} vs {:?}",
                    jet[k],
                    want[k]
                );
            }
        }
    }

    #[test]
    fn non_finite_end_data_is_an_error() {
        let force: Arc<dyn Curve> = Arc::new(Hermite::new(
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::zeros(),
        ));
        let bad = Vec3::new(f64::NAN, 0.0, 0.0);
        let err = OdeCurve::new(Vec3::zeros(), bad, Vec3::zeros(), Vec3::zeros(), force)
            .unwrap_err()
            .to_string();
        assert!(err.contains("c1"), "{err}");
    }
}
