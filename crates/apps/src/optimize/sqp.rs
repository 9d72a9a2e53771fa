//! The gradient search (`--method gradient`): sequential quadratic programming (SLSQP, Kraft's
//! algorithm as in NLopt, from the `slsqp` crate) with the exact sensitivities of
//! [`Problem::gradient`], the parameters' bounds, and the constraints as constraints (not
//! penalties).
//!
//! - The parameters are scaled to `[0, 1]` by their bounds and the objective by its value at the
//!   start, so that the quasi-Newton matrix starts well conditioned.
//! - `expr ≥ min` and `expr ≤ max` become `(min − g)/s ≤ 0`, `(g − max)/s ≤ 0` with
//!   `s = max(|bound|, 1)`; an equality `g = t` becomes the band
//!   `|g − t| ≤ ½ EQUALITY_TOLERANCE · max(|t|, 1)` (two inequalities: the crate takes
//!   inequalities only), so that its result is feasible in the sense of the module
//!   documentation.
//! - Every evaluation is one gradient ([`Problem::gradient`]: the point's solve plus one per
//!   affine parameter, two per rotation, four per approximate parameter); the result is the best
//!   feasible point evaluated that also meets the search's own constraints (to [`KKT_ACTIVE`]),
//!   else the best feasible point, else the least penalised one.
//! - More than one start (`starts`): the first from the parameters' initial values, the others
//!   drawn uniformly within the bounds (seeded), each run to its own end; the best result wins.

use super::anneal::{Record, SearchResult};
use super::{Evaluation, Outcome, Problem, EQUALITY_TOLERANCE};
use crate::spec::limits::{MAX_GRADIENT_EVALUATIONS, MAX_STARTS};
use crate::{Error, Result};
use rand::{Rng, SeedableRng};
use std::cell::RefCell;

/// Options of the gradient search.
#[derive(Clone, Debug, PartialEq)]
pub struct GradientOptions {
    /// Most gradient evaluations per start (default 100).
    pub evaluations: usize,
    /// Starts (default 1: the initial values only).
    pub starts: usize,
    /// Seed of the further starts.
    pub seed: u64,
    /// Relative change of the objective below which a start ends (default 10⁻¹⁰).
    pub ftol_rel: f64,
    /// A start also ends at the first point evaluated whose first-order conditions ([`Kkt`])
    /// hold to this (stationarity and dual infeasibility at most `kkt_tol`, primal
    /// infeasibility at most [`KKT_ACTIVE`]; default 10⁻⁶).
    pub kkt_tol: f64,
}

impl Default for GradientOptions {
    fn default() -> Self {
        GradientOptions {
            evaluations: 100,
            starts: 1,
            seed: 1,
            ftol_rel: 1e-10,
            kkt_tol: 1e-6,
        }
    }
}

impl GradientOptions {
    /// Checks the options: errors name the option (`evaluations`, `starts`, `ftol_rel`,
    /// `kkt_tol`).
    pub fn check(&self) -> Result<()> {
        if !(1..=MAX_GRADIENT_EVALUATIONS).contains(&self.evaluations) {
            return Err(Error::invalid(format!(
                "must be between 1 and {MAX_GRADIENT_EVALUATIONS} (got {})",
                self.evaluations
            ))
            .at("evaluations"));
        }
        if !(1..=MAX_STARTS).contains(&self.starts) {
            return Err(Error::invalid(format!(
                "must be between 1 and {MAX_STARTS} (got {})",
                self.starts
            ))
            .at("starts"));
        }
        if !(self.ftol_rel > 0.0 && self.ftol_rel < 1.0) {
            return Err(
                Error::invalid(format!("must lie in (0, 1) (got {})", self.ftol_rel))
                    .at("ftol_rel"),
            );
        }
        if !(self.kkt_tol > 0.0 && self.kkt_tol < 1.0) {
            return Err(
                Error::invalid(format!("must lie in (0, 1) (got {})", self.kkt_tol)).at("kkt_tol"),
            );
        }
        Ok(())
    }
}

/// One evaluated point: the scaled objective and constraints with their gradients in the
/// scaled parameters.
#[derive(Clone, Debug)]
struct Scaled {
    y: Vec<f64>,
    f: f64,
    df: Vec<f64>,
    /// `(value, gradient)` of each inequality `c ≤ 0`.
    cons: Vec<(f64, Vec<f64>)>,
}

