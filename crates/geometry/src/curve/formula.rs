use super::series::{factorial, LEN};
use super::taylor::{Taylor, TaylorOps};
use super::{Curve, Domain};
use crate::check::finite;
use crate::formula::interval::Iv;
use crate::formula::program::{self, Program};
use crate::formula::trace::{Sym, SymOps};
use crate::formula::{self, short, Parsed, Variables};
use crate::{Error, Result, Vec3, TAU};
use exmex::Differentiate;
use exmex::Express;

type Expr = formula::Expr<Taylor, TaylorOps>;

/// A curve given by three formulas in the parameter `v`, e.g. `x = "2*cos(v)"`. Derivatives are
/// exact: each formula is evaluated on truncated Taylor series (`v + ε`), which yields all
/// derivatives up to [`MAX_ORDER`](super::MAX_ORDER) in one pass (automatic differentiation; no expression swell,
/// unlike repeated symbolic differentiation).
///
/// Syntax (parsed by the `exmex` crate): numbers (`2`, `0.5`, `.5`, `1e-3`), the variable `v`,
/// parentheses, the operators `+ - * / ^` (power; integer exponents work for any base, others
/// need a positive base) and unary minus, the functions `sin cos tan asin acos atan sinh cosh
/// tanh asinh acosh atanh exp ln log (natural) log2 log10 sqrt cbrt abs`, and the constants
/// `pi`, `PI`, `π`, `TAU`, `τ` (2π) and `E`, `e` (Euler's number). Functions without derivatives
/// (`min`, `max`, `floor`, …) are unknown operators. A formula may be a constant (`"0"`).
/// Binary operators follow exmex's precedence (`^` before `/` before `*` before `-` before `+`,
/// left to right, so `2^3^2 = 64`); a unary minus directly in front of a power (`-v^2`,
/// `2*-v^2`) is refused as ambiguous, since exmex would read it as `(-v)^2`.
#[derive(Clone, Debug)]
pub struct Formula {
    /// The formulas as given.
    pub text: [String; 3],
    domain: Domain,
    /// On the heap: a parsed expression over Taylor numbers is about 20 kB.
    exprs: Vec<Expr>,
    /// The programs of `C⁽ᵏ⁾`, `k = 0 ..= 4`, per component (`None`: identically zero), derived
    /// symbolically on first use by [`Curve::derivative_bounds`]; `Err` if they cannot be.
    derived: std::sync::OnceLock<std::result::Result<Box<Derived>, String>>,
}

/// `[component][k]`: the program of `d^k x_c / dv^k` (`None`: identically zero).
type Derived = [[Option<Program>; 6]; 3];

/// Pieces per period a periodic interval is cut into before interval evaluation (a narrower
/// box gives a tighter enclosure), and the most halvings of a piece without enclosure.
const BOUND_PIECES: f64 = 256.0;
const BOUND_DEPTH: u32 = 6;

const NAMES: [&str; 3] = ["x", "y", "z"];

/// The one variable of curve formulas.
const V: Variables = Variables::every(&["v"]);

impl Formula {
    /// Errors name their place as in a curve table of the design file: the component (`x`, `y`
    /// or `z`) whose formula is empty, does not parse, uses a variable other than `v`, or
    /// evaluates to a non-finite number on the domain; `domain[0]`, `domain[1]` or `domain` for
    /// an interval that is not finite or not increasing.
    ///
    /// Checks: the domain is `Periodic` or a finite interval `[a, b]` with `a < b`; value and
    /// first two derivatives are finite at 257 equally spaced parameters of the domain (ends
    /// included); a periodic formula repeats after 2π (value and first derivative at
    /// `v = 0, 0.7, 2.1, 4.4` against `v + 2π`, to `10⁻⁹` of the curve's size).
    pub fn new(x: &str, y: &str, z: &str, domain: Domain) -> Result<Self> {
        for (name, f) in NAMES.iter().zip([x, y, z]) {
            if f.trim().is_empty() {
                return Err(Error::invalid("is empty").at(name));
            }
        }
        if let Domain::Interval(t0, t1) = domain {
            finite(t0, "domain[0]")?;
            finite(t1, "domain[1]")?;
            if t0 >= t1 {
                return Err(Error::invalid(format!(
                    "must be an interval [t0, t1] with t0 < t1 (got [{t0}, {t1}])"
                ))
                .at("domain"));
            }
        }
        let mut exprs = Vec::with_capacity(3);
        for (name, given) in NAMES.iter().zip([x, y, z]) {
            let parsed: formula::Parsed<Taylor, TaylorOps> =
                formula::parse(given, &V).map_err(|e| e.at(name))?;
            exprs.push(parsed.expr);
        }
        let f = Formula {
            text: [x.to_string(), y.to_string(), z.to_string()],
            domain,
            exprs,
            derived: std::sync::OnceLock::new(),
        };
        f.check_finite()?;
        if domain == Domain::Periodic {
            f.check_periodic()?;
        }
        Ok(f)
    }

