//! The formula language of the crate, over the `exmex` parser: curve formulas
//! ([`crate::curve::Formula`], evaluated on Taylor series), parametric surfaces
//! ([`crate::surface::ParametricSurface`], differentiated symbolically), the fields of a dynamic
//! curve ([`crate::dynamic`]) and the objective and constraints of a search ([`crate::optimize`])
//! all read their text here. Each keeps its own number type and operators; this module holds
//! what they share: the number literals, the names of the constants (`pi` → `π`, `e` → `E`), the
//! refusal of an ambiguous unary minus (`-v^2`), the variables a formula may use and their
//! numbering, and the messages of all of these.
//!
//! Syntax: numbers (`2`, `0.5`, `.5`, `2.`, `1e-3`, `2.5E+4`), variables, parentheses, the
//! operators `+ - * / ^` (with exmex's precedence: `^` before `/` before `*` before `-` before `+`,
//! left to right) and unary minus, functions, and the constants `pi`, `PI`, `π`, `TAU`, `τ`, `E`,
//! `e`.
//!
//! Evaluation over arrays: [`program::Program`] compiles a formula once (its tree read off exmex
//! by [`trace`]) and evaluates it over whole arrays of points; the `f64` callers (dynamic
//! curves, parametric surfaces) use it, the Taylor-series curve formulas keep exmex.
//! [`interval`] evaluates a compiled program over boxes (outward-rounded enclosures), for the
//! certified bounds of formula surfaces.

pub mod interval;
pub(crate) mod program;
pub(crate) mod trace;

use crate::{Error, Result};
use exmex::{DataType, Express, FlatEx, MakeOperators};
use std::fmt::Debug;
use std::str::FromStr;

/// A parsed expression in the number type `T` with the operators `OF` and the crate's
/// [`NumberLiteral`]s.
pub(crate) type Expr<T, OF> = FlatEx<T, OF, NumberLiteral>;

/// Number literals: `12`, `1.5`, `.5`, `2.`, with an optional exponent `e-3`/`E+4`.
#[derive(Clone, Debug)]
pub struct NumberLiteral;

impl exmex::MatchLiteral for NumberLiteral {
    fn is_literal(text: &str) -> Option<&str> {
        let b = text.as_bytes();
        let digits = |mut i: usize| {
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
            i
        };
        let int_end = digits(0);
        let mut end = int_end;
        if end < b.len() && b[end] == b'.' {
            end = digits(end + 1);
        }
        // At least one digit.
        if int_end == 0 && end <= 1 {
            return None;
        }
        if end < b.len() && (b[end] == b'e' || b[end] == b'E') {
            let mut j = end + 1;
            if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                j += 1;
            }
            let k = digits(j);
            if k > j {
                end = k;
            }
        }
        Some(&text[..end])
    }
}

/// Replaces the identifiers `pi` by `π` and `e` by `E`, exmex's names of the constants.
pub(crate) fn normalise(text: &str) -> String {
    rename_identifiers(text, |word| match word {
        "pi" => Some("π"),
        "e" => Some("E"),
        _ => None,
    })
}

/// `text` with every identifier for which `rename` gives a new name replaced by it. An
/// identifier starts with a letter or `_` that does not follow a digit or a `.` (so the exponent
/// of `1e-3` stays as it is) and goes on with letters, digits and `_`.
pub fn rename_identifiers<'a>(text: &str, rename: impl Fn(&str) -> Option<&'a str>) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let after_digit = i > 0 && (chars[i - 1].is_ascii_digit() || chars[i - 1] == '.');
        if (c.is_alphabetic() || c == '_') && !after_digit {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect();
            out.push_str(rename(&word).unwrap_or(&word));
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// Finds a unary minus whose operand is raised to a power (`-v^2`, `2*-v^2`): exmex binds that
/// minus first (`(-v)^2`), against the usual convention, so such input is refused as ambiguous.
/// Returns the byte offset of the minus.
pub(crate) fn unary_minus_before_power(text: &str) -> Option<usize> {
    let b: Vec<(usize, char)> = text.char_indices().collect();
    let skip_ws = |mut i: usize| {
        while i < b.len() && b[i].1.is_whitespace() {
            i += 1;
        }
        i
    };
    let group_end = |mut i: usize| {
        // b[i] is '('; returns the index after the matching ')'.
        let mut depth = 0usize;
        while i < b.len() {
            match b[i].1 {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return i + 1;
                    }
                }
                _ => {}
            }
            i += 1;
        }
        i
    };
    let mut prev: Option<char> = None;
    for i in 0..b.len() {
        let c = b[i].1;
        if c.is_whitespace() {
            continue;
        }
        let unary =
            c == '-' && matches!(prev, None | Some('(' | ',' | '+' | '-' | '*' | '/' | '^'));
        prev = Some(c);
        if !unary {
            continue;
        }
        let mut j = skip_ws(i + 1);
        if j >= b.len() {
            return None;
        }
        let d = b[j].1;
        if d.is_ascii_digit() || d == '.' {
            while j < b.len() && (b[j].1.is_ascii_digit() || b[j].1 == '.') {
                j += 1;
            }
            if j < b.len() && (b[j].1 == 'e' || b[j].1 == 'E') {
                let mut k = j + 1;
                if k < b.len() && (b[k].1 == '+' || b[k].1 == '-') {
                    k += 1;
                }
                if k < b.len() && b[k].1.is_ascii_digit() {
                    j = k;
                    while j < b.len() && b[j].1.is_ascii_digit() {
                        j += 1;
                    }
                }
            }
        } else if d.is_alphabetic() || d == '_' {
            while j < b.len() && (b[j].1.is_alphanumeric() || b[j].1 == '_') {
                j += 1;
            }
            let k = skip_ws(j);
            if k < b.len() && b[k].1 == '(' {
                j = group_end(k);
            }
        } else if d == '(' {
            j = group_end(j);
        } else {
            continue;
        }
        let k = skip_ws(j);
        if k < b.len() && b[k].1 == '^' {
            return Some(b[i].0);
        }
    }
    None
}

