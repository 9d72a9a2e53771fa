//! Design for function (book chapter 7): design parameters on the boundary curves (§7.5), an
//! objective built from the design's integrals, constraints, and a search by simulated
//! annealing (§7.3–7.4) with a Nelder–Mead polish.
//!
//! ```text
//! DesignSpec + [optimize] ──Problem::new──▶ parameters x (bounds), objective, constraints
//!     x ──Parameters::apply──▶ DesignSpec ──build_design──▶ SolvedDesign ──integrals──▶ f(x)
//!     anneal::minimize(f) ──▶ best x ──Parameters::apply_to_text──▶ the optimised design file
//! ```
//!
//! The variables of the objective and constraint formulas are the integrals of the whole design
//! (all patches; [`crate::analysis::integrate_design`], whose conventions they keep: `H` with
//! respect to the outward normal, so `H = −1/R` on a sphere):
//!
//! | name | value |
//! |---|---|
//! | `area` | `A = ∫ dA` |
//! | `volume` | `V`, the enclosed volume (open boundaries closed by caps) |
//! | `mean` | `∫ H dA` |
//! | `mean_sq` | `∫ H² dA` |
//! | `gauss` | `∫ K dA` |
//! | `bending` | `∫ (κ₁² + κ₂²) dA = ∫ (4H² − 2K) dA` (§7.5) |
//! | `willmore` | `∫ (2H)² dA` (16π for any sphere) |
//! | `helfrich` | `∫ (C₁ + C₂ − C₀)² dA` (Eq. 7.8 with its square restored, without the constant Gaussian term; 16π for any sphere at `C₀ = 0`) |
//! | `nu` | reduced volume `ν = V / (4π R₀³ / 3)`, `R₀ = √(A / 4π)` (Eq. 7.9 corrected) |
//! | `c0` | reduced spontaneous curvature `c₀ = C₀ R₀` (Eq. 7.10) |
//! | `C0` | the spontaneous curvature `C₀` of `[optimize]` |
//!
//! Constraints (equalities such as a fixed volume, area or `ν`, and inequalities) are enforced by
//! the quadratic penalty `w · violation²` added to the objective; bounds by the crude penalty of
//! §7.4.2 (see [`anneal`]).

pub mod anneal;
#[cfg(test)]
mod measure;
mod params;

pub use crate::spec::{ConstraintSpec, OptimizeSpec, ParameterSpec};
pub use anneal::{minimize, nelder_mead, Record, SearchOptions, SearchResult};
pub use params::{ParamKind, Parameter, Parameters};

use crate::analysis::{integrate_design, Integrals, Quadrature};
use crate::design::{solve_design, SolvedDesign};
use crate::formula::{self, Parsed, Variables};
use crate::spec::DesignSpec;
use crate::{Error, Result};
use exmex::FloatOpsFactory;

/// The variables formulas may use, in this order in [`Evaluation::variables`].
pub const VARIABLES: [&str; 11] = [
    "area", "volume", "mean", "mean_sq", "gauss", "bending", "willmore", "helfrich", "nu", "c0",
    "C0",
];

/// Most quadrature points per direction for the search.
const MAX_QUADRATURE: usize = 4096;

/// The values of [`VARIABLES`] for the integrals `t` of a design and the spontaneous curvature
/// `c0_abs` (`C₀`).
pub fn variables(t: &Integrals, c0_abs: f64) -> [f64; 11] {
    [
        t.area,
        t.volume,
        t.mean,
        t.mean_sq,
        t.gauss,
        t.bending_energy(),
        t.willmore(),
        t.helfrich(c0_abs),
        t.reduced_volume(),
        t.reduced_spontaneous_curvature(c0_abs),
        c0_abs,
    ]
}

/// The integrals of a built design with `qu` Gauss–Legendre nodes in `u` (rounded up to a
/// multiple of 8) and `qv` trapezoid nodes in a periodic `v`, one fixed level
/// ([`Quadrature::fixed`]): cheap and, for the smooth patches of a search, accurate (see the
/// tests).
pub fn measure(built: &SolvedDesign, qu: usize, qv: usize) -> Result<Integrals> {
    let t = integrate_design(built, &Quadrature::fixed(qu, qv))?.total;
    if [t.area, t.volume, t.mean, t.mean_sq, t.gauss]
        .iter()
        .all(|x| x.is_finite())
    {
        Ok(t)
    } else {
        Err(Error::invalid(format!(
            "the design's integrals are not finite (area {}, volume {}, ∫H² dA {})",
            t.area, t.volume, t.mean_sq
        )))
    }
}

