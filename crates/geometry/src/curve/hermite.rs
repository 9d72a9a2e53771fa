use super::{poly_jet, Curve, Domain};
use crate::check::finite3;
use crate::{Result, Vec3};

/// Cubic Hermite curve on `[0, 1]` from end points and end tangents (book Eq. 5.4):
/// `H(t) = p₀ h₀₀(t) + p₁ h₀₁(t) + d₀ h₁₀(t) + d₁ h₁₁(t)` with `h₀₀ = 2t³ − 3t² + 1`,
/// `h₀₁ = −2t³ + 3t²`, `h₁₀ = t³ − 2t² + t`, `h₁₁ = t³ − t²`. Outside `[0, 1]` the cubic is
/// extended.
#[derive(Clone, Debug)]
pub struct Hermite {
    /// Start point `p₀ = H(0)`.
    pub p0: Vec3,
    /// End point `p₁ = H(1)`.
    pub p1: Vec3,
    /// Start tangent `d₀ = H'(0)`.
    pub d0: Vec3,
    /// End tangent `d₁ = H'(1)`.
    pub d1: Vec3,
}

impl Hermite {
    /// The cubic with end points `p0`, `p1` and end tangents `d0`, `d1` (not checked; see
    /// [`Hermite::try_new`]).
    pub fn new(p0: Vec3, p1: Vec3, d0: Vec3, d1: Vec3) -> Self {
        Hermite { p0, p1, d0, d1 }
    }

    /// [`Hermite::new`], refusing end points or tangents that are not finite (places `p0[c]`,
    /// `p1[c]`, `d0[c]`, `d1[c]`, as in the design file's `hermite` table).
    pub fn try_new(p0: Vec3, p1: Vec3, d0: Vec3, d1: Vec3) -> Result<Self> {
        for (name, v) in [("p0", &p0), ("p1", &p1), ("d0", &d0), ("d1", &d1)] {
            finite3(v, name)?;
        }
        Ok(Hermite { p0, p1, d0, d1 })
    }

    /// Power-form coefficients `H(t) = c₀ + c₁ t + c₂ t² + c₃ t³`.
    fn power_form(&self) -> [Vec3; 4] {
        let (p0, p1, d0, d1) = (self.p0, self.p1, self.d0, self.d1);
        [
            p0,
            d0,
            (p1 - p0) * 3.0 - d0 * 2.0 - d1,
            (p0 - p1) * 2.0 + d0 + d1,
        ]
    }
}

impl Curve for Hermite {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        poly_jet(&self.power_form(), t, out);
    }
    /// One cubic everywhere (extended outside `[0, 1]`): Taylor's formula about the middle of
    /// `(t0, t1)` ([`super::polynomial_piece_bounds`]).
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let pieces = super::pieces(&[], false, t0, t1);
        super::polynomial_piece_bounds(self, 3, &pieces, out)
    }
}

/// The cubic Hermite basis on `[0, 1]` (value at 0, slope at 0, value at 1, slope at 1) with
/// its first and second derivatives: `[order][function]`.
pub(crate) fn hermite_basis(t: f64) -> [[f64; 4]; 3] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ],
        [
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        ],
        [
            12.0 * t - 6.0,
            6.0 * t - 4.0,
            -12.0 * t + 6.0,
            6.0 * t - 2.0,
        ],
    ]
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;

    #[test]
    fn hermite_matches_basis_and_end_conditions() {
        let h = Hermite::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(3.0, 0.0, 1.0),
            Vec3::new(-1.0, 1.0, 0.5),
        );
        assert_close(&h.point(0.0), &h.p0, 0.0, "p0");
        assert_close(&h.point(1.0), &h.p1, 1e-15, "p1");
        assert_close(&h.derivative(0.0, 1), &h.d0, 0.0, "d0");
        assert_close(&h.derivative(1.0, 1), &h.d1, 1e-14, "d1");
        for &t in &[0.2, 0.5, 0.9, -0.5, 1.7] {
            let (t2, t3) = (t * t, t * t * t);
            let want = h.p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
                + h.p1 * (-2.0 * t3 + 3.0 * t2)
                + h.d0 * (t3 - 2.0 * t2 + t)
                + h.d1 * (t3 - t2);
            let dwant = h.p0 * (6.0 * t2 - 6.0 * t)
                + h.p1 * (-6.0 * t2 + 6.0 * t)
                + h.d0 * (3.0 * t2 - 4.0 * t + 1.0)
                + h.d1 * (3.0 * t2 - 2.0 * t);
            let d2want = h.p0 * (12.0 * t - 6.0)
                + h.p1 * (-12.0 * t + 6.0)
                + h.d0 * (6.0 * t - 4.0)
                + h.d1 * (6.0 * t - 2.0);
            let d3want = (h.p0 - h.p1) * 12.0 + (h.d0 + h.d1) * 6.0;
            let j = jet(&h, t);
            assert_close(&j[0], &want, 1e-13, "value");
            assert_close(&j[1], &dwant, 1e-13, "first");
            assert_close(&j[2], &d2want, 1e-13, "second");
            assert_close(&j[3], &d3want, 1e-13, "third");
            for d in &j[4..] {
                assert_eq!(*d, Vec3::zeros());
            }
        }
        check_fd(&h, &[0.1, 0.5, 0.8], 1e-4, 5, 10.0);
    }

    #[test]
    fn refusals_are_placed_and_worded_as_in_the_design_file() {
        let (z, x) = (Vec3::zeros(), Vec3::x());
        let bad = Vec3::new(0.0, 0.0, f64::NAN);
        let e = Hermite::try_new(z, x, bad, z).unwrap_err();
        assert_eq!(e.to_string(), "d0[2]: must be finite (got NaN)");
        let e = Hermite::try_new(z, bad, bad, z).unwrap_err();
        assert_eq!(e.to_string(), "p1[2]: must be finite (got NaN)");
        let e = Hermite::try_new(z, x, z, bad).unwrap_err().at("curves.h");
        assert_eq!(e.place(), "curves.h.d1[2]");
        let h = Hermite::try_new(z, x, x, x).unwrap();
        assert_eq!(h.point(1.0), x);
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;

    /// One cubic: the bounds hold, the constant third derivative's is attained.
    #[test]
    fn bounds_hold_and_are_tight() {
        let h = Hermite::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(0.0, 2.0, 1.0),
            Vec3::new(1.0, -1.0, 0.0),
        );
        let r = check_bounds(&h, 5, 40, 1.0);
        eprintln!("hermite: {r:?}");
        assert!(r[3] <= 1.0 + 1e-6, "{r:?}");
        assert!(r[..3].iter().all(|&x| x <= 3.0), "{r:?}");
    }
}
