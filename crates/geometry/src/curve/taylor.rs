//! Truncated Taylor series as a number type for `exmex`, so that evaluating a parsed formula at
//! `v + ε` yields all derivatives up to [`MAX_ORDER`](super::MAX_ORDER) exactly (Taylor-mode
//! automatic differentiation): `f(v + ε) = Σ_k f⁽ᵏ⁾(v)/k! εᵏ`.

use super::series::{self, Series, LEN};
use exmex::{BinOp, MakeOperators, Operator};
use std::str::FromStr;

/// Taylor coefficients `c_k = f⁽ᵏ⁾(v)/k!`, `k = 0..=MAX_ORDER`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Taylor(pub Series);

impl Taylor {
    pub(super) fn constant(c: f64) -> Self {
        let mut s = [0.0; LEN];
        s[0] = c;
        Taylor(s)
    }
    /// The independent variable at `v`: `v + ε`.
    pub(super) fn variable(v: f64) -> Self {
        let mut s = [0.0; LEN];
        s[0] = v;
        s[1] = 1.0;
        Taylor(s)
    }
    fn is_constant(&self) -> bool {
        self.0[1..].iter().all(|&c| c == 0.0)
    }
    fn map(&self, f: impl Fn(f64) -> f64) -> Self {
        let mut s = self.0;
        for c in s.iter_mut() {
            *c = f(*c);
        }
        Taylor(s)
    }
    fn nan() -> Self {
        Taylor([f64::NAN; LEN])
    }
}

impl FromStr for Taylor {
    type Err = std::num::ParseFloatError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        s.parse::<f64>().map(Taylor::constant)
    }
}

fn add(a: Taylor, b: Taylor) -> Taylor {
    let mut s = a.0;
    for (x, y) in s.iter_mut().zip(b.0) {
        *x += y;
    }
    Taylor(s)
}
fn sub(a: Taylor, b: Taylor) -> Taylor {
    add(a, neg(b))
}
fn neg(a: Taylor) -> Taylor {
    a.map(|x| -x)
}
fn mul(a: Taylor, b: Taylor) -> Taylor {
    Taylor(series::mul(&a.0, &b.0, LEN))
}
fn div(a: Taylor, b: Taylor) -> Taylor {
    Taylor(series::mul(&a.0, &series::recip(&b.0, LEN), LEN))
}

/// `(f')_j = (j + 1) f_{j+1}`.
fn derivative(a: &Series) -> Series {
    let mut d = [0.0; LEN];
    for j in 0..LEN - 1 {
        d[j] = (j + 1) as f64 * a[j + 1];
    }
    d
}
/// `f` with `f₀` given and `f' = g`: `f_k = g_{k−1}/k`.
fn integrate(f0: f64, g: &Series) -> Taylor {
    let mut f = [0.0; LEN];
    f[0] = f0;
    for k in 1..LEN {
        f[k] = g[k - 1] / k as f64;
    }
    Taylor(f)
}

