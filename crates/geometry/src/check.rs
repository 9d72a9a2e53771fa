//! Checks of single input values in the wording of the design file: the message says what is
//! wrong, the place says where, relative to the table being read (`radius: must be positive (got
//! -1)`, `control[2][1]: must be finite (got NaN)`). A caller that knows where the table sits
//! prefixes it with [`crate::Error::at`].

use crate::{Error, Result, Vec3};

/// A number for a message: plain for moderate magnitudes, scientific otherwise (`1e308`, not 309
/// digits).
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `text` with every long decimal number in short scientific form: a number with more than 15
/// digits before its point (`100000…0.0000`, as `{}` or `{:.4}` print 1e308) or a zero with more
/// than 6 zeros after its point (`0.0000…1`), as [`num`] prints it. Other text, and numbers
/// already short, are unchanged. Every message of [`Error`] goes through it.
pub fn short_numbers(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut copied = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit()
            && (i == 0
                || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_' || b[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        let int_digits = j - i;
        let mut end = j;
        let mut zeros = 0;
        if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
            end = j + 1;
            while end < b.len() && b[end] == b'0' {
                end += 1;
                zeros += 1;
            }
            while end < b.len() && b[end].is_ascii_digit() {
                end += 1;
            }
        }
        let ends = end == b.len() || !(b[end].is_ascii_alphanumeric() || b[end] == b'_');
        let long = int_digits > 15 || (&text[i..j] == "0" && zeros > 6 && end > j + 1 + zeros);
        match text[i..end].parse::<f64>() {
            Ok(x) if long && ends => {
                out.push_str(&text[copied..i]);
                out.push_str(&format!("{x:e}"));
                copied = end;
            }
            _ => {}
        }
        i = end.max(i + 1);
    }
    out.push_str(&text[copied..]);
    out
}

/// `x` is finite.
pub fn finite(x: f64, place: &str) -> Result<()> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(format!("must be finite (got {x})")).at(place))
    }
}

/// Every coordinate of `v` is finite (places `place[0]` to `place[2]`).
pub fn finite3(v: &Vec3, place: &str) -> Result<()> {
    // The place is formatted only for the error (this check runs on every Fourier series built).
    for (i, x) in v.iter().enumerate().filter(|(_, x)| !x.is_finite()) {
        finite(*x, &format!("{place}[{i}]"))?;
    }
    Ok(())
}

/// Every coordinate of every point is finite (places `place[i][c]`).
pub(crate) fn finite_points(points: &[Vec3], place: &str) -> Result<()> {
    for (i, p) in points.iter().enumerate() {
        if !p.iter().all(|x| x.is_finite()) {
            finite3(p, &format!("{place}[{i}]"))?;
        }
    }
    Ok(())
}

/// `x` is finite and positive.
pub fn positive(x: f64, place: &str) -> Result<()> {
    finite(x, place)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!("must be positive (got {})", num(x))).at(place))
    }
}

/// `v` is finite and not zero (however small its coordinates).
pub fn nonzero_vector(v: &Vec3, place: &str) -> Result<()> {
    finite3(v, place)?;
    if v.amax() > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid("must not be the zero vector").at(place))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_in_messages_are_short() {
        let huge = format!("{:.4}", 1e308);
        assert!(huge.len() > 300);
        assert_eq!(
            short_numbers(&format!(
                "its u runs from -{huge} to {}, outside 0 < u < 1",
                1e30
            )),
            "its u runs from -1e308 to 1e30, outside 0 < u < 1"
        );
        assert_eq!(short_numbers(&format!("got {}", 1e-300)), "got 1e-300");
        // Short numbers, names with digits and version-like text are left as they are.
        for text in [
            "mode 12 of 0.0001 at u = 0.25, 1e308, 3.0e5",
            "curve c12345678901234567890x",
            "v = 0.04908738521234052",
            "x_12345678901234567890",
        ] {
            assert_eq!(short_numbers(text), text);
        }
        let e = Error::invalid(format!("radius {}", 1e200)).at("curves.rim");
        assert_eq!(e.to_string(), "curves.rim: radius 1e200");
    }

    #[test]
    fn messages_and_places() {
        assert_eq!(num(0.25), "0.25");
        assert_eq!(num(-3.0), "-3");
        assert_eq!(num(1e-7), "1e-7");
        assert_eq!(num(1e300), "1e300");
        let e = |r: Result<()>| r.unwrap_err().to_string();
        assert_eq!(e(finite(f64::NAN, "t")), "t: must be finite (got NaN)");
        assert_eq!(
            e(finite3(&Vec3::new(0.0, f64::INFINITY, 0.0), "at")),
            "at[1]: must be finite (got inf)"
        );
        let pts = [Vec3::zeros(), Vec3::new(1.0, 2.0, f64::NEG_INFINITY)];
        assert_eq!(
            e(finite_points(&pts, "points")),
            "points[1][2]: must be finite (got -inf)"
        );
        assert_eq!(
            e(positive(-1e-9, "radius")),
            "radius: must be positive (got -1e-9)"
        );
        assert_eq!(e(positive(0.0, "rx")), "rx: must be positive (got 0)");
        assert_eq!(e(positive(f64::NAN, "ry")), "ry: must be finite (got NaN)");
        assert_eq!(
            e(nonzero_vector(&Vec3::zeros(), "normal")),
            "normal: must not be the zero vector"
        );
        assert!(nonzero_vector(&Vec3::new(0.0, 0.0, 1e-300), "normal").is_ok());
    }
}
