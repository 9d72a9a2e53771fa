//! The choice of search and its options, as the CLI (`pdeshape optimize --method …`) and Python
//! (`Design.optimize(method=…)`) ask for it: one place that decides what each option means for
//! each method and refuses the combinations that mean nothing, so that both shells pass the
//! user's words through and report the same errors.
//!
//! | method | search | `evaluations` | `chains`, `polish` | `starts` |
//! |---|---|---|---|---|
//! | `anneal` | simulated annealing and a Nelder–Mead polish ([`super::anneal`]) | annealing evaluations, all chains together | yes | refused |
//! | `gradient` | SLSQP on the exact sensitivities ([`super::sqp`]) | gradient evaluations per start | refused | yes (default 1) |
//! | `hybrid` | annealing as `anneal`, then the gradient search from each chain's best point ([`Problem::run_hybrid`]) | annealing's | yes | refused (the starts are the chains) |
//!
//! Options not given keep the values of the design's `[optimize]` section (annealing) or of
//! [`GradientOptions::default`] (gradient; the hybrid's gradient stage too); `seed` seeds both.
//!
//! The hybrid is a method of its own rather than a flag of the gradient search (such as
//! `--starts-from anneal`) so that every option keeps its annealing meaning (`evaluations` all
//! chains together, `chains`, `polish`) and its result compares directly with `anneal`'s at the
//! same seed: it contains that run, and is never worse than it (see [`Problem::run_hybrid`]).

use super::{GradientOptions, Outcome, Problem};
use crate::{Error, Result};

/// The search of [`Problem::run_search`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchMethod {
    /// Simulated annealing and a Nelder–Mead polish (the book's).
    Anneal,
    /// SLSQP on the exact sensitivities, with bounds and constraints.
    Gradient,
    /// Annealing, then the gradient search from each chain's best point.
    Hybrid,
}

impl SearchMethod {
    /// Every method, in the order of [`SearchMethod::name`]'s list.
    pub const ALL: [SearchMethod; 3] = [
        SearchMethod::Anneal,
        SearchMethod::Gradient,
        SearchMethod::Hybrid,
    ];

    /// The method's name: `anneal`, `gradient`, `hybrid`.
    pub fn name(self) -> &'static str {
        match self {
            SearchMethod::Anneal => "anneal",
            SearchMethod::Gradient => "gradient",
            SearchMethod::Hybrid => "hybrid",
        }
    }

    /// The method named `name`; an unknown name is an error at `method` that lists the names.
    pub fn parse(name: &str) -> Result<SearchMethod> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
                Error::invalid(format!(
                    "unknown method '{name}' (expected one of: {})",
                    names.join(", ")
                ))
                .at("method")
            })
    }
}

/// The options a caller gives (`None`: the default; see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct SearchRequest {
    /// The search.
    pub method: SearchMethod,
    /// Seed of the random numbers (annealing's chains, the gradient search's further starts).
    pub seed: Option<u64>,
    /// Annealing evaluations (all chains), or gradient evaluations per start.
    pub evaluations: Option<usize>,
    /// Annealing chains.
    pub chains: Option<usize>,
    /// Nelder–Mead polish evaluations after annealing.
    pub polish: Option<usize>,
    /// Starts of the gradient search.
    pub starts: Option<usize>,
}

impl SearchRequest {
    /// A request for `method` with every option at its default.
    pub fn new(method: SearchMethod) -> SearchRequest {
        SearchRequest {
            method,
            seed: None,
            evaluations: None,
            chains: None,
            polish: None,
            starts: None,
        }
    }
}

/// A checked request: the method, with the annealing options set on the [`Problem`] and the
/// gradient search's here.
#[derive(Clone, Debug, PartialEq)]
pub struct SearchPlan {
    /// The search.
    pub method: SearchMethod,
    /// The gradient search's options (`None` for annealing).
    pub gradient: Option<GradientOptions>,
}

impl SearchPlan {
    /// The most evaluations the search makes (annealing's and the polish's, or gradient
    /// evaluations over all starts), for a progress bar and the log's memory.
    pub fn evaluations(&self, problem: &Problem) -> usize {
        let anneal = problem
            .options
            .evaluations
            .saturating_add(problem.options.polish);
        let gradient = |g: &GradientOptions| g.evaluations.saturating_mul(g.starts);
        match (self.method, &self.gradient) {
            (SearchMethod::Anneal, _) => anneal,
            (SearchMethod::Hybrid, Some(g)) => anneal.saturating_add(gradient(g)),
            (_, Some(g)) => gradient(g),
            (_, None) => anneal,
        }
    }
}