/// `exp`: `e₀ = exp a₀`, `e_k = (1/k) Σ_{j=1}^{k} j a_j e_{k−j}`.
fn exp(a: Taylor) -> Taylor {
    let a = a.0;
    let mut e = [0.0; LEN];
    e[0] = a[0].exp();
    for k in 1..LEN {
        e[k] = (1..=k).map(|j| j as f64 * a[j] * e[k - j]).sum::<f64>() / k as f64;
    }
    Taylor(e)
}
/// `ln a = ln a₀ + ∫ a'/a`.
fn ln(a: Taylor) -> Taylor {
    let q = series::mul(&derivative(&a.0), &series::recip(&a.0, LEN), LEN);
    integrate(a.0[0].ln(), &q)
}
/// `(sin a, cos a)` together: `s' = a' c`, `c' = −a' s`.
fn sin_cos(a: Taylor) -> (Taylor, Taylor) {
    let a = a.0;
    let (mut s, mut c) = ([0.0; LEN], [0.0; LEN]);
    (s[0], c[0]) = a[0].sin_cos();
    for k in 1..LEN {
        let (mut ss, mut cc) = (0.0, 0.0);
        for j in 1..=k {
            ss += j as f64 * a[j] * c[k - j];
            cc += j as f64 * a[j] * s[k - j];
        }
        s[k] = ss / k as f64;
        c[k] = -cc / k as f64;
    }
    (Taylor(s), Taylor(c))
}
/// `(sinh a, cosh a)`: `s' = a' c`, `c' = a' s`.
fn sinh_cosh(a: Taylor) -> (Taylor, Taylor) {
    let a = a.0;
    let (mut s, mut c) = ([0.0; LEN], [0.0; LEN]);
    s[0] = a[0].sinh();
    c[0] = a[0].cosh();
    for k in 1..LEN {
        let (mut ss, mut cc) = (0.0, 0.0);
        for j in 1..=k {
            ss += j as f64 * a[j] * c[k - j];
            cc += j as f64 * a[j] * s[k - j];
        }
        s[k] = ss / k as f64;
        c[k] = cc / k as f64;
    }
    (Taylor(s), Taylor(c))
}
fn sqrt(a: Taylor) -> Taylor {
    Taylor(series::sqrt(&a.0, LEN))
}
/// `f = f₀ + ∫ a' · w(a)` for the inverse functions, `w` given as a series in `a`.
fn inverse_fn(a: Taylor, f0: f64, w: Taylor) -> Taylor {
    integrate(f0, &series::mul(&derivative(&a.0), &w.0, LEN))
}
fn one_minus_sq(a: Taylor) -> Taylor {
    sub(Taylor::constant(1.0), mul(a, a))
}
fn one_plus_sq(a: Taylor) -> Taylor {
    add(Taylor::constant(1.0), mul(a, a))
}
fn recip(a: Taylor) -> Taylor {
    Taylor(series::recip(&a.0, LEN))
}

/// Integer power by repeated squaring (any base).
fn powi(a: Taylor, n: i64) -> Taylor {
    if n < 0 {
        return recip(powi(a, -n));
    }
    let mut result = Taylor::constant(1.0);
    let mut base = a;
    let mut m = n;
    while m > 0 {
        if m & 1 == 1 {
            result = mul(result, base);
        }
        base = mul(base, base);
        m >>= 1;
    }
    result
}

/// `a^b`: integer constant exponents by multiplication (any base), otherwise `exp(b ln a)`
/// (which needs `a₀ > 0`; NaN otherwise).
fn pow(a: Taylor, b: Taylor) -> Taylor {
    if b.is_constant() {
        let c = b.0[0];
        if c == c.trunc() && c.abs() <= 1024.0 {
            return powi(a, c as i64);
        }
        if a.0[0] > 0.0 {
            return exp(mul(b, ln(a)));
        }
        if a.is_constant() {
            return Taylor::constant(a.0[0].powf(c));
        }
        return Taylor::nan();
    }
    if a.0[0] > 0.0 {
        exp(mul(b, ln(a)))
    } else {
        Taylor::nan()
    }
}

fn cbrt(a: Taylor) -> Taylor {
    if a.is_constant() {
        return Taylor::constant(a.0[0].cbrt());
    }
    if a.0[0] < 0.0 {
        neg(pow(neg(a), Taylor::constant(1.0 / 3.0)))
    } else {
        pow(a, Taylor::constant(1.0 / 3.0))
    }
}

/// `|a| = sign(a₀) a` (exact away from zeros of `a`).
fn abs(a: Taylor) -> Taylor {
    if a.0[0] < 0.0 {
        neg(a)
    } else {
        a
    }
}

/// The operators available in formulas.
#[derive(Clone, Debug)]
pub(crate) struct TaylorOps;