/// What the evaluations of one search share.
struct State {
    last: Option<Scaled>,
    gradients: usize,
    solves: usize,
    tangent_solves: usize,
    log: Vec<Record>,
    best: Option<(Vec<f64>, Evaluation)>,
    /// Whether `best` meets the search's own constraints (see [`Problem::gradient_from`]).
    best_inside: bool,
    /// The scaled evaluation of `best` and the start that found it.
    best_scaled: Option<(Scaled, usize)>,
    start: Option<Evaluation>,
    failure: Option<String>,
    /// The objective's scale: its value at the first point evaluated.
    fscale: Option<f64>,
    /// Why the current start ended on the search's own test (`first_order`,
    /// `max_evaluations`); SLSQP's further requests are then answered with the last point's
    /// values, unevaluated, until it returns.
    ended: Option<&'static str>,
}

/// How one start of the gradient search ended.
#[derive(Clone, Debug, PartialEq)]
pub struct StartReport {
    /// The start point.
    pub x: Vec<f64>,
    /// The best value (objective + penalty) this start evaluated.
    pub best: f64,
    /// How the start ended: `first_order` (a point met the first-order conditions to
    /// [`GradientOptions::kkt_tol`]), or SLSQP's `success`, `ftol_reached`, `xtol_reached`
    /// (converged); `max_evaluations` (the start's budget of gradient evaluations spent),
    /// `roundoff_limited`, `failure`, … (not).
    pub status: &'static str,
    /// Whether SLSQP ended on one of its convergence tests.
    pub converged: bool,
    /// Gradient evaluations of this start.
    pub evaluations: usize,
}

/// The first-order (Karush–Kuhn–Tucker) conditions at the result, in the search's scaled
/// variables (each parameter's range mapped to `[0, 1]`, the objective divided by its value at
/// the first point, each constraint `c ≤ 0` divided by `max(|bound|, 1)`; see [`super::sqp`]).
/// A constraint is active when `c ≥ −`[`KKT_ACTIVE`], a bound when the scaled parameter is
/// within 10⁻⁹ of it; the multipliers `λ` of the active constraints are the least-squares ones
/// over the parameters at no bound, and `r = ∇f + Σ λᵢ ∇cᵢ`.
#[derive(Clone, Debug, PartialEq)]
pub struct Kkt {
    /// `max |r_k|` over the parameters at no bound, `max(−r_k, 0)` at a lower and
    /// `max(r_k, 0)` at an upper bound (0 at a first-order optimum).
    pub stationarity: f64,
    /// `max(−λᵢ, 0)` (0 when every active constraint pushes the right way).
    pub dual_infeasibility: f64,
    /// `max(cᵢ, 0)`: the largest scaled violation of a constraint.
    pub primal_infeasibility: f64,
    /// Constraints (as inequalities `c ≤ 0`) active at the result.
    pub active_constraints: usize,
    /// Parameters at a bound.
    pub active_bounds: usize,
}

/// A constraint `c ≤ 0` counts as active in [`Kkt`] when `c ≥ −KKT_ACTIVE` (scaled).
pub const KKT_ACTIVE: f64 = 1e-6;

/// What the gradient search reports beside its result.
#[derive(Clone, Debug, PartialEq)]
pub struct GradientReport {
    /// Gradient evaluations, all starts together.
    pub evaluations: usize,
    /// Design solves they made.
    pub solves: usize,
    /// Batched tangent solves they made (see [`super::Outcome::tangent_solves`]).
    pub tangent_solves: usize,
    /// Each start, in order.
    pub starts: Vec<StartReport>,
    /// The start that found the result.
    pub best_start: usize,
    /// Whether that start converged ([`StartReport::converged`]).
    pub converged: bool,
    /// The first-order conditions at the result.
    pub kkt: Kkt,
}

/// Whether `a` is a better result than `b`: feasible first, then the lower objective (feasible)
/// or total (infeasible).
pub(crate) fn better(a: &Evaluation, b: &Evaluation) -> bool {
    match (a.feasible, b.feasible) {
        (true, false) => true,
        (false, true) => false,
        (true, true) => a.objective < b.objective,
        (false, false) => a.total() < b.total(),
    }
}

/// SLSQP's answer: its status, last point and value.
type Ended<S> = (S, Vec<f64>, f64);

