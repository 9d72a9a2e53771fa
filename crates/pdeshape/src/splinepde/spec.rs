//! The `[spline]` section of a design file: a B-spline or Bézier surface solving a linear PDE
//! (see `docs/design-file.md`, section "[spline]").

use super::basis::Direction;
use super::bezier::{clamped_uniform, ring_indices};
use super::engine::{solve, Point, SplineNet, SplineProblem};
use super::linalg::Solve;
use super::operator::Operator;
use super::scalar::Scalar;
use crate::spec::V3;
use crate::{Error, Result, Vec3};
use num_rational::BigRational;
use schemars::JsonSchema;
use serde::{Deserialize, Deserializer};

/// `[spline]`: degrees, knots, the PDE, and the control points the designer fixes.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SplineSpec {
    /// Degrees `[p, q]` in u and v, each 1 to 20.
    pub degree: [usize; 2],
    /// Spans `[s_u, s_v]` of clamped uniform knot vectors on `[0, 1]` (default `[1, 1]`: a
    /// Bézier patch). Not allowed together with `knots_u`/`knots_v`.
    #[serde(default)]
    pub spans: Option<[usize; 2]>,
    /// The full knot vector in u (`n_u + p + 1` non-decreasing values); with `knots_v`.
    #[serde(default)]
    pub knots_u: Option<Vec<f64>>,
    /// The full knot vector in v (`n_v + q + 1` values); with `knots_u`.
    #[serde(default)]
    pub knots_v: Option<Vec<f64>>,
    /// The PDE (a table with `kind`).
    #[serde(deserialize_with = "deserialize_spline_operator")]
    #[schemars(with = "SplineOperatorSpec")]
    pub operator: SplineOperatorSpec,
    /// Solve in exact rational arithmetic (every number of the file taken at its exact binary
    /// value) instead of `f64` (default false).
    #[serde(default)]
    pub exact: bool,
    /// A whole control net, `n_u` rows of `n_v` points `[x, y, z]` (row `i` along u), from
    /// which `fix` takes the fixed points.
    #[serde(default)]
    pub net: Option<Vec<Vec<V3>>>,
    /// Which points of `net` are fixed: "boundary" (the outer ring), "two-rings" (boundary and
    /// the ring inside it), "first-last-rows" (rows `i = 0` and `i = n_u − 1`), or "all".
    #[serde(default)]
    pub fix: Option<FixSpec>,
    /// Individually fixed control points (added to those of `net`/`fix`).
    #[serde(default)]
    pub fixed: Vec<FixedPointSpec>,
}

/// Which points of `net` are fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, JsonSchema)]
pub enum FixSpec {
    #[serde(rename = "boundary")]
    Boundary,
    #[serde(rename = "two-rings")]
    TwoRings,
    #[serde(rename = "first-last-rows")]
    FirstLastRows,
    #[serde(rename = "all")]
    All,
}

/// One fixed control point.
#[derive(Clone, Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FixedPointSpec {
    /// `[i, j]`: `i` along u, `j` along v, from 0.
    pub index: [usize; 2],
    /// `[x, y, z]`.
    pub point: V3,
}

/// The PDE of a `[spline]` section.
#[derive(Clone, Debug, PartialEq, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "kind")]
pub enum SplineOperatorSpec {
    /// `a x_uu + b x_uv + c x_vv + d x_u + e x_v + f x = g` (coefficients default 0).
    #[serde(rename = "second-order")]
    Second {
        #[serde(default)]
        a: f64,
        #[serde(default)]
        b: f64,
        #[serde(default)]
        c: f64,
        #[serde(default)]
        d: f64,
        #[serde(default)]
        e: f64,
        #[serde(default)]
        f: f64,
        /// Constant right-hand side (default `[0, 0, 0]`).
        #[serde(default)]
        g: Option<V3>,
    },
    /// `a x_uuuu + b x_uuuv + c x_uuvv + d x_uvvv + e x_vvvv = 0` (coefficients default 0).
    #[serde(rename = "fourth-order")]
    Fourth {
        #[serde(default)]
        a: f64,
        #[serde(default)]
        b: f64,
        #[serde(default)]
        c: f64,
        #[serde(default)]
        d: f64,
        #[serde(default)]
        e: f64,
    },
    /// `x_uu + x_vv = 0`.
    #[serde(rename = "laplace")]
    Laplace {},
    /// `x_uuuu + 2 x_uuvv + x_vvvv = 0` (`L_{1,0,2,0,1}`).
    #[serde(rename = "biharmonic")]
    Biharmonic {},
    /// `x_uuvv = 0` (`L_{0,0,1,0,0}`, the Coons functional).
    #[serde(rename = "coons")]
    Coons {},
    /// `x_uuuu + 2a² x_uuvv + a⁴ x_vvvv = 0` (`F_a = L_{1,0,2a²,0,a⁴}`).
    #[serde(rename = "modified-biharmonic")]
    ModifiedBiharmonic { a: f64 },
}