impl MakeOperators<Taylor> for TaylorOps {
    fn make<'a>() -> Vec<Operator<'a, Taylor>> {
        use std::f64::consts::{E, LN_10, LN_2, PI, TAU};
        vec![
            Operator::make_bin(
                "^",
                BinOp {
                    apply: pow,
                    prio: 4,
                    is_commutative: false,
                },
            ),
            Operator::make_bin(
                "*",
                BinOp {
                    apply: mul,
                    prio: 2,
                    is_commutative: true,
                },
            ),
            Operator::make_bin(
                "/",
                BinOp {
                    apply: div,
                    prio: 3,
                    is_commutative: false,
                },
            ),
            Operator::make_bin_unary(
                "+",
                BinOp {
                    apply: add,
                    prio: 0,
                    is_commutative: true,
                },
                |a| a,
            ),
            Operator::make_bin_unary(
                "-",
                BinOp {
                    apply: sub,
                    prio: 1,
                    is_commutative: false,
                },
                neg,
            ),
            Operator::make_unary("abs", abs),
            Operator::make_unary("sin", |a| sin_cos(a).0),
            Operator::make_unary("cos", |a| sin_cos(a).1),
            Operator::make_unary("tan", |a| {
                let (s, c) = sin_cos(a);
                div(s, c)
            }),
            Operator::make_unary("asin", |a| {
                inverse_fn(a, a.0[0].asin(), recip(sqrt(one_minus_sq(a))))
            }),
            Operator::make_unary("acos", |a| {
                inverse_fn(a, a.0[0].acos(), neg(recip(sqrt(one_minus_sq(a)))))
            }),
            Operator::make_unary("atan", |a| {
                inverse_fn(a, a.0[0].atan(), recip(one_plus_sq(a)))
            }),
            Operator::make_unary("sinh", |a| sinh_cosh(a).0),
            Operator::make_unary("cosh", |a| sinh_cosh(a).1),
            Operator::make_unary("tanh", |a| {
                let (s, c) = sinh_cosh(a);
                div(s, c)
            }),
            Operator::make_unary("asinh", |a| {
                inverse_fn(a, a.0[0].asinh(), recip(sqrt(one_plus_sq(a))))
            }),
            Operator::make_unary("acosh", |a| {
                let sq_minus_one = sub(mul(a, a), Taylor::constant(1.0));
                inverse_fn(a, a.0[0].acosh(), recip(sqrt(sq_minus_one)))
            }),
            Operator::make_unary("atanh", |a| {
                inverse_fn(a, a.0[0].atanh(), recip(one_minus_sq(a)))
            }),
            Operator::make_unary("exp", exp),
            Operator::make_unary("sqrt", sqrt),
            Operator::make_unary("cbrt", cbrt),
            Operator::make_unary("ln", ln),
            Operator::make_unary("log", ln),
            Operator::make_unary("log2", |a| ln(a).map(|x| x / LN_2)),
            Operator::make_unary("log10", |a| ln(a).map(|x| x / LN_10)),
            Operator::make_constant("PI", Taylor::constant(PI)),
            Operator::make_constant("π", Taylor::constant(PI)),
            Operator::make_constant("TAU", Taylor::constant(TAU)),
            Operator::make_constant("τ", Taylor::constant(TAU)),
            Operator::make_constant("E", Taylor::constant(E)),
            Operator::make_constant("e", Taylor::constant(E)),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::series::factorial;

    /// Compares the Taylor coefficients of `got` with the derivatives `want[k]` (as `k!·c_k`).
    fn check(got: Taylor, want: &[f64], rel: f64, what: &str) {
        for (k, w) in want.iter().enumerate() {
            let d = got.0[k] * factorial(k);
            // Coefficients carry rounding relative to their terms; derivatives are k!·c_k.
            assert!(
                (d - w).abs() <= rel * w.abs().max(factorial(k)),
                "{what}: order {k}: {d} vs {w}"
            );
        }
    }

    #[test]
    fn elementary_functions_have_exact_derivatives() {
        let x = 0.3;
        let v = Taylor::variable(x);
        let tol = 1e-13;
        // exp: all derivatives exp(x).
        check(exp(v), &[x.exp(); LEN], tol, "exp");
        // sin: sin(x + kπ/2).
        let s: Vec<f64> = (0..LEN).map(|k| (x + k as f64 * FRAC).sin()).collect();
        check(sin_cos(v).0, &s, tol, "sin");
        // ln: (−1)^{k−1}(k−1)!/x^k.
        let l: Vec<f64> = (0..LEN)
            .map(|k| {
                if k == 0 {
                    x.ln()
                } else {
                    (-1f64).powi(k as i32 - 1) * factorial(k - 1) / x.powi(k as i32)
                }
            })
            .collect();
        check(ln(v), &l, tol, "ln");
        // 1/(1 − x): k!/(1 − x)^{k+1}.
        let r: Vec<f64> = (0..LEN)
            .map(|k| factorial(k) / (1.0 - x).powi(k as i32 + 1))
            .collect();
        check(
            div(Taylor::constant(1.0), sub(Taylor::constant(1.0), v)),
            &r,
            tol,
            "recip",
        );
        // x^5: 5!/(5−k)! x^{5−k}; negative base too.
        for x in [0.7f64, -1.3] {
            let p: Vec<f64> = (0..LEN)
                .map(|k| {
                    if k > 5 {
                        0.0
                    } else {
                        factorial(5) / factorial(5 - k) * x.powi(5 - k as i32)
                    }
                })
                .collect();
            check(
                pow(Taylor::variable(x), Taylor::constant(5.0)),
                &p,
                tol,
                "pow",
            );
        }
        // sinh/cosh/tanh consistency: cosh² − sinh² = 1 as a series.
        let (sh, ch) = sinh_cosh(v);
        let one = sub(mul(ch, ch), mul(sh, sh));
        check(
            one,
            &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            tol,
            "cosh² − sinh²",
        );
        // Inverse functions: sin(asin v) = v, tan(atan v) = v, exp(asinh v) ... via identities.
        let id = [x, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let asin = inverse_fn(v, x.asin(), recip(sqrt(one_minus_sq(v))));
        check(sin_cos(asin).0, &id, tol, "sin∘asin");
        let acos = inverse_fn(v, x.acos(), neg(recip(sqrt(one_minus_sq(v)))));
        check(sin_cos(acos).1, &id, tol, "cos∘acos");
        let atan = inverse_fn(v, x.atan(), recip(one_plus_sq(v)));
        let (s, c) = sin_cos(atan);
        check(div(s, c), &id, tol, "tan∘atan");
        let asinh = inverse_fn(v, x.asinh(), recip(sqrt(one_plus_sq(v))));
        check(sinh_cosh(asinh).0, &id, tol, "sinh∘asinh");
        let atanh = inverse_fn(v, x.atanh(), recip(one_minus_sq(v)));
        let (s, c) = sinh_cosh(atanh);
        check(div(s, c), &id, tol, "tanh∘atanh");
        let w = Taylor::variable(1.7);
        let sq = sub(mul(w, w), Taylor::constant(1.0));
        let acosh = inverse_fn(w, 1.7f64.acosh(), recip(sqrt(sq)));
        let id2 = [1.7, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        check(sinh_cosh(acosh).1, &id2, tol, "cosh∘acosh");
        check(powi(cbrt(w), 3), &id2, tol, "cbrt³");
        check(
            powi(cbrt(neg(w)), 3),
            &id2.map(|c| -c),
            tol,
            "cbrt³ negative",
        );
        assert!(pow(Taylor::variable(-1.0), Taylor::constant(0.5)).0[0].is_nan());
    }

    const FRAC: f64 = std::f64::consts::FRAC_PI_2;
}
