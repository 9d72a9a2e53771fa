//! The nodal values of a dynamic curve as a core [`Curve`]: the clamped C² cubic spline through
//! `P_j = C(u_j)`, `u_j = j/J`, with the end tangents of the curve.
//!
//! With `h = 1/J` and moments `M_j = S''(u_j)`:
//! `M_{j−1} + 4M_j + M_{j+1} = 6(P_{j+1} − 2P_j + P_{j−1})/h²` (`0 < j < J`),
//! `2M_0 + M_1 = 6[(P_1 − P_0)/h − P_0']/h`, `M_{J−1} + 2M_J = 6[P_J' − (P_J − P_{J−1})/h]/h`,
//! and on `[u_j, u_{j+1}]`, `x = u − u_j`:
//! `S = P_j + [(P_{j+1} − P_j)/h − h(2M_j + M_{j+1})/6] x + M_j x²/2 + (M_{j+1} − M_j) x³/(6h)`.

use crate::curve::{Curve, Domain};
use crate::linalg::band::BandMatrix;
use crate::{Error, Result, Vec3};

/// Clamped cubic spline through uniformly spaced nodes on `[0, 1]`.
#[derive(Debug, Clone)]
pub struct NodalCurve {
    points: Vec<Vec3>,
    moments: Vec<Vec3>,
}

impl NodalCurve {
    /// Builds the spline through `points` (at `u_j = j/J`, `J = points.len() − 1 ≥ 1`) with end
    /// derivatives `d0 = S'(0)`, `d1 = S'(1)`.
    pub fn new(points: Vec<Vec3>, d0: Vec3, d1: Vec3) -> Result<Self> {
        if points.len() < 2 {
            return Err(Error::invalid(format!(
                "{} nodes; a curve needs at least 2",
                points.len()
            )));
        }
        if let Some((j, p)) = points
            .iter()
            .chain([&d0, &d1])
            .enumerate()
            .find(|(_, p)| !p.iter().all(|x| x.is_finite()))
        {
            return Err(Error::invalid(format!("value {j} = {p:?} is not finite")));
        }
        let n = points.len();
        let jn = n - 1;
        let h = 1.0 / jn as f64;
        let mut m = BandMatrix::zeros(n, 1, 1);
        for j in 0..n {
            if j > 0 {
                m.set(j, j - 1, 1.0);
            }
            if j + 1 < n {
                m.set(j, j + 1, 1.0);
            }
            m.set(j, j, if j == 0 || j == jn { 2.0 } else { 4.0 });
        }
        m.factorize()?;
        let mut moments = vec![Vec3::zeros(); n];
        for c in 0..3 {
            let p: Vec<f64> = points.iter().map(|q| q[c]).collect();
            let mut rhs: Vec<f64> = (0..n)
                .map(|j| {
                    if j == 0 {
                        6.0 * ((p[1] - p[0]) / h - d0[c]) / h
                    } else if j == jn {
                        6.0 * (d1[c] - (p[jn] - p[jn - 1]) / h) / h
                    } else {
                        6.0 * (p[j + 1] - 2.0 * p[j] + p[j - 1]) / (h * h)
                    }
                })
                .collect();
            m.solve_in_place(&mut rhs);
            for (mo, r) in moments.iter_mut().zip(rhs) {
                mo[c] = r;
            }
        }
        Ok(NodalCurve { points, moments })
    }

    /// The nodes `P_j`.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }
}

impl Curve for NodalCurve {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }

    /// Value and derivatives of the cubic piece containing `u` (the last piece for `u = 1`;
    /// pieces are extended outside `[0, 1]`). Orders above 3 are zero.
    fn jet(&self, u: f64, out: &mut [Vec3]) {
        let jn = self.points.len() - 1;
        let h = 1.0 / jn as f64;
        let j = ((u / h).floor().max(0.0) as usize).min(jn - 1);
        let x = u - j as f64 * h;
        let (p0, p1) = (self.points[j], self.points[j + 1]);
        let (m0, m1) = (self.moments[j], self.moments[j + 1]);
        let b = (p1 - p0) / h - (m0 * 2.0 + m1) * (h / 6.0);
        let c3 = (m1 - m0) / (6.0 * h);
        let vals = [
            p0 + b * x + m0 * (x * x / 2.0) + c3 * (x * x * x),
            b + m0 * x + c3 * (3.0 * x * x),
            m0 + c3 * (6.0 * x),
            c3 * 6.0,
        ];
        for (k, o) in out.iter_mut().enumerate() {
            *o = if k < 4 { vals[k] } else { Vec3::zeros() };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic is reproduced exactly (its moments satisfy every equation), with its derivatives.
    #[test]
    fn reproduces_a_cubic() {
        let c = [
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(2.0, -1.0, 0.5),
            Vec3::new(-3.0, 4.0, 1.0),
            Vec3::new(0.5, 2.0, -2.0),
        ];
        let f = |u: f64| c[0] + c[1] * u + c[2] * (u * u) + c[3] * (u * u * u);
        let df = |u: f64| c[1] + c[2] * (2.0 * u) + c[3] * (3.0 * u * u);
        let jn = 7;
        let pts: Vec<Vec3> = (0..=jn).map(|j| f(j as f64 / jn as f64)).collect();
        let s = NodalCurve::new(pts, df(0.0), df(1.0)).unwrap();
        for i in 0..=50 {
            let u = i as f64 / 50.0;
            let mut jet = [Vec3::zeros(); 5];
            s.jet(u, &mut jet);
            let want = [
                f(u),
                df(u),
                c[2] * 2.0 + c[3] * (6.0 * u),
                c[3] * 6.0,
                Vec3::zeros(),
            ];
            for k in 0..5 {
                // Rounding: the moments inherit ε·|P|·24/h² ≈ 1e-12 from the right-hand side;
                // each further derivative divides by about h = 1/7.
                let tol = [1e-13, 1e-12, 1e-11, 1e-10, 0.0][k];
                let err = (jet[k] - want[k]).amax();
                assert!(err <= tol, "u = {u}, order {k}: {err:e}");
            }
        }
    }

    /// Nodes are interpolated and the second derivative is continuous across nodes.
    #[test]
    fn interpolates_and_is_c2() {
        let pts: Vec<Vec3> = (0..=10)
            .map(|j| Vec3::new((j as f64).sin(), (j * j) as f64 * 0.1, 0.0))
            .collect();
        let s = NodalCurve::new(pts.clone(), Vec3::new(1.0, 0.0, 0.0), Vec3::zeros()).unwrap();
        for (j, p) in pts.iter().enumerate() {
            assert!((s.point(j as f64 / 10.0) - p).amax() < 1e-14);
        }
        for j in 1..10 {
            let u = j as f64 / 10.0;
            let (l, r) = (s.derivative(u - 1e-12, 2), s.derivative(u + 1e-12, 2));
            assert!((l - r).amax() < 1e-9 * (1.0 + l.amax()), "node {j}");
        }
        assert!((s.derivative(0.0, 1) - Vec3::new(1.0, 0.0, 0.0)).amax() < 1e-13);
        assert!(s.derivative(1.0, 1).amax() < 1e-13);
        assert!(NodalCurve::new(vec![Vec3::zeros()], Vec3::zeros(), Vec3::zeros()).is_err());
    }
}
