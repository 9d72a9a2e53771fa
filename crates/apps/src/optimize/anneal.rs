//! Simulated annealing (§7.3–7.4) over a box of parameters, in independent chains, followed by
//! a Nelder–Mead polish of the best point.
//!
//! One chain is the book's algorithm (§7.4.1): from the configuration `i` a move to a neighbour
//! `j` is proposed, accepted with probability 1 if `Δf_ij = f(j) − f(i) ≤ 0` and with
//! probability `e^{−Δf_ij/c}` otherwise (the Metropolis criterion, tested against a uniform
//! random number in `(0, 1)`); after `L` moves at one value of the control parameter it is
//! lowered by the exponential schedule of Eq. (7.3), `c_m = c_0 e^{(s−1)m}`, `0 < s < 1`.
//!
//! Choices the book leaves open:
//! - a move changes one parameter, drawn at random, by a uniform step in `[−δ_i, δ_i]`; after
//!   each level `δ_i` grows when more than 60 % of the level's moves were accepted and shrinks
//!   when fewer than 40 % were (Corana et al. 1987), within `[10⁻⁹, 1] · (max_i − min_i)`;
//! - `L = max(10, 2n)` moves per level for `n` parameters; unless `s` is given, it is chosen so
//!   that the last level of the budget runs at `c_0 · 10⁻⁵`;
//! - unless given, `c_0 = median(Δf⁺) / ln(1/0.8)` from `max(n, 5)` trial moves around the
//!   start, so that a typical uphill move is accepted with probability 0.8 at first (the median,
//!   not the mean, so that a few moves into a penalised region do not make it hot);
//! - bounds (§7.4.2): a point outside the box is not evaluated; its value is the crude penalty
//!   `P (1 + Σ_i violation_i / (max_i − min_i))` with `P = 10¹⁵`, which the Metropolis criterion
//!   never accepts and which tells Nelder–Mead the way back. Such points do not count as
//!   evaluations (they cost nothing), but they count as moves;
//! - an objective that returns NaN or +∞ (a design the solver refuses) is infeasible: treated as
//!   +∞, never accepted;
//! - every chain starts at the given start point (the designer's choice, as in §7.5.2); chain `k`
//!   draws its random numbers from ChaCha8 seeded with `seed`, stream `k`, so every chain
//!   and the whole result are the same whatever the number of threads.

use crate::{Error, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Value given to points outside the bounds (times `1 + relative violation`).
pub(crate) const BOUND_PENALTY: f64 = 1e15;

/// Options of [`minimize`].
#[derive(Clone, Debug, PartialEq)]
pub struct SearchOptions {
    /// Seed of the random numbers.
    pub seed: u64,
    /// Evaluations by annealing, all chains together.
    pub evaluations: usize,
    /// Independent chains.
    pub chains: usize,
    /// Evaluations of the Nelder–Mead polish (0: none).
    pub polish: usize,
    /// `s` of Eq. (7.3); `None`: chosen from the budget.
    pub cooling: Option<f64>,
    /// `c_0`; `None`: estimated from trial moves.
    pub temperature: Option<f64>,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            seed: 1,
            evaluations: 2000,
            chains: 4,
            polish: 200,
            cooling: None,
            temperature: None,
        }
    }
}

impl SearchOptions {
    /// Checks the options; errors name the `[optimize]` key.
    pub fn check(&self) -> Result<()> {
        crate::spec::limits::check_optimize_counts(self.evaluations, self.polish, self.chains)
            .map_err(|e| e.at("optimize"))?;
        if let Some(s) = self.cooling {
            if !(s > 0.0 && s < 1.0) {
                return Err(Error::invalid(format!("must satisfy 0 < s < 1 (got {s})"))
                    .at("optimize.cooling"));
            }
        }
        if let Some(c) = self.temperature {
            if !(c > 0.0 && c.is_finite()) {
                return Err(
                    Error::invalid(format!("must be positive and finite (got {c})"))
                        .at("optimize.temperature"),
                );
            }
        }
        Ok(())
    }
}

/// What happened at one evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// `anneal` or `polish`.
    pub phase: &'static str,
    /// The chain (the polish has the number of chains).
    pub chain: usize,
    /// Annealing level `m` (0 for the trial moves and the polish).
    pub level: usize,
    /// Control parameter `c_m` (0 for the trial moves and the polish).
    pub temperature: f64,
    /// The point.
    pub x: Vec<f64>,
    /// Its value (penalties included; +∞ for a failed evaluation).
    pub value: f64,
    /// Whether the move was accepted.
    pub accepted: bool,
    /// Best value of this chain so far.
    pub best: f64,
}