impl Problem {
    /// Checks `request` against its method and sets its annealing options on the problem.
    /// Errors are at the option's name (`method`, `evaluations`, `chains`, `polish`, `starts`),
    /// which the CLI shows as `--name` and Python as the argument's name.
    pub fn plan(&mut self, request: &SearchRequest) -> Result<SearchPlan> {
        let r = request;
        let refuse = |name: &str, only: &str| {
            Err(Error::invalid(format!(
                "only with the {only} method (got method {})",
                r.method.name()
            ))
            .at(name))
        };
        match r.method {
            SearchMethod::Anneal | SearchMethod::Hybrid => {
                if r.starts.is_some() {
                    return refuse("starts", "gradient");
                }
            }
            SearchMethod::Gradient => {
                if r.chains.is_some() {
                    return refuse("chains", "anneal");
                }
                if r.polish.is_some() {
                    return refuse("polish", "anneal");
                }
            }
        }
        let mut options = self.options.clone();
        if let Some(s) = r.seed {
            options.seed = s;
        }
        if r.method != SearchMethod::Gradient {
            if let Some(n) = r.evaluations {
                options.evaluations = n;
            }
        }
        if let Some(n) = r.chains {
            options.chains = n;
        }
        if let Some(n) = r.polish {
            options.polish = n;
        }
        options.check().map_err(|e| {
            let name = e.place().trim_start_matches("optimize.");
            Error::invalid(e.detail().to_string()).at(name)
        })?;
        let gradient = match r.method {
            SearchMethod::Anneal => None,
            SearchMethod::Gradient => {
                let defaults = GradientOptions::default();
                let g = GradientOptions {
                    evaluations: r.evaluations.unwrap_or(defaults.evaluations),
                    starts: r.starts.unwrap_or(defaults.starts),
                    seed: options.seed,
                    ..defaults
                };
                g.check()?;
                Some(g)
            }
            SearchMethod::Hybrid => Some(GradientOptions {
                starts: options.chains,
                seed: options.seed,
                ..GradientOptions::default()
            }),
        };
        self.options = options;
        Ok(SearchPlan {
            method: r.method,
            gradient,
        })
    }