fn deserialize_spline_operator<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<SplineOperatorSpec, D::Error> {
    let table = toml::Table::deserialize(d)?;
    crate::spec::deserialize_tagged(table, "kind", "")
}

impl SplineOperatorSpec {
    /// The operator.
    pub fn operator(&self) -> Operator {
        match *self {
            SplineOperatorSpec::Second {
                a,
                b,
                c,
                d,
                e,
                f,
                g,
            } => Operator::Second {
                a,
                b,
                c,
                d,
                e,
                f,
                g: g.map(Vec3::from).unwrap_or_else(Vec3::zeros),
            },
            SplineOperatorSpec::Fourth { a, b, c, d, e } => Operator::fourth(a, b, c, d, e),
            SplineOperatorSpec::Laplace {} => Operator::laplace(),
            SplineOperatorSpec::Biharmonic {} => Operator::biharmonic(),
            SplineOperatorSpec::Coons {} => Operator::coons(),
            SplineOperatorSpec::ModifiedBiharmonic { a } => Operator::modified_biharmonic(a),
        }
    }
}

/// A solved `[spline]` section in the arithmetic it asked for.
#[derive(Clone, Debug)]
pub enum SolvedSpline {
    Float(SplineNet<f64>),
    Exact(SplineNet<BigRational>),
}

impl SolvedSpline {
    /// The net in `f64`.
    pub fn to_f64(&self) -> SplineNet<f64> {
        match self {
            SolvedSpline::Float(n) => n.clone(),
            SolvedSpline::Exact(n) => n.to_f64(),
        }
    }
    /// The solve report.
    pub fn report(&self) -> &super::SolveReport {
        match self {
            SolvedSpline::Float(n) => &n.report,
            SolvedSpline::Exact(n) => &n.report,
        }
    }
    /// JSON export ([`super::export::to_json`]).
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            SolvedSpline::Float(n) => super::export::to_json(n),
            SolvedSpline::Exact(n) => super::export::to_json(n),
        }
    }
}

fn finite(x: f64, place: &str) -> Result<()> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(format!("must be finite (got {x})")).at(place))
    }
}

fn direction<T: Scalar>(spec: &SplineSpec, axis: usize, name: &str) -> Result<Direction<T>> {
    let p = spec.degree[axis];
    let knots = if axis == 0 {
        &spec.knots_u
    } else {
        &spec.knots_v
    };
    match knots {
        Some(k) => {
            let mut out = Vec::with_capacity(k.len());
            for (i, x) in k.iter().enumerate() {
                finite(*x, &format!("spline.knots_{name}[{i}]"))?;
                out.push(T::from_f64(*x).unwrap_or_else(T::zero));
            }
            Ok(Direction {
                degree: p,
                knots: out,
            })
        }
        None => {
            let s = spec.spans.unwrap_or([1, 1])[axis];
            Ok(clamped_uniform(p, s))
        }
    }
}

