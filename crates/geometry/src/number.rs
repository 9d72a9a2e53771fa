//! Numbers for people: the one way reports (`pdeshape check`, `analyze`, `fit`, the colour
//! legends of `render` and `fit --picture`) print a value: a fixed number of significant
//! digits, plain decimals for moderate magnitudes, a short scientific form otherwise, and the
//! unit after the number when there is one. JSON keeps full precision and does not use this.

/// Significant digits of the numbers in reports.
pub const DIGITS: usize = 4;

/// `x` with `digits` significant digits (at least 1): plain decimals when `10⁻³ ≤ |x| < 10⁵`
/// (`10.61`, `0.005384`, `12340`), otherwise `1.061e-5`, `2.500e7`; zero as `0`, non-finite
/// values as `NaN`, `inf`, `-inf`. Trailing zeros are kept, so every value of a column shows the
/// same precision.
pub fn sig(x: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if x == 0.0 {
        return "0".to_string();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    // The exponent after rounding to `digits` (9.9996 → 1.000e1).
    let e = format!("{:.*e}", digits - 1, x);
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-3..5).contains(&exp) {
        let rounded: f64 = e.parse().unwrap_or(x);
        let decimals = (digits as i32 - 1 - exp).max(0) as usize;
        format!("{rounded:.decimals$}")
    } else {
        format!("{mantissa}e{exp}")
    }
}

/// [`sig`] with [`DIGITS`], followed by ` unit` when `unit` is not empty.
pub fn quantity(x: f64, unit: &str) -> String {
    if unit.is_empty() {
        sig(x, DIGITS)
    } else {
        format!("{} {unit}", sig(x, DIGITS))
    }
}

/// The unit of a quantity of dimension `length^power` in the length unit `length` (`mm`,
/// `in`): `mm`, `mm²`, `mm³`, `1/mm`, `1/mm²`; empty without a length unit or for power 0.
pub fn length_power(length: Option<&str>, power: i32) -> String {
    let Some(l) = length else {
        return String::new();
    };
    let sup = |p: i32| match p {
        1 => String::new(),
        2 => "²".to_string(),
        3 => "³".to_string(),
        4 => "⁴".to_string(),
        p => format!("^{p}"),
    };
    match power {
        0 => String::new(),
        p if p > 0 => format!("{l}{}", sup(p)),
        p => format!("1/{l}{}", sup(-p)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_have_four_significant_digits() {
        assert_eq!(sig(10.605407918, 4), "10.61");
        assert_eq!(sig(5.384, 4), "5.384");
        assert_eq!(sig(-5.014478, 4), "-5.014");
        assert_eq!(sig(0.0053841, 4), "0.005384");
        assert_eq!(sig(2.0, 4), "2.000");
        assert_eq!(sig(12345.6, 4), "12350");
        assert_eq!(sig(123456.0, 4), "1.235e5");
        assert_eq!(sig(1.06054e-5, 4), "1.061e-5");
        assert_eq!(sig(-3.2e-12, 2), "-3.2e-12");
        assert_eq!(sig(9.99996, 4), "10.00");
        assert_eq!(sig(0.00099996, 4), "0.001000");
        assert_eq!(sig(0.0, 4), "0");
        assert_eq!(sig(f64::NAN, 4), "NaN");
        assert_eq!(sig(f64::NEG_INFINITY, 4), "-inf");
        assert_eq!(sig(7.0, 0), "7");
    }

    #[test]
    fn units_follow_the_number() {
        assert_eq!(quantity(10.6054, "mm²"), "10.61 mm²");
        assert_eq!(quantity(10.6054, ""), "10.61");
        assert_eq!(length_power(Some("mm"), 2), "mm²");
        assert_eq!(length_power(Some("in"), 3), "in³");
        assert_eq!(length_power(Some("mm"), -1), "1/mm");
        assert_eq!(length_power(Some("cm"), -2), "1/cm²");
        assert_eq!(length_power(Some("mm"), 0), "");
        assert_eq!(length_power(None, 2), "");
    }
}