/// Result of [`minimize`].
#[derive(Clone, Debug)]
pub struct SearchResult {
    /// The best point found (after the polish).
    pub x: Vec<f64>,
    /// Its value.
    pub value: f64,
    /// The value at the start point.
    pub start_value: f64,
    /// Best point and value of every chain (before the polish).
    pub chains: Vec<(Vec<f64>, f64)>,
    /// Every evaluation: the chains in order, then the polish.
    pub log: Vec<Record>,
    /// Evaluations made (annealing and polish).
    pub evaluations: usize,
}

/// The objective with the bound penalty and failed evaluations mapped to +∞. `None` when the
/// point lies outside the box (value in the second slot).
fn bounded<F: Fn(&[f64]) -> f64>(f: &F, bounds: &[(f64, f64)], x: &[f64]) -> (bool, f64) {
    let mut violation = 0.0;
    for (&xi, &(lo, hi)) in x.iter().zip(bounds) {
        if xi < lo {
            violation += (lo - xi) / (hi - lo);
        } else if xi > hi {
            violation += (xi - hi) / (hi - lo);
        }
    }
    if violation > 0.0 {
        return (false, BOUND_PENALTY * (1.0 + violation));
    }
    let v = f(x);
    (true, if v.is_nan() { f64::INFINITY } else { v })
}

/// Shared progress: evaluations done and best value so far.
struct Progress<'a> {
    done: AtomicUsize,
    best: AtomicU64,
    report: &'a (dyn Fn(usize, f64) + Sync),
}

impl Progress<'_> {
    fn note(&self, value: f64) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let mut cur = self.best.load(Ordering::Relaxed);
        while value < f64::from_bits(cur) {
            match self.best.compare_exchange_weak(
                cur,
                value.to_bits(),
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => break,
                Err(c) => cur = c,
            }
        }
        (self.report)(done, f64::from_bits(self.best.load(Ordering::Relaxed)));
    }
}

struct ChainOut {
    best_x: Vec<f64>,
    best: f64,
    start_value: f64,
    step: Vec<f64>,
    log: Vec<Record>,
    evaluations: usize,
}

/// Minimises `f` over the box `bounds` by simulated annealing in `opts.chains` independent
/// chains (run in parallel) and a Nelder–Mead polish of the best point; see the module
/// documentation for the algorithm. `report(evaluations, best)` is called after every
/// evaluation, from any thread.
pub fn minimize<F: Fn(&[f64]) -> f64 + Sync>(
    f: &F,
    bounds: &[(f64, f64)],
    start: &[f64],
    opts: &SearchOptions,
    report: &(dyn Fn(usize, f64) + Sync),
) -> Result<SearchResult> {
    opts.check()?;
    if bounds.is_empty() || bounds.len() != start.len() {
        return Err(Error::invalid(format!(
            "{} bounds for {} start values",
            bounds.len(),
            start.len()
        )));
    }
    for (i, &(lo, hi)) in bounds.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::invalid(format!(
                "parameter {i}: bounds [{lo}, {hi}] must be finite with min < max"
            )));
        }
        if !(lo..=hi).contains(&start[i]) {
            return Err(Error::invalid(format!(
                "parameter {i}: start {} outside [{lo}, {hi}]",
                start[i]
            )));
        }
    }
    let progress = Progress {
        done: AtomicUsize::new(0),
        best: AtomicU64::new(f64::INFINITY.to_bits()),
        report,
    };
    let chains = opts.chains;
    let outs: Vec<ChainOut> = (0..chains)
        .into_par_iter()
        .map(|k| {
            let budget = opts.evaluations / chains + usize::from(k < opts.evaluations % chains);
            run_chain(f, bounds, start, opts, k, budget, &progress)
        })
        .collect();
    let mut best_k = 0;
    for (k, o) in outs.iter().enumerate() {
        if o.best < outs[best_k].best {
            best_k = k;
        }
    }
    let mut log = Vec::new();
    let mut evaluations = 0;
    for o in &outs {
        log.extend(o.log.iter().cloned());
        evaluations += o.evaluations;
    }
    let (mut x, mut value) = (outs[best_k].best_x.clone(), outs[best_k].best);
    if opts.polish > 0 && value.is_finite() {
        let steps: Vec<f64> = outs[best_k]
            .step
            .iter()
            .zip(bounds)
            .map(|(s, (lo, hi))| s.clamp(1e-6 * (hi - lo), 0.1 * (hi - lo)))
            .collect();
        let mut used = 0;
        let g = |p: &[f64]| -> f64 {
            let (inside, v) = bounded(f, bounds, p);
            if inside {
                progress.note(v);
            }
            v
        };
        let (px, pv, plog) = nelder_mead(&g, &x, value, &steps, opts.polish, &mut used);
        evaluations += used;
        for (p, v, best) in plog {
            log.push(Record {
                phase: "polish",
                chain: chains,
                level: 0,
                temperature: 0.0,
                x: p,
                value: v,
                accepted: v <= best,
                best,
            });
        }
        if pv < value {
            x = px;
            value = pv;
        }
    }
    Ok(SearchResult {
        x,
        value,
        start_value: outs[0].start_value,
        chains: outs.iter().map(|o| (o.best_x.clone(), o.best)).collect(),
        log,
        evaluations,
    })
}