/// A formula over [`VARIABLES`], parsed.
#[derive(Clone, Debug)]
struct Formula {
    text: String,
    parsed: Parsed<f64, FloatOpsFactory<f64>>,
}

impl Formula {
    fn parse(text: &str, place: &str) -> Result<Formula> {
        let parsed = formula::parse(text, &Variables::this(&VARIABLES)).map_err(|e| e.at(place))?;
        Ok(Formula {
            text: text.to_string(),
            parsed,
        })
    }

    fn eval(&self, vars: &[f64; 11]) -> f64 {
        self.parsed.eval(vars).unwrap_or(f64::NAN)
    }
}

/// A constraint with its penalty.
#[derive(Clone, Debug)]
struct Constraint {
    formula: Formula,
    equal: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    weight: f64,
}

impl Constraint {
    fn new(c: &ConstraintSpec, place: &str) -> Result<Constraint> {
        let formula = Formula::parse(&c.expr, &format!("{place}.expr"))?;
        for (key, v) in [("equal", c.equal), ("min", c.min), ("max", c.max)] {
            if let Some(v) = v {
                if !v.is_finite() {
                    return Err(Error::invalid(format!("must be finite (got {v})"))
                        .at(&format!("{place}.{key}")));
                }
            }
        }
        match (c.equal, c.min, c.max) {
            (None, None, None) => {
                return Err(Error::invalid("give `equal`, or `min` and/or `max`").at(place))
            }
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                return Err(
                    Error::invalid("an equality constraint takes no `min` or `max`").at(place),
                )
            }
            (None, Some(lo), Some(hi)) if lo > hi => {
                return Err(
                    Error::invalid(format!("must be at least min = {lo} (got {hi})"))
                        .at(&format!("{place}.max")),
                )
            }
            _ => {}
        }
        if !(c.weight > 0.0 && c.weight.is_finite()) {
            return Err(
                Error::invalid(format!("must be positive and finite (got {})", c.weight))
                    .at(&format!("{place}.weight")),
            );
        }
        Ok(Constraint {
            formula,
            equal: c.equal,
            min: c.min,
            max: c.max,
            weight: c.weight,
        })
    }

    /// `w · violation²`.
    fn penalty(&self, vars: &[f64; 11]) -> f64 {
        let g = self.formula.eval(vars);
        let violation = if let Some(t) = self.equal {
            g - t
        } else if self.min.is_some_and(|lo| g < lo) {
            g - self.min.unwrap_or(g)
        } else if self.max.is_some_and(|hi| g > hi) {
            g - self.max.unwrap_or(g)
        } else if g.is_nan() {
            f64::NAN
        } else {
            0.0
        };
        self.weight * violation * violation
    }
}

/// One evaluated design.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// The objective formula's value.
    pub objective: f64,
    /// The constraint penalties' sum.
    pub penalty: f64,
    /// The values of [`VARIABLES`].
    pub variables: [f64; 11],
}

impl Evaluation {
    /// `objective + penalty`, the value minimised.
    pub fn total(&self) -> f64 {
        self.objective + self.penalty
    }
}

/// An optimisation problem read from a design's `[optimize]` section.
#[derive(Clone, Debug)]
pub struct Problem {
    /// The design as written (the parameters act on a copy of it).
    pub base: DesignSpec,
    pub parameters: Parameters,
    objective: Formula,
    constraints: Vec<Constraint>,
    /// `C₀`.
    pub spontaneous_curvature: f64,
    /// Quadrature points `(u, v)` per patch.
    pub quadrature: (usize, usize),
    pub options: SearchOptions,
}

/// The outcome of [`Problem::run`].
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The search.
    pub search: SearchResult,
    /// The start point and its evaluation (`None` if the design at the start fails).
    pub start: (Vec<f64>, Option<Evaluation>),
    /// The best point and its evaluation.
    pub best: (Vec<f64>, Evaluation),
}