/// A value in a formula's message: six significant digits, trailing zeros trimmed.
pub fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (5 - v.abs().log10().floor() as i32).clamp(0, 17) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The variables a kind of formula may use, in order (a formula's variables are numbered by
/// their position here), and how an unknown one is reported.
#[derive(Clone, Copy, Debug)]
pub struct Variables<'a> {
    names: &'a [&'a str],
    /// Every formula of the kind uses the same variables (curves: `v`; surfaces: `u`, `v`), so
    /// the message says what formulas use; otherwise it quotes the formula and says what this
    /// one may use.
    every: bool,
}

impl<'a> Variables<'a> {
    /// The variables of every formula of a kind: `unknown variable 'w'; formulas use u and v`.
    pub(crate) const fn every(names: &'a [&'a str]) -> Self {
        Variables { names, every: true }
    }

    /// The variables of a formula in one role: `'x*y': unknown variable 'y'; this formula may
    /// use u, t, x`.
    pub const fn this(names: &'a [&'a str]) -> Self {
        Variables {
            names,
            every: false,
        }
    }

    fn unknown(&self, text: &str, name: &str) -> Error {
        Error::invalid(if self.every {
            let list = match self.names.split_last() {
                Some((last, rest)) if !rest.is_empty() => {
                    format!("{} and {last}", rest.join(", "))
                }
                _ => self.names.join(""),
            };
            format!("unknown variable '{name}'; formulas use {list}")
        } else {
            format!(
                "'{text}': unknown variable '{name}'; this formula may use {}",
                self.names.join(", ")
            )
        })
    }
}

/// A formula as parsed: the expression and, for each of its variables (in exmex's order, sorted
/// by name), the position of that variable in the [`Variables`] it was parsed against.
#[derive(Clone, Debug)]
pub struct Parsed<T: DataType, OF: MakeOperators<T>>
where
    <T as FromStr>::Err: Debug,
{
    /// The expression, in exmex's form.
    pub expr: Expr<T, OF>,
    /// For each of the expression's variables, its position in the [`Variables`].
    pub slots: Vec<usize>,
}

/// Parses `text` as given by the user (the messages quote it): refuses an empty formula, an
/// ambiguous unary minus (`-v^2`), text exmex cannot parse, and variables not in `vars`. The
/// errors have no place; the caller adds it.
pub fn parse<T, OF>(text: &str, vars: &Variables) -> Result<Parsed<T, OF>>
where
    T: DataType,
    OF: MakeOperators<T>,
    <T as FromStr>::Err: Debug,
{
    let norm = normalise(text);
    if norm.trim().is_empty() {
        return Err(Error::invalid("the formula is empty"));
    }
    if let Some(at) = unary_minus_before_power(&norm) {
        return Err(Error::invalid(format!(
            "'{text}': the minus at character {} is applied before the power; write -(…^…) or \
             (-…)^… explicitly",
            at + 1
        )));
    }
    let expr = Expr::<T, OF>::parse(&norm)
        .map_err(|e| Error::invalid(format!("cannot parse '{text}': {e}")))?;
    let slots = expr
        .var_names()
        .iter()
        .map(|name| {
            vars.names
                .iter()
                .position(|a| a == name)
                .ok_or_else(|| vars.unknown(text, name))
        })
        .collect::<Result<Vec<usize>>>()?;
    Ok(Parsed { expr, slots })
}