fn run_chain<F: Fn(&[f64]) -> f64>(
    f: &F,
    bounds: &[(f64, f64)],
    start: &[f64],
    opts: &SearchOptions,
    k: usize,
    budget: usize,
    progress: &Progress<'_>,
) -> ChainOut {
    let n = bounds.len();
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    rng.set_stream(k as u64);
    let mut x: Vec<f64> = if k == 0 {
        start.to_vec()
    } else {
        bounds
            .iter()
            .map(|&(lo, hi)| rng.gen_range(lo..=hi))
            .collect()
    };
    let mut step: Vec<f64> = bounds.iter().map(|(lo, hi)| 0.25 * (hi - lo)).collect();
    let mut log = Vec::new();
    let mut evaluations = 0;
    let mut moves = 0;
    let max_moves = budget.saturating_mul(20);
    // One evaluation, noted in the log and the progress.
    let eval = |p: &[f64], evaluations: &mut usize| -> (bool, f64) {
        let (inside, v) = bounded(f, bounds, p);
        if inside {
            *evaluations += 1;
            progress.note(v);
        }
        (inside, v)
    };
    let mut fx = eval(&x, &mut evaluations).1;
    let start_value = fx;
    let (mut best_x, mut best) = (x.clone(), fx);
    log.push(Record {
        phase: "anneal",
        chain: k,
        level: 0,
        temperature: 0.0,
        x: x.clone(),
        value: fx,
        accepted: true,
        best,
    });
    let propose = |x: &[f64], step: &[f64], rng: &mut ChaCha8Rng| -> Vec<f64> {
        let i = rng.gen_range(0..n);
        let mut y = x.to_vec();
        y[i] += step[i] * rng.gen_range(-1.0..=1.0);
        y
    };
    // Trial moves for c_0 (greedy: an improvement is kept).
    let c0 = match opts.temperature {
        Some(c) => c,
        None => {
            let trials = n.max(5).min(budget.saturating_sub(evaluations) / 4);
            let mut uphill = Vec::new();
            let mut tried = 0;
            while tried < trials && evaluations < budget && moves < max_moves {
                let y = propose(&x, &step, &mut rng);
                moves += 1;
                let (inside, fy) = eval(&y, &mut evaluations);
                if !inside {
                    continue;
                }
                tried += 1;
                let d = fy - fx;
                if d.is_finite() && d > 0.0 {
                    uphill.push(d);
                }
                let accepted = fy < fx;
                if accepted {
                    x = y.clone();
                    fx = fy;
                    if fx < best {
                        best = fx;
                        best_x = x.clone();
                    }
                }
                log.push(Record {
                    phase: "anneal",
                    chain: k,
                    level: 0,
                    temperature: 0.0,
                    x: y,
                    value: fy,
                    accepted,
                    best,
                });
            }
            if !uphill.is_empty() {
                uphill.sort_by(f64::total_cmp);
                let m = uphill.len();
                let median = if m % 2 == 1 {
                    uphill[m / 2]
                } else {
                    0.5 * (uphill[m / 2 - 1] + uphill[m / 2])
                };
                median / (1.0f64 / 0.8).ln()
            } else {
                0.1 * fx.abs().max(1.0)
            }
        }
    };
    let per_level = (2 * n).max(10);
    let levels = ((budget.saturating_sub(evaluations)) / per_level).max(1);
    let s = opts
        .cooling
        .unwrap_or_else(|| 1.0 + (1e-5f64).ln() / levels as f64);
    let mut m = 0usize;
    while evaluations < budget && moves < max_moves {
        let c = c0 * ((s - 1.0) * m as f64).exp();
        let mut accepted_here = vec![0usize; n];
        let mut tried_here = vec![0usize; n];
        let mut done = 0;
        while done < per_level && evaluations < budget && moves < max_moves {
            let i = rng.gen_range(0..n);
            let mut y = x.clone();
            y[i] += step[i] * rng.gen_range(-1.0..=1.0);
            moves += 1;
            let (inside, fy) = eval(&y, &mut evaluations);
            if inside {
                done += 1;
            }
            tried_here[i] += 1;
            // The Metropolis criterion; a random number is drawn for every move so that the
            // stream does not depend on the values. A failed point (+∞) is accepted only from
            // another failed point (a walk out of an infeasible region), a point outside the
            // bounds never.
            let r: f64 = rng.gen();
            let accepted = inside
                && if fx.is_infinite() {
                    true
                } else if fy.is_infinite() {
                    false
                } else {
                    let d = fy - fx;
                    d <= 0.0 || (-d / c).exp() > r
                };
            if accepted {
                accepted_here[i] += 1;
                x = y.clone();
                fx = fy;
                if fx < best {
                    best = fx;
                    best_x = x.clone();
                }
            }
            if inside {
                log.push(Record {
                    phase: "anneal",
                    chain: k,
                    level: m + 1,
                    temperature: c,
                    x: y,
                    value: fy,
                    accepted,
                    best,
                });
            }
        }
        // Step control per parameter (Corana et al.).
        for i in 0..n {
            if tried_here[i] == 0 {
                continue;
            }
            let ratio = accepted_here[i] as f64 / tried_here[i] as f64;
            let range = bounds[i].1 - bounds[i].0;
            if ratio > 0.6 {
                step[i] *= 1.0 + 2.0 * (ratio - 0.6) / 0.4;
            } else if ratio < 0.4 {
                step[i] /= 1.0 + 2.0 * (0.4 - ratio) / 0.4;
            }
            step[i] = step[i].clamp(1e-9 * range, range);
        }
        m += 1;
    }
    ChainOut {
        best_x,
        best,
        start_value,
        step,
        log,
        evaluations,
    }
}