/// SLSQP's ending as a label and whether it is convergence.
fn status_of(
    r: &std::result::Result<Ended<slsqp::SuccessStatus>, Ended<slsqp::FailStatus>>,
) -> (&'static str, bool) {
    use slsqp::{FailStatus as F, SuccessStatus as S};
    match r {
        Ok((S::Success, ..)) => ("success", true),
        Ok((S::FtolReached, ..)) => ("ftol_reached", true),
        Ok((S::XtolReached, ..)) => ("xtol_reached", true),
        Ok((S::StopValReached, ..)) => ("stopval_reached", true),
        Ok((S::MaxEvalReached, ..)) => ("max_evaluations", false),
        Ok((S::MaxTimeReached, ..)) => ("max_time", false),
        Err((F::RoundoffLimited, ..)) => ("roundoff_limited", false),
        Err((F::ForcedStop, ..)) => ("forced_stop", false),
        Err((F::InvalidArgs, ..)) => ("invalid_arguments", false),
        Err((F::OutOfMemory, ..)) => ("out_of_memory", false),
        Err((F::Failure, ..)) | Err((F::UnexpectedError, ..)) => ("failure", false),
    }
}

/// The first-order conditions at a scaled point (see [`Kkt`]).
fn kkt(s: &Scaled) -> Kkt {
    let n = s.y.len();
    let lower: Vec<bool> = s.y.iter().map(|&y| y <= 1e-9).collect();
    let upper: Vec<bool> = s.y.iter().map(|&y| y >= 1.0 - 1e-9).collect();
    let free: Vec<usize> = (0..n).filter(|&k| !lower[k] && !upper[k]).collect();
    let active: Vec<&(f64, Vec<f64>)> = s.cons.iter().filter(|(c, _)| *c >= -KKT_ACTIVE).collect();
    let m = active.len();
    // Normal equations of min ‖(∇f + Σ λᵢ ∇cᵢ)_free‖ over λ, by Gaussian elimination with
    // partial pivoting; a pivot below 10⁻¹² of the largest diagonal (a dependent constraint)
    // leaves its multiplier 0.
    let mut a = vec![vec![0.0; m + 1]; m];
    for (i, (_, gi)) in active.iter().enumerate() {
        for (j, (_, gj)) in active.iter().enumerate() {
            a[i][j] = free.iter().map(|&k| gi[k] * gj[k]).sum();
        }
        a[i][m] = -free.iter().map(|&k| gi[k] * s.df[k]).sum::<f64>();
    }
    let big = (0..m).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    let mut lambda = vec![0.0; m];
    let mut pivots = vec![None; m];
    let mut used = vec![false; m];
    for col in 0..m {
        let Some(row) = (0..m)
            .filter(|&r| !used[r])
            .max_by(|&r, &q| a[r][col].abs().total_cmp(&a[q][col].abs()))
        else {
            break;
        };
        if a[row][col].abs() <= 1e-12 * big || big == 0.0 {
            continue;
        }
        used[row] = true;
        pivots[col] = Some(row);
        let pivot_row = a[row].clone();
        for (r, line) in a.iter_mut().enumerate() {
            if r != row {
                let f = line[col] / pivot_row[col];
                for (v, p) in line.iter_mut().zip(&pivot_row).skip(col) {
                    *v -= f * p;
                }
            }
        }
    }
    for (col, p) in pivots.iter().enumerate() {
        if let Some(row) = *p {
            lambda[col] = a[row][m] / a[row][col];
        }
    }
    let r: Vec<f64> = (0..n)
        .map(|k| {
            s.df[k]
                + active
                    .iter()
                    .zip(&lambda)
                    .map(|((_, g), l)| l * g[k])
                    .sum::<f64>()
        })
        .collect();
    let stationarity = (0..n)
        .map(|k| {
            if lower[k] {
                (-r[k]).max(0.0)
            } else if upper[k] {
                r[k].max(0.0)
            } else {
                r[k].abs()
            }
        })
        .fold(0.0, f64::max);
    Kkt {
        stationarity,
        dual_infeasibility: lambda.iter().map(|l| (-l).max(0.0)).fold(0.0, f64::max),
        primal_infeasibility: s.cons.iter().map(|(c, _)| c.max(0.0)).fold(0.0, f64::max),
        active_constraints: m,
        active_bounds: n - free.len(),
    }
}

impl Problem {
    /// The number of inequalities the constraints become (see the module documentation).
    fn inequalities(&self) -> usize {
        self.constraints
            .iter()
            .map(|c| {
                if c.equal.is_some() {
                    2
                } else {
                    usize::from(c.min.is_some()) + usize::from(c.max.is_some())
                }
            })
            .sum()
    }

