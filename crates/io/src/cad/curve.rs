//! B-spline curves (in 3D, or in a surface's `(u, v)` plane with `z = 0`) for the edges of
//! trimmed faces: evaluation with one-sided derivatives, knot insertion, and the chain of cubic
//! Bézier pieces a Hermite interpolation writes.

use crate::{Error, Result, Vec3};

/// A clamped or unclamped B-spline curve: degree, full knot vector, control points
/// (`knots.len() = points.len() + degree + 1`); its domain is `[knots[p], knots[n]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct BCurve {
    /// Polynomial degree `p ≥ 1`.
    pub degree: usize,
    /// Full knot vector, non-decreasing, `points.len() + degree + 1` knots.
    pub knots: Vec<f64>,
    /// Control points (with `z = 0` for a curve in a surface's `(u, v)` plane).
    pub points: Vec<Vec3>,
}

impl BCurve {
    /// Checks the sizes and the knots' order.
    pub fn new(degree: usize, knots: Vec<f64>, points: Vec<Vec3>) -> Result<BCurve> {
        if degree == 0
            || points.len() <= degree
            || knots.len() != points.len() + degree + 1
            || knots.windows(2).any(|w| {
                w[0].partial_cmp(&w[1]) == Some(std::cmp::Ordering::Greater)
                    || w[0].is_nan()
                    || w[1].is_nan()
            })
        {
            return Err(Error::invalid(
                "a curve's degree, knots and control points do not fit together",
            ));
        }
        Ok(BCurve {
            degree,
            knots,
            points,
        })
    }

    /// The parameter domain `[knots[p], knots[n]]`.
    pub fn domain(&self) -> [f64; 2] {
        [self.knots[self.degree], self.knots[self.points.len()]]
    }

    /// The knot span `k` (`knots[k] ≤ s < knots[k + 1]`, or `≤` on the right when `left`) used
    /// at `s`, kept inside the domain.
    fn span(&self, s: f64, left: bool) -> usize {
        let (p, n) = (self.degree, self.points.len());
        let mut k = p;
        while k + 1 < n
            && (if left {
                self.knots[k + 1] < s
            } else {
                self.knots[k + 1] <= s
            })
        {
            k += 1;
        }
        k
    }

    /// The point at `s` (de Boor), from the span on the right of `s` (on the left if `left`).
    fn eval(degree: usize, knots: &[f64], points: &[Vec3], k: usize, s: f64) -> Vec3 {
        let p = degree;
        let mut d: Vec<Vec3> = (0..=p).map(|j| points[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let den = knots[i + p + 1 - r] - knots[i];
                let a = if den > 0.0 { (s - knots[i]) / den } else { 0.0 };
                d[j] = d[j - 1] * (1.0 - a) + d[j] * a;
            }
        }
        d[p]
    }

    /// The point at `s`.
    pub fn point(&self, s: f64) -> Vec3 {
        let k = self.span(s, false);
        Self::eval(self.degree, &self.knots, &self.points, k, s)
    }

    /// The first derivative at `s`, from the left of `s` if `left` (one-sided at a corner).
    pub fn derivative(&self, s: f64, left: bool) -> Vec3 {
        let p = self.degree;
        let n = self.points.len();
        let q: Vec<Vec3> = (0..n - 1)
            .map(|i| {
                let den = self.knots[i + p + 1] - self.knots[i + 1];
                if den > 0.0 {
                    (self.points[i + 1] - self.points[i]) * (p as f64 / den)
                } else {
                    Vec3::zeros()
                }
            })
            .collect();
        let knots = &self.knots[1..self.knots.len() - 1];
        let k = self.span(s, left);
        if p == 1 {
            return q[k - 1];
        }
        Self::eval(p - 1, knots, &q, k - 1, s)
    }

    /// The same curve with the knot `s` inserted once (Boehm).
    pub fn insert(&self, s: f64) -> BCurve {
        let p = self.degree;
        let k = self.span(s, false);
        let mut pts = Vec::with_capacity(self.points.len() + 1);
        for i in 0..=self.points.len() {
            if i + p <= k {
                pts.push(self.points[i]);
            } else if i > k {
                pts.push(self.points[i - 1]);
            } else {
                let den = self.knots[i + p] - self.knots[i];
                let a = if den > 0.0 {
                    (s - self.knots[i]) / den
                } else {
                    0.0
                };
                pts.push(self.points[i - 1] * (1.0 - a) + self.points[i] * a);
            }
        }
        let mut knots = self.knots.clone();
        knots.insert(k + 1, s);
        BCurve {
            degree: p,
            knots,
            points: pts,
        }
    }

