//! Coefficients, forces, end conditions and initial data of a dynamic curve given as formula
//! strings, e.g. `d = "x"`, `f = "(1 + exp(-t))^2 * (sin(pi*u)^2 - cos(pi*u)^2)"`.
//!
//! The syntax is that of the curve formulas ([`crate::curve::Formula`]), parsed by `exmex` and
//! evaluated in `f64`: numbers, `+ - * / ^`, unary minus, parentheses, the functions `sin cos tan
//! asin acos atan sinh cosh tanh exp ln log2 log10 sqrt cbrt abs …`, and the constants `pi`/`π`,
//! `TAU`/`τ`, `E`/`e`. A unary minus directly in front of a power (`-u^2`) is refused as
//! ambiguous, as for curves. The variables allowed depend on the role: `u, t, x` for the fields
//! `a, b, d, f`; `t` for the end conditions; `u` for the initial position and velocity; `u, t` for
//! an exact solution.

use super::{Field, FieldFn, Scalar};
use crate::formula::program::{Input, Program};
use crate::formula::{self, Parsed, Variables};
use crate::{Error, Result};
use exmex::FloatOpsFactory;
use std::sync::Arc;

/// A parsed formula in a fixed list of allowed variables.
#[derive(Clone, Debug)]
pub struct Expression {
    /// The formula as given.
    pub text: String,
    parsed: Parsed<f64, FloatOpsFactory<f64>>,
    /// The value, if the formula uses no variable.
    constant: Option<f64>,
    /// The formula compiled for arrays of points, the variable `t` (if allowed) uniform.
    program: Program,
}

impl Expression {
    /// Parses `text`, which may use the variables `allowed` (e.g. `["u", "t", "x"]`). Errors name
    /// the text and, for an unknown variable, the variables allowed.
    pub fn parse(text: &str, allowed: &[&str]) -> Result<Self> {
        let vars = Variables::this(allowed);
        let parsed: Parsed<f64, FloatOpsFactory<f64>> = formula::parse(text, &vars)?;
        let uniform: Vec<usize> = allowed.iter().position(|&a| a == "t").into_iter().collect();
        let program = Program::compile(text, &vars, &uniform)?;
        let constant = if parsed.slots.is_empty() {
            let v = parsed
                .eval(&[])
                .map_err(|e| Error::invalid(format!("cannot evaluate '{text}': {e}")))?;
            if !v.is_finite() {
                return Err(Error::invalid(format!("'{text}' evaluates to {v}")));
            }
            Some(v)
        } else {
            None
        };
        Ok(Expression {
            text: text.to_string(),
            parsed,
            constant,
            program,
        })
    }

    /// The value at `values` (one per allowed variable, in the order given to
    /// [`Expression::parse`]); NaN where the formula is undefined.
    pub fn eval(&self, values: &[f64]) -> f64 {
        if let Some(c) = self.constant {
            return c;
        }
        self.program.eval_one(values)
    }

    /// The constant value, if the formula uses no variable.
    pub fn constant(&self) -> Option<f64> {
        self.constant
    }

    /// Whether the formula uses the allowed variable with index `slot`.
    pub fn uses(&self, slot: usize) -> bool {
        self.parsed.slots.contains(&slot)
    }
}

/// A field `φ(u, t, x)` from a formula in `u, t, x`, evaluated a whole level at a time by its
/// compiled program (the parameters `u` as a ramp, `t` once per level, `x` per node).
pub fn field_formula(text: &str) -> Result<Field> {
    let e = Expression::parse(text, &["u", "t", "x"])?;
    Ok(match e.constant() {
        Some(c) => super::constant_field(c),
        None => Field(Arc::new(Compiled(e.program))),
    })
}

/// A field given by a compiled formula in `u, t, x`.
struct Compiled(Program);

impl FieldFn for Compiled {
    fn at(&self, u: f64, t: f64, x: f64) -> f64 {
        self.0.eval_one(&[u, t, x])
    }

    fn fill(&self, offset: f64, h: f64, t: f64, x: &[f64], out: &mut [f64]) {
        let u = Input::Ramp { offset, step: h };
        self.0.eval(&[u, Input::Scalar(t), Input::Slice(x)], out);
    }
}