    /// Taylor coefficients of component `c` at `v` (NaN if exmex fails to evaluate).
    fn series(&self, c: usize, v: f64) -> Taylor {
        let e = &self.exprs[c];
        let r = if e.var_names().is_empty() {
            e.eval(&[])
        } else {
            e.eval(&[Taylor::variable(v)])
        };
        r.unwrap_or(Taylor([f64::NAN; LEN]))
    }

    /// `C(v), …, C⁽ᵏ⁾(v)` for `k < LEN`.
    fn derivatives(&self, v: f64) -> [Vec3; LEN] {
        let s = [self.series(0, v), self.series(1, v), self.series(2, v)];
        let mut out = [Vec3::zeros(); LEN];
        for (k, o) in out.iter_mut().enumerate() {
            *o = Vec3::new(s[0].0[k], s[1].0[k], s[2].0[k]) * factorial(k);
        }
        out
    }

    fn check_finite(&self) -> Result<()> {
        let (a, b) = match self.domain {
            Domain::Periodic => (0.0, TAU),
            Domain::Interval(a, b) => (a, b),
        };
        let n = 256;
        for i in 0..=n {
            let v = if i == n {
                b
            } else {
                a + (b - a) * i as f64 / n as f64
            };
            let d = self.derivatives(v);
            for (k, dk) in d.iter().enumerate().take(3) {
                for c in 0..3 {
                    let value = dk[c];
                    if !value.is_finite() {
                        let what = match k {
                            0 => "evaluates to".to_string(),
                            1 => "has a first derivative".to_string(),
                            _ => "has a second derivative".to_string(),
                        };
                        return Err(
                            Error::invalid(format!("{what} {value} at v = {}", short(v)))
                                .at(NAMES[c]),
                        );
                    }
                }
            }
        }
        Ok(())
    }

    fn check_periodic(&self) -> Result<()> {
        let n = 64;
        let mut size = [0.0f64; 2];
        for i in 0..n {
            let v = TAU * i as f64 / n as f64;
            let d = self.derivatives(v);
            for (k, s) in size.iter_mut().enumerate() {
                *s = s.max(d[k].norm());
            }
        }
        for &v in &[0.0, 0.7, 2.1, 4.4] {
            let (d0, d1) = (self.derivatives(v), self.derivatives(v + TAU));
            for (k, s) in size.iter().enumerate() {
                let tol = 1e-9 * s;
                for (c, name) in NAMES.iter().enumerate() {
                    let (p, q) = (d0[k][c], d1[k][c]);
                    if (p - q).abs() > tol {
                        let prime = if k == 1 { "'" } else { "" };
                        let at = short(v);
                        let shifted = if v == 0.0 {
                            "2π".to_string()
                        } else {
                            format!("{at} + 2π")
                        };
                        return Err(Error::invalid(format!(
                            "not periodic: {name}{prime}({at}) = {}, {name}{prime}({shifted}) = {}",
                            short(p),
                            short(q)
                        )));
                    }
                }
            }
        }
        Ok(())
    }
}

