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
//! | `mass` | the wall's mass `ρ t A` (kg) of the `[shell]` set-up (or its defaults): density × thickness × area in m²; no finite elements |
//! | `max_shear` | the largest shear stress `max (σ₁ − σ₃)/2` (Pa, Eq. 7.7) of a CalculiX shell analysis of the design ([`crate::shell`]) |
//! | `yield` | the `[shell]` material's yield stress (Pa), for constraints such as `max_shear / yield <= 0.3` |
//!
//! The shell analysis runs only when a formula uses `max_shear`: geometry-only problems (and
//! `mass`) pay nothing for it. Each evaluation runs its own solver in its own temporary
//! directory, so the chains (on their own threads) analyse in parallel. A failed analysis (the
//! solver fails, times out or its mesh is refused) makes that design infeasible (`+∞`), and
//! is counted ([`Outcome::solver_failures`]); a failed analysis of the starting design is an
//! error (the solver is missing or the set-up is wrong, and every evaluation would fail).
//!
//! A design is *feasible* when every inequality holds exactly and every equality within
//! [`EQUALITY_TOLERANCE`] relative to its target (at least 1 in absolute terms). With shell
//! measures the result is the best feasible design of the search, if any (the lowest objective
//! among feasible evaluations), since the penalised minimum may lie just outside a stress limit;
//! otherwise, as without them, the lowest objective plus penalties.
//!
//! Constraints (equalities such as a fixed volume, area or `ν`, and inequalities) are enforced by
//! the quadratic penalty `w · violation²` added to the objective; bounds by the crude penalty of
//! §7.4.2 (see [`anneal`]).

pub mod anneal;
mod gradient;
#[cfg(test)]
mod measure;
mod params;
mod search;
mod sqp;
mod values;

pub use crate::spec::{ConstraintSpec, OptimizeSpec, ParameterSpec};
pub use anneal::{minimize, nelder_mead, Record, SearchOptions, SearchResult};
pub use gradient::{
    d_variables, nonlinear_design, sensitivities, ConstraintGradient, Method, ProblemGradient,
    Sensitivities, SHEAR_ROUNDING, SHEAR_STEP,
};
pub use params::{ParamKind, Parameter, Parameters};
pub use search::{SearchMethod, SearchPlan, SearchRequest};
pub use sqp::{GradientOptions, GradientReport, Kkt, StartReport, KKT_ACTIVE};
pub use values::{apply_values, ValueError};

use crate::analysis::{
    integrate_design, integrate_design_keeping, DesignIntegrals, Integrals, NodePartials,
    Quadrature,
};
use crate::design::{solve_design, SolvedDesign};
use crate::formula::{self, Parsed, Variables};
use crate::shell::ShellSetup;
use crate::spec::DesignSpec;
use crate::{Error, Result};
use exmex::{Differentiate, FloatOpsFactory};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Number of [`VARIABLES`].
pub const NVARS: usize = 14;

/// The variables formulas may use, in this order in [`Evaluation::variables`].
pub const VARIABLES: [&str; NVARS] = [
    "area",
    "volume",
    "mean",
    "mean_sq",
    "gauss",
    "bending",
    "willmore",
    "helfrich",
    "nu",
    "c0",
    "C0",
    "mass",
    "max_shear",
    "yield",
];

/// The names the formula parser sees: [`VARIABLES`] with `max_shear` renamed, since the parser
/// reads a leading `max` as its operator.
const PARSED_NAMES: [&str; NVARS] = {
    let mut names = VARIABLES;
    names[MAX_SHEAR] = "shear_max";
    names
};

/// `text` with the identifier `max_shear` renamed as in [`PARSED_NAMES`].
fn rename_for_parser(text: &str) -> String {
    crate::formula::rename_identifiers(text, |word| {
        (word == VARIABLES[MAX_SHEAR]).then_some(PARSED_NAMES[MAX_SHEAR])
    })
}

/// Positions of the shell measures in [`VARIABLES`].
const MASS: usize = 11;
pub(crate) const MAX_SHEAR: usize = 12;
const YIELD: usize = 13;

/// Relative tolerance of an equality constraint for a design to count as feasible.
pub const EQUALITY_TOLERANCE: f64 = 1e-3;

/// Most quadrature points per direction for the search.
const MAX_QUADRATURE: usize = 4096;

/// The values of [`VARIABLES`] for the integrals `t` of a design and the spontaneous curvature
/// `c0_abs` (`C₀`); the shell measures (`mass`, `max_shear`, `yield`) are NaN here (the
/// [`Problem`] fills them in when its formulas use them).
pub fn variables(t: &Integrals, c0_abs: f64) -> [f64; NVARS] {
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
        f64::NAN,
        f64::NAN,
        f64::NAN,
    ]
}

