use super::{Curve, Domain};
use crate::check::finite_points;
use crate::{Error, Result, Vec3};

/// Bézier curve of any degree `n` on `[0, 1]`: `B(t) = Σ_{i=0}^{n} P_i C(n,i) tⁱ (1 − t)ⁿ⁻ⁱ`,
/// evaluated by de Casteljau; the `k`-th derivative is the Bézier curve of the `k`-th hodograph,
/// `n!/(n−k)! Δᵏ P_i`. Outside `[0, 1]` the polynomial is extended.
#[derive(Clone, Debug)]
pub struct Bezier {
    /// Control points `P_0 … P_n`.
    pub control: Vec<Vec3>,
    /// `hodographs[k]` holds the control points of `B⁽ᵏ⁾` for `k = 0..=min(n, MAX_ORDER)`.
    hodographs: Vec<Vec<Vec3>>,
}

impl Bezier {
    /// At least two control points, all finite. Errors are placed as in a `bezier` table of the
    /// design file: `control[i][c]`, `control`.
    pub fn new(control: Vec<Vec3>) -> Result<Self> {
        finite_points(&control, "control")?;
        if control.len() < 2 {
            return Err(Error::invalid(format!(
                "needs at least 2 control points (got {})",
                control.len()
            ))
            .at("control"));
        }
        let n = control.len() - 1;
        let mut hodographs = vec![control.clone()];
        for k in 1..=n.min(super::MAX_ORDER) {
            let prev = &hodographs[k - 1];
            let m = (n - k + 1) as f64;
            let next: Vec<Vec3> = prev.windows(2).map(|w| (w[1] - w[0]) * m).collect();
            hodographs.push(next);
        }
        Ok(Bezier {
            control,
            hodographs,
        })
    }

    /// Degree `n`.
    pub fn degree(&self) -> usize {
        self.control.len() - 1
    }
}

/// de Casteljau's algorithm (on the stack up to degree 15).
fn de_casteljau(points: &[Vec3], t: f64) -> Vec3 {
    const STACK: usize = 16;
    if points.len() <= STACK {
        let mut w = [Vec3::zeros(); STACK];
        w[..points.len()].copy_from_slice(points);
        return de_casteljau_in(&mut w[..points.len()], t);
    }
    de_casteljau_in(&mut points.to_vec(), t)
}

fn de_casteljau_in(w: &mut [Vec3], t: f64) -> Vec3 {
    let n = w.len();
    for r in 1..n {
        for i in 0..n - r {
            w[i] = w[i] * (1.0 - t) + w[i + 1] * t;
        }
    }
    w[0]
}