impl<T, OF> Parsed<T, OF>
where
    T: DataType,
    OF: MakeOperators<T>,
    <T as FromStr>::Err: Debug,
{
    /// The value with `values[i]` for the `i`-th of the [`Variables`] (those the formula does
    /// not use are ignored).
    pub fn eval(&self, values: &[T]) -> exmex::ExResult<T> {
        let mut buf: [T; 8] = Default::default();
        if self.slots.len() <= buf.len() {
            for (b, &s) in buf.iter_mut().zip(&self.slots) {
                *b = values[s].clone();
            }
            self.expr.eval(&buf[..self.slots.len()])
        } else {
            let args: Vec<T> = self.slots.iter().map(|&s| values[s].clone()).collect();
            self.expr.eval(&args)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use exmex::{FloatOpsFactory, MatchLiteral};

    type F = Parsed<f64, FloatOpsFactory<f64>>;

    #[test]
    fn literals() {
        assert_eq!(NumberLiteral::is_literal("12+v"), Some("12"));
        assert_eq!(NumberLiteral::is_literal("1.5e-3*v"), Some("1.5e-3"));
        assert_eq!(NumberLiteral::is_literal(".5"), Some(".5"));
        assert_eq!(NumberLiteral::is_literal("2.E4"), Some("2.E4"));
        assert_eq!(NumberLiteral::is_literal("2e"), Some("2"));
        assert_eq!(NumberLiteral::is_literal("2*e"), Some("2"));
        assert_eq!(NumberLiteral::is_literal("."), None);
        assert_eq!(NumberLiteral::is_literal("e"), None);
    }

    #[test]
    fn constants_are_renamed_outside_numbers() {
        assert_eq!(normalise("pi*spin + pi2 - 2*pi"), "π*spin + pi2 - 2*π");
        assert_eq!(
            normalise("e + 1e-3 + 2.e5 + exp(e)"),
            "E + 1e-3 + 2.e5 + exp(E)"
        );
    }

    #[test]
    fn an_ambiguous_minus_is_found() {
        for ok in [
            "0 - v^2",
            "-(v^2)",
            "(-v)^2",
            "2^-1",
            "-sin(v)",
            "1 - 2e-3^2",
            "v*-2",
        ] {
            assert_eq!(unary_minus_before_power(ok), None, "{ok}");
        }
        for amb in [
            "-v^2",
            "2*-v^2",
            "(-sin(v)^2)",
            "2^-v^2",
            "- 3 ^ 2",
            "-(v)^2",
            "-1e-3^2",
        ] {
            assert!(unary_minus_before_power(amb).is_some(), "{amb}");
        }
    }

    #[test]
    fn variables_are_numbered_by_the_allowed_list_and_messages_quote_the_text() {
        let uvt = Variables::this(&["u", "t", "x"]);
        let f: F = parse("x*u + t^2 + pi - e", &uvt).unwrap();
        // exmex sorts its variables by name: t, u, x.
        assert_eq!(f.slots, vec![1, 0, 2]);
        let want = 3.0 * 2.0 + 5.0f64.powi(2) + std::f64::consts::PI - std::f64::consts::E;
        assert!((f.eval(&[2.0, 5.0, 3.0]).unwrap() - want).abs() < 1e-13);
        let e = parse::<f64, FloatOpsFactory<f64>>("x*y", &uvt).unwrap_err();
        assert_eq!(
            e.to_string(),
            "'x*y': unknown variable 'y'; this formula may use u, t, x"
        );
        let uv = Variables::every(&["u", "v"]);
        let e = parse::<f64, FloatOpsFactory<f64>>("w*u", &uv).unwrap_err();
        assert_eq!(e.to_string(), "unknown variable 'w'; formulas use u and v");
        let v = Variables::every(&["v"]);
        let e = parse::<f64, FloatOpsFactory<f64>>("w", &v).unwrap_err();
        assert_eq!(e.to_string(), "unknown variable 'w'; formulas use v");
        let e = parse::<f64, FloatOpsFactory<f64>>(" ", &v).unwrap_err();
        assert_eq!(e.to_string(), "the formula is empty");
        let e = parse::<f64, FloatOpsFactory<f64>>("2*-v^2", &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "'2*-v^2': the minus at character 3 is applied before the power; write -(…^…) or \
             (-…)^… explicitly"
        );
        let e = parse::<f64, FloatOpsFactory<f64>>("cos(v", &v).unwrap_err();
        assert!(e.to_string().starts_with("cannot parse 'cos(v': "), "{e}");
        // Scientific notation everywhere.
        let f: F = parse("1.5e-1*v + 2E+1", &v).unwrap();
        assert!((f.eval(&[2.0]).unwrap() - 20.3).abs() < 1e-14);
    }

    #[test]
    fn short_keeps_six_significant_digits() {
        assert_eq!(short(std::f64::consts::TAU), "6.28319");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(1234.5678), "1234.57");
        assert_eq!(short(0.000123456789), "0.000123457");
        assert_eq!(short(f64::INFINITY), "inf");
    }
}
