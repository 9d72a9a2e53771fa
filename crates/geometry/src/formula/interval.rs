//! Interval arithmetic for the formula language: enclosures `[lo, hi]` of every function a
//! formula may use, rounded outwards, for bounding a formula (or its symbolic derivatives) over
//! a box of its variables ([`super::program::Program::eval_interval`]).
//!
//! # Enclosures
//!
//! Every operation returns an interval that contains `f(x)` for every `x` in its arguments'
//! intervals, and also the value the crate's `f64` evaluation computes for any `f64` point in
//! them (so an interval evaluated at a point contains both the exact value of the formula and
//! the one the program computes):
//!
//! - `+ − × ÷` and square roots are correctly rounded in IEEE arithmetic, so moving the computed
//!   ends one step outwards ([`down`], [`up`]) encloses the exact range.
//! - The library functions (`sin`, `exp`, `ln`, …) are not correctly rounded; glibc documents
//!   errors of at most a few units in the last place for them. Their computed ends move
//!   [`LIBM_ULPS`] steps outwards.
//! - Monotone functions (`exp`, `ln`, `atan`, `sqrt`, …) take their ends' values; `sin` and `cos`
//!   add ±1 where an extremum `π/2 + kπ` (`kπ`) may lie in the interval (decided with a margin,
//!   so a doubtful extremum is included); even powers and `cosh` take their minimum where the
//!   interval contains 0.
//!
//! # Smoothness
//!
//! The enclosures are meant for bounding derivatives, which exist only where the formula is
//! smooth. Every operation therefore refuses ([`Unbounded`]) an interval on which it is not
//! analytic in a neighbourhood: a division by an interval containing 0, `ln`/`log2`/`log10` and
//! `sqrt` of an interval reaching 0, `tan` over a pole, `asin`/`acos`/`atanh` reaching ±1,
//! `acosh` reaching 1, a non-integer power of a base reaching 0, `cbrt` of an interval
//! containing 0, `abs`/`signum` over 0, `floor`/`ceil`/`trunc`/`fract` over an integer,
//! `round` over a half-integer, `min`/`max` of overlapping intervals, `atan2` on a box touching
//! the origin or the cut along the negative `x` axis, and any end that is not finite. A formula
//! whose evaluation on a box succeeds is therefore analytic on that box, and the enclosures of
//! its symbolic derivatives bound its true derivatives there.

use super::trace::{Op1, Op2};
use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;

/// Steps of outward rounding for library functions (glibc's documented maxima for the
/// functions used here are at most 4 units in the last place on x86_64 and aarch64).
pub(crate) const LIBM_ULPS: u32 = 8;

/// The next `f64` above `x` (`x` itself for `+∞` and NaN).
pub(crate) fn up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// The next `f64` below `x`.
pub(crate) fn down(x: f64) -> f64 {
    -up(-x)
}

fn up_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = up(x);
    }
    x
}

fn down_n(mut x: f64, n: u32) -> f64 {
    for _ in 0..n {
        x = down(x);
    }
    x
}

/// Why a formula has no derivative bound on a box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unbounded {
    /// The function (`/`, `ln`, `tan`, …).
    pub op: &'static str,
    /// What goes wrong.
    pub why: &'static str,
}

impl fmt::Display for Unbounded {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.op, self.why)
    }
}

fn fail<T>(op: &'static str, why: &'static str) -> Result<T, Unbounded> {
    Err(Unbounded { op, why })
}

/// A closed interval `[lo, hi]` of finite numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Iv {
    pub lo: f64,
    pub hi: f64,
}

pub(crate) type IvResult = Result<Iv, Unbounded>;

impl Iv {
    /// `[lo, hi]`; both must be finite with `lo ≤ hi` (else [`Unbounded`]).
    pub(crate) fn new(lo: f64, hi: f64) -> IvResult {
        if lo.is_finite() && hi.is_finite() && lo <= hi {
            Ok(Iv { lo, hi })
        } else {
            fail("value", "is not finite")
        }
    }

    pub(crate) fn point(x: f64) -> IvResult {
        Iv::new(x, x)
    }