    /// Runs the gradient search (see [`super::sqp`]) from the initial values (and further
    /// starts); `report(evaluations, best)` is called after each gradient evaluation.
    pub fn run_gradient(
        &self,
        o: &GradientOptions,
        report: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<Outcome> {
        o.check()?;
        let n = self.parameters.len();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(o.seed);
        let mut starts = vec![self.to_unit(&self.parameters.initial())];
        for _ in 1..o.starts {
            starts.push((0..n).map(|_| rng.gen_range(0.0..=1.0)).collect());
        }
        self.gradient_from(&starts, o, report)
    }

    /// The hybrid search (see [`super::search`]): annealing as [`Problem::run`] runs it, then
    /// the gradient search from each chain's best point (the same point once), the result the
    /// better ([`better`]) of annealing's and the gradient search's.
    pub fn run_hybrid(
        &self,
        o: &GradientOptions,
        report: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<Outcome> {
        // Its starts are the chains (checked by annealing's options), not `o.starts`.
        GradientOptions {
            starts: 1,
            ..o.clone()
        }
        .check()?;
        let anneal = self.run(report)?;
        let mut starts: Vec<Vec<f64>> = Vec::new();
        for (x, _) in &anneal.search.chains {
            let y = self.to_unit(x);
            if !starts.contains(&y) {
                starts.push(y);
            }
        }
        let done = anneal.search.evaluations;
        let so_far = anneal.best.1.total();
        let grad = self.gradient_from(&starts, o, &|k, best| report(done + k, best.min(so_far)))?;
        let (best, best_feasible) = if better(&grad.best.1, &anneal.best.1) {
            (grad.best.clone(), grad.best_feasible.clone())
        } else {
            let f = match (&anneal.best_feasible, &grad.best_feasible) {
                (Some(a), Some(g)) if better(&g.1, &a.1) => Some(g.clone()),
                (None, Some(g)) => Some(g.clone()),
                (a, _) => a.clone(),
            };
            (anneal.best.clone(), f)
        };
        let mut log = anneal.search.log;
        log.extend(grad.search.log);
        let search = SearchResult {
            x: best.0.clone(),
            value: best.1.total(),
            start_value: anneal.search.start_value,
            chains: anneal.search.chains,
            log,
            evaluations: done + grad.search.evaluations,
        };
        Ok(Outcome {
            search,
            start: anneal.start,
            best,
            best_feasible,
            solver_failures: anneal.solver_failures,
            first_failure: anneal.first_failure,
            solves: anneal.solves + grad.solves,
            tangent_solves: grad.tangent_solves,
            gradient: grad.gradient,
        })
    }

    /// `x` scaled to `[0, 1]` by the parameters' bounds.
    pub(crate) fn to_unit(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .zip(self.parameters.bounds())
            .map(|(&v, (lo, hi))| (v - lo) / (hi - lo))
            .collect()
    }

    /// The gradient search from each of `starts` (scaled to `[0, 1]`), each run to its own end;
    /// the result is the best point evaluated: first the feasible points that meet the search's
    /// own constraints within [`KKT_ACTIVE`] (scaled; an equality's inner half-band), then by
    /// [`better`]. `o.starts` is not used.
    pub(crate) fn gradient_from(
        &self,
        starts: &[Vec<f64>],
        o: &GradientOptions,
        report: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<Outcome> {
        let bounds = self.parameters.bounds();
        let n = bounds.len();
        let x0 = self.parameters.initial();
        let to_x = |y: &[f64]| -> Vec<f64> {
            y.iter()
                .zip(&bounds)
                .map(|(&t, &(lo, hi))| (lo + t * (hi - lo)).clamp(lo, hi))
                .collect()
        };
        let state = RefCell::new(State {
            last: None,
            gradients: 0,
            solves: 0,
            tangent_solves: 0,
            log: Vec::new(),
            best: None,
            best_inside: false,
            best_scaled: None,
            start: None,
            failure: None,
            fscale: None,
            ended: None,
        });
        let mut chains = Vec::new();
        let mut reports = Vec::new();
        for (start, y0) in starts.iter().enumerate() {
            state.borrow_mut().last = None;
            state.borrow_mut().ended = None;
            let before = state.borrow().gradients;
            let chain_best = RefCell::new(f64::INFINITY);
            let eval = |y: &[f64]| {
                let mut st = state.borrow_mut();
                if st.last.as_ref().is_some_and(|l| l.y == y) || st.ended.is_some() {
                    return;
                }
                if st.gradients - before >= o.evaluations {
                    st.ended = Some("max_evaluations");
                    return;
                }
                let x = to_x(y);
                let mut improved = false;
                let scaled = match self.gradient(&x) {
                    Ok(g) => {
                        st.gradients += 1;
                        st.solves += g.sensitivities.solves;
                        st.tangent_solves += g.sensitivities.tangent_solves;
                        let e = self.evaluate_variables(g.sensitivities.values);
                        if st.start.is_none() {
                            st.start = Some(e.clone());
                        }
                        let fscale = *st.fscale.get_or_insert(g.objective.abs().max(1e-12));
                        let total = if e.total().is_nan() {
                            f64::INFINITY
                        } else {
                            e.total()
                        };
                        let mut cb = chain_best.borrow_mut();
                        *cb = cb.min(total);
                        let level = st.gradients;
                        st.log.push(Record {
                            phase: "gradient",
                            chain: start,
                            level,
                            temperature: 0.0,
                            x: x.clone(),
                            value: total,
                            accepted: true,
                            best: *cb,
                        });
                        let w: Vec<f64> = bounds.iter().map(|(lo, hi)| hi - lo).collect();
                        let scale = |d: &[f64], s: f64| -> Vec<f64> {
                            d.iter().zip(&w).map(|(d, w)| d * w / s).collect()
                        };
                        let mut cons = Vec::new();
                        for c in &g.constraints {
                            if let Some(t) = c.equal {
                                let s = t.abs().max(1.0);
                                let band = 0.5 * EQUALITY_TOLERANCE * s;
                                cons.push(((c.value - t - band) / s, scale(&c.gradient, s)));
                                cons.push(((t - band - c.value) / s, scale(&c.gradient, -s)));
                            }
                            if let Some(lo) = c.min {
                                let s = lo.abs().max(1.0);
                                cons.push(((lo - c.value) / s, scale(&c.gradient, -s)));
                            }
                            if let Some(hi) = c.max {
                                let s = hi.abs().max(1.0);
                                cons.push(((c.value - hi) / s, scale(&c.gradient, s)));
                            }
                        }
                        // The search's own constraints met (to KKT_ACTIVE) rank first: a
                        // point in the equality's outer half-band counts as feasible, but is
                        // not one the search converges to.
                        let inside = e.feasible && cons.iter().all(|(c, _)| *c <= KKT_ACTIVE);
                        let first = match &st.best {
                            None => true,
                            Some(_) if inside != st.best_inside => inside,
                            Some((_, b)) => better(&e, b),
                        };
                        if first {
                            st.best = Some((x.clone(), e));
                            st.best_inside = inside;
                            improved = true;
                        }
                        Scaled {
                            y: y.to_vec(),
                            f: g.objective / fscale,
                            df: scale(&g.d_objective, fscale),
                            cons,
                        }
                    }
                    Err(e) => {
                        st.failure.get_or_insert_with(|| e.to_string());
                        Scaled {
                            y: y.to_vec(),
                            f: f64::INFINITY,
                            df: vec![0.0; n],
                            cons: vec![(f64::INFINITY, vec![0.0; n]); self.inequalities()],
                        }
                    }
                };
                if improved {
                    st.best_scaled = Some((scaled.clone(), start));
                }
                if scaled.f.is_finite() {
                    let k = kkt(&scaled);
                    if k.stationarity <= o.kkt_tol
                        && k.dual_infeasibility <= o.kkt_tol
                        && k.primal_infeasibility <= KKT_ACTIVE
                    {
                        st.ended = Some("first_order");
                    }
                }
                report(
                    st.gradients,
                    st.best.as_ref().map_or(f64::INFINITY, |(_, b)| b.total()),
                );
                st.last = Some(scaled);
            };
            let objective = |y: &[f64], grad: Option<&mut [f64]>, _: &mut ()| -> f64 {
                eval(y);
                let st = state.borrow();
                let Some(l) = &st.last else {
                    return f64::INFINITY;
                };
                if let Some(g) = grad {
                    g.copy_from_slice(&l.df);
                }
                l.f
            };
            let constraint = |i: usize| {
                let eval = &eval;
                let state = &state;
                move |y: &[f64], grad: Option<&mut [f64]>, _: &mut ()| -> f64 {
                    eval(y);
                    let st = state.borrow();
                    let Some((v, d)) = st.last.as_ref().and_then(|l| l.cons.get(i)) else {
                        return f64::INFINITY;
                    };
                    if let Some(g) = grad {
                        g.copy_from_slice(d);
                    }
                    *v
                }
            };
            let closures: Vec<_> = (0..self.inequalities()).map(constraint).collect();
            let cons: Vec<&dyn slsqp::Func<()>> =
                closures.iter().map(|c| c as &dyn slsqp::Func<()>).collect();
            let unit = vec![(0.0, 1.0); n];
            let tols = slsqp::StopTols {
                ftol_rel: o.ftol_rel,
                ..Default::default()
            };
            // Failures (round-off limits, a failed line search) end this start; the points it
            // evaluated still count. SLSQP counts calls, and asks for the value and then the
            // gradient at each point its line search accepts (one gradient evaluation here):
            // its cap of 4 calls per evaluation never binds before the start's own budget
            // (at most 2 per evaluation), and leaves room to return once the start has ended.
            let calls = o.evaluations.saturating_mul(4);
            let ended = slsqp::minimize(objective, y0, &unit, &cons, (), calls, Some(tols));
            let (status, converged) = match state.borrow().ended {
                Some("first_order") => ("first_order", true),
                Some(s) => (s, false),
                None => status_of(&ended),
            };
            let best = *chain_best.borrow();
            chains.push((to_x(y0), best));
            reports.push(StartReport {
                x: to_x(y0),
                best,
                status,
                converged,
                evaluations: state.borrow().gradients - before,
            });
        }
        let st = state.into_inner();
        let (Some((best_x, best)), Some((scaled, best_start))) = (st.best, st.best_scaled) else {
            return Err(Error::invalid(format!(
                "no design of the gradient search could be built and measured{}",
                st.failure.map(|m| format!(": {m}")).unwrap_or_default()
            ))
            .at("optimize"));
        };
        let start = st.start;
        let search = SearchResult {
            x: best_x.clone(),
            value: best.total(),
            start_value: start.as_ref().map_or(f64::NAN, Evaluation::total),
            chains,
            log: st.log,
            evaluations: st.gradients,
        };
        let best_feasible = best.feasible.then(|| (best_x.clone(), best.clone()));
        let gradient = GradientReport {
            evaluations: st.gradients,
            solves: st.solves,
            tangent_solves: st.tangent_solves,
            converged: reports[best_start].converged,
            starts: reports,
            best_start,
            kkt: kkt(&scaled),
        };
        Ok(Outcome {
            search,
            start: (x0, start),
            best: (best_x, best),
            best_feasible,
            solver_failures: 0,
            first_failure: st.failure,
            solves: st.solves,
            tangent_solves: st.tangent_solves,
            gradient: Some(gradient),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::parse_design;

    fn example(name: &str) -> crate::spec::DesignSpec {
        let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
        parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// §7.5 without constraints: the search improves the start and ends at a first-order
    /// optimum of the box: each derivative, times its parameter's range, is below 10⁻³ of the
    /// objective inside the bounds, and points outward at a bound it ends on.
    #[test]
    fn the_curvature_search_ends_stationary_in_its_box() {
        let p = Problem::new(&example("optimize_curvature.toml")).unwrap();
        let o = p
            .run_gradient(&GradientOptions::default(), &|_, _| {})
            .unwrap();
        let start = o.start.1.as_ref().unwrap().total();
        let (x, best) = &o.best;
        assert!(best.total() < start, "{} vs {start}", best.total());
        assert_eq!(o.search.evaluations, o.search.log.len());
        let g = p.gradient(x).unwrap();
        assert!((g.objective - best.objective).abs() <= 1e-12 * best.objective.abs());
        for ((d, (lo, hi)), (xk, q)) in g
            .d_objective
            .iter()
            .zip(p.parameters.bounds())
            .zip(x.iter().zip(&p.parameters.list))
        {
            let s = d * (hi - lo) / g.objective.abs();
            let tol = 1e-3;
            let at_lo = *xk <= lo + 1e-9 * (hi - lo);
            let at_hi = *xk >= hi - 1e-9 * (hi - lo);
            let ok = if at_lo {
                s >= -tol
            } else if at_hi {
                s <= tol
            } else {
                s.abs() <= tol
            };
            assert!(
                ok,
                "{} = {xk} in [{lo}, {hi}]: scaled derivative {s}",
                q.name
            );
        }
        // The library's report: the start converged, no constraint, and its stationarity is
        // the projected derivative recomputed here, each times its range over the objective's
        // value at the start (the search's scale). The two gradients are the same computation
        // at the same point, so they agree to rounding.
        let r = o.gradient.as_ref().unwrap();
        assert_eq!(r.starts.len(), 1);
        assert!(r.converged, "{:?}", r.starts[0]);
        assert_eq!(r.evaluations, o.search.evaluations);
        assert_eq!(r.solves, o.solves);
        assert_eq!(r.kkt.active_constraints, 0);
        let fscale = o.start.1.as_ref().unwrap().objective.abs();
        let own = g
            .d_objective
            .iter()
            .zip(p.parameters.bounds())
            .zip(x)
            .map(|((d, (lo, hi)), xk)| {
                let s = d * (hi - lo) / fscale;
                if *xk <= lo + 1e-9 * (hi - lo) {
                    (-s).max(0.0)
                } else if *xk >= hi - 1e-9 * (hi - lo) {
                    s.max(0.0)
                } else {
                    s.abs()
                }
            })
            .fold(0.0, f64::max);
        assert!(
            (r.kkt.stationarity - own).abs() <= 1e-9 * own.max(1e-6),
            "{} vs {own}",
            r.kkt.stationarity
        );
        assert!(r.kkt.stationarity <= 1e-3);
        assert_eq!(r.kkt.dual_infeasibility, 0.0);
        assert_eq!(r.kkt.primal_infeasibility, 0.0);
    }

    /// §7.5.2 with its equality `ν = 0.8`: the result is feasible (ν within the feasibility
    /// tolerance; the band of half of it is met to SLSQP's own constraint accuracy) and its
    /// penalised value is below the start's, whose ν is far from 0.8 (its energy alone may be
    /// lower: the constraint costs energy). The default budget: the start ends on the
    /// first-order test within it (SLSQP's own `ftol_rel` test is made only at iterates that
    /// meet the constraints with no tolerance, which the active side of the band misses by
    /// rounding at every other iterate; it declared convergence only after 156 evaluations).
    #[test]
    fn the_vesicle_search_meets_its_reduced_volume() {
        let p = Problem::new(&example("vesicle.toml")).unwrap();
        let options = GradientOptions::default();
        let o = p.run_gradient(&options, &|_, _| {}).unwrap();
        let start = o.start.1.as_ref().unwrap();
        let best = &o.best.1;
        assert!(!start.feasible);
        assert!(best.feasible, "{:?}", best.variables);
        assert!((best.variables[8] - 0.8).abs() <= EQUALITY_TOLERANCE);
        assert!(best.total() < start.total());
        // A constrained first-order optimum: one side of the ν band active (the other lies
        // EQUALITY_TOLERANCE/max(0.8, 1) below it in scaled units, far from active), its
        // multiplier of the right sign, and the Lagrangian's projected gradient small.
        let r = o.gradient.as_ref().unwrap();
        assert!(r.converged, "{:?}", r.starts);
        assert_eq!(r.kkt.active_constraints, 1, "{:?}", r.kkt);
        assert!(r.kkt.primal_infeasibility <= KKT_ACTIVE, "{:?}", r.kkt);
        assert!(r.kkt.dual_infeasibility <= 1e-6, "{:?}", r.kkt);
        assert!(r.kkt.stationarity <= 1e-3, "{:?}", r.kkt);
        // It ended on the first-order test, at the point the report's conditions are of, and
        // within the budget: the tests hold there with the options' tolerance.
        assert_eq!(r.starts[0].status, "first_order", "{:?}", r.starts);
        assert!(r.evaluations < options.evaluations, "{}", r.evaluations);
        assert!(r.kkt.stationarity <= options.kkt_tol, "{:?}", r.kkt);
        assert!(r.kkt.dual_infeasibility <= options.kkt_tol, "{:?}", r.kkt);
    }

    /// The budget counts gradient evaluations (the points evaluated), not SLSQP's calls (it
    /// asks for a point's value and then its gradient): a start given 12 makes exactly 12,
    /// logs 12, and ends unconverged.
    #[test]
    fn a_start_makes_exactly_its_budget_of_evaluations() {
        let p = Problem::new(&example("vesicle.toml")).unwrap();
        let options = GradientOptions {
            evaluations: 12,
            ..Default::default()
        };
        let o = p.run_gradient(&options, &|_, _| {}).unwrap();
        let r = o.gradient.as_ref().unwrap();
        assert_eq!(r.evaluations, 12);
        assert_eq!(o.search.log.len(), 12);
        assert_eq!(r.starts[0].status, "max_evaluations");
        assert!(!r.converged);
    }

    /// Two starts: the second is drawn within the bounds and logged as chain 1; the result is
    /// the better of the two, so never worse than the first start's alone.
    #[test]
    fn a_second_start_is_logged_and_never_worsens_the_result() {
        let p = Problem::new(&example("vesicle.toml")).unwrap();
        let one = p
            .run_gradient(&GradientOptions::default(), &|_, _| {})
            .unwrap();
        let o = GradientOptions {
            starts: 2,
            ..GradientOptions::default()
        };
        let two = p.run_gradient(&o, &|_, _| {}).unwrap();
        assert_eq!(two.search.chains.len(), 2);
        assert!(two.search.log.iter().any(|r| r.chain == 1));
        let first: Vec<_> = two.search.log.iter().filter(|r| r.chain == 0).collect();
        assert_eq!(first.len(), one.search.log.len());
        // The first start's search is the same; the second's best replaces it only if it ranks
        // above (see `gradient_from`), so a feasible result stays feasible.
        let g = two.gradient.as_ref().unwrap();
        assert_eq!(g.starts[0], one.gradient.as_ref().unwrap().starts[0]);
        if g.best_start == 0 {
            // (Evaluations hold NaN shell measures: compared by point and values.)
            assert_eq!(two.best.0, one.best.0);
            assert_eq!(two.best.1.total(), one.best.1.total());
        } else {
            assert!(two.best.1.feasible || !one.best.1.feasible);
        }
        let (lo, hi): (Vec<f64>, Vec<f64>) = p.parameters.bounds().into_iter().unzip();
        let x1 = &two.search.chains[1].0;
        assert!(x1
            .iter()
            .zip(lo.iter().zip(&hi))
            .all(|(x, (l, h))| l <= x && x <= h));
        assert_ne!(x1, &p.parameters.initial());
    }

    /// The first-order conditions on hand-made points: `f = y₀ + y₁` at the lower corner
    /// (bounds only: the gradient points inward, stationary); the same with the constraint
    /// `1 − y₀ − 2y₁ ≤ 0` active at `(0, ½)` (a KKT point with `λ = ½`); a multiplier of the
    /// wrong sign; an interior point.
    #[test]
    fn kkt_conditions_of_hand_made_points() {
        let corner = Scaled {
            y: vec![0.0, 0.0],
            f: 0.0,
            df: vec![1.0, 1.0],
            cons: vec![],
        };
        let k = kkt(&corner);
        assert_eq!((k.stationarity, k.active_bounds), (0.0, 2));
        let c = (0.0, vec![-1.0, -2.0]);
        let edge = Scaled {
            y: vec![0.0, 0.5],
            f: 0.5,
            df: vec![1.0, 1.0],
            cons: vec![c.clone()],
        };
        let k = kkt(&edge);
        // y₁ is the only free parameter: λ = 1/2 from it, then y₀ at its lower bound has
        // r₀ = 1 − 1/2 ≥ 0 (fine), r₁ = 0.
        assert_eq!(k.active_constraints, 1);
        assert!(k.stationarity <= 1e-15, "{k:?}");
        assert_eq!(k.dual_infeasibility, 0.0);
        // f = −y₁ at the same point: λ = −1/2 (the constraint would have to pull outward).
        let wrong = Scaled {
            df: vec![0.0, -1.0],
            ..edge
        };
        let k = kkt(&wrong);
        assert!((k.dual_infeasibility - 0.5).abs() <= 1e-15, "{k:?}");
        // An interior point with an inactive constraint: stationarity is |∇f|∞, the violation
        // of a violated one is reported.
        let inner = Scaled {
            y: vec![0.5, 0.5],
            f: 0.0,
            df: vec![0.25, -0.5],
            cons: vec![(-0.1, vec![1.0, 0.0]), (0.2, vec![0.0, 0.0])],
        };
        let k = kkt(&inner);
        assert_eq!(k.stationarity, 0.5);
        assert_eq!(k.primal_infeasibility, 0.2);
    }
}
