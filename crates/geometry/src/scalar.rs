//! The one number abstraction of the exact-or-rounded code: `f64`, and exact rationals
//! ([`BigRational`]) so that fractions (dual bases, B-spline PDE solutions) can be reproduced
//! exactly. The multivariate Bézier patches and dual bases ([`crate::spline`]), the B-spline
//! basis and knot checks ([`crate::spline::bspline_basis`]) and the constraint engine of
//! [`crate::splinepde`] all compute in a `T: Scalar`.

use num_rational::BigRational;
use num_traits::{FromPrimitive, Num, Signed, ToPrimitive};
use std::fmt::Debug;
use std::ops::Neg;

/// An ordered field the generic code computes in: `+ − × ÷`, `0` and `1` (from [`Num`]),
/// comparisons, integers, and a float view.
pub trait Scalar:
    Clone + PartialEq + PartialOrd + Debug + Num + Neg<Output = Self> + Send + Sync + 'static
{
    /// True for exact arithmetic (no rounding).
    const EXACT: bool;
    /// The integer `n`, exactly (for `f64`: exact up to 2⁵³).
    fn int(n: i64) -> Self;
    /// `num / den`.
    fn ratio(num: i64, den: i64) -> Self {
        Self::int(num) / Self::int(den)
    }
    /// The exact value of a finite `f64` (every finite float is a dyadic rational); `None` for
    /// NaN and ±∞.
    fn from_f64(x: f64) -> Option<Self>;
    /// The nearest `f64` (correctly rounded for rationals, however large their numerator and
    /// denominator).
    fn to_f64(&self) -> f64;
    /// False for NaN and ±∞ (rationals are always finite).
    fn is_finite(&self) -> bool;
    /// A short text form for messages and exact output: the shortest decimal that reads back as
    /// the same `f64` (`0.25`, `3`), `p/q` for rationals (`-1/3`, `7`).
    fn to_text(&self) -> String;
}

impl Scalar for f64 {
    const EXACT: bool = false;
    fn int(n: i64) -> Self {
        n as f64
    }
    fn from_f64(x: f64) -> Option<Self> {
        x.is_finite().then_some(x)
    }
    fn to_f64(&self) -> f64 {
        *self
    }
    fn is_finite(&self) -> bool {
        f64::is_finite(*self)
    }
    fn to_text(&self) -> String {
        format!("{self}")
    }
}

impl Scalar for BigRational {
    const EXACT: bool = true;
    fn int(n: i64) -> Self {
        <BigRational as FromPrimitive>::from_i64(n).expect("every i64 is a rational")
    }
    fn from_f64(x: f64) -> Option<Self> {
        BigRational::from_float(x)
    }
    fn to_f64(&self) -> f64 {
        ToPrimitive::to_f64(self).unwrap_or(f64::NAN)
    }
    fn is_finite(&self) -> bool {
        true
    }
    fn to_text(&self) -> String {
        if self.is_integer() {
            self.numer().to_string()
        } else if self.is_negative() {
            format!("-{}/{}", self.numer().abs(), self.denom())
        } else {
            format!("{}/{}", self.numer(), self.denom())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rationals_convert_and_print_exactly() {
        let third = BigRational::ratio(-1, 3);
        assert_eq!(third.to_text(), "-1/3");
        assert_eq!(BigRational::int(7).to_text(), "7");
        assert_eq!(0.25f64.to_text(), "0.25");
        assert_eq!(3.0f64.to_text(), "3");
        assert_eq!(
            <BigRational as Scalar>::from_f64(0.375),
            Some(BigRational::ratio(3, 8))
        );
        assert_eq!(<BigRational as Scalar>::from_f64(f64::NAN), None);
        assert_eq!(<f64 as Scalar>::from_f64(f64::INFINITY), None);
        assert!(!Scalar::is_finite(&f64::NAN));
        // Numerator and denominator far beyond the f64 range: still the nearest float.
        let big = BigRational::new(
            num_bigint::BigInt::from(10).pow(400) * 2,
            num_bigint::BigInt::from(10).pow(400) * 3,
        );
        assert_eq!(Scalar::to_f64(&big), 2.0 / 3.0);
        assert_eq!(Scalar::to_f64(&third), -1.0 / 3.0);
    }
}