/// A function of one variable `var` (`"t"` for end conditions, `"u"` for initial data).
pub fn scalar_formula(text: &str, var: &str) -> Result<Scalar> {
    let e = Expression::parse(text, &[var])?;
    Ok(match e.constant() {
        Some(c) => super::constant(c),
        None => Arc::new(move |s| e.eval(&[s])),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn fields_evaluate_in_u_t_x() {
        let f = field_formula("(1 + exp(-t))^2 * (sin(pi*u)^2 - cos(pi*u)^2) + x/2").unwrap();
        for &(u, t, x) in &[
            (0.1f64, 0.0f64, 1.0f64),
            (0.37, 2.5, -3.0),
            (0.9, 15.0, 0.25),
        ] {
            let want = (1.0 + (-t).exp()).powi(2)
                * ((PI * u).sin().powi(2) - (PI * u).cos().powi(2))
                + x / 2.0;
            let got = f.at(u, t, x);
            assert!(
                (got - want).abs() <= 1e-14 * (1.0 + want.abs()),
                "{got} {want}"
            );
        }
        let c = field_formula("2*e - E + 1e-3").unwrap();
        assert_eq!(c.at(0.3, 1.0, 2.0), std::f64::consts::E + 1e-3);
        let s = scalar_formula("pi*(1 + exp(-t))", "t").unwrap();
        assert!((s(0.0) - 2.0 * PI).abs() < 1e-15);
        let p = scalar_formula("2*sin(π*u)", "u").unwrap();
        assert!((p(0.5) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn bad_formulas_are_errors() {
        let e = scalar_formula("sin(u)", "t").err().unwrap().to_string();
        assert!(
            e.contains("unknown variable 'u'") && e.contains("may use t"),
            "{e}"
        );
        let e = field_formula("x*y").err().unwrap().to_string();
        assert!(e.contains("'y'"), "{e}");
        assert!(field_formula("").is_err());
        assert!(field_formula("sin(").is_err());
        let e = field_formula("-u^2").err().unwrap().to_string();
        assert!(e.contains("minus"), "{e}");
        let e = field_formula("1/0").err().unwrap().to_string();
        assert!(e.contains("inf"), "{e}");
        // A formula that fails only at some values gives NaN there (caught by the scheme).
        let f = field_formula("sqrt(x)").unwrap();
        assert!(f.at(0.0, 0.0, -1.0).is_nan());
    }

    /// A whole level through the compiled program equals the formula point by point (exmex),
    /// NaN where exmex gives NaN; u runs over the nodes or the midpoints.
    #[test]
    fn a_level_is_the_formula_at_every_node() {
        let text = "(1 + exp(-t))^2 * (sin(pi*u)^2 - cos(pi*u)^2) + sqrt(x) - x/2 + ln(u)";
        let f = field_formula(text).unwrap();
        let exmex: Parsed<f64, FloatOpsFactory<f64>> =
            formula::parse(text, &Variables::this(&["u", "t", "x"])).unwrap();
        let n = 2001;
        let h = 1.0 / (n - 1) as f64;
        let x: Vec<f64> = (0..n).map(|k| (k as f64 * 0.01).sin()).collect();
        let mut out = vec![0.0; n];
        for (offset, t) in [(0.0, 0.3), (0.5, 7.25)] {
            f.fill(offset, h, t, &x, &mut out);
            let mut nan = 0;
            for k in 0..n {
                let u = (k as f64 + offset) * h;
                let want = exmex.eval(&[u, t, x[k]]).unwrap();
                if want.is_nan() {
                    assert!(out[k].is_nan(), "k = {k}");
                    nan += 1;
                } else if want.is_infinite() {
                    assert_eq!(out[k], want, "k = {k}");
                } else {
                    // Integer powers are multiplications: a few ulps of the terms.
                    let tol = 1e-14 * (1.0 + want.abs() + u.ln().abs());
                    assert!((out[k] - want).abs() <= tol, "k = {k}: {} {want}", out[k]);
                }
                assert_eq!(out[k].to_bits(), f.at(u, t, x[k]).to_bits());
            }
            assert!(nan > 100, "{nan}");
        }
    }
}