/// The integrals of a built design with `qu` Gauss–Legendre nodes in `u` (rounded up to a
/// multiple of 8) and `qv` trapezoid nodes in a periodic `v`, one fixed level
/// ([`Quadrature::fixed`]): cheap and, for the smooth patches of a search, accurate (see the
/// tests).
pub fn measure(built: &SolvedDesign, qu: usize, qv: usize) -> Result<Integrals> {
    Ok(measure_patches(built, &Quadrature::fixed(qu, qv))?.total)
}

/// The integrals of a built design per patch and in total with the quadrature `q`; a total
/// that is not finite is an error.
fn measure_patches(built: &SolvedDesign, q: &Quadrature) -> Result<DesignIntegrals> {
    finite_measures(integrate_design(built, q)?)
}

/// [`measure_patches`] with the partials its quadratures and caps evaluated, for the
/// derivatives' adjoint at the same nodes.
fn measure_patches_keeping(
    built: &SolvedDesign,
    q: &Quadrature,
) -> Result<(DesignIntegrals, NodePartials)> {
    let (d, kept) = integrate_design_keeping(built, q)?;
    Ok((finite_measures(d)?, kept))
}

/// `d`, unless one of its total integrals is not finite.
fn finite_measures(d: DesignIntegrals) -> Result<DesignIntegrals> {
    let t = d.total;
    if [t.area, t.volume, t.mean, t.mean_sq, t.gauss]
        .iter()
        .all(|x| x.is_finite())
    {
        Ok(d)
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
    /// The symbolic partial derivatives in the formula's own variables (`parsed.slots` order),
    /// or why exmex cannot differentiate it.
    partials: std::result::Result<Vec<Parsed<f64, FloatOpsFactory<f64>>>, String>,
}

impl Formula {
    fn parse(text: &str, place: &str) -> Result<Formula> {
        let renamed = rename_for_parser(text);
        let parsed = formula::parse(&renamed, &Variables::this(&PARSED_NAMES)).map_err(|e| {
            let back = |m: String| {
                m.replace(&renamed, text)
                    .replace(PARSED_NAMES[MAX_SHEAR], VARIABLES[MAX_SHEAR])
            };
            if e.kind() == crate::ErrorKind::Invalid {
                let message = back(e.detail().to_string());
                e.with_message(message)
            } else {
                e
            }
            .at(place)
        })?;
        let partials = (0..parsed.slots.len())
            .map(|i| {
                parsed
                    .expr
                    .clone()
                    .partial(i)
                    .map(|expr| Parsed {
                        expr,
                        slots: parsed.slots.clone(),
                    })
                    .map_err(|e| e.to_string())
            })
            .collect();
        Ok(Formula {
            text: text.to_string(),
            parsed,
            partials,
        })
    }

    /// The value and the partial derivatives `∂f/∂VARIABLES[j]` (0 for variables the formula
    /// does not use), by exmex's symbolic differentiation.
    fn gradient(&self, vars: &[f64; NVARS]) -> Result<(f64, [f64; NVARS])> {
        let partials = self
            .partials
            .as_ref()
            .map_err(|e| Error::invalid(format!("cannot differentiate '{}': {e}", self.text)))?;
        let mut grad = [0.0; NVARS];
        for (p, &slot) in partials.iter().zip(&self.parsed.slots) {
            grad[slot] += p.eval(vars).unwrap_or(f64::NAN);
        }
        Ok((self.eval(vars), grad))
    }

    fn eval(&self, vars: &[f64; NVARS]) -> f64 {
        self.parsed.eval(vars).unwrap_or(f64::NAN)
    }

    fn uses(&self, slot: usize) -> bool {
        self.parsed.slots.contains(&slot)
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
    fn penalty(&self, vars: &[f64; NVARS]) -> f64 {
        let violation = self.violation(vars);
        self.weight * violation * violation
    }

    /// Whether the constraint holds: an inequality exactly, an equality within
    /// [`EQUALITY_TOLERANCE`] `· max(|target|, 1)`.
    fn holds(&self, vars: &[f64; NVARS]) -> bool {
        let v = self.violation(vars);
        match self.equal {
            Some(t) => v.abs() <= EQUALITY_TOLERANCE * t.abs().max(1.0),
            None => v == 0.0,
        }
    }

    /// The formula's distance outside its bounds (NaN where it cannot be evaluated).
    fn violation(&self, vars: &[f64; NVARS]) -> f64 {
        let g = self.formula.eval(vars);
        if let Some(t) = self.equal {
            g - t
        } else if self.min.is_some_and(|lo| g < lo) {
            g - self.min.unwrap_or(g)
        } else if self.max.is_some_and(|hi| g > hi) {
            g - self.max.unwrap_or(g)
        } else if g.is_nan() {
            f64::NAN
        } else {
            0.0
        }
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
    pub variables: [f64; NVARS],
    /// Whether every constraint holds (see the module documentation).
    pub feasible: bool,
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
    /// The parameters searched over, with their bounds.
    pub parameters: Parameters,
    objective: Formula,
    constraints: Vec<Constraint>,
    /// `C₀`.
    pub spontaneous_curvature: f64,
    /// Quadrature points `(u, v)` per patch.
    pub quadrature: (usize, usize),
    /// Options of the annealing search and its polish.
    pub options: SearchOptions,
    /// The shell analysis, when a formula uses `mass`, `max_shear` or `yield`.
    strength: Option<Strength>,
    /// What the search has seen so far (shared by the chains' threads).
    tracker: Arc<Tracker>,
}

/// The shell set-up of a problem whose formulas use the shell measures.
#[derive(Clone, Debug)]
struct Strength {
    setup: ShellSetup,
    /// Whether a formula uses `max_shear` (only then does CalculiX run).
    solve: bool,
}

/// The best feasible design seen and the failed analyses, updated by every evaluation.
#[derive(Debug, Default)]
struct Tracker {
    best_feasible: Mutex<Option<(f64, Vec<f64>)>>,
    solver_failures: AtomicUsize,
    first_failure: Mutex<Option<String>>,
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
    /// The best feasible point of the search and its evaluation, if any was feasible.
    pub best_feasible: Option<(Vec<f64>, Evaluation)>,
    /// Shell analyses that failed during the search (those designs counted as infeasible).
    pub solver_failures: usize,
    /// The first failed analysis's message.
    pub first_failure: Option<String>,
    /// Design solves made by the search (an annealing evaluation is one; a gradient is the
    /// point plus two per level of each approximate parameter, and, where its exact parameters
    /// are not batched, one per affine parameter and two per rotation).
    pub solves: usize,
    /// Batched tangent solves made by the gradient search: one per gradient of a design of
    /// analytic PDE patches, all its exact parameters' tangent curves as one block of
    /// right-hand sides ([`gradient::Sensitivities::tangent_solves`]); not counted in `solves`.
    pub tangent_solves: usize,
    /// What the gradient search reports (`None` for annealing alone).
    pub gradient: Option<GradientReport>,
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
        let uses =
            |slot: usize| objective.uses(slot) || constraints.iter().any(|c| c.formula.uses(slot));
        let strength = if uses(MASS) || uses(MAX_SHEAR) || uses(YIELD) {
            let built = solve_design(spec)?;
            let setup = ShellSetup::new(spec, &built.names())?;
            setup.check_size(built.surfaces.len(), "shell.elements")?;
            Some(Strength {
                setup,
                solve: uses(MAX_SHEAR),
            })
        } else {
            None
        };
        Ok(Problem {
            base: spec.clone(),
            parameters,
            objective,
            constraints,
            spontaneous_curvature: opt.spontaneous_curvature,
            quadrature: (opt.quadrature_u, opt.quadrature_v),
            options,
            strength,
            tracker: Arc::default(),
        })
    }

    /// The shell set-up, when the formulas use the shell measures.
    pub fn shell_setup(&self) -> Option<&ShellSetup> {
        self.strength.as_ref().map(|s| &s.setup)
    }

    /// Whether an evaluation runs the shell solver (a formula uses `max_shear`).
    pub fn runs_solver(&self) -> bool {
        self.strength.as_ref().is_some_and(|s| s.solve)
    }

    /// The best feasible design the current search has evaluated: `(objective, x)`.
    pub fn best_feasible(&self) -> Option<(f64, Vec<f64>)> {
        self.tracker
            .best_feasible
            .lock()
            .map(|b| b.clone())
            .unwrap_or(None)
    }

    /// `[mass, max_shear, yield]` of a built design (`max_shear` NaN unless a formula uses it).
    fn shell_values(
        &self,
        s: &Strength,
        built: &SolvedDesign,
        totals: &Integrals,
    ) -> Result<[f64; 3]> {
        let setup = &s.setup;
        let m2 = setup.metres * setup.metres;
        let mass = setup.material.density * setup.thickness * totals.area * m2;
        let max_shear = if s.solve {
            self.max_shear(setup, built)?
        } else {
            f64::NAN
        };
        Ok([mass, max_shear, setup.material.yield_stress])
    }

    /// The largest shear stress of a built design from a shell analysis; a failure is counted
    /// (and the first one kept) before it is returned.
    fn max_shear(&self, setup: &ShellSetup, built: &SolvedDesign) -> Result<f64> {
        let analysed = setup
            .model(built)
            .and_then(|model| crate::shell::analyse(&model, &setup.run_options()));
        analysed.map(|r| r.peak.value).inspect_err(|e| {
            self.tracker.solver_failures.fetch_add(1, Ordering::Relaxed);
            if let Ok(mut first) = self.tracker.first_failure.lock() {
                first.get_or_insert_with(|| e.to_string());
            }
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
        let shell = match &self.strength {
            Some(s) => Some(self.shell_values(s, &built, &totals)?),
            None => None,
        };
        Ok(self.evaluate_with(&totals, shell))
    }

    /// The objective and penalties for given integrals (the shell measures NaN).
    pub fn evaluate_totals(&self, totals: &Integrals) -> Evaluation {
        self.evaluate_with(totals, None)
    }

    /// The objective and penalties for given integrals and shell measures
    /// `[mass, max_shear, yield]`.
    pub fn evaluate_with(&self, totals: &Integrals, shell: Option<[f64; 3]>) -> Evaluation {
        let mut variables = variables(totals, self.spontaneous_curvature);
        if let Some(s) = shell {
            variables[MASS..=YIELD].copy_from_slice(&s);
        }
        self.evaluate_variables(variables)
    }

    /// The objective and penalties for given values of [`VARIABLES`].
    pub fn evaluate_variables(&self, variables: [f64; NVARS]) -> Evaluation {
        let objective = self.objective.eval(&variables);
        let penalty = 0.0
            + self
                .constraints
                .iter()
                .map(|c| c.penalty(&variables))
                .sum::<f64>();
        let feasible =
            objective.is_finite() && self.constraints.iter().all(|c| c.holds(&variables));
        Evaluation {
            objective,
            penalty,
            variables,
            feasible,
        }
    }

    /// The value minimised at `x`: objective plus penalties, +∞ where the design fails. A
    /// feasible design better than any before is remembered ([`Problem::best_feasible`]).
    pub fn value(&self, x: &[f64]) -> f64 {
        match self.evaluate(x) {
            Ok(e) => {
                if e.feasible {
                    if let Ok(mut best) = self.tracker.best_feasible.lock() {
                        if best.as_ref().is_none_or(|(f, _)| e.objective < *f) {
                            *best = Some((e.objective, x.to_vec()));
                        }
                    }
                }
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
        if let Ok(mut b) = self.tracker.best_feasible.lock() {
            *b = None;
        }
        if let Ok(mut f) = self.tracker.first_failure.lock() {
            *f = None;
        }
        self.tracker.solver_failures.store(0, Ordering::Relaxed);
        if self.runs_solver() {
            // The starting design's analysis first: a missing solver or a set-up the solver
            // refuses is an error, not a search in which every design is infeasible.
            if let Ok(built) = solve_design(&self.design(&x0)) {
                if let Some(s) = &self.strength {
                    let analysed = s
                        .setup
                        .model(&built)
                        .and_then(|m| crate::shell::analyse(&m, &s.setup.run_options()));
                    match analysed {
                        Err(e) if e.kind() == crate::ErrorKind::Io => {
                            let message = format!(
                                "the shell analysis of the starting design failed: {}",
                                e.detail()
                            );
                            return Err(e.with_message(message));
                        }
                        Err(e) => return Err(e),
                        Ok(_) => {}
                    }
                }
            }
        }
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
        let solver_failures = self.tracker.solver_failures.load(Ordering::Relaxed);
        let first_failure = self
            .tracker
            .first_failure
            .lock()
            .ok()
            .and_then(|f| f.clone());
        let best_feasible = match self.best_feasible() {
            Some((_, x)) => Some((x.clone(), self.evaluate(&x).map_err(|e| e.at("optimize"))?)),
            None => None,
        };
        let mut best = (
            search.x.clone(),
            self.evaluate(&search.x).map_err(|e| e.at("optimize"))?,
        );
        if self.strength.is_some() && !best.1.feasible {
            if let Some(f) = &best_feasible {
                best = f.clone();
            }
        }
        let start = self.evaluate(&x0).ok();
        Ok(Outcome {
            best,
            best_feasible,
            solver_failures,
            first_failure,
            start: (x0, start),
            solves: search.evaluations,
            tangent_solves: 0,
            search,
            gradient: None,
        })
    }
}

#[cfg(test)]
mod tests;
