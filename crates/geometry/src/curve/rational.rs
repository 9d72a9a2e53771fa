//! Rational B-spline (NURBS) curves: the curves CAD systems exchange (their circles and conics
//! are rational).

use super::{BSpline, Curve, Domain, MAX_ORDER};
use crate::{Error, Result, Vec3};

/// A rational B-spline curve `C(t) = Σ N_i(t) w_i P_i / Σ N_i(t) w_i` on the knots of a
/// [`BSpline`] of the same degree, with positive weights.
///
/// The numerator `A = Σ N_i w_i P_i` and the weight `w = Σ N_i w_i` are B-splines with exact
/// derivatives; those of `C` follow from Leibniz's rule on `A = w C`:
/// `C⁽ᵐ⁾ = (A⁽ᵐ⁾ − Σ_{j=1}^{m} binom(m, j) w⁽ʲ⁾ C⁽ᵐ⁻ʲ⁾) / w`.
#[derive(Clone, Debug)]
pub struct RationalBSpline {
    /// `Σ N_i w_i P_i`.
    numerator: BSpline,
    /// `Σ N_i w_i` in the first coordinate.
    weight: BSpline,
}

impl RationalBSpline {
    /// An open rational B-spline: as [`BSpline::clamped`], with one positive weight per control
    /// point (errors at `weights` or `weights[i]`).
    pub fn clamped(
        degree: usize,
        control: Vec<Vec3>,
        weights: &[f64],
        knots: Option<Vec<f64>>,
    ) -> Result<Self> {
        let (num, den) = homogeneous(&control, weights)?;
        Ok(RationalBSpline {
            numerator: BSpline::clamped(degree, num, knots.clone())?,
            weight: BSpline::clamped(degree, den, knots)?,
        })
    }

    /// A periodic rational B-spline on `[0, 2π)`: as [`BSpline::periodic`], with one positive
    /// weight per control point.
    pub fn periodic(
        degree: usize,
        control: Vec<Vec3>,
        weights: &[f64],
        knots: Option<Vec<f64>>,
    ) -> Result<Self> {
        let (num, den) = homogeneous(&control, weights)?;
        Ok(RationalBSpline {
            numerator: BSpline::periodic(degree, num, knots.clone())?,
            weight: BSpline::periodic(degree, den, knots)?,
        })
    }
}

/// The control points `w_i P_i` of the numerator and `(w_i, 0, 0)` of the weight.
fn homogeneous(control: &[Vec3], weights: &[f64]) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
    if weights.len() != control.len() {
        return Err(Error::invalid(format!(
            "needs one weight per control point ({} control points, {} weights)",
            control.len(),
            weights.len()
        ))
        .at("weights"));
    }
    for (i, w) in weights.iter().enumerate() {
        if !(w.is_finite() && *w > 0.0) {
            return Err(Error::invalid(format!("must be finite and > 0 (got {w})"))
                .at(&format!("weights[{i}]")));
        }
    }
    Ok((
        control.iter().zip(weights).map(|(p, w)| p * *w).collect(),
        weights.iter().map(|w| Vec3::new(*w, 0.0, 0.0)).collect(),
    ))
}

