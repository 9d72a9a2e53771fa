//! Surfaces given by three formulas in `u` and `v` (spheres, cylinders, tori, … — shapes the PDE
//! method cannot produce exactly), with exact partial derivatives from symbolic differentiation.

use super::{Interval, Partials, PartialsRows, RowBuf, RowEvaluator, Surface, VDomain};
use crate::formula::interval::{Iv, Unbounded};
use crate::formula::program::{self, Input, Program};
use crate::formula::trace::{Sym, SymOps};
use crate::formula::{self, short, Parsed, Variables};
use crate::{Error, Result, Vec3, TAU};
use exmex::prelude::*;
use exmex::{Differentiate, FloatOpsFactory};

type Expr = formula::Expr<f64, FloatOpsFactory<f64>>;

/// The variables of surface formulas: `u` (slot 0) and `v` (slot 1).
const UV: Variables = Variables::every(&["u", "v"]);

const NAMES: [&str; 3] = ["x", "y", "z"];

/// One component and its partials: `f, f_u, f_v, f_uu, f_uv, f_vv` (`None`: identically zero
/// because the formula does not use the variable).
#[derive(Clone, Debug)]
struct Component {
    /// On the heap: a parsed expression is a few kilobytes.
    exprs: [Option<Box<Expr>>; 6],
    /// For each variable of the expressions (exmex sorts them by name): 0 for `u`, 1 for `v`.
    vars: Vec<usize>,
    /// The same six compiled for rows `u = const` (`u` uniform, `v` per point).
    programs: [Option<Program>; 6],
}

impl Component {
    fn eval(&self, k: usize, uv: [f64; 2]) -> f64 {
        let Some(e) = &self.exprs[k] else {
            return 0.0;
        };
        let mut args = [0.0; 2];
        for (a, &i) in args.iter_mut().zip(&self.vars) {
            *a = uv[i];
        }
        e.eval(&args[..self.vars.len()]).unwrap_or(f64::NAN)
    }

    /// `out[j]` = partial `k` at `(u, vs[j])`.
    fn row(&self, k: usize, u: f64, vs: &[f64], out: &mut [f64]) {
        match &self.programs[k] {
            Some(p) => p.eval(&[Input::Scalar(u), Input::Slice(vs)], out),
            None => out.fill(0.0),
        }
    }
}

/// `X(u, v) = (x(u, v), y(u, v), z(u, v))` for `u ∈ [0, 1]` (or the range given to
/// [`ParametricSurface::with_u_range`]) and `v` in a periodic (`[0, 2π)`) or interval domain. The partials are the formulas' symbolic derivatives (exmex), exact up to
/// rounding. Formula syntax is that of [`crate::curve::Formula`], with the variables `u` and `v`.
#[derive(Clone, Debug)]
pub struct ParametricSurface {
    /// The formulas as given.
    pub text: [String; 3],
    u_range: Interval,
    domain: VDomain,
    comps: Vec<Component>,
}

impl ParametricSurface {
    /// Parses and checks the formulas. Errors name the component (`x`, `y`, `z`) whose formula
    /// does not parse, uses a variable other than `u` and `v`, or is not finite (value or a
    /// partial up to second order) on a 33 × 33 grid of the domain (ends included). A periodic
    /// domain also requires `X` and `X_v` to repeat after 2π in `v` (at four `u` and four `v`, to
    /// `10⁻⁹` of their size); an interval must be finite with start < end.
    pub fn new(x: &str, y: &str, z: &str, domain: VDomain) -> Result<Self> {
        Self::with_u_range(x, y, z, Interval::UNIT, domain)
    }

