//! `[dynamic]` designs: the section checked and turned into a dynamic PDE curve run or an
//! interpolation problem (`pdeshape curve`).

use crate::dynamic::formula::{field_formula, scalar_formula, Expression};
use crate::dynamic::interp::{Interpolation, ParamMode};
use crate::dynamic::{Component, DynamicCurve, TimeGrid};
use crate::spec::{ComponentSpec, DynamicSpec, FormulaText, ParamsSpec};
use crate::{Error, Result, Vec3};

/// Most grid intervals `J` a design may ask for.
pub const MAX_INTERVALS: usize = 1_000_000;

/// A general run, built.
pub struct DynamicRun {
    /// The components `[dynamic.x]` (and `y`, `z` when given), in that order, with their
    /// coefficients, force, end conditions and initial data parsed.
    pub curve: DynamicCurve,
    /// The intervals `J`, steps `L` and final time `T` (checked).
    pub grid: TimeGrid,
    /// `check_positivity`: refuse a level where `a < 0`, `b < 0` or `d ≤ 0`.
    pub positivity: bool,
    /// Exact solutions `x(u, t)` given per component.
    pub exact: Vec<Option<Expression>>,
}

/// What a `[dynamic]` section asks for.
pub enum DynamicPlan {
    /// A general run of the scheme (the section has components `[dynamic.x]`, …).
    Run(DynamicRun),
    /// An interpolation of data points (§4; the section has `points`).
    Interpolate {
        /// The problem: the paper's set-up with the section's points, end conditions and
        /// constants.
        problem: Interpolation,
        /// 2 or 3: the number of coordinates of the data.
        dim: usize,
    },
}

/// What `pdeshape curve` does with a `[dynamic]` section.
pub struct BuiltDynamic {
    /// The run or interpolation to carry out.
    pub plan: DynamicPlan,
    /// Frames every this many levels.
    pub frames_every: usize,
}

const INTERPOLATION_KEYS: [&str; 15] = [
    "points",
    "start",
    "end",
    "start_tangent",
    "end_tangent",
    "stiffness",
    "tension",
    "damping",
    "k",
    "eps",
    "tolerance",
    "dt",
    "speed",
    "max_steps",
    "params",
];

impl DynamicSpec {
    fn interpolation_keys(&self) -> Vec<&'static str> {
        let present = [
            self.points.is_some(),
            self.start.is_some(),
            self.end.is_some(),
            self.start_tangent.is_some(),
            self.end_tangent.is_some(),
            self.stiffness.is_some(),
            self.tension.is_some(),
            self.damping.is_some(),
            self.k.is_some(),
            self.eps.is_some(),
            self.tolerance.is_some(),
            self.dt.is_some(),
            self.speed.is_some(),
            self.max_steps.is_some(),
            self.params.is_some(),
        ];
        INTERPOLATION_KEYS
            .iter()
            .zip(present)
            .filter(|(_, p)| *p)
            .map(|(k, _)| *k)
            .collect()
    }
}

fn formula_at<T>(f: &FormulaText, place: &str, parse: impl FnOnce(&str) -> Result<T>) -> Result<T> {
    parse(&f.text()).map_err(|e| e.at(place))
}

fn build_component(c: &ComponentSpec, place: &str) -> Result<(Component, Option<Expression>)> {
    let fld = |v: &Option<FormulaText>, key: &str| -> Result<crate::dynamic::Field> {
        match v {
            Some(f) => formula_at(f, &format!("{place}.{key}"), field_formula),
            None => Ok(crate::dynamic::constant_field(0.0)),
        }
    };
    let sc = |f: &FormulaText, key: &str, var: &str| {
        formula_at(f, &format!("{place}.{key}"), |t| scalar_formula(t, var))
    };
    let comp = Component {
        a: fld(&c.a, "a")?,
        b: fld(&c.b, "b")?,
        d: formula_at(&c.d, &format!("{place}.d"), field_formula)?,
        f: fld(&c.f, "f")?,
        start: sc(&c.start, "start", "t")?,
        end: sc(&c.end, "end", "t")?,
        start_slope: sc(&c.start_slope, "start_slope", "t")?,
        end_slope: sc(&c.end_slope, "end_slope", "t")?,
        position: sc(&c.position, "position", "u")?,
        velocity: match &c.velocity {
            Some(f) => sc(f, "velocity", "u")?,
            None => crate::dynamic::constant(0.0),
        },
    };
    let exact = c
        .exact
        .as_ref()
        .map(|f| {
            formula_at(f, &format!("{place}.exact"), |t| {
                Expression::parse(t, &["u", "t"])
            })
        })
        .transpose()?;
    Ok((comp, exact))
}

fn vector(v: &[f64], dim: usize, place: &str) -> Result<Vec3> {
    if v.len() != dim {
        return Err(Error::invalid(format!(
            "has {} coordinates; the data of this design have {dim}",
            v.len()
        ))
        .at(place));
    }
    let mut p = Vec3::zeros();
    for (i, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(
                Error::invalid(format!("must be finite (got {x})")).at(&format!("{place}[{i}]"))
            );
        }
        p[i] = *x;
    }
    Ok(p)
}

fn intervals_checked(j: usize, place: &str) -> Result<usize> {
    if !(5..=MAX_INTERVALS).contains(&j) {
        return Err(Error::invalid(format!(
            "J = {j} intervals; must be between 5 and {MAX_INTERVALS}"
        ))
        .at(place));
    }
    Ok(j)
}