impl Curve for RationalBSpline {
    fn domain(&self) -> Domain {
        self.numerator.domain()
    }

    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let k = out.len().min(MAX_ORDER + 1);
        let mut a = [Vec3::zeros(); MAX_ORDER + 1];
        let mut w = [Vec3::zeros(); MAX_ORDER + 1];
        self.numerator.jet(t, &mut a[..k]);
        self.weight.jet(t, &mut w[..k]);
        let w0 = w[0].x;
        for m in 0..k {
            let mut v = a[m];
            let mut binom = 1.0;
            for j in 1..=m {
                binom = binom * (m + 1 - j) as f64 / j as f64;
                v -= out[m - j] * (binom * w[j].x);
            }
            out[m] = v / w0;
        }
        for o in out.iter_mut().skip(k) {
            *o = Vec3::zeros();
        }
    }

    fn breaks(&self) -> Vec<f64> {
        self.numerator.breaks()
    }
    /// The numerator's and the weight's (a quotient with a positive denominator is as smooth
    /// as both).
    fn continuity(&self) -> usize {
        self.numerator.continuity().min(self.weight.continuity())
    }

    /// From the bounds of the numerator's and the weight's derivatives (B-splines) over the
    /// interval and Leibniz's rule above: `|C| ≤ max |P_i|` (the curve lies in the convex hull
    /// of its control points, the weights being positive), and
    /// `|C⁽ᵐ⁾| ≤ (sup|A⁽ᵐ⁾| + Σ_{j=1}^{m} binom(m, j) sup|w⁽ʲ⁾| sup|C⁽ᵐ⁻ʲ⁾|) / min w`, with
    /// `w ≥ min w_i` (the basis functions are non-negative and sum to one).
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let k = out.len();
        let (mut a, mut w) = ([0.0f64; 6], [0.0f64; 6]);
        if k > 6
            || !self.numerator.derivative_bounds(t0, t1, &mut a[..k])
            || !self.weight.derivative_bounds(t0, t1, &mut w[..k])
        {
            return false;
        }
        let (num, den) = (
            self.numerator.control_points(),
            self.weight.control_points(),
        );
        let w_min = den.iter().map(|d| d.x).fold(f64::INFINITY, f64::min);
        if w_min.is_nan() || w_min <= 0.0 {
            return false;
        }
        for m in 0..k {
            out[m] = if m == 0 {
                num.iter()
                    .zip(den)
                    .map(|(p, d)| p.norm() / d.x)
                    .fold(0.0, f64::max)
            } else {
                let mut sum = a[m];
                let mut binom = 1.0;
                for j in 1..=m {
                    binom = binom * (m + 1 - j) as f64 / j as f64;
                    sum += binom * w[j] * out[m - j];
                }
                sum / w_min
            } * (1.0 + super::BOUND_ROUNDING);
        }
        out.iter().all(|o| o.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit circle as the classic nine-point rational quadratic: four arcs, weights
    /// `1, √2/2, 1, …`, double inner knots.
    fn circle() -> RationalBSpline {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let p = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
        ];
        let control = p.iter().map(|(x, y)| Vec3::new(*x, *y, 0.0)).collect();
        let weights = [1.0, h, 1.0, h, 1.0, h, 1.0, h, 1.0];
        let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0];
        RationalBSpline::clamped(2, control, &weights, Some(knots)).unwrap()
    }

    #[test]
    fn the_nine_point_circle_is_the_circle_with_exact_derivatives() {
        let c = circle();
        assert_eq!(c.domain(), Domain::Interval(0.0, 4.0));
        let mut jet = [Vec3::zeros(); 3];
        let mut prev = [Vec3::zeros(); 3];
        for i in 0..=400 {
            let t = 4.0 * i as f64 / 400.0;
            c.jet(t, &mut jet);
            // On the circle, and its derivatives those of a curve on it: C·C' = 0 and
            // C·C'' + |C'|² = 0 (the derivatives of |C|² = 1).
            assert!(
                (jet[0].norm() - 1.0).abs() < 1e-15,
                "t {t}: {}",
                jet[0].norm()
            );
            assert!(jet[0].dot(&jet[1]).abs() < 1e-14, "t {t}");
            assert!(
                (jet[0].dot(&jet[2]) + jet[1].norm_squared()).abs() < 1e-13,
                "t {t}"
            );
            if i > 0 && (t.fract() > 0.01 && t.fract() < 0.99) {
                // The second derivative against a difference of first derivatives.
                let fd = (jet[1] - prev[1]) / 0.01;
                let mid = (jet[2] + prev[2]) / 2.0;
                assert!((fd - mid).norm() < 1e-3 * mid.norm(), "t {t}");
            }
            prev = jet;
        }
        // A quarter per knot span: the point at t = 1 is (0, 1).
        assert!((c.point(1.0) - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-15);
        assert_eq!(c.breaks(), vec![1.0, 2.0, 3.0]);
    }

    /// The bounds hold: every derivative up to order 5 of the circle and of a curve with
    /// uneven weights, sampled on sub-intervals (their knot spans and across them), lies below
    /// its bound.
    #[test]
    fn the_derivative_bounds_hold() {
        let uneven = RationalBSpline::clamped(
            3,
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 2.0, 0.0),
                Vec3::new(3.0, -1.0, 1.0),
                Vec3::new(4.0, 0.5, -2.0),
                Vec3::new(6.0, 1.0, 0.0),
            ],
            &[1.0, 3.0, 0.4, 2.0, 1.0],
            None,
        )
        .unwrap();
        for curve in [circle(), uneven] {
            let (a, b) = match curve.domain() {
                Domain::Interval(a, b) => (a, b),
                Domain::Periodic => (0.0, std::f64::consts::TAU),
            };
            for (x0, x1) in [(0.0, 1.0), (0.1, 0.3), (0.45, 0.55), (0.7, 0.72)] {
                let (t0, t1) = (a + (b - a) * x0, a + (b - a) * x1);
                let mut bound = [0.0; 6];
                assert!(curve.derivative_bounds(t0, t1, &mut bound));
                let mut seen = [0.0f64; 6];
                for i in 0..=200 {
                    let mut jet = [Vec3::zeros(); 6];
                    curve.jet(t0 + (t1 - t0) * i as f64 / 200.0, &mut jet);
                    for (s, j) in seen.iter_mut().zip(&jet) {
                        *s = s.max(j.norm());
                    }
                }
                for k in 0..6 {
                    assert!(
                        seen[k] <= bound[k] * (1.0 + 1e-12),
                        "order {k} on [{t0}, {t1}]: {} > {}",
                        seen[k],
                        bound[k]
                    );
                }
            }
        }
    }

    #[test]
    fn bad_weights_are_refused_with_their_place() {
        let control = vec![Vec3::zeros(), Vec3::x(), Vec3::y()];
        let e = RationalBSpline::clamped(2, control.clone(), &[1.0, 1.0], None).unwrap_err();
        assert_eq!(e.place(), "weights");
        let e = RationalBSpline::clamped(2, control.clone(), &[1.0, 0.0, 1.0], None).unwrap_err();
        assert_eq!(e.place(), "weights[1]");
        let e = RationalBSpline::periodic(2, control, &[1.0, f64::NAN, 1.0], None).unwrap_err();
        assert_eq!(e.place(), "weights[1]");
        // Equal weights give the polynomial B-spline.
        let control = vec![
            Vec3::zeros(),
            Vec3::x(),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::y(),
        ];
        let r = RationalBSpline::clamped(3, control.clone(), &[2.5; 4], None).unwrap();
        let b = BSpline::clamped(3, control, None).unwrap();
        let (mut x, mut y) = ([Vec3::zeros(); 4], [Vec3::zeros(); 4]);
        for t in [0.0, 0.3, 0.77, 1.0] {
            r.jet(t, &mut x);
            b.jet(t, &mut y);
            for k in 0..4 {
                assert!(
                    (x[k] - y[k]).norm() < 1e-13 * (1.0 + y[k].norm()),
                    "t {t} k {k}"
                );
            }
        }
    }
}