impl Formula {
    /// The derivatives' programs: exmex's symbolic differentiation over [`Sym`], as for
    /// formula surfaces (`ParametricSurface::fourth_partials`).
    fn derive(&self) -> std::result::Result<Box<Derived>, String> {
        let mut out: Box<Derived> = Box::default();
        for (c, text) in self.text.iter().enumerate() {
            let Parsed { expr, slots } =
                formula::parse::<Sym, SymOps>(text, &V).map_err(|e| e.to_string())?;
            let iv = slots.iter().position(|&i| i == 0);
            for (k, o) in out[c].iter_mut().enumerate() {
                let e = match (k, iv) {
                    (0, _) => expr.clone(),
                    (_, None) => continue,
                    (_, Some(i)) => expr
                        .clone()
                        .partial_iter(std::iter::repeat_n(i, k))
                        .map_err(|e| format!("cannot differentiate '{text}': {e}"))?,
                };
                let parsed = Parsed {
                    expr: e,
                    slots: slots.clone(),
                };
                let tree = program::tree(&parsed, &V).map_err(|e| e.to_string())?;
                *o = Some(Program::new(&tree, 1, &[]));
            }
        }
        Ok(out)
    }

    /// Bounds over the box `[a, b]` by interval evaluation of every derivative's program, or
    /// `None` where a function is not analytic on it (halved up to `depth` more times).
    fn box_bounds(d: &Derived, a: f64, b: f64, depth: u32, out: &mut [f64]) -> bool {
        let eval = |out: &mut [f64]| -> bool {
            let Ok(x) = Iv::new(a, b) else { return false };
            for (k, o) in out.iter_mut().enumerate() {
                let mut sq = 0.0f64;
                for comp in d {
                    let Some(p) = &comp[k] else { continue };
                    match p.eval_interval(&[x]) {
                        Ok(r) => sq += r.mag() * r.mag(),
                        Err(_) => return false,
                    }
                }
                *o = sq.sqrt() * (1.0 + 1e-14);
            }
            out.iter().all(|o| o.is_finite())
        };
        if eval(out) {
            return true;
        }
        if depth == 0 {
            return false;
        }
        let m = 0.5 * (a + b);
        let mut other = vec![0.0; out.len()];
        if !Self::box_bounds(d, a, m, depth - 1, out)
            || !Self::box_bounds(d, m, b, depth - 1, &mut other)
        {
            return false;
        }
        for (o, p) in out.iter_mut().zip(&other) {
            *o = o.max(*p);
        }
        true
    }
}