    /// The same curve on a knot vector clamped at its domain's ends (end knots of
    /// multiplicity `p + 1`), so that it starts and ends at its first and last control points.
    pub fn clamped(&self) -> BCurve {
        let p = self.degree;
        let [a, b] = self.domain();
        let mult = |c: &BCurve, x: f64| c.knots.iter().filter(|&&k| k == x).count();
        let mut c = self.clone();
        while mult(&c, a) < p + 1 {
            c = c.insert(a);
        }
        while mult(&c, b) < p + 1 {
            c = c.insert(b);
        }
        let i0 = c.knots.iter().position(|&x| x == a).unwrap_or(0);
        let i1 = c
            .knots
            .iter()
            .rposition(|&x| x == b)
            .unwrap_or(c.knots.len() - 1);
        let knots = c.knots[i0..=i1].to_vec();
        let count = knots.len() - p - 1;
        BCurve {
            degree: p,
            points: c.points[i0..i0 + count].to_vec(),
            knots,
        }
    }

    /// The curve traversed backwards on the same domain.
    pub fn reversed(&self) -> BCurve {
        let [a, b] = [self.knots[0], *self.knots.last().unwrap()];
        BCurve {
            degree: self.degree,
            knots: self.knots.iter().rev().map(|k| a + b - k).collect(),
            points: self.points.iter().rev().copied().collect(),
        }
    }

    /// The distinct knot values inside and at the ends of the domain.
    pub fn breaks(&self) -> Vec<f64> {
        let [a, b] = self.domain();
        let mut out: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|&k| k >= a && k <= b)
            .collect();
        out.dedup();
        out
    }

    /// The cubic through the nodes `s_0 < … < s_m` with the values `x_k` and the one-sided
    /// derivatives `d⁺_k` (to the right of `s_k`) and `d⁻_k` (to the left): one cubic Bézier
    /// piece per interval, joined with triple knots (C⁰ where `d⁻ ≠ d⁺`, C¹ where equal).
    pub fn hermite_chain(s: &[f64], x: &[Vec3], right: &[Vec3], left: &[Vec3]) -> BCurve {
        let m = s.len() - 1;
        let mut knots = vec![s[0]; 4];
        let mut points = vec![x[0]];
        for k in 0..m {
            let h = s[k + 1] - s[k];
            points.push(x[k] + right[k] * (h / 3.0));
            points.push(x[k + 1] - left[k + 1] * (h / 3.0));
            points.push(x[k + 1]);
            let reps = if k + 1 == m { 4 } else { 3 };
            knots.extend(std::iter::repeat_n(s[k + 1], reps));
        }
        BCurve {
            degree: 3,
            knots,
            points,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insertion_and_clamping_keep_the_curve() {
        // An unclamped uniform cubic on 6 points.
        let pts: Vec<Vec3> = (0..6)
            .map(|i| Vec3::new((i as f64).cos(), (i as f64 * 0.7).sin(), 0.1 * i as f64))
            .collect();
        let c = BCurve::new(3, (0..10).map(|k| k as f64).collect(), pts).unwrap();
        let d = c.clamped();
        assert_eq!(d.domain(), c.domain());
        assert_eq!(d.knots[..4], [3.0; 4]);
        for k in 0..=40 {
            let s = 3.0 + 3.0 * k as f64 / 40.0;
            assert!((c.point(s) - d.point(s)).norm() < 1e-13, "s = {s}");
            let h = 1e-6;
            let fd = (c.point((s + h).min(6.0)) - c.point((s - h).max(3.0)))
                / ((s + h).min(6.0) - (s - h).max(3.0));
            assert!((c.derivative(s, false) - fd).norm() < 1e-6, "s = {s}");
        }
        assert!((d.points[0] - c.point(3.0)).norm() < 1e-14);
        assert!((d.points.last().unwrap() - c.point(6.0)).norm() < 1e-14);
    }

    #[test]
    fn hermite_chain_interpolates_values_and_one_sided_slopes() {
        let s = [0.0, 0.5, 2.0];
        let x = [
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
        ];
        let r = [Vec3::x(), Vec3::y(), Vec3::y()];
        let l = [Vec3::x(), Vec3::x(), Vec3::y()];
        let c = BCurve::hermite_chain(&s, &x, &r, &l);
        for k in 0..3 {
            assert!((c.point(s[k]) - x[k]).norm() < 1e-15);
        }
        assert!((c.derivative(0.5, true) - Vec3::x()).norm() < 1e-14);
        assert!((c.derivative(0.5, false) - Vec3::y()).norm() < 1e-14);
        assert!((c.derivative(2.0, true) - Vec3::y()).norm() < 1e-14);
    }
}