/// Checks the section and builds the problem in the scalar `T`.
pub fn build_problem<T: Scalar>(spec: &SplineSpec) -> Result<SplineProblem<T>> {
    for (k, &p) in spec.degree.iter().enumerate() {
        if !(1..=20).contains(&p) {
            return Err(
                Error::invalid(format!("must be between 1 and 20 (got {p})"))
                    .at(&format!("spline.degree[{k}]")),
            );
        }
    }
    match (&spec.knots_u, &spec.knots_v, &spec.spans) {
        (Some(_), Some(_), None) | (None, None, _) => {}
        (Some(_), Some(_), Some(_)) => {
            return Err(
                Error::invalid("give either spans or knots_u and knots_v, not both")
                    .at("spline.spans"),
            )
        }
        (Some(_), None, _) => {
            return Err(Error::invalid("knots_u needs knots_v too").at("spline.knots_u"))
        }
        (None, Some(_), _) => {
            return Err(Error::invalid("knots_v needs knots_u too").at("spline.knots_v"))
        }
    }
    if let Some(s) = spec.spans {
        for (k, &n) in s.iter().enumerate() {
            if !(1..=1000).contains(&n) {
                return Err(
                    Error::invalid(format!("must be between 1 and 1000 (got {n})"))
                        .at(&format!("spline.spans[{k}]")),
                );
            }
        }
    }
    let u: Direction<T> = direction(spec, 0, "u")?;
    let v: Direction<T> = direction(spec, 1, "v")?;
    u.check("u").map_err(|e| e.at("spline"))?;
    v.check("v").map_err(|e| e.at("spline"))?;
    let (nu, nv) = (u.count(), v.count());
    if nu * nv > 10_000 {
        return Err(Error::invalid(format!(
            "{nu} × {nv} control points: at most 10000 are solved for (dense linear algebra)"
        ))
        .at("spline"));
    }
    let op = spec.operator.operator();
    op.check().map_err(|e| e.at("spline.operator"))?;
    if let SplineOperatorSpec::ModifiedBiharmonic { a } = spec.operator {
        finite(a, "spline.operator.a")?;
    }
    let point = |x: &V3, place: &str| -> Result<Point<T>> {
        for (d, c) in x.iter().enumerate() {
            finite(*c, &format!("{place}[{d}]"))?;
        }
        Ok([
            T::from_f64(x[0]).unwrap_or_else(T::zero),
            T::from_f64(x[1]).unwrap_or_else(T::zero),
            T::from_f64(x[2]).unwrap_or_else(T::zero),
        ])
    };
    let mut fixed: Vec<([usize; 2], Point<T>)> = Vec::new();
    let mut from_net = std::collections::HashSet::new();
    match (&spec.net, spec.fix) {
        (Some(net), Some(fix)) => {
            if net.len() != nu {
                return Err(Error::invalid(format!(
                    "needs n_u = {nu} rows of control points (got {})",
                    net.len()
                ))
                .at("spline.net"));
            }
            for (i, row) in net.iter().enumerate() {
                if row.len() != nv {
                    return Err(Error::invalid(format!(
                        "needs n_v = {nv} points (got {})",
                        row.len()
                    ))
                    .at(&format!("spline.net[{i}]")));
                }
            }
            let idx: Vec<[usize; 2]> = match fix {
                FixSpec::Boundary => ring_indices([nu - 1, nv - 1], 1),
                FixSpec::TwoRings => ring_indices([nu - 1, nv - 1], 2),
                FixSpec::FirstLastRows => (0..nv).flat_map(|j| [[0, j], [nu - 1, j]]).collect(),
                FixSpec::All => ring_indices([nu - 1, nv - 1], usize::MAX),
            };
            for [i, j] in idx {
                if from_net.insert([i, j]) {
                    fixed.push(([i, j], point(&net[i][j], &format!("spline.net[{i}][{j}]"))?));
                }
            }
        }
        (Some(_), None) => {
            return Err(Error::invalid(
                "a net needs `fix` (boundary, two-rings, first-last-rows or all) to say which points are fixed",
            )
            .at("spline.net"))
        }
        (None, Some(_)) => {
            return Err(Error::invalid("`fix` takes its points from `net`, which is missing")
                .at("spline.fix"))
        }
        (None, None) => {}
    }
    let mut seen = std::collections::HashMap::new();
    for (k, f) in spec.fixed.iter().enumerate() {
        let [i, j] = f.index;
        let place = format!("spline.fixed[{k}].index");
        if i >= nu || j >= nv {
            return Err(Error::invalid(format!(
                "control point [{i}, {j}] does not exist: the net has {nu} × {nv} points (indices from 0)"
            ))
            .at(&place));
        }
        if from_net.contains(&[i, j]) {
            return Err(Error::invalid(format!(
                "control point [{i}, {j}] is already fixed by `net` and `fix`"
            ))
            .at(&place));
        }
        if let Some(prev) = seen.insert([i, j], k) {
            return Err(Error::invalid(format!(
                "control point [{i}, {j}] is already fixed by spline.fixed[{prev}]"
            ))
            .at(&place));
        }
        fixed.push((
            f.index,
            point(&f.point, &format!("spline.fixed[{k}].point"))?,
        ));
    }
    Ok(SplineProblem {
        u,
        v,
        operator: op,
        fixed,
    })
}

/// Solves a `[spline]` section (in exact arithmetic if it asks for it).
pub fn solve_spec(spec: &SplineSpec) -> Result<SolvedSpline> {
    fn go<T: Solve>(spec: &SplineSpec) -> Result<SplineNet<T>> {
        let problem = build_problem::<T>(spec)?;
        solve(&problem).map_err(|e| {
            // A contradiction involves all fixed points; point at the key that fixed them.
            if e.place() == "spline.fixed" && spec.fixed.is_empty() && spec.net.is_some() {
                match e {
                    Error::Invalid { message, .. } => Error::invalid(message).at("spline.fix"),
                    other => other,
                }
            } else {
                e
            }
        })
    }
    if spec.exact {
        go::<BigRational>(spec).map(SolvedSpline::Exact)
    } else {
        go::<f64>(spec).map(SolvedSpline::Float)
    }
}
