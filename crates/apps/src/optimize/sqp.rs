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
//!   feasible point evaluated (else the least penalised one), as for the annealing search with
//!   shell measures.
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
}

impl Default for GradientOptions {
    fn default() -> Self {
        GradientOptions {
            evaluations: 100,
            starts: 1,
            seed: 1,
            ftol_rel: 1e-10,
        }
    }
}

impl GradientOptions {
    /// Checks the options: errors name the option (`evaluations`, `starts`, `ftol_rel`).
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
        Ok(())
    }
}

/// One evaluated point: the scaled objective and constraints with their gradients in the
/// scaled parameters.
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
    log: Vec<Record>,
    best: Option<(Vec<f64>, Evaluation)>,
    start: Option<Evaluation>,
    failure: Option<String>,
    /// The objective's scale: its value at the first point evaluated.
    fscale: Option<f64>,
}

/// Whether `a` is a better result than `b`: feasible first, then the lower objective (feasible)
/// or total (infeasible).
fn better(a: &Evaluation, b: &Evaluation) -> bool {
    match (a.feasible, b.feasible) {
        (true, false) => true,
        (false, true) => false,
        (true, true) => a.objective < b.objective,
        (false, false) => a.total() < b.total(),
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
    /// starts); `report(evaluations, best)` is called after each gradient evaluation. Refused
    /// when a formula uses `max_shear`.
    pub fn run_gradient(
        &self,
        o: &GradientOptions,
        report: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<Outcome> {
        o.check()?;
        if self.runs_solver() {
            return Err(Error::invalid(
                "the gradient search does not differentiate the shell analysis (max_shear) yet: \
                 use the annealing search (--method anneal) for problems with shell stress",
            )
            .at("optimize"));
        }
        let bounds = self.parameters.bounds();
        let n = bounds.len();
        let x0 = self.parameters.initial();
        let to_x = |y: &[f64]| -> Vec<f64> {
            y.iter()
                .zip(&bounds)
                .map(|(&t, &(lo, hi))| (lo + t * (hi - lo)).clamp(lo, hi))
                .collect()
        };
        let to_y = |x: &[f64]| -> Vec<f64> {
            x.iter()
                .zip(&bounds)
                .map(|(&v, &(lo, hi))| (v - lo) / (hi - lo))
                .collect()
        };
        let state = RefCell::new(State {
            last: None,
            gradients: 0,
            solves: 0,
            log: Vec::new(),
            best: None,
            start: None,
            failure: None,
            fscale: None,
        });
        let mut chains = Vec::new();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(o.seed);
        for start in 0..o.starts {
            let y0 = if start == 0 {
                to_y(&x0)
            } else {
                (0..n).map(|_| rng.gen_range(0.0..=1.0)).collect()
            };
            state.borrow_mut().last = None;
            let chain_best = RefCell::new(f64::INFINITY);
            let eval = |y: &[f64]| {
                let mut st = state.borrow_mut();
                if st.last.as_ref().is_some_and(|l| l.y == y) {
                    return;
                }
                let x = to_x(y);
                let scaled = match self.gradient(&x) {
                    Ok(g) => {
                        st.gradients += 1;
                        st.solves += g.sensitivities.solves;
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
                        if st.best.as_ref().is_none_or(|(_, b)| better(&e, b)) {
                            st.best = Some((x.clone(), e));
                        }
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
            // evaluated still count.
            let _ = slsqp::minimize(objective, &y0, &unit, &cons, (), o.evaluations, Some(tols));
            let best = *chain_best.borrow();
            chains.push((to_x(&y0), best));
        }
        let st = state.into_inner();
        let Some((best_x, best)) = st.best else {
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
        Ok(Outcome {
            search,
            start: (x0, start),
            best: (best_x, best),
            best_feasible,
            solver_failures: 0,
            first_failure: st.failure,
            solves: st.solves,
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
    }

    /// §7.5.2 with its equality `ν = 0.8`: the result is feasible (ν within the feasibility
    /// tolerance; the band of half of it is met to SLSQP's own constraint accuracy) and its
    /// penalised value is below the start's, whose ν is far from 0.8 (its energy alone may be
    /// lower: the constraint costs energy).
    #[test]
    fn the_vesicle_search_meets_its_reduced_volume() {
        let p = Problem::new(&example("vesicle.toml")).unwrap();
        let o = p
            .run_gradient(&GradientOptions::default(), &|_, _| {})
            .unwrap();
        let start = o.start.1.as_ref().unwrap();
        let best = &o.best.1;
        assert!(!start.feasible);
        assert!(best.feasible, "{:?}", best.variables);
        assert!((best.variables[8] - 0.8).abs() <= EQUALITY_TOLERANCE);
        assert!(best.total() < start.total());
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
        assert!(!better(&one.best.1, &two.best.1));
        let (lo, hi): (Vec<f64>, Vec<f64>) = p.parameters.bounds().into_iter().unzip();
        let x1 = &two.search.chains[1].0;
        assert!(x1
            .iter()
            .zip(lo.iter().zip(&hi))
            .all(|(x, (l, h))| l <= x && x <= h));
        assert_ne!(x1, &p.parameters.initial());
    }

    /// Shell stress is refused, before any analysis.
    #[test]
    fn max_shear_is_refused() {
        let p = Problem::new(&example("yoghurt_optimize.toml")).unwrap();
        let e = p
            .run_gradient(&GradientOptions::default(), &|_, _| {})
            .unwrap_err();
        assert_eq!(e.place(), "optimize");
        assert!(e.to_string().contains("max_shear"), "{e}");
    }
}