impl Curve for Bezier {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        for (k, o) in out.iter_mut().enumerate() {
            *o = match self.hodographs.get(k) {
                Some(h) => de_casteljau(h, t),
                None => Vec3::zeros(),
            };
        }
    }
    /// One polynomial everywhere (extended outside `[0, 1]`). Up to degree `MAX_ORDER`:
    /// Taylor's formula about the middle of `(t0, t1)` ([`super::polynomial_piece_bounds`]).
    /// Above it, inside `[0, 1]` only: `B⁽ᵏ⁾` is the Bézier curve of the `k`-th hodograph, a
    /// convex combination of its control points (Bernstein weights are non-negative and sum to
    /// one), so their largest norm bounds it.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let n = self.degree();
        if n <= super::MAX_ORDER {
            let pieces = super::pieces(&[], false, t0, t1);
            return super::polynomial_piece_bounds(self, n, &pieces, out);
        }
        if !(0.0 <= t0 && t0 < t1 && t1 <= 1.0) {
            return false;
        }
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.hodographs.get(k).map_or(0.0, |h| {
                h.iter().map(|p| p.norm()).fold(0.0, f64::max) * (1.0 + super::BOUND_ROUNDING)
            });
        }
        out.iter().all(|o| o.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;

    fn binom(n: usize, k: usize) -> f64 {
        (0..k).fold(1.0, |b, i| b * (n - i) as f64 / (i + 1) as f64)
    }

    #[test]
    fn bezier_matches_bernstein_form() {
        let ctrl = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(2.0, -1.0, 1.0),
            Vec3::new(3.0, 0.5, 2.0),
            Vec3::new(4.0, 1.0, -1.0),
        ];
        let b = Bezier::new(ctrl.clone()).unwrap();
        let n = 4;
        for &t in &[0.0f64, 0.25, 0.6, 1.0, -0.3, 1.4] {
            let want: Vec3 = (0..=n).fold(Vec3::zeros(), |s, i| {
                s + ctrl[i] * binom(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32)
            });
            // B'(t) = n Σ (P_{i+1} − P_i) b_{i,n−1}(t).
            let dwant: Vec3 = (0..n).fold(Vec3::zeros(), |s, i| {
                s + (ctrl[i + 1] - ctrl[i])
                    * (n as f64
                        * binom(n - 1, i)
                        * t.powi(i as i32)
                        * (1.0 - t).powi((n - 1 - i) as i32))
            });
            let j = jet(&b, t);
            assert_close(&j[0], &want, 1e-13, "value");
            assert_close(&j[1], &dwant, 1e-12, "first");
            // 4th derivative of a quartic: 24 Δ⁴P.
            let d4 = (ctrl[4] - ctrl[3] * 4.0 + ctrl[2] * 6.0 - ctrl[1] * 4.0 + ctrl[0]) * 24.0;
            assert_close(&j[4], &d4, 1e-12, "fourth");
            for d in &j[5..] {
                assert_eq!(*d, Vec3::zeros());
            }
        }
        assert_close(&b.point(0.0), &ctrl[0], 0.0, "start");
        assert_close(&b.point(1.0), &ctrl[4], 0.0, "end");
        check_fd(&b, &[0.1, 0.5, 0.9], 1e-4, 5, 10.0);
        // A line.
        let l = Bezier::new(vec![Vec3::zeros(), Vec3::x()]).unwrap();
        assert_close(&l.derivative(0.3, 1), &Vec3::x(), 0.0, "line");
        assert_eq!(l.derivative(0.3, 2), Vec3::zeros());
    }

    #[test]
    fn bezier_rejects_bad_input() {
        assert!(Bezier::new(vec![]).is_err());
        assert!(Bezier::new(vec![Vec3::x()]).is_err());
        let e = Bezier::new(vec![Vec3::x(), Vec3::new(f64::NAN, 0.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("control[1]"), "{e}");
        assert!(Bezier::new(vec![Vec3::x(), Vec3::new(0.0, f64::INFINITY, 0.0)]).is_err());
    }

    #[test]
    fn refusals_are_placed_and_worded_as_in_the_design_file() {
        let err = |c: Vec<Vec3>| Bezier::new(c).unwrap_err().to_string();
        assert_eq!(
            err(vec![Vec3::x()]),
            "control: needs at least 2 control points (got 1)"
        );
        assert_eq!(
            err(vec![Vec3::x(), Vec3::new(0.0, 0.0, f64::NAN)]),
            "control[1][2]: must be finite (got NaN)"
        );
        // Finite points are checked before their count, as in the design file.
        assert_eq!(
            err(vec![Vec3::new(f64::INFINITY, 0.0, 0.0)]),
            "control[0][0]: must be finite (got inf)"
        );
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;

    /// Degree 4 (Taylor bounds) and degree 10 (hodograph hulls inside [0, 1]) hold; the
    /// quartic's constant fourth derivative is attained.
    #[test]
    fn bounds_hold() {
        let pts = |n: usize| -> Vec<Vec3> {
            (0..=n)
                .map(|i| {
                    let x = i as f64;
                    Vec3::new(x, (1.7 * x).sin(), (0.4 * x).cos())
                })
                .collect()
        };
        let quartic = Bezier::new(pts(4)).unwrap();
        let r = check_bounds(&quartic, 6, 40, 1.0);
        eprintln!("bezier 4: {r:?}");
        assert!(r[4] <= 1.0 + 1e-6, "{r:?}");
        assert!(r.iter().all(|&x| x <= 3.0), "{r:?}");
        let high = Bezier::new(pts(10)).unwrap();
        let r = check_bounds(&high, 7, 40, 1.0);
        eprintln!("bezier 10: {r:?}");
        assert!(!high.derivative_bounds(-0.1, 0.5, &mut [0.0; 5]));
    }
}
