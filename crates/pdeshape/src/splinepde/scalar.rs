//! The two number types of the engine: `f64` and exact rationals (`BigRational`).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A field the constraint engine computes in: `f64` (rounded) or [`BigRational`] (exact).
pub trait Scalar:
    Clone
    + Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    fn zero() -> Self;
    /// 1.
    fn one() -> Self;
    /// An integer.
    fn from_i64(i: i64) -> Self;
    /// The exact value of a finite `f64` (`None` for NaN or ±∞).
    fn from_f64(x: f64) -> Option<Self>;
    /// The nearest `f64`.
    fn to_f64(&self) -> f64;
    /// True for exactly zero.
    fn is_zero(&self) -> bool;
    /// True for the exact (rational) type.
    fn is_exact() -> bool;
    /// A short text form: shortest round-trip decimal for `f64`, `p/q` for rationals.
    fn to_text(&self) -> String;
}

impl Scalar for f64 {
    fn zero() -> Self {
        0.0
    }
    fn one() -> Self {
        1.0
    }
    fn from_i64(i: i64) -> Self {
        i as f64
    }
    fn from_f64(x: f64) -> Option<Self> {
        x.is_finite().then_some(x)
    }
    fn to_f64(&self) -> f64 {
        *self
    }
    fn is_zero(&self) -> bool {
        *self == 0.0
    }
    fn is_exact() -> bool {
        false
    }
    fn to_text(&self) -> String {
        format!("{self:?}")
    }
}

impl Scalar for BigRational {
    fn zero() -> Self {
        Zero::zero()
    }
    fn one() -> Self {
        One::one()
    }
    fn from_i64(i: i64) -> Self {
        BigRational::from_integer(BigInt::from(i))
    }
    fn from_f64(x: f64) -> Option<Self> {
        BigRational::from_float(x)
    }
    fn to_f64(&self) -> f64 {
        // Numerator and denominator may both overflow f64; scale them down together.
        if let (Some(n), Some(d)) = (self.numer().to_f64(), self.denom().to_f64()) {
            if n.is_finite() && d.is_finite() {
                return n / d;
            }
        }
        let shift = self
            .numer()
            .bits()
            .max(self.denom().bits())
            .saturating_sub(1000);
        let n = (self.numer() >> shift).to_f64().unwrap_or(f64::NAN);
        let d = (self.denom() >> shift).to_f64().unwrap_or(f64::NAN);
        n / d
    }
    fn is_zero(&self) -> bool {
        Zero::is_zero(self)
    }
    fn is_exact() -> bool {
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