    /// Runs the search `plan` ([`Problem::plan`]); `report(evaluations, best)` after each
    /// evaluation.
    pub fn run_search(
        &self,
        plan: &SearchPlan,
        report: &(dyn Fn(usize, f64) + Sync),
    ) -> Result<Outcome> {
        match (plan.method, &plan.gradient) {
            (SearchMethod::Gradient, Some(g)) => self.run_gradient(g, report),
            (SearchMethod::Gradient, None) => {
                self.run_gradient(&GradientOptions::default(), report)
            }
            (SearchMethod::Hybrid, g) => {
                let d = GradientOptions {
                    starts: self.options.chains,
                    seed: self.options.seed,
                    ..GradientOptions::default()
                };
                self.run_hybrid(g.as_ref().unwrap_or(&d), report)
            }
            (SearchMethod::Anneal, _) => self.run(report),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::parse_design;

    fn problem() -> Problem {
        let path = format!(
            "{}/../../examples/optimize_curvature.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        Problem::new(&parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()).unwrap()
    }

    /// Each refusal names its option, and leaves the problem's options as they were.
    #[test]
    fn bad_requests_name_their_option() {
        let e = SearchMethod::parse("newton").unwrap_err();
        assert_eq!(e.place(), "method");
        assert!(e.to_string().contains("'newton'"), "{e}");
        assert!(e.to_string().contains("anneal, gradient, hybrid"), "{e}");
        let mut p = problem();
        let before = p.options.clone();
        let cases = [
            (SearchMethod::Gradient, None, None, None, Some(0), "starts"),
            (
                SearchMethod::Gradient,
                Some(0),
                None,
                None,
                None,
                "evaluations",
            ),
            (SearchMethod::Gradient, None, Some(2), None, None, "chains"),
            (SearchMethod::Gradient, None, None, Some(5), None, "polish"),
            (SearchMethod::Anneal, None, None, None, Some(2), "starts"),
            (
                SearchMethod::Anneal,
                Some(0),
                None,
                None,
                None,
                "evaluations",
            ),
            (
                SearchMethod::Anneal,
                Some(3),
                Some(4),
                None,
                None,
                "evaluations",
            ),
            (SearchMethod::Anneal, None, Some(0), None, None, "chains"),
            (SearchMethod::Hybrid, None, None, None, Some(2), "starts"),
            (
                SearchMethod::Hybrid,
                Some(1),
                Some(2),
                None,
                None,
                "evaluations",
            ),
        ];
        for (method, evaluations, chains, polish, starts, place) in cases {
            let r = SearchRequest {
                method,
                seed: Some(7),
                evaluations,
                chains,
                polish,
                starts,
            };
            let e = p.plan(&r).unwrap_err();
            assert_eq!(e.place(), place, "{r:?}: {e}");
            assert_eq!(p.options, before);
        }
    }

    /// What each option means for each method.
    #[test]
    fn requests_set_their_options() {
        let mut p = problem();
        let file = p.options.clone();
        let plan = p.plan(&SearchRequest::new(SearchMethod::Anneal)).unwrap();
        assert_eq!((plan.gradient, &p.options), (None, &file));
        let r = SearchRequest {
            seed: Some(9),
            evaluations: Some(40),
            chains: Some(2),
            polish: Some(0),
            ..SearchRequest::new(SearchMethod::Anneal)
        };
        p.plan(&r).unwrap();
        let o = &p.options;
        assert_eq!((o.seed, o.evaluations, o.chains, o.polish), (9, 40, 2, 0));
        assert_eq!(p.plan(&r).unwrap().evaluations(&p), 40);
        let mut p = problem();
        let r = SearchRequest {
            seed: Some(9),
            evaluations: Some(7),
            starts: Some(3),
            ..SearchRequest::new(SearchMethod::Gradient)
        };
        let plan = p.plan(&r).unwrap();
        let g = plan.gradient.clone().unwrap();
        assert_eq!((g.seed, g.evaluations, g.starts), (9, 7, 3));
        // --evaluations counts gradient evaluations: annealing's budget is untouched.
        assert_eq!(p.options.evaluations, file.evaluations);
        assert_eq!(plan.evaluations(&p), 21);
    }

    fn example(name: &str) -> Problem {
        let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
        Problem::new(&parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()).unwrap()
    }

    /// The hybrid's annealing stage is annealing's run (the same log), its gradient starts are
    /// the chains' best points, its counts are the two stages' sums, and its result is never
    /// worse than annealing's alone (`better`: feasible first, then the objective): a theorem
    /// of the construction, checked on §7.5 (bounds only) and on §7.5.2 (the ν = 0.8 equality),
    /// where the result is feasible.
    #[test]
    fn hybrid_is_never_worse_than_annealing_alone() {
        for (name, constrained) in [("optimize_curvature.toml", false), ("vesicle.toml", true)] {
            let anneal_request = SearchRequest {
                seed: Some(5),
                evaluations: Some(120),
                chains: Some(3),
                polish: Some(20),
                ..SearchRequest::new(SearchMethod::Anneal)
            };
            let mut a = example(name);
            let plan = a.plan(&anneal_request).unwrap();
            let anneal = a.run_search(&plan, &|_, _| {}).unwrap();
            let mut h = example(name);
            let plan = h
                .plan(&SearchRequest {
                    method: SearchMethod::Hybrid,
                    ..anneal_request
                })
                .unwrap();
            assert_eq!(plan.gradient.as_ref().unwrap().starts, 3);
            let hybrid = h.run_search(&plan, &|_, _| {}).unwrap();
            let n = anneal.search.log.len();
            assert_eq!(hybrid.search.log[..n], anneal.search.log[..], "{name}");
            assert!(hybrid.search.log[n..].iter().all(|r| r.phase == "gradient"));
            let g = hybrid.gradient.as_ref().unwrap();
            assert!((1..=3).contains(&g.starts.len()));
            let bounds = h.parameters.bounds();
            for s in &g.starts {
                let from_chain = anneal.search.chains.iter().any(|(x, _)| {
                    x.iter()
                        .zip(&s.x)
                        .zip(&bounds)
                        .all(|((a, b), (lo, hi))| (a - b).abs() <= 1e-12 * (hi - lo))
                });
                assert!(from_chain, "{name}: start {:?}", s.x);
            }
            assert_eq!(
                hybrid.search.evaluations,
                anneal.search.evaluations + g.evaluations
            );
            assert_eq!(hybrid.solves, anneal.solves + g.solves);
            assert!(
                !crate::optimize::sqp::better(&anneal.best.1, &hybrid.best.1),
                "{name}: annealing {:?} beats the hybrid {:?}",
                anneal.best.1,
                hybrid.best.1
            );
            if constrained {
                assert!(hybrid.best.1.feasible, "{:?}", hybrid.best.1.variables);
            }
        }
    }
}