impl Problem {
    /// Reads `[optimize]` (which must be present) and checks it against the design: every
    /// error names its place (`optimize.parameters[2].name`, `optimize.objective`, …).
    pub fn new(spec: &DesignSpec) -> Result<Problem> {
        let opt = spec
            .optimize
            .as_ref()
            .ok_or_else(|| Error::invalid("the design has no [optimize] section").at("optimize"))?;
        crate::design::validate_design(spec)?;
        let parameters = Parameters::new(spec, opt)?;
        let objective = Formula::parse(&opt.objective, "optimize.objective")?;
        let constraints = opt
            .constraints
            .iter()
            .enumerate()
            .map(|(i, c)| Constraint::new(c, &format!("optimize.constraints[{i}]")))
            .collect::<Result<Vec<_>>>()?;
        if !opt.spontaneous_curvature.is_finite() {
            return Err(Error::invalid(format!(
                "must be finite (got {})",
                opt.spontaneous_curvature
            ))
            .at("optimize.spontaneous_curvature"));
        }
        for (key, q, least) in [
            ("quadrature_u", opt.quadrature_u, 2),
            ("quadrature_v", opt.quadrature_v, 3),
        ] {
            if !(least..=MAX_QUADRATURE).contains(&q) {
                return Err(Error::invalid(format!(
                    "must be between {least} and {MAX_QUADRATURE} (got {q})"
                ))
                .at(&format!("optimize.{key}")));
            }
        }
        let options = SearchOptions {
            seed: opt.seed,
            evaluations: opt.evaluations,
            chains: opt.chains,
            polish: opt.polish,
            cooling: opt.cooling,
            temperature: opt.temperature,
        };
        options.check()?;
        Ok(Problem {
            base: spec.clone(),
            parameters,
            objective,
            constraints,
            spontaneous_curvature: opt.spontaneous_curvature,
            quadrature: (opt.quadrature_u, opt.quadrature_v),
            options,
        })
    }

    /// The design with the parameters `x` applied.
    pub fn design(&self, x: &[f64]) -> DesignSpec {
        self.parameters.apply(&self.base, x)
    }

    /// Builds the design at `x`, integrates it and evaluates the objective and the penalties.
    pub fn evaluate(&self, x: &[f64]) -> Result<Evaluation> {
        let built = solve_design(&self.design(x))?;
        let totals = measure(&built, self.quadrature.0, self.quadrature.1)?;
        Ok(self.evaluate_totals(&totals))
    }

    /// The objective and penalties for given integrals.
    pub fn evaluate_totals(&self, totals: &Integrals) -> Evaluation {
        let variables = variables(totals, self.spontaneous_curvature);
        let objective = self.objective.eval(&variables);
        let penalty = 0.0
            + self
                .constraints
                .iter()
                .map(|c| c.penalty(&variables))
                .sum::<f64>();
        Evaluation {
            objective,
            penalty,
            variables,
        }
    }

    /// The value minimised at `x`: objective plus penalties, +∞ where the design fails.
    pub fn value(&self, x: &[f64]) -> f64 {
        match self.evaluate(x) {
            Ok(e) => {
                let t = e.total();
                if t.is_nan() {
                    f64::INFINITY
                } else {
                    t
                }
            }
            Err(_) => f64::INFINITY,
        }
    }

    /// The objective's text.
    pub fn objective_text(&self) -> &str {
        &self.objective.text
    }

    /// Runs the search ([`anneal::minimize`]) from the parameters' initial values;
    /// `report(evaluations, best)` is called after each evaluation.
    pub fn run(&self, report: &(dyn Fn(usize, f64) + Sync)) -> Result<Outcome> {
        let x0 = self.parameters.initial();
        let search = minimize(
            &|x: &[f64]| self.value(x),
            &self.parameters.bounds(),
            &x0,
            &self.options,
            report,
        )?;
        if !search.value.is_finite() {
            return Err(Error::invalid(
                "no design in the search could be built and measured: every evaluation failed",
            )
            .at("optimize"));
        }
        let best = self.evaluate(&search.x).map_err(|e| e.at("optimize"))?;
        let start = self.evaluate(&x0).ok();
        Ok(Outcome {
            best: (search.x.clone(), best),
            start: (x0, start),
            search,
        })
    }
}

#[cfg(test)]
mod tests;