impl Curve for Formula {
    fn domain(&self) -> Domain {
        self.domain
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let v = match self.domain {
            Domain::Periodic => super::reduce_periodic(t),
            Domain::Interval(..) => t,
        };
        let d = self.derivatives(v);
        for (o, dk) in out.iter_mut().zip(d.iter()) {
            *o = *dk;
        }
    }
    /// The derivatives are derived symbolically and evaluated over `(t0, t1)` (a periodic
    /// curve's in `[0, 2π]`, where [`Curve::jet`] evaluates them) in outward-rounded interval
    /// arithmetic ([`crate::formula::interval`]), cut into pieces of at most `2π/256` and halved
    /// where a function is not analytic on a piece; `false` if a piece keeps touching a pole,
    /// a square root or logarithm of 0, a kink of `abs`, … There an enclosure would be no
    /// bound, and the curve has no breaks: it is analytic wherever the bounds exist.
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        if out.len() > 6 {
            return false;
        }
        let Ok(d) = self.derived.get_or_init(|| self.derive()) else {
            return false;
        };
        let windows = match self.domain {
            Domain::Periodic => super::periodic_windows(t0, t1),
            Domain::Interval(..) if t0.is_finite() && t1.is_finite() && t0 < t1 => {
                vec![(t0, t1)]
            }
            Domain::Interval(..) => Vec::new(),
        };
        if windows.is_empty() {
            return false;
        }
        out.iter_mut().for_each(|o| *o = 0.0);
        let mut part = vec![0.0; out.len()];
        for (a, b) in windows {
            let n = ((b - a) / (TAU / BOUND_PIECES)).ceil().clamp(1.0, 1e4) as usize;
            for i in 0..n {
                let x0 = a + (b - a) * i as f64 / n as f64;
                let x1 = if i + 1 == n {
                    b
                } else {
                    a + (b - a) * (i + 1) as f64 / n as f64
                };
                if !Self::box_bounds(d, x0, x1, BOUND_DEPTH, &mut part) {
                    return false;
                }
                for (o, p) in out.iter_mut().zip(&part) {
                    *o = o.max(*p);
                }
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;

    #[test]
    fn derivatives_match_closed_forms() {
        let f = Formula::new(
            "2*cos(v)",
            "sin(v)^2 + v^0",
            "pi*sin(3*v)",
            Domain::Periodic,
        )
        .unwrap();
        for &v in &[0.0, 0.4, 2.0, 5.5, -3.0, 20.0] {
            let j = jet(&f, v);
            for (k, d) in j.iter().enumerate() {
                let ph = |w: f64| w + k as f64 * std::f64::consts::FRAC_PI_2;
                // sin² v + 1 = 3/2 − cos(2v)/2.
                let y =
                    if k == 0 { 1.5 } else { 0.0 } - 0.5 * 2f64.powi(k as i32) * ph(2.0 * v).cos();
                let want = Vec3::new(
                    2.0 * ph(v).cos(),
                    y,
                    std::f64::consts::PI * 3f64.powi(k as i32) * ph(3.0 * v).sin(),
                );
                let tol = 1e-13 * 3f64.powi(k as i32) * (1.0 + v.abs());
                assert_close(d, &want, tol, &format!("order {k} at v = {v}"));
            }
        }
        check_fd(&f, &[0.3, 1.0, 4.0], 1e-4, 5, 10.0);
    }

    #[test]
    fn open_formulas_constants_and_syntax() {
        let f = Formula::new("v", "v^3 - 2*v", "0", Domain::Interval(-1.0, 2.0)).unwrap();
        let j = jet(&f, 1.5);
        assert_close(
            &j[0],
            &Vec3::new(1.5, 1.5f64.powi(3) - 3.0, 0.0),
            1e-14,
            "value",
        );
        assert_close(&j[1], &Vec3::new(1.0, 3.0 * 2.25 - 2.0, 0.0), 1e-14, "d1");
        assert_close(&j[2], &Vec3::new(0.0, 9.0, 0.0), 1e-14, "d2");
        assert_close(&j[3], &Vec3::new(0.0, 6.0, 0.0), 1e-14, "d3");
        assert_close(&j[4], &Vec3::zeros(), 1e-14, "d4");
        // Negative base with integer power: derivative stays finite.
        let j = jet(&f, -0.5);
        assert!(j.iter().all(|d| d.iter().all(|c| c.is_finite())), "{j:?}");
        // Constants.
        let f = Formula::new("PI", "TAU - 2*π", "exp(1) - e + 1e-3", Domain::Periodic).unwrap();
        assert_close(
            &f.point(1.0),
            &Vec3::new(std::f64::consts::PI, 0.0, 1e-3),
            1e-15,
            "constants",
        );
        assert_eq!(f.derivative(1.0, 1), Vec3::zeros());
        // Functions.
        let f = Formula::new("exp(v)", "ln(v)", "sqrt(v)", Domain::Interval(1.0, 2.0)).unwrap();
        let j = jet(&f, 1.3);
        assert!((j[3].x - 1.3f64.exp()).abs() < 1e-14);
        assert!((j[3].y - 2.0 / 1.3f64.powi(3)).abs() < 1e-14);
        assert!((j[2].z + 0.25 * 1.3f64.powf(-1.5)).abs() < 1e-14);
        check_fd(&f, &[1.2, 1.5, 1.8], 1e-4, 5, 10.0);
        let f = Formula::new("1.5e-1*v", "2E+1", ".5", Domain::Interval(0.0, 1.0)).unwrap();
        assert_close(&f.point(2.0), &Vec3::new(0.3, 20.0, 0.5), 1e-15, "literals");
    }

    #[test]
    fn formula_is_small() {
        // Results are moved around by value; the expressions live on the heap.
        assert!(std::mem::size_of::<Formula>() <= 256);
    }

    #[test]
    fn errors_name_the_component() {
        let e = Formula::new("cos(v)", "sin(v)", "w", Domain::Periodic)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "z: unknown variable 'w'; formulas use v");
        let e = Formula::new("cos(v", "0", "0", Domain::Periodic)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("x: cannot parse"), "{e}");
        let e = Formula::new("0", "1/(1 - sin(v))", "0", Domain::Periodic)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("y: "), "{e}");
        let e = Formula::new("0", "0", "ln(v - 1)", Domain::Interval(0.0, 2.0))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("z: evaluates to NaN at v = 0"), "{e}");
        let e = Formula::new("v", "0", "0", Domain::Periodic)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "not periodic: x(0) = 0, x(2π) = 6.28319");
        let e = Formula::new("cos(v) + 0.001*v*0", "sin(v/2)^2", "0", Domain::Periodic);
        assert!(e.is_ok(), "{e:?}");
        let e = Formula::new("cos(v)", "sin(v/2)", "0", Domain::Periodic)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("not periodic: y"), "{e}");
        assert!(Formula::new("floor(v)", "0", "0", Domain::Interval(0.0, 1.0)).is_err());
        assert!(Formula::new("min(v, 1)", "0", "0", Domain::Interval(0.0, 1.0)).is_err());
        assert!(Formula::new("", "0", "0", Domain::Periodic).is_err());
        let e = Formula::new("0", "-v^2", "0", Domain::Interval(0.0, 1.0))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("y: '-v^2': the minus at character 1"), "{e}");
        let f = Formula::new(
            "0 - v^2",
            "-(v^2)",
            "2^3^2 + 8/2/2",
            Domain::Interval(0.0, 4.0),
        )
        .unwrap();
        assert_close(
            &f.point(3.0),
            &Vec3::new(-9.0, -9.0, 66.0),
            1e-13,
            "precedence",
        );
        for bad in [
            "(",
            ")",
            "+",
            "sin",
            "v v",
            "1..2",
            "^2",
            "v^",
            "()",
            "sin()",
            "2*",
            "*2",
            "cos(v))",
            "((v)",
            "v/",
            "√v",
            "v!",
            "1,2",
            "atan2(v, 1)",
        ] {
            let r = Formula::new(bad, "0", "0", Domain::Interval(0.5, 1.0));
            assert!(r.is_err(), "{bad}: {r:?}");
        }
        assert!(Formula::new("v", "0", "0", Domain::Interval(1.0, 1.0)).is_err());
        assert!(Formula::new("v", "0", "0", Domain::Interval(0.0, f64::INFINITY)).is_err());
        assert!(Formula::new("v", "0", "0", Domain::Interval(f64::NAN, 1.0)).is_err());
        assert!(Formula::new("1/0", "0", "0", Domain::Periodic).is_err());
        assert!(Formula::new("0", "sqrt(v - 3)", "0", Domain::Periodic).is_err());
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;

    /// Interval enclosures of the symbolic derivatives hold on random intervals (a periodic and
    /// an open curve) and on intervals of at most 0.5 stay within a factor 4 of the sampled
    /// maximum for sums and products of trigonometric, exponential and root functions (cut
    /// into pieces of at most 2π/256, observed ≤ 1.6); a curve with a kink
    /// of `abs` on the interval has none.
    #[test]
    fn interval_bounds_hold() {
        let f = Formula::new(
            "cos(v) + 0.3*cos(3*v)",
            "sin(v) - 0.2*sin(2*v)",
            "0.1*exp(sin(v))",
            Domain::Periodic,
        )
        .unwrap();
        let r = check_bounds(&f, 17, 60, 0.5);
        eprintln!("formula periodic: {r:?}");
        assert!(r.iter().all(|&x| x <= 4.0), "{r:?}");
        check_bounds(&f, 18, 20, TAU);
        let open = Formula::new(
            "v",
            "sin(v)*exp(-v)",
            "sqrt(1+v)",
            Domain::Interval(0.0, 2.0),
        )
        .unwrap();
        let r = check_bounds(&open, 19, 40, 0.5);
        eprintln!("formula open: {r:?}");
        assert!(r.iter().all(|&x| x <= 4.0), "{r:?}");
        // A quotient's symbolic derivatives cancel heavily, and their enclosures are loose
        // (observed up to ≈ 50 at the fourth derivative): bounds, but not tight ones.
        let rational = Formula::new("v", "v^2/(1+v^2)", "0", Domain::Interval(0.0, 2.0)).unwrap();
        let r = check_bounds(&rational, 20, 40, 0.5);
        eprintln!("formula rational: {r:?}");
        let kink = Formula::new("abs(v - 1)", "v", "0", Domain::Interval(0.0, 2.0)).unwrap();
        assert!(!kink.derivative_bounds(0.5, 1.5, &mut [0.0; 5]));
    }
}
