//! `[spline]` designs: the section checked and turned into a [`SplineProblem`] in `f64` or exact
//! rationals, and solved.

use crate::spec::{FixSpec, SplineOperatorSpec, SplineSpec, V3};
use crate::splinepde::{
    clamped_uniform, ring_indices, solve, Direction, Operator, Point, Scalar, Solve, SplineNet,
    SplineProblem,
};
use crate::{Error, Result, Vec3};
use num_rational::BigRational;
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
    /// Solved in `f64` (`exact = false`, the default).
    Float(SplineNet<f64>),
    /// Solved in exact rational arithmetic (`exact = true`).
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
    pub fn report(&self) -> &crate::splinepde::SolveReport {
        match self {
            SolvedSpline::Float(n) => &n.report,
            SolvedSpline::Exact(n) => &n.report,
        }
    }
    /// JSON export ([`crate::splinepde::export::to_json`]).
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            SolvedSpline::Float(n) => crate::splinepde::export::to_json(n),
            SolvedSpline::Exact(n) => crate::splinepde::export::to_json(n),
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
    // The dense systems of the solve: about six n × n matrices of the scalar (a rational takes
    // at least 64 bytes with its digits).
    let n = (nu * nv) as u64;
    let entry = if std::mem::size_of::<T>() <= 8 { 8 } else { 64 };
    crate::memory::check_items(
        n * n,
        6 * entry,
        &format!("solving for {nu} × {nv} control points"),
        "spline",
    )?;
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
                if e.kind() == crate::ErrorKind::Invalid {
                    Error::invalid(e.detail()).at("spline.fix")
                } else {
                    e
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