/// Nelder–Mead (1965) from `x0` (value `f0`) with the initial simplex `x0 + steps_i e_i`,
/// coefficients reflection 1, expansion 2, contraction ½, shrink ½, for at most `budget`
/// evaluations (counted in `used`) or until the simplex's values agree to 10⁻¹⁴ relative.
/// Returns the best vertex, its value and `(point, value, best so far)` for every evaluation.
#[allow(clippy::type_complexity)]
pub fn nelder_mead<G: Fn(&[f64]) -> f64>(
    g: &G,
    x0: &[f64],
    f0: f64,
    steps: &[f64],
    budget: usize,
    used: &mut usize,
) -> (Vec<f64>, f64, Vec<(Vec<f64>, f64, f64)>) {
    let n = x0.len();
    let mut log = Vec::new();
    let mut best_seen = f0;
    let mut call = |p: &[f64], used: &mut usize, log: &mut Vec<(Vec<f64>, f64, f64)>| -> f64 {
        *used += 1;
        let v = g(p);
        let v = if v.is_nan() { f64::INFINITY } else { v };
        if v < best_seen {
            best_seen = v;
        }
        log.push((p.to_vec(), v, best_seen));
        v
    };
    let mut simplex: Vec<(Vec<f64>, f64)> = vec![(x0.to_vec(), f0)];
    for i in 0..n {
        if *used >= budget {
            break;
        }
        let mut p = x0.to_vec();
        p[i] += steps[i];
        let v = call(&p, used, &mut log);
        simplex.push((p, v));
    }
    if simplex.len() < n + 1 {
        let (x, v) = simplex
            .into_iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((x0.to_vec(), f0));
        return (x, v, log);
    }
    let at = |c: &[f64], w: &[f64], t: f64| -> Vec<f64> {
        c.iter().zip(w).map(|(ci, wi)| ci + t * (wi - ci)).collect()
    };
    while *used < budget {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (lo, hi) = (simplex[0].1, simplex[n].1);
        if hi.is_finite() && (hi - lo).abs() <= 1e-14 * lo.abs().max(1e-300) {
            break;
        }
        let mut centroid = vec![0.0; n];
        for (p, _) in &simplex[..n] {
            for (c, x) in centroid.iter_mut().zip(p) {
                *c += x / n as f64;
            }
        }
        let worst = simplex[n].0.clone();
        let xr = at(&centroid, &worst, -1.0);
        let fr = call(&xr, used, &mut log);
        if fr < simplex[0].1 {
            if *used >= budget {
                simplex[n] = (xr, fr);
                break;
            }
            let xe = at(&centroid, &worst, -2.0);
            let fe = call(&xe, used, &mut log);
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            if *used >= budget {
                break;
            }
            // Outside contraction if the reflected point beats the worst, inside otherwise.
            let (xc, fc) = if fr < simplex[n].1 {
                let xc = at(&centroid, &xr, 0.5);
                let fc = call(&xc, used, &mut log);
                (xc, fc)
            } else {
                let xc = at(&centroid, &worst, 0.5);
                let fc = call(&xc, used, &mut log);
                (xc, fc)
            };
            if fc < fr.min(simplex[n].1) {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best vertex.
                let best = simplex[0].0.clone();
                for vertex in simplex.iter_mut().skip(1) {
                    if *used >= budget {
                        break;
                    }
                    let p = at(&best, &vertex.0, 0.5);
                    let v = call(&p, used, &mut log);
                    *vertex = (p, v);
                }
            }
        }
    }
    let (x, v) = simplex
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((x0.to_vec(), f0));
    (x, v, log)
}