    /// [`ParametricSurface::new`] with `u` over `u_range` instead of `[0, 1]` (a sphere in
    /// latitude and longitude, `u ∈ [−π/2, π/2]`): the surface reports that range
    /// ([`Surface::u_range`]) and the checks run over it. The range must be finite with
    /// start < end.
    pub fn with_u_range(
        x: &str,
        y: &str,
        z: &str,
        u_range: Interval,
        domain: VDomain,
    ) -> Result<Self> {
        if !u_range.is_valid() {
            return Err(Error::invalid(format!(
                "the u range [{}, {}] must be finite with start < end",
                u_range.start, u_range.end
            ))
            .at("u_range"));
        }
        if let VDomain::Interval(a, b) = domain {
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(Error::invalid(format!(
                    "the interval [{a}, {b}] must be finite with start < end"
                ))
                .at("domain"));
            }
        }
        let mut comps = Vec::with_capacity(3);
        for (c, given) in [x, y, z].into_iter().enumerate() {
            comps.push(parse_component(given).map_err(|e| e.at(NAMES[c]))?);
        }
        let s = ParametricSurface {
            text: [x.to_string(), y.to_string(), z.to_string()],
            u_range,
            domain,
            comps,
        };
        s.check_finite()?;
        if domain == VDomain::Periodic {
            s.check_periodic()?;
        }
        Ok(s)
    }

    fn values(&self, k: usize, u: f64, v: f64) -> Vec3 {
        Vec3::new(
            self.comps[0].eval(k, [u, v]),
            self.comps[1].eval(k, [u, v]),
            self.comps[2].eval(k, [u, v]),
        )
    }

    fn check_finite(&self) -> Result<()> {
        let (a, b) = match self.domain {
            VDomain::Periodic => (0.0, TAU),
            VDomain::Interval(a, b) => (a, b),
        };
        const WHAT: [&str; 6] = [
            "evaluates to",
            "has ∂/∂u",
            "has ∂/∂v",
            "has ∂²/∂u²",
            "has ∂²/∂u∂v",
            "has ∂²/∂v²",
        ];
        let n = 32;
        for i in 0..=n {
            let u = if i == n {
                self.u_range.end
            } else {
                self.u_range.lerp(i as f64 / n as f64)
            };
            for j in 0..=n {
                let v = if j == n {
                    b
                } else {
                    a + (b - a) * j as f64 / n as f64
                };
                for (c, comp) in self.comps.iter().enumerate() {
                    for (k, what) in WHAT.iter().enumerate() {
                        let value = comp.eval(k, [u, v]);
                        if !value.is_finite() {
                            return Err(Error::invalid(format!(
                                "{what} {value} at u = {}, v = {}",
                                short(u),
                                short(v)
                            ))
                            .at(NAMES[c]));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn check_periodic(&self) -> Result<()> {
        for &s in &[0.0, 0.3, 0.7, 1.0] {
            let u = self.u_range.lerp(s);
            let mut size = [0.0f64; 2];
            for j in 0..64 {
                let v = TAU * j as f64 / 64.0;
                size[0] = size[0].max(self.values(0, u, v).amax());
                size[1] = size[1].max(self.values(2, u, v).amax());
            }
            for &v in &[0.0, 0.7, 2.1, 4.4] {
                for (i, k) in [0usize, 2].into_iter().enumerate() {
                    let (p, q) = (self.values(k, u, v), self.values(k, u, v + TAU));
                    for c in 0..3 {
                        if (p[c] - q[c]).abs() > 1e-9 * size[i].max(f64::MIN_POSITIVE) {
                            let d = if k == 2 { "_v" } else { "" };
                            return Err(Error::invalid(format!(
                                "not periodic in v: {name}{d}({}, {}) = {}, {name}{d}({}, {} + 2π) = {} \
                                 (use domain = [v0, v1] for an open surface)",
                                short(u),
                                short(v),
                                short(p[c]),
                                short(u),
                                short(v),
                                short(q[c]),
                                name = NAMES[c],
                            ))
                            .at(NAMES[c]));
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// Parses one formula and differentiates it symbolically, once in `f64` (the point-wise
/// values) and once over [`Sym`] (the same derivatives as trees, compiled for rows).
fn parse_component(given: &str) -> Result<Component> {
    let programs = compile_component(given)?;
    let Parsed { expr, slots: vars } = formula::parse(given, &UV)?;
    let idx = |var: usize| vars.iter().position(|&i| i == var);
    let diff = |e: &Option<Box<Expr>>, var: usize| -> Result<Option<Box<Expr>>> {
        match (e, idx(var)) {
            (Some(e), Some(i)) => (**e)
                .clone()
                .partial(i)
                .map(|d| Some(Box::new(d)))
                .map_err(|err| Error::invalid(format!("cannot differentiate '{given}': {err}"))),
            _ => Ok(None),
        }
    };
    let f = Some(Box::new(expr));
    let fu = diff(&f, 0)?;
    let fv = diff(&f, 1)?;
    let fuu = diff(&fu, 0)?;
    let fuv = diff(&fu, 1)?;
    let fvv = diff(&fv, 1)?;
    Ok(Component {
        exprs: [f, fu, fv, fuu, fuv, fvv],
        vars,
        programs,
    })
}

/// The programs of `f, f_u, f_v, f_uu, f_uv, f_vv` (`None` where identically zero because the
/// formula does not use the variable), by exmex's differentiation over [`Sym`].
fn compile_component(given: &str) -> Result<[Option<Program>; 6]> {
    type SymExpr = formula::Expr<Sym, SymOps>;
    let Parsed { expr, slots } = formula::parse::<Sym, SymOps>(given, &UV)?;
    let idx = |var: usize| slots.iter().position(|&i| i == var);
    let diff =
        |e: &Option<SymExpr>, var: usize| -> Result<Option<SymExpr>> {
            match (e, idx(var)) {
                (Some(e), Some(i)) => e.clone().partial(i).map(Some).map_err(|err| {
                    Error::invalid(format!("cannot differentiate '{given}': {err}"))
                }),
                _ => Ok(None),
            }
        };
    let f = Some(expr);
    let fu = diff(&f, 0)?;
    let fv = diff(&f, 1)?;
    let fuu = diff(&fu, 0)?;
    let fuv = diff(&fu, 1)?;
    let fvv = diff(&fv, 1)?;
    let mut out: [Option<Program>; 6] = Default::default();
    for (o, e) in out.iter_mut().zip([f, fu, fv, fuu, fuv, fvv]) {
        if let Some(expr) = e {
            let parsed = Parsed {
                expr,
                slots: slots.clone(),
            };
            let tree = program::tree(&parsed, &UV)?;
            *o = Some(Program::new(&tree, 2, &[0]));
        }
    }
    Ok(out)
}

/// The fourth-order partials the certified CAD bound needs (`cad::certify`): for each of the
/// three components the programs of `f` (whose interval evaluation proves the component
/// analytic on a box), `∂u⁴f`, `∂v⁴f` and `∂u∂v⁴f` (`None`: identically zero), by exmex's
/// symbolic differentiation over [`Sym`], for evaluation over boxes of `(u, v)`.
#[derive(Clone, Debug)]
pub struct FourthPartials {
    programs: [[Option<Program>; 4]; 3],
}

/// Sizes of the three fourth-order partials over a box (`sup|∂u⁴X|`, `sup|∂v⁴X|`,
/// `sup|∂u∂v⁴X|`, Euclidean norms) and of the surface (`sup|X|`), or why the surface has no
/// bound there.
pub(crate) type BoxBounds = std::result::Result<[f64; 4], Unbounded>;

impl FourthPartials {
    /// Upper bounds of `|∂u⁴X|`, `|∂v⁴X|`, `|∂u∂v⁴X|` and `|X|` over `[u0, u1] × [v0, v1]`, from
    /// outward-rounded interval enclosures of each component ([`Program::eval_interval`]), or
    /// the reason the surface is not analytic on the box (a pole, a square root or logarithm
    /// reaching 0, …): then no bound holds there.
    pub fn bounds(&self, u: [f64; 2], v: [f64; 2]) -> BoxBounds {
        let boxes = [Iv::new(u[0], u[1])?, Iv::new(v[0], v[1])?];
        let mut sq = [0.0f64; 4];
        for comp in &self.programs {
            for (k, p) in comp.iter().enumerate() {
                let Some(p) = p else { continue };
                let m = p.eval_interval(&boxes)?.mag();
                sq[k] += m * m;
            }
        }
        // Upward: the sums of three squares and the root carry a few roundings.
        let up = |s: f64| s.sqrt() * (1.0 + 1e-14);
        Ok([up(sq[1]), up(sq[2]), up(sq[3]), up(sq[0])])
    }
}

impl ParametricSurface {
    /// The programs of [`FourthPartials`], derived from the formulas as given.
    pub fn fourth_partials(&self) -> Result<FourthPartials> {
        type SymExpr = formula::Expr<Sym, SymOps>;
        let mut programs: [[Option<Program>; 4]; 3] = Default::default();
        for (c, text) in self.text.iter().enumerate() {
            let Parsed { expr, slots } =
                formula::parse::<Sym, SymOps>(text, &UV).map_err(|e| e.at(NAMES[c]))?;
            let idx = |var: usize| slots.iter().position(|&i| i == var);
            let (iu, iv) = (idx(0), idx(1));
            let chain = |vars: Option<Vec<usize>>| -> Result<Option<SymExpr>> {
                let Some(vars) = vars else { return Ok(None) };
                if vars.is_empty() {
                    return Ok(Some(expr.clone()));
                }
                expr.clone()
                    .partial_iter(vars.into_iter())
                    .map(Some)
                    .map_err(|err| {
                        Error::invalid(format!("cannot differentiate '{text}': {err}")).at(NAMES[c])
                    })
            };
            let exprs = [
                chain(Some(Vec::new()))?,
                chain(iu.map(|i| vec![i; 4]))?,
                chain(iv.map(|i| vec![i; 4]))?,
                chain(iu.zip(iv).map(|(i, j)| vec![i, j, j, j, j]))?,
            ];
            for (o, e) in programs[c].iter_mut().zip(exprs) {
                if let Some(expr) = e {
                    let parsed = Parsed {
                        expr,
                        slots: slots.clone(),
                    };
                    let tree = program::tree(&parsed, &UV)?;
                    *o = Some(Program::new(&tree, 2, &[0]));
                }
            }
        }
        Ok(FourthPartials { programs })
    }
}

/// Rows `u = const` of a parametric surface through the compiled programs.
struct Rows<'a> {
    surface: &'a ParametricSurface,
    vs: &'a [f64],
}

impl Rows<'_> {
    /// Partial `k` of the three components along the row, into `out[c·n .. (c+1)·n]`.
    fn fill(&self, k: usize, u: f64, out: &mut [f64]) {
        let n = self.vs.len();
        for (c, o) in out.chunks_mut(n).take(3).enumerate() {
            self.surface.comps[c].row(k, u, self.vs, o);
        }
    }
}

fn at(buf: &[f64], n: usize, j: usize) -> Vec3 {
    Vec3::new(buf[j], buf[n + j], buf[2 * n + j])
}

impl RowEvaluator for Rows<'_> {
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        let n = self.vs.len();
        let comps = &self.surface.comps;
        comps[0].row(0, u, self.vs, &mut row.x);
        comps[1].row(0, u, self.vs, &mut row.y);
        comps[2].row(0, u, self.vs, &mut row.z);
        row.scratch.resize(9 * n, 0.0);
        let (xu, rest) = row.scratch.split_at_mut(3 * n);
        let (xv, xuv) = rest.split_at_mut(3 * n);
        self.fill(1, u, xu);
        self.fill(2, u, xv);
        self.fill(4, u, xuv);
        for j in 0..n {
            let p = Partials {
                xu: at(xu, n, j),
                xv: at(xv, n, j),
                xuv: at(xuv, n, j),
                ..Partials::default()
            };
            let nrm = p.normal();
            (row.nx[j], row.ny[j], row.nz[j]) = (nrm.x, nrm.y, nrm.z);
        }
    }
}

impl PartialsRows for Rows<'_> {
    fn eval_row(&self, u: f64, out: &mut [Partials]) {
        let n = self.vs.len();
        let mut buf = vec![0.0; 18 * n];
        for (k, b) in buf.chunks_mut(3 * n).enumerate() {
            self.fill(k, u, b);
        }
        let b = |k: usize, j: usize| at(&buf[3 * n * k..], n, j);
        for (j, o) in out.iter_mut().enumerate().take(n) {
            *o = Partials {
                x: b(0, j),
                xu: b(1, j),
                xv: b(2, j),
                xuu: b(3, j),
                xuv: b(4, j),
                xvv: b(5, j),
            };
        }
    }
}

impl Surface for ParametricSurface {
    fn v_domain(&self) -> VDomain {
        self.domain
    }

    fn u_range(&self) -> Interval {
        self.u_range
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(Rows { surface: self, vs })
    }

    fn partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn PartialsRows + 'a> {
        Box::new(Rows { surface: self, vs })
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        Partials {
            x: self.values(0, u, v),
            xu: self.values(1, u, v),
            xv: self.values(2, u, v),
            xuu: self.values(3, u, v),
            xuv: self.values(4, u, v),
            xvv: self.values(5, u, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partials_are_exact() {
        let s = ParametricSurface::new(
            "(2 + cos(2*pi*u))*cos(v)",
            "(2 + cos(2*pi*u))*sin(v)",
            "sin(2*pi*u) + u^2*v",
            VDomain::Interval(0.0, 1.0),
        )
        .unwrap();
        let (u, v) = (0.3, 0.8);
        let p = s.partials(u, v);
        let k = 2.0 * std::f64::consts::PI;
        let w = 2.0 + (k * u).cos();
        let want = Partials {
            x: Vec3::new(w * v.cos(), w * v.sin(), (k * u).sin() + u * u * v),
            xu: Vec3::new(
                -k * (k * u).sin() * v.cos(),
                -k * (k * u).sin() * v.sin(),
                k * (k * u).cos() + 2.0 * u * v,
            ),
            xv: Vec3::new(-w * v.sin(), w * v.cos(), u * u),
            xuu: Vec3::new(
                -k * k * (k * u).cos() * v.cos(),
                -k * k * (k * u).cos() * v.sin(),
                -k * k * (k * u).sin() + 2.0 * v,
            ),
            xuv: Vec3::new(
                k * (k * u).sin() * v.sin(),
                -k * (k * u).sin() * v.cos(),
                2.0 * u,
            ),
            xvv: Vec3::new(-w * v.cos(), -w * v.sin(), 0.0),
        };
        for (a, b) in [
            (p.x, want.x),
            (p.xu, want.xu),
            (p.xv, want.xv),
            (p.xuu, want.xuu),
            (p.xuv, want.xuv),
            (p.xvv, want.xvv),
        ] {
            assert!((a - b).norm() < 1e-13 * b.norm().max(1.0), "{a} {b}");
        }
        // Constants and one-variable formulas.
        let c = ParametricSurface::new("3", "u", "2*v", VDomain::Interval(0.0, 1.0)).unwrap();
        let p = c.partials(0.5, 0.25);
        assert_eq!(p.x, Vec3::new(3.0, 0.5, 0.5));
        assert_eq!(p.xu, Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(p.xv, Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(p.xuu + p.xuv + p.xvv, Vec3::zeros());
    }

    /// Rows through the compiled programs equal the point-wise partials (exmex) to rounding,
    /// normals included, on a torus with a pole-free and a degenerate (cone tip) surface.
    #[test]
    fn rows_equal_the_pointwise_partials() {
        for (x, y, z, domain) in [
            (
                "(2 + cos(2*pi*u))*cos(v)",
                "(2 + cos(2*pi*u))*sin(v)",
                "sin(2*pi*u) + u^2*v^3/(1 + v^2)",
                VDomain::Interval(0.0, TAU),
            ),
            ("u*cos(v)", "u*sin(v)", "u", VDomain::Periodic),
        ] {
            let s = ParametricSurface::new(x, y, z, domain).unwrap();
            let vs: Vec<f64> = (0..700).map(|j| TAU * j as f64 / 700.0).collect();
            let rows = s.partials_rows(&vs);
            let points = s.row_evaluator(&vs);
            let mut out = vec![Partials::default(); vs.len()];
            let mut row = RowBuf::new(vs.len());
            for &u in &[0.0, 0.3, 1.0] {
                rows.eval_row(u, &mut out);
                points.eval_row(u, &mut row);
                for (j, &v) in vs.iter().enumerate() {
                    let p = s.partials(u, v);
                    let scale = 1.0 + p.x.norm() + p.xuu.norm() + p.xvv.norm();
                    for (a, b) in [
                        (out[j].x, p.x),
                        (out[j].xu, p.xu),
                        (out[j].xv, p.xv),
                        (out[j].xuu, p.xuu),
                        (out[j].xuv, p.xuv),
                        (out[j].xvv, p.xvv),
                    ] {
                        assert!((a - b).norm() <= 1e-14 * scale, "{x} at {u}, {v}: {a} {b}");
                    }
                    assert!((row.point(j) - p.x).norm() <= 1e-14 * scale);
                    assert!(
                        (row.normal(j) - p.normal()).norm() <= 1e-12,
                        "{x} at {u}, {v}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_formulas_are_named() {
        let err = |x: &str, y: &str, d: VDomain| {
            ParametricSurface::new(x, y, "0", d)
                .unwrap_err()
                .to_string()
        };
        let per = VDomain::Periodic;
        assert_eq!(
            err("cos(v)", "w*u", per),
            "y: unknown variable 'w'; formulas use u and v"
        );
        assert!(err("cos(v", "0", per).starts_with("x: cannot parse 'cos(v'"));
        assert!(err("-u^2", "0", per).starts_with("x: '-u^2': the minus"));
        assert!(err("", "0", per).starts_with("x: the formula is empty"));
        assert!(
            err("1/u", "0", per).starts_with("x: evaluates to inf at u = 0, v = 0"),
            "{}",
            err("1/u", "0", per)
        );
        assert!(err("sqrt(u)", "0", per).starts_with("x: has ∂/∂u inf at u = 0"));
        assert!(err("v", "0", per).starts_with("x: not periodic in v"));
        assert!(err("v", "0", VDomain::Interval(1.0, 1.0)).starts_with("domain: the interval"));
        ParametricSurface::new("v", "u", "0", VDomain::Interval(-1.0, 2.0)).unwrap();
    }
}