    /// The largest `|x|` in the interval.
    pub(crate) fn mag(&self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest `|x|` in the interval.
    fn mig(&self) -> f64 {
        if self.lo <= 0.0 && self.hi >= 0.0 {
            0.0
        } else {
            self.lo.abs().min(self.hi.abs())
        }
    }

    fn contains_zero(&self) -> bool {
        self.lo <= 0.0 && self.hi >= 0.0
    }

    /// Computed ends moved one step outwards (for correctly rounded operations).
    fn out1(lo: f64, hi: f64) -> IvResult {
        Iv::new(down(lo), up(hi))
    }

    /// Computed ends of a library function moved [`LIBM_ULPS`] steps outwards.
    fn outl(lo: f64, hi: f64) -> IvResult {
        Iv::new(down_n(lo, LIBM_ULPS), up_n(hi, LIBM_ULPS))
    }

    /// An increasing library function.
    fn increasing(self, f: fn(f64) -> f64) -> IvResult {
        Iv::outl(f(self.lo), f(self.hi))
    }

    /// The interval clamped to `[a, b]` (for functions whose range is known).
    fn within(self, a: f64, b: f64) -> Iv {
        Iv {
            lo: self.lo.max(a),
            hi: self.hi.min(b),
        }
    }
}

pub(crate) fn add(a: Iv, b: Iv) -> IvResult {
    Iv::out1(a.lo + b.lo, a.hi + b.hi)
}

pub(crate) fn sub(a: Iv, b: Iv) -> IvResult {
    Iv::out1(a.lo - b.hi, a.hi - b.lo)
}

pub(crate) fn neg(a: Iv) -> IvResult {
    Iv::new(-a.hi, -a.lo)
}

pub(crate) fn mul(a: Iv, b: Iv) -> IvResult {
    let p = [a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi];
    let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Iv::out1(lo, hi)
}

pub(crate) fn div(a: Iv, b: Iv) -> IvResult {
    if b.contains_zero() {
        return fail("/", "by an interval containing 0");
    }
    let p = [a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi];
    let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Iv::out1(lo, hi)
}

/// `x²` (not `x·x`: the two factors are the same number).
pub(crate) fn square(a: Iv) -> IvResult {
    let (m, n) = (a.mig(), a.mag());
    Iv::out1(m * m, n * n).map(|r| r.within(0.0, f64::INFINITY))
}

/// `xⁿ` for an integer `n` (`x⁰ = 1`, as `powf`); a negative `n` needs `0 ∉ x`.
pub(crate) fn powi(a: Iv, n: i64) -> IvResult {
    if n == 0 {
        return Iv::point(1.0);
    }
    if n < 0 {
        if a.contains_zero() {
            return fail("^", "with a negative exponent on a base containing 0");
        }
        return div(Iv::point(1.0)?, powi(a, -n)?);
    }
    // The power of a point by repeated squaring in interval arithmetic (an enclosure), applied
    // to the ends of the monotone pieces.
    let point = |x: f64| -> IvResult {
        let mut base = Iv::point(x)?;
        let mut acc = Iv::point(1.0)?;
        let mut k = n;
        while k > 0 {
            if k & 1 == 1 {
                acc = mul(acc, base)?;
            }
            k >>= 1;
            if k > 0 {
                base = mul(base, base)?;
            }
        }
        Ok(acc)
    };
    if n % 2 == 0 {
        let (lo, hi) = (point(a.mig())?, point(a.mag())?);
        Iv::new(lo.lo.max(0.0), hi.hi)
    } else {
        Iv::new(point(a.lo)?.lo, point(a.hi)?.hi)
    }
}

/// `a^b`: an integer point `b` as [`powi`]; otherwise `exp(b · ln a)`, which needs `a > 0`.
pub(crate) fn pow(a: Iv, b: Iv) -> IvResult {
    if b.lo == b.hi && b.lo.fract() == 0.0 && b.lo.abs() < 1e9 {
        // `powf` itself is a library function: its value may lie up to its error away from
        // the exact power.
        let r = powi(a, b.lo as i64)?;
        return Iv::outl(r.lo, r.hi);
    }
    if a.lo <= 0.0 {
        return fail("^", "with a non-integer exponent on a base reaching 0");
    }
    // exmex computes `powf`; its value lies in the enclosure of exp(b ln a) widened by the
    // rounding of `powf` itself.
    let e = exp(mul(b, ln(a)?)?)?;
    Iv::outl(e.lo, e.hi).map(|r| r.within(0.0, f64::INFINITY))
}

/// Whether some `c + kπ` may lie in `[lo, hi]` (a margin makes doubtful cases count), and
/// whether such a `k` may be even and odd: `[possible, even, odd]`.
fn hits(a: Iv, c: f64) -> [bool; 3] {
    let margin = 1e-12 * (1.0 + a.mag());
    let k0 = ((a.lo - margin - c) / PI).ceil();
    let k1 = ((a.hi + margin - c) / PI).floor();
    if k1 < k0 {
        return [false, false, false];
    }
    if k1 > k0 {
        return [true, true, true];
    }
    let even = k0.rem_euclid(2.0) == 0.0;
    [true, even, !even]
}

pub(crate) fn sin(a: Iv) -> IvResult {
    if a.hi - a.lo >= 2.0 * PI || a.mag() > 1e15 {
        return Iv::new(-1.0, 1.0);
    }
    let (x, y) = (a.lo.sin(), a.hi.sin());
    let mut r = Iv::outl(x.min(y), x.max(y))?;
    // sin(π/2 + kπ) = (−1)^k.
    let [any, even, odd] = hits(a, FRAC_PI_2);
    if any {
        if even {
            r.hi = 1.0;
        }
        if odd {
            r.lo = -1.0;
        }
    }
    Ok(r.within(-1.0, 1.0))
}

pub(crate) fn cos(a: Iv) -> IvResult {
    if a.hi - a.lo >= 2.0 * PI || a.mag() > 1e15 {
        return Iv::new(-1.0, 1.0);
    }
    let (x, y) = (a.lo.cos(), a.hi.cos());
    let mut r = Iv::outl(x.min(y), x.max(y))?;
    // cos(kπ) = (−1)^k.
    let [any, even, odd] = hits(a, 0.0);
    if any {
        if even {
            r.hi = 1.0;
        }
        if odd {
            r.lo = -1.0;
        }
    }
    Ok(r.within(-1.0, 1.0))
}

pub(crate) fn tan(a: Iv) -> IvResult {
    if a.hi - a.lo >= PI || a.mag() > 1e15 || hits(a, FRAC_PI_2)[0] {
        return fail("tan", "over a pole");
    }
    a.increasing(f64::tan)
}

pub(crate) fn exp(a: Iv) -> IvResult {
    a.increasing(f64::exp).map(|r| r.within(0.0, f64::INFINITY))
}

fn log_with(a: Iv, f: fn(f64) -> f64, op: &'static str) -> IvResult {
    if a.lo <= 0.0 {
        return fail(op, "of an interval reaching 0");
    }
    a.increasing(f)
}

pub(crate) fn ln(a: Iv) -> IvResult {
    log_with(a, f64::ln, "ln")
}

pub(crate) fn sqrt(a: Iv) -> IvResult {
    if a.lo <= 0.0 {
        return fail("sqrt", "of an interval reaching 0");
    }
    // Correctly rounded.
    Iv::out1(a.lo.sqrt(), a.hi.sqrt()).map(|r| r.within(0.0, f64::INFINITY))
}

pub(crate) fn cbrt(a: Iv) -> IvResult {
    if a.contains_zero() {
        return fail("cbrt", "of an interval containing 0");
    }
    a.increasing(f64::cbrt)
}

fn inside_unit(a: Iv, op: &'static str) -> Result<(), Unbounded> {
    if a.lo <= -1.0 || a.hi >= 1.0 {
        return fail(op, "of an interval reaching ±1");
    }
    Ok(())
}

pub(crate) fn asin(a: Iv) -> IvResult {
    inside_unit(a, "asin")?;
    a.increasing(f64::asin)
}

pub(crate) fn acos(a: Iv) -> IvResult {
    inside_unit(a, "acos")?;
    // Decreasing.
    Iv::outl(a.hi.acos(), a.lo.acos()).map(|r| r.within(0.0, PI + 1e-15))
}

pub(crate) fn atanh(a: Iv) -> IvResult {
    inside_unit(a, "atanh")?;
    a.increasing(f64::atanh)
}

pub(crate) fn acosh(a: Iv) -> IvResult {
    if a.lo <= 1.0 {
        return fail("acosh", "of an interval reaching 1");
    }
    a.increasing(f64::acosh)
}

pub(crate) fn cosh(a: Iv) -> IvResult {
    let (m, n) = (a.mig(), a.mag());
    Iv::outl(m.cosh(), n.cosh()).map(|r| r.within(1.0, f64::INFINITY))
}

pub(crate) fn abs(a: Iv) -> IvResult {
    if a.lo <= 0.0 && a.hi >= 0.0 {
        return fail("abs", "over 0");
    }
    Iv::new(a.mig(), a.mag())
}

pub(crate) fn signum(a: Iv) -> IvResult {
    if a.lo <= 0.0 && a.hi >= 0.0 {
        return fail("signum", "over 0");
    }
    Iv::point(a.lo.signum())
}

/// A piecewise constant function (`floor`, …) on an interval free of its jumps at
/// `offset + k`: its value at the interval's start.
fn step_fn(a: Iv, f: fn(f64) -> f64, offset: f64, op: &'static str) -> IvResult {
    // Jumps where x − offset is an integer: refused if the interval reaches one.
    let (p, q) = ((a.lo - offset).floor(), (a.hi - offset).floor());
    if p != q || (a.lo - offset).fract() == 0.0 || a.mag() > 1e15 {
        return fail(op, "over a jump");
    }
    Iv::point(f(a.lo))
}

pub(crate) fn atan2(y: Iv, x: Iv) -> IvResult {
    if x.lo <= 0.0 && y.contains_zero() {
        return fail(
            "atan2",
            "on a box touching the origin or the cut y = 0, x ≤ 0",
        );
    }
    // The angle of a convex set off the cut ranges between its extreme points' angles: the
    // corners.
    let c = [
        y.lo.atan2(x.lo),
        y.lo.atan2(x.hi),
        y.hi.atan2(x.lo),
        y.hi.atan2(x.hi),
    ];
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Iv::outl(lo, hi).map(|r| r.within(-PI - 1e-15, PI + 1e-15))
}

pub(crate) fn min(a: Iv, b: Iv) -> IvResult {
    if a.hi < b.lo {
        Ok(a)
    } else if b.hi < a.lo {
        Ok(b)
    } else {
        fail("min", "of overlapping intervals")
    }
}

pub(crate) fn max(a: Iv, b: Iv) -> IvResult {
    if a.hi < b.lo {
        Ok(b)
    } else if b.hi < a.lo {
        Ok(a)
    } else {
        fail("max", "of overlapping intervals")
    }
}

/// A function of one argument of the formula language.
pub(crate) fn apply1(op: Op1, a: Iv) -> IvResult {
    match op {
        Op1::Neg => neg(a),
        Op1::Abs => abs(a),
        Op1::Signum => signum(a),
        Op1::Sin => sin(a),
        Op1::Cos => cos(a),
        Op1::Tan => tan(a),
        Op1::Asin => asin(a),
        Op1::Acos => acos(a),
        Op1::Atan => a
            .increasing(f64::atan)
            .map(|r| r.within(-FRAC_PI_2 - 1e-15, FRAC_PI_2 + 1e-15)),
        Op1::Sinh => a.increasing(f64::sinh),
        Op1::Cosh => cosh(a),
        Op1::Tanh => a.increasing(f64::tanh).map(|r| r.within(-1.0, 1.0)),
        Op1::Asinh => a.increasing(f64::asinh),
        Op1::Acosh => acosh(a),
        Op1::Atanh => atanh(a),
        Op1::Floor => step_fn(a, f64::floor, 0.0, "floor"),
        Op1::Round => step_fn(a, f64::round, 0.5, "round"),
        Op1::Ceil => step_fn(a, f64::ceil, 0.0, "ceil"),
        Op1::Trunc => step_fn(a, f64::trunc, 0.0, "trunc"),
        Op1::Fract => {
            // x − trunc(x): linear between integers.
            let t = apply1(Op1::Trunc, a)?;
            sub(a, t)
        }
        Op1::Exp => exp(a),
        Op1::Sqrt => sqrt(a),
        Op1::Cbrt => cbrt(a),
        Op1::Ln => ln(a),
        Op1::Log2 => log_with(a, f64::log2, "log2"),
        Op1::Log10 => log_with(a, f64::log10, "log10"),
    }
}

/// A function of two arguments of the formula language.
pub(crate) fn apply2(op: Op2, a: Iv, b: Iv) -> IvResult {
    match op {
        Op2::Add => add(a, b),
        Op2::Sub => sub(a, b),
        Op2::Mul => mul(a, b),
        Op2::Div => div(a, b),
        Op2::Pow => pow(a, b),
        Op2::Atan2 => atan2(a, b),
        Op2::Min => min(a, b),
        Op2::Max => max(a, b),
    }
}

#[cfg(test)]
mod tests;