/// Validates and builds a `[dynamic]` section. Places are paths from the file's root
/// (`dynamic.x.d`, `dynamic.points[2]`).
pub fn build_dynamic(spec: &DynamicSpec) -> Result<BuiltDynamic> {
    let run_keys: Vec<&str> = [
        ("x", spec.x.is_some()),
        ("y", spec.y.is_some()),
        ("z", spec.z.is_some()),
        ("steps", spec.steps.is_some()),
        ("t_end", spec.t_end.is_some()),
        ("check_positivity", spec.check_positivity),
    ]
    .iter()
    .filter(|(_, p)| *p)
    .map(|(k, _)| *k)
    .collect();
    let interp_keys = spec.interpolation_keys();
    if let Some(e) = spec.frames_every {
        if e == 0 {
            return Err(Error::invalid("must be at least 1").at("dynamic.frames_every"));
        }
    }
    if spec.points.is_some() {
        if let Some(k) = run_keys.first() {
            return Err(Error::invalid(format!(
                "`{k}` belongs to a general run, but this section has `points` (an interpolation)"
            ))
            .at(&format!("dynamic.{k}")));
        }
        let problem_dim = build_interpolation(spec)?;
        let every = spec.frames_every.unwrap_or(1000);
        return Ok(BuiltDynamic {
            plan: DynamicPlan::Interpolate {
                problem: problem_dim.0,
                dim: problem_dim.1,
            },
            frames_every: every,
        });
    }
    if spec.x.is_none() {
        if let Some(k) = interp_keys.first() {
            return Err(Error::invalid(format!(
                "`{k}` belongs to an interpolation, which needs `points`"
            ))
            .at(&format!("dynamic.{k}")));
        }
        return Err(Error::invalid(
            "give either components [dynamic.x] (a general run) or `points` (an interpolation)",
        )
        .at("dynamic"));
    }
    if let Some(k) = interp_keys.first() {
        return Err(Error::invalid(format!(
            "`{k}` belongs to an interpolation (with `points`), not to a general run"
        ))
        .at(&format!("dynamic.{k}")));
    }
    if spec.z.is_some() && spec.y.is_none() {
        return Err(Error::invalid("[dynamic.z] needs [dynamic.y]").at("dynamic.z"));
    }
    let missing = |k: &str| {
        Error::invalid(format!(
            "missing key `{k}`: a general run needs intervals, steps and t_end"
        ))
        .at("dynamic")
    };
    let grid = TimeGrid {
        intervals: intervals_checked(
            spec.intervals.ok_or_else(|| missing("intervals"))?,
            "dynamic.intervals",
        )?,
        steps: spec.steps.ok_or_else(|| missing("steps"))?,
        t_end: spec.t_end.ok_or_else(|| missing("t_end"))?,
    };
    grid.validate().map_err(|e| e.at("dynamic"))?;
    let mut components = Vec::new();
    let mut exact = Vec::new();
    for (name, c) in [("x", &spec.x), ("y", &spec.y), ("z", &spec.z)] {
        if let Some(c) = c {
            let (comp, ex) = build_component(c, &format!("dynamic.{name}"))?;
            components.push(comp);
            exact.push(ex);
        }
    }
    let every = spec
        .frames_every
        .unwrap_or_else(|| (grid.steps / 10).max(1));
    Ok(BuiltDynamic {
        plan: DynamicPlan::Run(DynamicRun {
            curve: DynamicCurve { components },
            grid,
            positivity: spec.check_positivity,
            exact,
        }),
        frames_every: every,
    })
}

fn build_interpolation(spec: &DynamicSpec) -> Result<(Interpolation, usize)> {
    let mut p = Interpolation::paper_example();
    let points = spec.points.as_ref().expect("checked by the caller");
    if points.is_empty() {
        return Err(Error::invalid("needs at least one interior point").at("dynamic.points"));
    }
    let dim = points[0].len();
    if !(2..=3).contains(&dim) {
        return Err(Error::invalid(format!(
            "has {dim} coordinates; points have 2 (planar) or 3 (space)"
        ))
        .at("dynamic.points[0]"));
    }
    p.points = points
        .iter()
        .enumerate()
        .map(|(i, q)| vector(q, dim, &format!("dynamic.points[{i}]")))
        .collect::<Result<_>>()?;
    let need = |v: &Option<Vec<f64>>, key: &str| -> Result<Vec3> {
        match v {
            Some(v) => vector(v, dim, &format!("dynamic.{key}")),
            None => Err(Error::invalid(format!(
                "missing key `{key}`: an interpolation needs start, end, start_tangent and end_tangent"
            ))
            .at("dynamic")),
        }
    };
    p.start = need(&spec.start, "start")?;
    p.end = need(&spec.end, "end")?;
    p.start_tangent = need(&spec.start_tangent, "start_tangent")?;
    p.end_tangent = need(&spec.end_tangent, "end_tangent")?;
    let set = |target: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *target = v;
        }
    };
    set(&mut p.stiffness, spec.stiffness);
    set(&mut p.tension, spec.tension);
    set(&mut p.damping, spec.damping);
    set(&mut p.k, spec.k);
    set(&mut p.eps, spec.eps);
    set(&mut p.tolerance, spec.tolerance);
    set(&mut p.dt, spec.dt);
    set(&mut p.speed, spec.speed);
    if let Some(m) = spec.max_steps {
        if m == 0 {
            return Err(Error::invalid("must be at least 1").at("dynamic.max_steps"));
        }
        p.max_steps = m;
    }
    if let Some(j) = spec.intervals {
        p.intervals = intervals_checked(j, "dynamic.intervals")?;
    }
    p.params = match spec.params.unwrap_or(ParamsSpec::Fixed) {
        ParamsSpec::Fixed => ParamMode::Fixed,
        ParamsSpec::ClosestEachStep => ParamMode::ClosestEachStep,
        ParamsSpec::ClosestEachUpdate => ParamMode::ClosestEachUpdate,
    };
    p.validate().map_err(|e| e.at("dynamic"))?;
    Ok((p, dim))
}
